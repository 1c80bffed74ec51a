"""The command line: renders valid PNGs, validates files, and rejects bad input clearly."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import krsview
from krsview import files
from krsview.cli import main

from .conftest import krsview_cli


def test_render_writes_png_of_requested_size_and_buffers(tmp_path):
    out, npz = tmp_path / "a.png", tmp_path / "a.npz"
    r = krsview_cli(
        "render",
        "sierpinski",
        "-o",
        str(out),
        "--size",
        "96x64",
        "--buffers",
        str(npz),
        "--repeats",
        "1",
    )
    assert r.returncode == 0, r.stderr
    assert "frame time" in r.stdout and str(out) in r.stdout
    im = Image.open(out)
    assert im.size == (96, 64) and im.mode == "RGB"
    b = np.load(npz)
    assert b["depth"].shape == (64, 96) and b["hit"].any() and np.isfinite(b["normal"]).all()


def test_reference_render_matches_size(tmp_path):
    out = tmp_path / "r.png"
    assert main(["render", "sierpinski", "-o", str(out), "--size", "40x30", "--reference"]) == 0
    assert Image.open(out).size == (40, 30)


@pytest.mark.parametrize(
    "args, message",
    [
        (["render", "tree", "--size", "640"], "expected WIDTHxHEIGHT"),
        (["render", "tree", "--size", "0x10"], "each side must be 1..8192"),
        # a window needs room for its image and HUD; the control: 64x48 opens (test_playback)
        (["view", "tree", "--size", "10x10"], "--size '10x10': each side must be 48..8192"),
        (["edit", "tree", "--size", "47x200"], "--size '47x200': each side must be 48..8192"),
        # the latency bench opens the editor's window: its range, said as every --size is
        (["bench", "latency", "tree", "--size", "8x4"], "--size '8x4': each side must be 48..8192"),
        (
            ["render", "tree", "--epsilon-scale", "nan"],
            "--epsilon-scale = nan: NaN and infinity are "
            "not allowed; allowed: 0.0001 ≤ value ≤ 100",
        ),
        (
            ["render", "tree", "--epsilon-scale", "0"],
            "--epsilon-scale = 0: allowed: 0.0001 ≤ value",
        ),
        (
            ["render", "tree", "--max-iterations", "-3"],
            "--max-iterations = -3: allowed: 1 ≤ value ≤ 10000",
        ),
        (["render", "tree", "--tracer", "bent"], "--tracer = 'bent': allowed: 'sphere', 'binary'"),
        (["check", "sierpinsky"], "not a file and not a preset; did you mean `sierpinski`?"),
        # options this run would ignore (they were taken and did nothing)
        (["render", "rock", "--steps", "5"], "--steps = 5: applies to --path compute"),
        (["render", "rock", "--reference", "--prepass", "4"], "no effect with --reference"),
        (["render", "rock", "--reference", "--shadow-block", "2"], "no effect with --reference"),
        (["check", "Tree"], "did you mean `tree` or"),
        (["check", ""], "PRESET = '': expected a preset's name or a scene file (.toml)"),
        (
            ["render", "no-such-preset"],
            "not a file and not a preset; presets: bent-tree, forest, grass, grove",
        ),
        (["render", "tree", "--levels", "40"], "this scene has 23 levels"),
        (["render", "tree", "--time", "-2"], "--time = -2.0: a time in seconds; allowed 0..1e+06"),
        (["render", "tree", "--time", "nan"], "--time = nan: a time in seconds"),
        (["render", "tree", "--time", "soon"], "--time: invalid float value: 'soon'"),
        (["check", "missing.toml"], "no such scene file"),
        (["frobnicate"], "invalid choice"),
        # values starting with '-' reach the option's own check (not "expected one argument")
        (["render", "tree", "--size", "-5x3"], "--size '-5x3': each side must be 1..8192"),
        (["render", "tree", "--epsilon-scale", "-inf"], "--epsilon-scale = -inf: NaN and infinity"),
        # outputs are checked before the render runs
        (["render", "tree", "-o", "x.jpg"], "-o = 'x.jpg': the file must end in .png"),
        (["bench", "zoom", "tree", "--plot", "z.txt"], "--plot = 'z.txt': the file must end in"),
        (["render", "tree", "-o", "/tmp"], "-o = '/tmp': the file must end in .png"),
        (
            ["render", "tree", "-o", "/proc/no/such.png"],
            "-o = '/proc/no/such.png': cannot write there",
        ),
        # a name past the system's limit was refused only when the image was written
        (["render", "tree", "-o", "a" * 300 + ".png"], "a file name of 304 bytes; allowed: at"),
        (
            ["render", "tree", "--buffers", "x.txt"],
            "--buffers = 'x.txt': the file must end in .npz",
        ),
        (["bench", "levels", "tree", "--csv", "/tmp"], "--csv = '/tmp': the file must end in .csv"),
        (
            ["check", "tree.toml"],
            "no such scene file; the preset of that name is `tree` (no .toml)",
        ),
        (["check", "/tmp"], "'/tmp': is a folder"),
        # options this run would ignore: accepted silently, they seemed to take effect [review]
        (["render", "tree", "--fps", "60"], "--fps = 60.0: needs --camera-path FILE"),
        (["render", "tree", "--legend-max", "50"], "--legend-max = 50: needs --view iterations"),
        (
            ["render", "tree", "--relaxation", "1.5"],
            "--relaxation = 1.5: applies to --tracer relaxed (this run traces sphere)",
        ),
        (
            ["render", "tree", "--walk-restart", "on", "--tracer", "binary"],
            "--walk-restart = 'on': applies to --tracer sphere (this run traces binary)",
        ),
        (["render", "tree", "--reference", "--repeats", "3"], "--repeats = 3: has no effect with"),
        (["render", "tree", "--reference", "--path", "compute"], "--path = 'compute': has no"),
        (["check", "tree", "--segments", "10"], "--segments = 10: needs --oracle"),
        (["render", "tree", "--effects", ""], "--effects = '': give effects by name, or 'none'"),
        (
            ["bench", "accuracy", "tree", "--cache", "/proc/no/cache"],
            "--cache = '/proc/no/cache': cannot write there",
        ),
        (["check", "tree", "--size", "10x10"], "--size = '10x10': needs --stability or --oracle"),
    ],
)
def test_bad_arguments_exit_nonzero_with_a_clear_message(args, message):
    r = krsview_cli(*args)
    assert r.returncode != 0
    assert message in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert "frame time" not in r.stdout  # refused before any work


def test_an_options_mistake_is_one_line():
    """argparse's usage block (15 lines for `render`) no longer comes before the mistake."""
    r = krsview_cli("render", "tree", "--lod", "-1")
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "--lod = -1: allowed: 0 ≤ value ≤ 8 ε" in r.stderr and "--help" in r.stderr


def test_ctrl_c_a_full_disk_and_a_closed_pipe_end_in_one_line(tmp_path, monkeypatch, capsys):
    import os
    import signal
    import time

    p = subprocess.Popen(
        [sys.executable, "-m", "krsview", "render", "tree", "--size", "320x180"]
        + ["--repeats", "500", "-o", str(tmp_path / "a.png")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "DISPLAY": ""},
    )
    assert "krsview: tree" in p.stdout.readline()  # working now
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 130 and err.strip() == "krsview: interrupted", err
    assert not (tmp_path / "a.png").exists()

    def full(*args, **kw):
        raise OSError(28, "No space left on device", str(tmp_path / "b.png"))

    monkeypatch.setattr(files.os, "fsync", full)  # the encoded image meets a full disk
    capsys.readouterr()
    assert (
        main(["render", "rock", "--size", "16x9", "--repeats", "1", "-o", str(tmp_path / "b.png")])
        == 3
    )
    assert (
        capsys.readouterr().err
        == f"krsview: error: {tmp_path / 'b.png'}: No space left on device\n"
    )
    monkeypatch.undo()

    read, write = os.pipe()
    os.close(read)  # `| head` gone
    closed = os.fdopen(write, "w")
    monkeypatch.setattr(sys, "stdout", closed)
    assert main(["check", "palm"]) == 1
    assert "Traceback" not in capsys.readouterr().err
    closed.close()  # main put /dev/null under it: what was left goes nowhere, quietly


def test_version():
    r = krsview_cli("--version")
    assert r.returncode == 0 and r.stdout.strip().startswith("krsview 0.")


def test_bad_scene_file_gets_file_field_value(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("[tree]\nlevels = 12\nbranch_angle = -5.0\n")
    r = krsview_cli("check", str(bad))
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert f"{bad}: tree.branch_angle = -5.0: allowed: 0 ≤ value ≤ 89 degrees" in r.stderr


def test_check_prints_statistics(capsys):
    assert main(["check", "tree"]) == 0
    out = capsys.readouterr().out
    assert "levels          23" in out and "8,388,607" in out
    assert "effects         kernel_texture, soft_shadows, sky, tone_mapping" in out
    assert "moves" not in out  # a still scene
    assert main(["check", "palm-curl"]) == 0
    assert "moves           30 keyframe tracks — loop 4 s" in capsys.readouterr().out
    assert main(["check", "tree-sway"]) == 0
    assert "moves           sway of 3 levels, 4° at 0.4 Hz — loop" in capsys.readouterr().out
    assert main(["check", "tree-wind"]) == 0
    assert "moves           wind — loop 12 s" in capsys.readouterr().out


def test_bench_levels_prints_the_ratio_table(capsys):
    assert (
        main(["bench", "levels", "sierpinski", "--size", "48x32", "--rounds", "1", "--step", "8"])
        == 0
    )
    out = capsys.readouterr().out
    assert "| levels | kernel instances |" in out
    rows = [line for line in out.splitlines() if line.startswith("| ") and line[2].isdigit()]
    assert [int(r.split("|")[1]) for r in rows] == [8, 16, 22]
    assert rows[0].split("|")[4].strip() == "1.00×"  # the smallest level count is the unit


def test_view_without_a_display_says_what_to_do():
    import os

    r = subprocess.run(
        [sys.executable, "-m", "krsview", "view", "tree"],
        capture_output=True,
        text=True,
        timeout=60,
        env={k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")},
    )
    assert r.returncode == 3 and "Traceback" not in r.stderr
    assert r.stderr.strip() == (
        "krsview: error: cannot open a window: GLFW found no display "
        "(is DISPLAY set? use `krsview render` to render headless)"
    )


@pytest.mark.parametrize("tracer", ["sphere", "binary"])
def test_iterations_view_writes_a_heat_map_with_legend(tmp_path, tracer):
    from krsview.heatmap import LEGEND_HEIGHT, heat

    out, npz = tmp_path / "it.png", tmp_path / "b.npz"
    r = krsview_cli(
        "render",
        "tree",
        "--view",
        "iterations",
        "--tracer",
        tracer,
        "--legend-max",
        "60",
        "-o",
        str(out),
        "--size",
        "96x64",
        "--buffers",
        str(npz),
        "--repeats",
        "1",
    )
    assert r.returncode == 0, r.stderr
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    assert img.shape == (64 + LEGEND_HEIGHT, 96, 3)
    it = np.load(npz)["iterations"]
    want = np.round(heat(it / 60) * 255)
    assert np.abs(img[:64] - want).max() <= 1  # the image is the iteration count
    assert img[64:].max() >= 250 and img[64:].min() <= 40  # the legend's bar runs dark → white
    assert "iterations per pixel: median" in r.stdout


def test_heat_ramp_runs_from_black_to_white_and_brightens():
    """Every count must map to a distinct brightness: no flat white top of the scale."""
    from krsview.heatmap import heat

    x = np.linspace(0, 1, 101)
    lum = heat(x) @ [0.2126, 0.7152, 0.0722]
    assert np.allclose(heat(np.array([0.0, 1.0])), [[0, 0, 0], [1, 1, 1]])
    assert (np.diff(lum) > 0).all()


def test_sphere_tracer_on_a_mokrs_is_refused():
    r = krsview_cli("render", "palm", "--tracer", "sphere", "-o", "/tmp/never.png")
    assert r.returncode == 2
    assert "--tracer = 'sphere': this scene is a MöKRS" in r.stderr


def test_bench_tracers_prints_ratios_and_best_pair(capsys):
    from krsview.cli import main

    assert main(["bench", "tracers", "tree", "--size", "32x24", "--rounds", "1"]) == 0
    out = capsys.readouterr().out
    assert "| sphere |" in out and "| binary | 2.0 | 0.3 |" in out
    assert out.count("| binary |") == 9 and "fastest ξ pair:" in out


def test_every_complete_scene_in_the_readme_renders_something(renderer):
    """The README's scene examples (those with a camera) load and draw: an example that
    passes `check` but shows an empty sky teaches nothing."""
    from krsview.scene import scene_from_toml

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    blocks = [b.split("```")[0] for b in readme.split("```toml\n")[1:]]
    complete = [b for b in blocks if "[camera]" in b]
    assert len(complete) >= 2  # the KRS and the MöKRS examples
    for text in complete:
        scene = scene_from_toml(text, "README.md")
        assert renderer.render(scene, 64, 36).hit.mean() > 0.01, scene.name
    # negative control: the MöKRS example looking the other way shows an empty sky
    mokrs = next(b for b in complete if "[[mokrs.levels]]" in b)
    away = mokrs.replace("target = [0.0, 0.5, 0.0]", "target = [0.0, 2.0, -20.0]")
    assert away != mokrs
    assert renderer.render(scene_from_toml(away, "README.md"), 64, 36).hit.mean() == 0


def test_progress_reporting_does_not_change_the_image(renderer, monkeypatch):
    """Slow renders show progress: the reference in chunks of rays, the GPU's first frame in
    bands of rows; the pixels are the same as in one piece, and progress reaches the end."""
    from krsview.reference import render as reference_render
    from krsview.scene import load_scene
    from krsview.scene.presets import resolve

    scene = load_scene(resolve("sierpinski"))
    monkeypatch.setattr(reference_render, "PROGRESS_CHUNK", 100)
    calls: list = []
    whole = reference_render.render_reference(scene, 24, 10)
    chunked = reference_render.render_reference(
        scene, 24, 10, progress=lambda d, n: calls.append((d, n))
    )
    assert calls[-1] == (240, 240) and len(calls) == 3
    for name in ("color", "depth", "normal", "iterations", "hit"):
        assert np.array_equal(getattr(whole, name), getattr(chunked, name)), name
    calls.clear()
    one = renderer.render(scene, 40, 20)
    from dataclasses import replace

    away = replace(
        scene,
        camera=replace(
            scene.camera,
            target=tuple(2 * np.array(scene.camera.position) - np.array(scene.camera.target)),
        ),
    )
    assert not renderer.render(away, 40, 20).hit.any()  # the framebuffer now holds sky
    banded = renderer.render(scene, 40, 20, progress=lambda d, n: calls.append((d, n)))
    assert calls[-1] == (16, 16)
    assert np.array_equal(one.color, banded.color) and np.array_equal(one.hit, banded.hit)
    assert one.hit.any() and not one.hit.all()


def test_check_stability_prints_the_table_and_fails_when_an_invariant_does(capsys, monkeypatch):
    assert main(["check", "--stability", "hard:points-on-planes"]) == 0
    out = capsys.readouterr().out
    assert "| points-on-planes | 3% | yes | yes | 0 / 0 |" in out and out.rstrip().endswith(
        "| ok |"
    )
    from krsview.bench import stability

    monkeypatch.setattr(stability, "CONTINUITY", -1.0)  # no image can meet this
    assert main(["check", "--stability", "sierpinski"]) == 1
    assert capsys.readouterr().out.rstrip().endswith("| FAILS |")
    assert main(["check", "--stability", "hard:nope"]) == 2


def test_check_oracle_prints_certified_counts(capsys):
    assert main(["check", "--oracle", "sierpinski", "--size", "24x14"]) == 0
    out = capsys.readouterr().out
    hits = int(krsview.render("sierpinski", (24, 14)).hit.sum())  # the image it certifies
    assert f"| sphere | 336 | {hits} | 0 | 0 | 0 | 0 |" in out and "| binary | 336 |" in out
    # a budget of one segment per ray decides only rays whose whole segment clears at once
    assert main(["check", "--oracle", "sierpinski", "--size", "24x14", "--segments", "1"]) == 0
    row = capsys.readouterr().out.splitlines()[2].split("|")
    assert int(row[7]) > 0  # the undecided column
    assert main(["check", "--oracle", "hard:twist-ground"]) == 2
    assert "the oracle covers scenes without twist or empty zones" in capsys.readouterr().err


def test_every_render_option_takes_its_range_and_help_from_the_schema(capsys):
    """Each [render] knob `render` offers accepts its field's bounds and refuses a value just
    beyond them with the schema's own words; its help is the field's help (docs/architecture.md, one
    schema). Negative control: an option's value outside the range exits 2."""
    from dataclasses import fields

    from krsview.cli import build_parser
    from krsview.cli.render import KNOBS
    from krsview.scene import Render
    from krsview.scene.schema import describe_range

    parser = build_parser()
    for f in fields(Render):
        meta, flag = f.metadata, "--" + f.name.replace("_", "-")
        if f.name not in KNOBS:
            continue
        if meta["choices"]:
            for choice in meta["choices"]:
                assert getattr(parser.parse_args(["render", flag, choice]), f.name) == choice
            continue
        kind = int if f.name == "prepass" else type(f.default)  # prepass: int | None
        for bound in (meta["lo"], meta["hi"]):
            assert getattr(parser.parse_args(["render", flag, str(kind(bound))]), f.name) == bound
        with pytest.raises(SystemExit):
            parser.parse_args(["render", f"{flag}={kind(meta['hi']) + 1}"])
        assert describe_range(dict(meta), kind) in capsys.readouterr().err
    help_text = " ".join(
        parser._subparsers._group_actions[0].choices["render"].format_help().split()
    )
    assert all(
        " ".join(f.metadata["help"].split()) in help_text for f in fields(Render) if f.name in KNOBS
    )


def test_view_options_come_from_the_settings_fields(capsys):
    from dataclasses import fields

    from krsview.cli import build_parser
    from krsview.scene import Render
    from krsview.scene.schema import describe_range

    parser = build_parser()
    view = parser.parse_args(["view"])
    assert (view.size, view.target_fps, view.prepass, view.hud, view.moving_effects) == (
        (960, 540),
        30.0,
        None,
        True,
        False,
    )
    assert parser.parse_args(["edit"]).size == (1280, 720)
    v = parser.parse_args(["view", "--no-hud", "--moving-effects", "--fps", "60", "--prepass", "8"])
    assert (v.hud, v.moving_effects, v.target_fps, v.prepass) == (False, True, 60.0, 8)
    prepass = next(f for f in fields(Render) if f.name == "prepass")
    with pytest.raises(SystemExit):  # the pre-pass tile's range is the scene schema's
        parser.parse_args(["view", "--prepass", str(prepass.metadata["hi"] + 1)])
    assert describe_range(dict(prepass.metadata), int) in capsys.readouterr().err
    with pytest.raises(SystemExit):
        parser.parse_args(["view", "--fps", "0.5"])
    assert "--fps = 0.5: allowed: 1 ≤ value ≤ 240" in capsys.readouterr().err
    with pytest.raises(SystemExit):  # a number is said as it was typed: 0, not 0.0
        parser.parse_args(["view", "--fps", "0"])
    assert "--fps = 0: allowed" in capsys.readouterr().err


def test_render_draws_fast_unless_exact(tmp_path, capsys):
    """`render` draws with the pre-pass and the level of detail unless --exact; --exact
    with either knob is refused in one line, and so is a level of detail out of range."""
    out = tmp_path / "a.png"
    fast = tmp_path / "fast.npz"
    exact = tmp_path / "exact.npz"
    base = ["render", "rock", "--size", "32x18", "--repeats", "1", "-o", str(out)]
    assert main([*base, "--buffers", str(fast)]) == 0
    assert main([*base, "--exact", "--buffers", str(exact)]) == 0
    f, e = np.load(fast), np.load(exact)
    plain = krsview.render("rock", (32, 18), prepass=0, lod=0.0, shadow_block=1)
    assert np.array_equal(e["color"], plain.color)
    assert f["iterations"].sum() < e["iterations"].sum()  # the pre-pass spared steps
    capsys.readouterr()
    assert main([*base, "--exact", "--lod", "1"]) == 2
    assert "--lod = 1.0: cannot be combined with --exact" in capsys.readouterr().err
    assert main([*base, "--exact", "--shadow-cone", "on"]) == 2  # named as it is typed
    assert "--shadow-cone = 'on': cannot be combined with --exact" in capsys.readouterr().err
    with pytest.raises(SystemExit) as bad:
        main([*base, "--lod", "-1"])
    assert bad.value.code == 2
    assert "--lod = -1: allowed: 0 ≤ value ≤ 8 ε" in capsys.readouterr().err


def test_written_files_are_said_by_their_whole_path(tmp_path):
    r = krsview_cli(
        "bench", "zoom", "tree", "--size", "16x9", "--rounds", "1", "--stops", "2",
        "--plot", "z.png", "--csv", "z.csv", cwd=tmp_path,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert f"wrote {tmp_path / 'z.png'}" in lines and f"wrote {tmp_path / 'z.csv'}" in lines
    assert (tmp_path / "z.png").stat().st_size > 1000
