"""Every shader variant the presets, the hard cases and the knobs produce is valid desktop GLSL
to the Khronos reference compiler (glslangValidator), not only to Mesa's llvmpipe, which accepts
code a stricter driver may refuse [issue 27 §5]. Each stage source is checked as the driver sees
it (``#version 430 core``) and as GLSL 4.50 core."""

from __future__ import annotations

import itertools
import shutil
import subprocess
from pathlib import Path

import pytest

import krsview
from krsview.compile.constants import VIEW_MODES
from krsview.gpu import program
from krsview.gpu.display import view_defines
from krsview.gpu.renderer import Renderer

# one worker builds the sources for all three tests (about 6 s: each variant is compiled)
pytestmark = pytest.mark.xdist_group("glsl")
SIZE = (32, 18)
VERSIONS = (f"#version {program.GL_VERSION} core", "#version 450 core")


def validate(sources: dict[str, str], folder: Path, version: str) -> str:
    """glslangValidator's complaints about ``sources`` (name.stage → text) with their
    ``#version`` line replaced by ``version``; '' when every one is valid."""
    files = []
    for name, text in sources.items():
        head, rest = text.split("\n", 1)
        assert head.startswith("#version"), name
        f = folder / name
        f.write_text(version + "\n" + rest)
        files.append(str(f))
    r = subprocess.run(["glslangValidator", *files], capture_output=True, text=True, timeout=300)
    return "" if r.returncode == 0 else r.stdout + r.stderr


def variants() -> list[tuple[krsview.Scene, dict]]:
    """(scene, prepare's keywords) for every variant to check: each preset on both paths, in
    float and double, without and with the pre-pass; every hard case on both paths; the
    knobs that change the source (tracers, culling, the level of detail off, shadow and
    component tasks, persistent lanes, the walk restart, the variant
    with every effect, the measuring probes)."""
    out = []
    for name in krsview.presets():
        scene = krsview.load(name)
        for path, precision, prepass in itertools.product(
            ("fragment", "compute"), ("float", "double"), (0, 4)
        ):
            out.append(
                (krsview.configure(scene, path=path, precision=precision, prepass=prepass), {})
            )
        out.append((scene, {"all_effects": True}))
    for scene in krsview.hard_cases().values():
        out += [(scene, {}), (krsview.configure(scene, path="compute", prepass=4), {})]
    tree, grove = krsview.load("tree"), krsview.load("grove")
    out += [
        (krsview.configure(tree, tracer="binary", prepass=4), {}),
        (krsview.configure(tree, tracer="relaxed"), {}),
        (krsview.configure(tree, culling="off"), {}),
        (krsview.configure(tree, lod=0.0), {}),  # every level (the presets draw at lod 0.5)
        (krsview.configure(krsview.load("palm"), lod=0.0, prepass=4), {}),
        (krsview.configure(tree, lod=0.0, path="compute", precision="double"), {}),
        (krsview.configure(tree, path="compute", shadow_tasks="off"), {}),
        (krsview.configure(tree, path="compute", steps=0, prepass=4), {}),  # persistent lanes
        (krsview.configure(grove, path="compute", component_tasks="on", prepass=4), {}),
        (krsview.configure(grove, tracer="binary", precision="double"), {}),
        (tree, {"probes": ("KRS_COUNT_LEVELS",)}),
        (krsview.load("palm"), {"probes": ("KRS_COUNT_LEVELS",)}),  # a MöKRS counts too
        (tree, {"probes": ("KRS_TRACE_ONLY",)}),
        (krsview.configure(tree, walk_restart="on"), {"probes": ("KRS_COUNT_LEVELS",)}),
        (krsview.configure(tree, walk_restart="on", lod=0.0, culling="off"), {}),
        (krsview.configure(tree, walk_restart="on", path="compute", precision="double"), {}),
    ]
    return out


@pytest.fixture(scope="session")  # not "module": a worker that runs another module's test
def stage_sources() -> dict[str, str]:  # between these would build them anew
    """The assembled source of every stage the renderer compiles for :func:`variants`, and
    the display and overlay passes', recorded as the renderer builds them."""
    seen: dict[str, tuple[str, dict]] = {}
    build_program, build_compute = program.build_program, program.build_compute

    def record(entry: str, defines: dict) -> None:
        text = program.Source(entry, defines).text
        seen.setdefault(text, (entry, defines))

    def recording_program(ctx, vertex, fragment, defines, shader_dir=program.SHADER_DIR):
        record(vertex, defines)
        record(fragment, defines)
        return build_program(ctx, vertex, fragment, defines, shader_dir)

    def recording_compute(ctx, entry, defines, shader_dir=program.SHADER_DIR):
        record(entry, defines)
        return build_compute(ctx, entry, defines, shader_dir)

    mp = pytest.MonkeyPatch()
    mp.setattr(program, "build_program", recording_program)
    mp.setattr(program, "build_compute", recording_compute)
    try:
        r = Renderer()
        for scene, keywords in variants():
            r.prepare(scene, *SIZE, **keywords)
    finally:
        mp.undo()
    for vertex, fragment in (("fullscreen.vert", "display.frag"), ("overlay.vert", "overlay.frag")):
        record(vertex, {})
        record(fragment, {})
    for view in VIEW_MODES[1:]:  # the display pass's other variants (gpu/display.py)
        record("display.frag", view_defines(view))
    return {
        f"s{k:03d}-{entry.replace('.', '-')}.{entry.rsplit('.', 1)[1]}": text
        for k, (text, (entry, _)) in enumerate(seen.items())
    }


@pytest.mark.parametrize("version", VERSIONS)
def test_every_variant_is_valid_desktop_glsl(stage_sources, tmp_path, version):
    assert shutil.which("glslangValidator"), "glslang-tools is missing: `make deps`"
    stages = {name.rsplit(".", 1)[1] for name in stage_sources}
    assert len(stage_sources) > 150 and stages == {"vert", "frag", "comp"}, "too few variants"
    assert validate(stage_sources, tmp_path, version) == ""


def test_the_validator_refuses_what_llvmpipe_might_let_through(stage_sources, tmp_path):
    """Negative controls: an undeclared call, and an implicit double → float narrowing,
    appended to a real source, are both refused."""
    name, text = next((n, t) for n, t in stage_sources.items() if n.endswith(".frag"))
    for junk in (
        "void junk() { undeclared_function(); }\n",
        "void junk() { double d = 1.0lf; float f = d; }\n",
    ):
        assert validate({name: text + junk}, tmp_path, VERSIONS[0]) != ""
