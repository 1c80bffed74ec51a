"""Fuzzing the scene files and the command line [issue 16]: random valid scenes render with
finite pixels inside the cap; random broken files and arguments always end in the clear
one-line error, never a traceback or a hang.

CI runs a bounded, seeded slice; `KRSVIEW_FUZZ=full pytest -m fuzz` runs the full campaign
(2000 scene files, 250 command lines); each test prints what it covered."""

from __future__ import annotations

import io
import math
import os
import tomllib
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from krsview.cli import main
from krsview.scene import SceneError, load_scene, scene_from_toml
from krsview.scene.presets import PRESET_DIR
from krsview.scene.toml_writer import dumps

FULL = os.environ.get("KRSVIEW_FUZZ") == "full"
SCENE_FILES = 2000 if FULL else 150
VALID_SCENES = 300 if FULL else 25
COMMAND_LINES = 250 if FULL else 40
pytestmark = pytest.mark.fuzz


def fuzz_settings(n: int):
    return settings(
        max_examples=n,
        deadline=None,
        derandomize=not FULL,
        database=None,
        suppress_health_check=list(HealthCheck),
    )


def report(capsys, what: str, counts: dict) -> None:
    """Prints what one test's campaign covered, also when the test passes. Each test reports
    its own counts: a report test at the module's end relied on running after the others in
    the same process, which a parallel run does not promise."""
    with capsys.disabled():
        print(f"\nfuzz, {what}:", ", ".join(f"{k}: {v}" for k, v in counts.items()))


# ----------------------------------------------------------------------- valid scenes
finite = st.floats(-5.0, 5.0, allow_nan=False)
point = st.tuples(finite, finite, finite)
unit = point.filter(lambda v: math.hypot(*v) > 0.1).map(
    lambda v: tuple(c / math.hypot(*v) for c in v)
)
radius = st.floats(0.01, 2.0)
kernel = st.one_of(
    st.builds(lambda c, r: {"type": "sphere", "center": list(c), "radius": r}, point, radius),
    st.builds(
        lambda a, b, r: {"type": "capsule", "a": list(a), "b": list(b), "radius": r},
        point,
        point,
        radius,
    ),
    st.builds(lambda n, w: {"type": "plane", "normal": list(n), "offset": w}, unit, finite),
    st.just({"type": "empty"}),
)


@st.composite
def valid_scene(draw) -> dict:
    n = draw(st.integers(1, 6))
    levels = [{"kernel": draw(kernel.filter(lambda k: k["type"] != "empty"))}]
    for _ in range(n - 1):
        levels.append(
            {"kernel": draw(kernel), "mirror": {"normal": list(draw(unit)), "offset": draw(finite)}}
        )
    eye = draw(point)
    target = draw(point.filter(lambda t: math.dist(t, eye) > 0.1))
    up = (0.0, 1.0, 0.0)
    return {
        "camera": {
            "position": list(eye),
            "target": list(target),
            "up": list(up),
            "fov_y": draw(st.floats(10.0, 120.0)),
        },
        "render": {
            "tracer": draw(st.sampled_from(["sphere", "binary", "relaxed"])),
            "max_iterations": draw(st.integers(1, 200)),
            "epsilon_scale": draw(st.floats(0.01, 10.0)),
        },
        "effects": draw(
            st.lists(
                st.sampled_from(["sky", "fog", "tone_mapping", "shadows", "ambient_occlusion"]),
                unique=True,
                max_size=2,
            )
        ),
        "krs": {"levels": levels},
    }


def one_sphere(z: float) -> dict:
    """A scene of one sphere on the view axis: in front of the camera (z > 0) or behind it."""
    return {
        "camera": {"position": [0.0, 0.0, 0.0], "target": [0.0, 0.0, 1.0], "up": [0.0, 1.0, 0.0]},
        "krs": {"levels": [{"kernel": {"type": "sphere", "center": [0.0, 0.0, z], "radius": 1.0}}]},
    }


def test_random_valid_scenes_render_finite_within_the_cap(renderer, capsys):
    rendered = []
    refused = 0

    @fuzz_settings(VALID_SCENES)
    @given(valid_scene())
    @example(one_sphere(4.0))  # fills the view, and a scene showing nothing: the random ones
    @example(one_sphere(-4.0))  # may all land on one side, so both are always among them
    def run(doc):
        try:
            scene = scene_from_toml(dumps(doc))
        except SceneError:  # e.g. the camera's up along the view: refused, not drawn
            nonlocal refused
            refused += 1
            return
        b = renderer.render(scene, 12, 8)
        for name in ("color", "depth", "normal"):
            assert np.isfinite(getattr(b, name)).all(), name
        assert b.iterations.min() >= 1 and b.iterations.max() <= scene.render.max_iterations
        rendered.append(b.hit.mean())

    run()
    report(capsys, "valid scenes", {"rendered": len(rendered), "refused": refused})
    assert len(rendered) >= 0.8 * VALID_SCENES  # not vacuous: most were drawn
    assert 0 < np.mean([h > 0 for h in rendered]) < 1  # and some show geometry, some not


# ----------------------------------------------------------------------- broken files
PRESET_DOCS = [tomllib.loads(p.read_text()) for p in sorted(PRESET_DIR.glob("*.toml"))]
junk = st.recursive(
    st.one_of(
        st.none(),
        st.booleans(),
        st.integers(-(10**30), 10**30),
        st.text(max_size=8),
        st.floats(allow_nan=True, allow_infinity=True),
        st.sampled_from([1e308, -1e308, 1e-320, 0.0, -0.0, 1e20, 65, 64, -1]),
    ),
    lambda inner: st.one_of(
        st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=6,
)


def paths(doc, prefix=()):
    """Every (path, value) inside a TOML document."""
    yield prefix
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield from paths(v, prefix + (k,))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield from paths(v, prefix + (i,))


def mutate(doc, path, value, delete: bool):
    if not path:
        return value
    parent = doc
    for k in path[:-1]:
        parent = parent[k]
    if delete and isinstance(parent, dict):
        del parent[path[-1]]
    else:
        parent[path[-1]] = value
    return doc


def to_toml(doc) -> str | None:
    try:
        return dumps(doc)
    except Exception:  # a value TOML cannot hold (None, …): write it raw instead
        return None


@st.composite
def broken_file(draw) -> bytes:
    kind = draw(st.sampled_from(["mutate", "mutate", "mutate", "bytes", "truncate"]))
    doc = tomllib.loads(dumps(draw(st.sampled_from(PRESET_DOCS))))
    if kind == "bytes":
        return draw(st.binary(max_size=200))
    text = dumps(doc)
    if kind == "truncate":
        return text.encode()[: draw(st.integers(0, len(text)))]
    for _ in range(draw(st.integers(1, 3))):
        where = draw(st.sampled_from(list(paths(doc))))
        doc = mutate(doc, where, draw(junk), draw(st.booleans()))
    out = to_toml(doc)
    return (out if out is not None else repr(doc)).encode()


def test_random_broken_scene_files_give_one_clear_line(tmp_path, capsys):
    outcomes = {"refused": 0, "accepted": 0}

    @fuzz_settings(SCENE_FILES)
    @given(broken_file())
    def run(content):
        path = tmp_path / "fuzz.toml"
        path.write_bytes(content)
        try:
            load_scene(path)
            outcomes["accepted"] += 1
        except SceneError as e:
            text = str(e)
            assert text.startswith(f"{path}: ") and "\n" not in text and len(text) < 2000
            outcomes["refused"] += 1

    run()
    report(capsys, "scene files", outcomes)
    assert outcomes["refused"] >= 0.5 * SCENE_FILES


# ----------------------------------------------------------------------- command lines
OPTIONS = {
    "--size": st.one_of(
        st.sampled_from(["8x6", "-5x3", "0x10", "x", "9999x9999", "12"]), st.text(max_size=6)
    ),
    "--epsilon-scale": st.sampled_from(["-inf", "nan", "0", "1e999", "0.5", "abc", "-1"]),
    "--max-iterations": st.sampled_from(["0", "-3", "1.5", "20", "1e9", ""]),
    "--tracer": st.sampled_from(["sphere", "binary", "relaxed", "bent", ""]),
    "--precision": st.sampled_from(["float", "double", "quad"]),
    "--relaxation": st.sampled_from(["1.5", "2.5", "0.9", "nan"]),
    "--levels": st.sampled_from(["0", "3", "99", "-1", "x"]),
    "--effects": st.sampled_from(["none", "sky,fog", "bogus", "sky,sky", ",", "twist"]),
    "-o": st.sampled_from(["x.jpg", "/tmp", "/proc/x/y.png", "OUT/a.png", "noext"]),
    "--buffers": st.sampled_from(["x.txt", "OUT/b.npz", "/tmp"]),
    "--repeats": st.sampled_from(["0", "1", "-2"]),
    "--view": st.sampled_from(["shaded", "iterations", "depth"]),
}
COMMANDS = ["render", "check", "bench levels", "bench tracers", "nonsense"]
PRESETS = ["sierpinski", "palm", "no-such", "tree.toml", "/tmp", ""]


@st.composite
def command_line(draw, out: str) -> list[str]:
    argv = draw(st.sampled_from(COMMANDS)).split()
    argv.append(draw(st.sampled_from(PRESETS)))
    for opt in draw(st.lists(st.sampled_from(sorted(OPTIONS)), max_size=4, unique=True)):
        argv += [opt, draw(OPTIONS[opt]).replace("OUT", out)]
    if argv[0] == "render" and "--size" not in argv:
        argv += ["--size", "8x6", "--repeats", "1"]
    if argv[0] == "bench":
        argv += ["--size", "8x6", "--rounds", "1"]
    return [a for a in argv if a != ""]


def test_random_command_lines_end_in_an_exit_code_not_a_traceback(tmp_path, capsys):
    codes: dict[int, int] = {}

    @fuzz_settings(COMMAND_LINES)
    @given(command_line(str(tmp_path)))
    def run(argv):
        if "--size" in argv:  # keep real renders small: a valid big size is not the point
            i = argv.index("--size") + 1
            if i < len(argv) and argv[i] == "9999x9999":
                argv[i] = "8x6"
        err = io.StringIO()
        with redirect_stdout(io.StringIO()), redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as e:  # argparse: usage errors exit 2, --help exits 0
                code = e.code
        assert "Traceback" not in err.getvalue()
        if code:
            last = err.getvalue().strip().splitlines()[-1]
            assert last.startswith(("krsview: error:", "krsview ")) and "error" in last, last
        codes[code] = codes.get(code, 0) + 1

    run()
    report(capsys, "command lines", {f"exit {k}": v for k, v in sorted(codes.items())})
    assert codes.get(0, 0) > 0 and sum(v for k, v in codes.items() if k) > 0
