"""The shading's nearest kernel from what the trace handed on [issue 27]: a hit's walk of
Alg. 1 found the least of the kernels it tested (and whether a level-of-detail ball was
nearer still), so the shading folds down to that kernel instead of testing every level's
(krs.glsl, krs_nearest). The image must be the whole walk's, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.api import fast_settings
from krsview.gpu.renderer import Renderer
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders

W, H = 96, 54
HANDED_ON = "scene_nearest(p, t, (slots & 0xffff) - 1, (slots >> 16) - 1, level, normal, xk);"


def handed(slot: str, cut: str) -> str:
    return f"scene_nearest(p, t, {slot}, {cut}, level, normal, xk);"


def scene_of(name: str, **render):
    scene = load_scene(resolve(name.split(" ")[0]))
    if name.startswith("tree"):
        scene = scene.edit(("tree", "levels"), 14)  # at 96×54 its crown's balls are cut
    for key, value in render.items():
        scene = scene.edit(("render", key), value)
    return fast_settings(scene)


CASES = {
    "tree": scene_of("tree"),  # pre-pass, level of detail, the passes' trace
    "tree in one pass": scene_of("tree", shadow_block=1),  # render.frag: trace and shade
    "tree in lanes": scene_of("tree", path="compute", steps=0),  # compute.comp, deferred.frag
    "tree restarted": scene_of("tree", walk_restart="on"),  # slots unknown above an anchor
    "tree in lanes, restarted": scene_of("tree", path="compute", steps=0, walk_restart="on"),
    "grove": scene_of("grove"),  # a compound: the trace's component may not be the nearest
    "tree-wind": scene_of("tree-wind"),  # looked up where the wind undoes its bend
    "bent-tree": scene_of("bent-tree"),
}


@pytest.fixture(scope="module")
def whole_walk(tmp_path_factory):
    """The shaders as before the hand-on: every hit's nearest kernel by the whole walk."""
    return Renderer(
        shader_dir=broken_shaders(
            tmp_path_factory.mktemp("whole"), "trace.glsl", HANDED_ON, handed("-1", "-1")
        )
    )


def image(renderer, scene):
    frame = renderer.render(scene, W, H)
    return frame.color, frame.normal


@pytest.mark.parametrize("name", CASES)
def test_the_handed_on_kernel_is_the_whole_walks(renderer, whole_walk, name):
    color, normal = image(renderer, CASES[name])
    want_color, want_normal = image(whole_walk, CASES[name])
    hit = np.abs(want_normal).sum(-1) > 0
    assert hit.mean() > 0.05
    assert np.array_equal(color, want_color)
    assert np.array_equal(normal, want_normal)


@pytest.mark.parametrize(
    "wrong, why, share",
    [
        (handed("(slots & 0xffff)", "(slots >> 16) - 1"), "the kernel one level coarser", 0.2),
        (handed("(slots & 0xffff) - 1", "-1"), "a ball that won ignored", 0.02),
    ],
)
def test_negative_control_a_wrong_hand_on_shows(renderer, tmp_path, wrong, why, share):
    """Both of what the trace hands on are used on `tree` at this size: the shading told a
    level one coarser, or not told that the level-of-detail ball won (so the kernels below
    it go untested), draws other normals on many pixels (481 and 612 of 1,150 hits when
    written; since the cut falls by the slots' top levels, compile/lod.py, a ball that won
    and hid a nearer kernel below it is rarer: 57 of 1,126)."""
    broken = Renderer(shader_dir=broken_shaders(tmp_path, "trace.glsl", HANDED_ON, wrong))
    _, normal = image(broken, CASES["tree"])
    _, want = image(renderer, CASES["tree"])
    hit = np.abs(want).sum(-1) > 0
    differ = (np.abs(normal - want).max(-1) > 1e-3) & hit
    assert differ.sum() > share * hit.sum(), f"{why}: {differ.sum()} of {hit.sum()} hits differ"
