"""The Python API (krsview/__init__.py): loading, editing, rendering to arrays, checking,
and a wheel that works outside the checkout. Compared with the layers underneath (the GPU
renderer, the scene file read by tomllib, the closed forms of instance counts)."""

from __future__ import annotations

import doctest
import io
import os
import subprocess
import sys
import threading
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import krsview
from krsview.gpu.renderer import Renderer as GpuRenderer
from krsview.scene.presets import resolve
from krsview.scene.scene import scene_from_toml, scene_to_toml

from .conftest import same

SIZE = (40, 24)


def test_load_dict_reads_what_a_file_holds():
    """A preset's TOML tables given as a dict make the scene the file makes."""
    for name in ("tree", "grove", "palm"):
        data = tomllib.loads(resolve(name).read_text())
        assert krsview.load_dict(data) == krsview.load(name)
    # negative control: a changed value makes another scene
    data = tomllib.loads(resolve("tree").read_text())
    data["render"]["epsilon_scale"] = 0.25
    assert krsview.load_dict(data) != krsview.load("tree")


def test_bad_input_is_one_line_naming_source_field_and_what_is_allowed():
    with pytest.raises(krsview.SceneError) as e:
        krsview.load_dict({"krs": {"levels": [{"kernel": {"type": "sphere", "radius": -1}}]}})
    text = str(e.value)
    assert text.startswith("<dict>: krs.levels[0].kernel.radius = -1") and "\n" not in text
    with pytest.raises(krsview.SceneError, match="'no-such-preset': not a file and not a preset"):
        krsview.load("no-such-preset")
    with pytest.raises(krsview.SceneError, match=r"^name_or_path = 'trea': .* mean `tree`"):
        krsview.load("trea")  # the argument's name, not the command line's PRESET
    scene = krsview.load("tree")
    with pytest.raises(krsview.SceneError, match=r"render.tracer = 'fast': allowed: 'sphere'"):
        scene.edit("render.tracer", "fast")
    with pytest.raises(krsview.SceneError, match="not a render knob"):
        krsview.render(scene, SIZE, epsilon=0.5)
    with pytest.raises(krsview.SceneError, match="allowed 1..23"):
        krsview.render(scene, SIZE, levels=40)
    with pytest.raises(krsview.SceneError, match="width = 0"):
        krsview.Renderer(0, 10)


def test_edit_returns_a_new_validated_scene_and_leaves_the_old_one():
    scene = krsview.load("bent-tree")
    moved = scene.edit("route.levels[2].fork", (0.1, 2.0, 0.3))
    assert moved.route.levels[2].fork == (0.1, 2.0, 0.3)
    assert scene.route.levels[2].fork != (0.1, 2.0, 0.3)
    assert moved.edit(("route", "levels", 2, "fork"), scene.route.levels[2].fork) == scene
    # the schema normalises as a file does: a mirror normal becomes a unit vector
    turned = scene.edit("route.levels[1].normal", (2.0, 0.0, 0.0))
    assert turned.route.levels[1].normal == (1.0, 0.0, 0.0)


def test_render_is_the_gpu_renderers_image_and_knobs_are_edits():
    scene = krsview.load("rock")
    frame = krsview.render(scene, SIZE)
    direct = GpuRenderer().render(
        krsview.api.fast_settings(scene, krsview.api.on_hardware()), *SIZE
    )
    for name in ("color", "depth", "normal", "iterations", "hit"):
        assert np.array_equal(getattr(frame, name), getattr(direct, name)), name
    assert frame.size == SIZE and frame.color.shape == (SIZE[1], SIZE[0], 3)
    knobbed = krsview.render("rock", SIZE, epsilon_scale=4.0, levels=5)
    edited = krsview.render(scene.edit("render.epsilon_scale", 4.0).with_levels(5), SIZE)
    assert np.array_equal(knobbed.color, edited.color)
    # negative control: the knobs change the image
    assert not np.array_equal(knobbed.color, frame.color)
    # exact: every level, no pre-pass, as the scene would be drawn without the fast settings
    exact = krsview.render(scene, SIZE, exact=True)
    plain = GpuRenderer().render(
        krsview.configure(scene, prepass=0, lod=0.0, shadow_block=1), *SIZE
    )
    assert np.array_equal(exact.color, plain.color)
    assert not np.array_equal(exact.iterations, frame.iterations)  # the pre-pass saves steps


def test_reference_render_agrees_with_the_gpu():
    scene = krsview.load("sierpinski")
    gpu = krsview.render(scene, SIZE, exact=True)
    ref = krsview.render(scene, SIZE, reference=True, exact=True)
    assert (gpu.hit == ref.hit).mean() > 0.98
    both = gpu.hit & ref.hit
    assert np.abs(gpu.color[both] - ref.color[both]).max() < 0.05


def test_a_renderer_keeps_its_variants():
    with krsview.Renderer(*SIZE) as r:
        r.render(krsview.load("tree"), levels=8)
        compiled = r.gpu.programs.compiles
        r.render(krsview.load("tree").edit("camera.position", (1.0, 3.0, -9.0)), levels=8)
        assert r.gpu.programs.compiles == compiled
        r.render(krsview.load("tree"), levels=8, effects=[])  # another effect set compiles
        assert r.gpu.programs.compiles > compiled


def test_render_from_several_threads_gives_the_sequential_images():
    names = ["rock", "sierpinski", "grass", "rock"]
    alone = [krsview.render(n, SIZE).color for n in names]
    out: dict[int, np.ndarray] = {}

    def work(k: int) -> None:
        out[k] = krsview.render(names[k], SIZE).color

    threads = [threading.Thread(target=work, args=(k,)) for k in range(len(names))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(np.array_equal(out[k], alone[k]) for k in range(len(names)))


def test_frame_saves_and_shows_itself(tmp_path):
    frame = krsview.render("rock", SIZE)
    png = frame.save(tmp_path / "a.png")
    assert np.array_equal(np.asarray(Image.open(png)), frame.rgb8())
    back = krsview.Frame.load(frame.save(tmp_path / "a.npz"))
    assert all(np.array_equal(getattr(back, k), getattr(frame, k)) for k in ("color", "hit"))
    shown = np.asarray(Image.open(io.BytesIO(frame._repr_png_())))
    assert np.array_equal(shown, frame.rgb8())
    assert "40×24" in repr(frame)


def test_check_counts_instances_by_closed_form():
    """A tree of n levels draws 2^n − 1 kernels (one per node of a full binary tree); the
    rock one sphere doubled by each of its 12 mirrors, and a ground plane once."""
    info = krsview.check("tree")
    assert info.instances == 2**info.levels - 1 and info.levels == 23
    rock = krsview.check("rock")
    assert rock.mirrors == 12 and rock.instances == 2**12 + 1
    assert krsview.check("grove").geometry == "compound"
    assert krsview.check("palm").geometry == "MöKRS"


def test_stability_and_certify_return_data():
    outcome = krsview.stability("rock", (24, 14))
    assert outcome.ok and outcome.name == "rock"
    counts = krsview.certify("sierpinski", (16, 9), tracer="sphere")
    assert counts.rays == 16 * 9 and counts.holes == 0
    assert (
        set(krsview.hard_cases()) >= {"camera-on-mirror", "deep-zoom-1e-9"}
        or len(krsview.hard_cases()) >= 20
    )


@pytest.mark.parametrize(
    "module",
    ["krsview.api", "krsview.export", "krsview.scene.scene", "krsview.frame"],
)
def test_docstring_examples_run(module):
    mod = __import__(module, fromlist=["_"])
    result = doctest.testmod(mod, optionflags=doctest.ELLIPSIS)
    assert result.failed == 0
    if module != "krsview.frame":
        assert result.attempted > 0, "no example ran"


@pytest.mark.parametrize(
    "example", sorted((Path(__file__).parent.parent / "examples").glob("*.py"))
)
def test_examples_run(example, tmp_path):
    r = subprocess.run(
        [sys.executable, str(example)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "KRSVIEW_EXAMPLE_SIZE": "48x27", "MPLBACKEND": "Agg"},
    )
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip(), "the example printed nothing"


def test_a_wheel_works_outside_the_checkout(tmp_path):
    """Built from pyproject.toml and unpacked elsewhere (a wheel of pure Python installs by
    unpacking): it renders a preset and finds the presets and the shipped measurements."""
    root = Path(__file__).resolve().parent.parent
    build = subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(tmp_path / "dist"),
            str(root),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert build.returncode == 0, build.stderr
    (wheel,) = (tmp_path / "dist").glob("krsview-*.whl")
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    names = zipfile.ZipFile(wheel).namelist()
    assert "krsview/presets/palm.toml" in names and "krsview/py.typed" in names
    assert "krsview/shaders/trace.glsl" in names
    code = (
        "import krsview; from krsview.viewer.measured import load_measured;"
        "f = krsview.render(krsview.load('palm'), size=(160, 90)); print(f.color.shape);"
        "print(krsview.__file__); print(len(krsview.presets()));"
        "print(len(load_measured('tree') or []))"
    )
    run = subprocess.run(
        [sys.executable, "-c", code],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(site)},
    )
    assert run.returncode == 0, run.stderr
    shape, where, presets, measured = run.stdout.split("\n")[:4]
    assert shape == "(90, 160, 3)"
    assert where.startswith(str(site))
    assert int(presets) == len(krsview.presets()) >= 11
    assert int(measured) > 10


def test_fast_settings_trace_a_deep_krs_by_persistent_lanes_the_same_image():
    from krsview.api import configure, fast_settings
    from krsview.cli import build_parser
    from krsview.cli.options import scene_of
    from krsview.cli.render import settled

    tree = krsview.load("tree")
    fast = fast_settings(tree)
    assert (fast.render.path, fast.render.steps, fast.render.prepass) == ("compute", 0, 4)
    # shallow, a MöKRS, a compound: the fragment path (lanes measured slower there)
    for name in ("rock", "palm", "grove"):
        assert fast_settings(krsview.load(name)).render.path == "fragment", name
    assert fast_settings(tree.with_levels(12)).render.path == "fragment"
    assert fast_settings(krsview.load("tree-sway")).render.path == "compute"  # a moving KRS
    rounds = tree.edit("render.path", "compute")  # a file's own choice of path stands
    assert fast_settings(rounds).render.steps == 16
    kept = scene_from_toml(scene_to_toml(tree.edit("render.path", "fragment")))  # so does this
    assert fast_settings(kept).render.path == "fragment", "a file's fragment path was overruled"
    assert scene_from_toml(scene_to_toml(tree)).render.path is None  # control: none set
    lanes = GpuRenderer().render(fast, *SIZE)
    fragment = GpuRenderer().render(configure(fast, path="fragment", steps=16), *SIZE)
    assert same(lanes, fragment)
    # on the command line an option given stands too
    for argv, path in ((["tree"], "compute"), (["tree", "--path", "fragment"], "fragment")):
        args = build_parser().parse_args(["render", *argv])
        assert settled(args, scene_of(args)).render.path == path, argv


def test_on_a_gpu_the_fast_settings_trace_by_the_compute_paths_rounds(monkeypatch):
    """On a GPU (not a CPU rasteriser) `render`, the API and the benches trace every scene
    whose file sets no path by the compute path's rounds, from the pre-pass tile
    HARDWARE_PREPASS (2.4–7.3× the fragment path on an H100; docs/speed.md); a file's own
    path, pre-pass and steps stand. The same scene on llvmpipe keeps lanes or the fragment
    path (the control), and the rounds draw the fragment path's image (tests/test_compute.py)."""
    from krsview import api
    from krsview.cli import build_parser
    from krsview.cli.options import scene_of
    from krsview.cli.render import settled
    from krsview.gpu.context import hardware
    from krsview.scene.render import HARDWARE_PREPASS, VIEW_PREPASS

    assert not hardware("llvmpipe (LLVM 15.0.6, 256 bits)")
    assert not hardware("Google SwiftShader") and not hardware("softpipe")
    assert hardware("NVIDIA H100 80GB HBM3/PCIe/SSE2") and hardware("AMD Radeon RX 7900 XTX")
    with api._lock, api._shared_context() as ctx:
        assert api.on_hardware() == hardware(ctx.info["GL_RENDERER"])
    for name in krsview.presets():
        scene = krsview.load(name)
        r, gpu = scene.render, api.fast_settings(scene, hardware=True).render
        assert gpu.path == (r.path or "compute"), name
        assert gpu.prepass == (HARDWARE_PREPASS if r.prepass is None else r.prepass), name
        assert gpu.steps == r.steps, name
    tree = krsview.load("tree")
    kept = tree.edit("render.path", "fragment").edit("render.prepass", 2)
    assert api.fast_settings(kept, hardware=True).render == kept.render  # the file's own
    monkeypatch.setattr(api, "_hardware", True)
    assert api.Renderer._settled(tree, False, True).render.path == "compute"
    assert api.Renderer._settled(tree, False, True).render.steps == 16
    assert api.Renderer._settled(tree, False, True, prepass=None).render.prepass == HARDWARE_PREPASS
    assert api.Renderer._settled(tree, True, True).render.path is None  # exact: as the file says
    assert api.Renderer._settled(tree, False, False).render.steps == 0  # the reference's
    args = build_parser().parse_args(["render", "rock"])
    assert settled(args, scene_of(args)).render.path == "compute"
    monkeypatch.setattr(api, "_hardware", False)  # control: a CPU rasteriser
    assert api.Renderer._settled(tree, False, True).render.steps == 0  # persistent lanes
    assert api.Renderer._settled(tree, False, True, prepass=None).render.prepass == VIEW_PREPASS
    assert settled(args, scene_of(args)).render.path == "fragment"


def test_the_reference_touches_no_gl_even_where_the_fast_settings_ask_the_device(tmp_path):
    """The float64 reference draws without GL: `render(reference=True)` and `krsview render
    --reference` make no GL context, although the fast settings depend on the device the
    GPU draws on (it did make one, and so failed where EGL cannot start). Control: a GPU
    render in the same process makes it."""
    code = (
        "import krsview, krsview.api as api\n"
        "from krsview.cli import main\n"
        "krsview.render('rock', (8, 6), reference=True)\n"
        "argv = ['render', 'rock', '--reference', '--size', '8x6', '-o', 'r.png']\n"
        "assert main(argv) in (0, None)\n"
        "assert api._context is None, 'a GL context was made'\n"
        "krsview.render('rock', (8, 6))\n"
        "assert api._context is not None\n"
        "print('ok')\n"
    )
    env = {**os.environ, "DISPLAY": ""}
    r = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        cwd=tmp_path,
    )
    assert r.returncode == 0 and r.stdout.strip().endswith("ok"), r.stderr[-2000:]
