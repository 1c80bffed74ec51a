"""Persistent lanes (`[render] steps = 0`, shaders/lanes.glsl): each lane takes the next pixel
as soon as its ray is done. They take the fragment path's steps (trace.glsl's ray_step), so the
image is the fragment path's bit for bit: colour, depth, normal, iterations and hits, on a KRS,
a compound and a MöKRS (binary tracer), with and without the pre-pass, in bands, in double
precision, with every preset's effects, with the walk restart, and as the trace pass of the
image in passes. Negative controls: a lane that skips a pixel, a round that does not finish
the rays the lanes left, lanes without their step budget (llvmpipe cuts every loop of an
invocation after 65535 loop iterations in all), a trace pass that shades, a lane that keeps
its last ray's anchor for the next pixel, and an anchor kept past its fold margin."""

from __future__ import annotations

import shutil
from dataclasses import replace

import numpy as np
import pytest

from krsview.api import on_hardware
from krsview.bench.metrics import COLOR_TOL, DEPTH_REL, NORMAL_DEG, agreement
from krsview.bench.zoom import stops
from krsview.compile.constants import BINDING_COUNTS, COMPUTE_GROUP
from krsview.compile.geometry import compile_geometry, walk_restarts
from krsview.compile.std430 import COUNTS, Struct
from krsview.gpu import compute, passes, program
from krsview.gpu.compute import LANE_STEPS_PER_PIXEL, path_defines
from krsview.gpu.renderer import Renderer
from krsview.gpu.uniforms import variant_defines
from krsview.scene import load_scene
from krsview.scene.presets import preset_names, resolve
from krsview.scene.render import VIEW_PREPASS

from .conftest import broken_shaders, same
from .test_constants import GL_OFFSET, resource
from .test_glsl_portable import VERSIONS, validate

W, H = 64, 36


def on_path(scene, path, **render):
    """``scene`` on ``path`` with ``render`` knobs, by default a shadow ray per pixel (as the
    shading pass after the lanes traces them), so the two paths draw the same image."""
    return replace(scene, render=replace(scene.render, **{"shadow_block": 1, **render}, path=path))


def lanes(scene, **render):
    return on_path(scene, "compute", steps=0, **render)


def lane_counts(renderer) -> dict[str, np.ndarray]:
    """compute.comp's Counts as the last traced frame left them (compile/std430.py)."""
    with renderer.current():
        raw = np.frombuffer(renderer._rays.buffers[BINDING_COUNTS].read(), np.uint32)
    return {name: raw[at // 4 :] for name, at in COUNTS.offsets().items()}


@pytest.mark.parametrize(
    "name, tracer", [("tree", "sphere"), ("grove", "sphere"), ("palm", "binary")]
)
@pytest.mark.parametrize("prepass", [0, 4])
def test_lanes_draw_the_fragment_paths_image(renderer, name, tracer, prepass):
    """A KRS, a compound and a MöKRS: the same image, bit for bit; the lanes took more pixels
    than there are lanes (they refilled), and every lane finished (the last sized the round
    after them): as many as hold LANE_STEPS_PER_PIXEL steps per listed pixel at the cap's
    steps each, fewer with the pre-pass, which lists only the tiles with rays to trace."""
    scene = on_path(load_scene(resolve(name)), "fragment", tracer=tracer, prepass=prepass)
    fragment = renderer.render(scene, W, H)
    traced = renderer.render(lanes(scene), W, H)
    assert same(fragment, traced)
    assert fragment.hit.any() and (fragment.iterations > 1).any()
    c = lane_counts(renderer)
    cap, block = scene.render.max_iterations, prepass or compute.LANE_BLOCK
    listed = int(c["count"][0]) * block**2
    assert (listed < W * H) == (prepass > 0) and listed >= W * H * (prepass == 0)
    lanes_n = -(-listed * LANE_STEPS_PER_PIXEL // (COMPUTE_GROUP * cap)) * COMPUTE_GROUP
    assert c["lanes_done"][0] == lanes_n < c["taken"][0]


@pytest.mark.parametrize("name", preset_names())
def test_every_preset_draws_the_same_with_lanes(renderer, name):
    """Every preset with its own tracer and effects (shadow rays traced while shading), at
    the viewer's pre-pass: the same image as the fragment path's."""
    scene = on_path(load_scene(resolve(name)), "fragment", prepass=VIEW_PREPASS)
    assert same(renderer.render(scene, W, H), renderer.render(lanes(scene), W, H))


def test_lanes_in_bands_in_double_and_short_of_budget(renderer, monkeypatch):
    """Drawn in progress bands (rows that do not start on the pre-pass's grid) and in double
    precision: the same image. Then with an iteration cap of 12, each subgroup's budget of
    12 steps, and subgroups for 1 step per pixel, so that the lanes leave rays live and pixels
    untaken to the round after them: still the same image."""
    scene = on_path(load_scene(resolve("tree")), "fragment", prepass=VIEW_PREPASS)
    double = replace(scene, render=replace(scene.render, precision="double"))
    banded = renderer.render(lanes(double), W, H, progress=lambda done, total: None)
    assert same(renderer.render(double, W, H), banded)
    capped = replace(scene, render=replace(scene.render, max_iterations=12))
    fragment = renderer.render(capped, W, H)
    monkeypatch.setattr(compute, "LANE_STEPS_PER_PIXEL", 1)
    traced = renderer.render(lanes(capped), W, H)
    c = lane_counts(renderer)
    listed = c["count"][0] * VIEW_PREPASS**2
    assert c["count"][1] > 0 and c["taken"][0] < listed  # rays left live, pixels untaken
    assert same(fragment, traced) and (fragment.iterations == 12).any()


def in_passes(monkeypatch) -> None:
    """Let gpu/passes.py draw a lanes scene's still image in passes where it does not yet:
    its trace pass drawn by the lanes (deferred.frag with KRS_TRACE_ONLY, KRS_TRACE_KERNELS)."""
    scene = lanes(load_scene(resolve("tree")), shadow_block=2)
    if not passes.splits_shadows(scene):
        fragment_only = passes.splits_shadows
        monkeypatch.setattr(
            passes,
            "splits_shadows",
            lambda s: (
                fragment_only(replace(s, render=replace(s.render, path="fragment")))
                and (s.render.path == "fragment" or s.render.steps == 0)
            ),
        )
    assert passes.still_ratio(scene) == 2


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_lanes_trace_the_passes_image(renderer, monkeypatch, name):
    """The still image in passes (shadow rays shared by 2×2 blocks, the scene's effects),
    its primary rays traced by the lanes: the fragment path's image, bit for bit."""
    in_passes(monkeypatch)
    scene = replace(
        load_scene(resolve(name)), render=replace(load_scene(resolve(name)).render, prepass=4)
    )
    fragment = renderer.render(scene, W, H)
    assert same(fragment, renderer.render(lanes(scene, shadow_block=2), W, H))


def test_a_trace_pass_that_shades_fails(tmp_path, renderer, monkeypatch):
    """Negative control: a lanes trace pass that writes the shaded pixel instead of the
    tracing (the hits' kernels) gives the passes after it wrong kernels."""
    in_passes(monkeypatch)
    shaders = broken_shaders(
        tmp_path, "deferred.frag", "write_trace(pixel_ray", "write_pixel(pixel_ray"
    )
    scene = lanes(load_scene(resolve("tree")), shadow_block=2)
    assert not same(renderer.render(scene, W, H), Renderer(shader_dir=shaders).render(scene, W, H))


def test_a_lane_that_skips_a_pixel_fails(tmp_path, renderer):
    """Negative control: lanes that skip the pixel after each one they finish leave pixels
    untraced."""
    shaders = broken_shaders(tmp_path, "lanes.glsl", "p = next;", "p = next + 1u;")
    scene = lanes(load_scene(resolve("tree")))
    assert not same(renderer.render(scene, W, H), Renderer(shader_dir=shaders).render(scene, W, H))


def test_rays_the_lanes_leave_must_be_finished(tmp_path, renderer):
    """Negative control: a round after the lanes that stores the rays they left without
    stepping them loses those pixels (an iteration cap of 12: the budget leaves some)."""
    if on_hardware():
        pytest.skip("a GPU's thousands of lanes take a pixel or two each: none is left")
    shaders = broken_shaders(
        tmp_path,
        "lanes.glsl",
        "    while (r.state == RAY_LIVE) ray_step(r, vec3r(0.0), dir);\n    rays[index] = r;",
        "    rays[index] = r;",
    )
    scene = lanes(load_scene(resolve("tree")), max_iterations=12)
    assert not same(renderer.render(scene, W, H), Renderer(shader_dir=shaders).render(scene, W, H))


def test_without_the_budget_llvmpipe_cuts_the_walk(tmp_path, renderer):
    """Why a subgroup takes at most the iteration cap's steps: on llvmpipe, which ends all of
    an invocation's loops after 65535 loop iterations in all, a subgroup that traces pixel
    after pixel inside the crown (the zoom's stop 3) has its walks cut short, and its image
    differs; with the budget it is the fragment path's."""
    if on_hardware():
        pytest.skip("the loop limit is llvmpipe's")
    scene = on_path(stops(load_scene(resolve("tree")), 12)[3], "fragment", prepass=VIEW_PREPASS)
    size = (160, 90)
    fragment = renderer.render(scene, *size)
    assert same(fragment, renderer.render(lanes(scene), *size))
    shaders = broken_shaders(
        tmp_path, "lanes.glsl", "int budget = u_steps;", "int budget = 1 << 30;"
    )
    assert not same(fragment, Renderer(shader_dir=shaders).render(lanes(scene), *size))


def test_lanes_sources_are_valid_desktop_glsl(tmp_path):
    """The lanes' compute stage and the shading and marking passes (shading, or the tracing
    alone for gpu/passes.py), for a KRS (with and without the walk restart), a compound and
    a MöKRS, in float and double, with and without the pre-pass, pass glslangValidator as
    the driver sees them and as GLSL 4.50; without the group-vote extension (negative
    control) the compute stage is refused."""
    assert shutil.which("glslangValidator"), "glslang-tools is missing: `make deps`"
    sources = {}
    for name in ("tree", "tree-restart", "grove", "palm"):
        scene = load_scene(resolve(name.removesuffix("-restart")))
        if name.endswith("-restart"):
            scene = scene.edit(("render", "walk_restart"), "on")
        for precision, prepass in ((p, t) for p in ("float", "double") for t in (0, 4)):
            s = lanes(scene, precision=precision, prepass=prepass)
            defines = path_defines(
                variant_defines(s, compile_geometry(s.geometry(), s.material.albedo)), s.render
            )
            assert "KRS_LANES" in defines and "KRS_SHADOW_TASKS" not in defines
            assert ("KRS_WALK_RESTART" in defines) == (name == "tree-restart")
            key = f"{name}-{precision}-{prepass}"
            sources[f"{key}.comp"] = program.Source("compute.comp", defines).text
            trace = {"KRS_TRACE_ONLY": None, "KRS_TRACE_KERNELS": None}
            marks = ({}, {"KRS_MISS_MARK": None}, trace, {**trace, "KRS_MISS_MARK": None})
            for k, extra in enumerate(marks):
                sources[f"{key}-{k}.frag"] = program.Source(
                    "deferred.frag", {**defines, **extra}
                ).text
    for version in VERSIONS:
        assert validate(sources, tmp_path, version) == ""
    comp = sources["tree-float-4.comp"]
    refused = comp.replace("#extension GL_ARB_shader_group_vote : require", "")
    assert refused != comp and validate({"tree.comp": refused}, tmp_path, VERSIONS[0]) != ""


def test_lanes_counts_are_laid_out_as_declared(renderer):
    """compute.comp's Counts in the lanes' variant, as the driver lays it out, against
    compile/std430.py's COUNTS (which Python sizes and writes); negative control: a
    declaration without the lanes' counters would size the buffer short of them."""
    scene = lanes(load_scene(resolve("tree")))
    defines = path_defines(
        variant_defines(scene, compile_geometry(scene.geometry(), scene.material.albedo)),
        scene.render,
    )
    names = {"count": "count[0]", "groups": "groups[0]", "taken": "taken"}
    names["lanes_done"] = "lanes_done"
    with renderer.current():
        glo = renderer.programs.compute("compute.comp", defines).glo
        driver = {f: resource(glo, n, GL_OFFSET) for f, n in names.items()}
    assert driver == COUNTS.offsets()
    assert Struct("Counts", COUNTS.fields[:2]).size() <= driver["taken"]


def restarted(scene, **render):
    """``scene`` on the fragment path at the viewer's pre-pass, the walk restarted."""
    return on_path(scene, "fragment", prepass=VIEW_PREPASS, walk_restart="on", **render)


def crown_stops():
    """tree's zoom (bench zoom): the whole-tree view (stop 0) and one inside the crown."""
    views = stops(load_scene(resolve("tree")), 12)
    return {"tree stop 0": views[0], "tree stop 3": views[3]}


RESTART_CASES = ["tree stop 0", "tree stop 3", *preset_names()]


@pytest.mark.parametrize("name", RESTART_CASES)
def test_lanes_take_the_restarted_steps(renderer, name):
    """The walk restart inside the lanes (the anchor lives in the Ray, trace.glsl): the
    fragment path's restarted image, bit for bit, for tree's whole view and crown and every
    preset (it compiles for each single undistorted sphere-traced KRS, and for no other).
    Where it compiles on tree, the image is not the plain walk's: the restart took part."""
    scene = restarted(crown_stops()[name] if name in crown_stops() else load_scene(resolve(name)))
    fragment, traced = renderer.render(scene, W, H), renderer.render(lanes(scene), W, H)
    assert same(fragment, traced)
    compiled = compile_geometry(scene.geometry(), scene.material.albedo)
    defines = path_defines(variant_defines(lanes(scene), compiled), lanes(scene).render)
    assert ("KRS_WALK_RESTART" in defines) == walk_restarts(scene, compiled)
    if name in ("tree stop 0", "tree stop 3", "tree"):
        plain = lanes(scene.edit(("render", "walk_restart"), "off"))
        assert "KRS_WALK_RESTART" in defines and not same(traced, renderer.render(plain, W, H))


def test_rays_saved_whole_keep_their_anchors(renderer, monkeypatch):
    """Inside the crown with subgroups for 1 step per pixel and a cap of 48, the lanes save
    rays in the middle of their walks (anchors held) and leave pixels untaken: the image is
    still the fragment path's restarted one."""
    scene = restarted(crown_stops()["tree stop 3"])
    # a lane's budget is the iteration cap: a low one leaves pixels to the last round
    scene = scene.edit(("render", "max_iterations"), 48)
    fragment = renderer.render(scene, W, H)
    monkeypatch.setattr(compute, "LANE_STEPS_PER_PIXEL", 1)
    traced = renderer.render(lanes(scene), W, H)
    c = lane_counts(renderer)
    assert c["count"][1] > 0 and c["taken"][0] < c["count"][0] * VIEW_PREPASS**2
    assert same(fragment, traced)


@pytest.mark.parametrize(
    "broken",
    [
        (  # a lane that takes the next pixel with the last ray's anchor
            "lanes.glsl",
            "            lane_begin(p, listed, r, dir, index);",
            "            Ray last = r;\n            lane_begin(p, listed, r, dir, index);\n"
            "            r.wx = last.wx; r.wdir = last.wdir; r.wt = last.wt; r.wm = last.wm;\n"
            "            r.wd = last.wd; r.wj = last.wj;",
        ),
        (  # an anchor kept however far the ray moved past its fold margin
            "krs.glsl",
            "s < min(am, adist) && top - aj <= lod.depth",
            "s < adist && top - aj <= lod.depth",
        ),
    ],
    ids=["stale anchor", "past the margin"],
)
def test_a_wrong_anchor_in_the_lanes_gives_wrong_hits(tmp_path, renderer, broken):
    """Negative controls: a lane that keeps its last ray's anchor for its next pixel, or a
    walk that restarts below an anchor past its fold margin, moves the hits inside the crown:
    more than a tenth of them are no longer within the metrics' depth tolerance of the
    fragment path's restarted image (which the lanes' own image matches bit for bit)."""
    scene = lanes(restarted(crown_stops()["tree stop 3"]))
    right = renderer.render(scene, W, H)
    wrong = Renderer(shader_dir=broken_shaders(tmp_path, *broken)).render(scene, W, H)
    agree = agreement(right, wrong, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert agree.depth_close < 0.9, agree


def test_the_lanes_dispatch_is_sized_by_the_listed_pixels(renderer):
    """At the whole-tree view (stop 0 of bench zoom) most pre-pass tiles are free past the far
    limit: the GPU sizes the lanes' dispatch from the pixels it listed, a quarter of those a
    dispatch sized by every pixel would hold, and the image is still the fragment path's."""
    scene = on_path(crown_stops()["tree stop 0"], "fragment", prepass=VIEW_PREPASS)
    size = (160, 90)
    fragment = renderer.render(scene, *size)
    assert same(fragment, renderer.render(lanes(scene), *size))
    c = lane_counts(renderer)
    listed, cap = int(c["count"][0]) * VIEW_PREPASS**2, scene.render.max_iterations
    per_group = COMPUTE_GROUP * cap
    every = -(-size[0] * size[1] * LANE_STEPS_PER_PIXEL // per_group) * COMPUTE_GROUP
    assert c["lanes_done"][0] == -(-listed * LANE_STEPS_PER_PIXEL // per_group) * COMPUTE_GROUP
    assert c["lanes_done"][0] <= every // 3, (c["lanes_done"][0], every)
