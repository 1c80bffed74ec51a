"""What a frame costs before it traces anything (gpu/renderer.py): with a pre-pass, the pixels
of tiles whose cone found every component free past the far limit are written by a small
pass of their own and skipped by the tracing pass's early depth test. The image is the one
of tracing every pixel, bit for bit; the skipped pixels are exactly those tiles', found in
NumPy from the pre-pass's free distances. Negative control: a mark that also skips rays
starting short of the far limit loses hits."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu.renderer import Renderer
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders

W, H = 48, 27
MARK = "gl_FragDepth = traced ? 1.0 : 0.0;"
TRACED = "bool hit = trace_ray(vec3r(0.0), dir, start, t, iterations, slots);"
FIELDS = ("color", "depth", "normal", "iterations", "hit")


def with_prepass(name: str, **render):
    """A preset with a pre-pass of 4-pixel tiles; ``tree`` with 4 levels (15 kernels): a
    small tree in a view that is mostly sky, where the skipped tiles are most."""
    scene = load_scene(resolve(name)).edit(("render", "prepass"), 4)
    if name == "tree":
        scene = scene.edit(("tree", "levels"), 3)
    for key, value in render.items():
        scene = scene.edit(("render", key), value)
    return scene


CASES = {
    "tree in passes": with_prepass("tree"),  # shared shadow rays: trace, blocks, shade
    "tree in one pass": with_prepass("tree", shadow_block=1),
    "grove": with_prepass("grove"),  # a compound: a free distance per component
    "palm": with_prepass("palm"),  # a MöKRS
}


@pytest.fixture(scope="module")
def tracing_all(tmp_path_factory):
    """A renderer whose free tiles' pass marks no pixel free: every pixel traced."""
    tmp = tmp_path_factory.mktemp("all")
    return Renderer(shader_dir=broken_shaders(tmp, "render.frag", MARK, "gl_FragDepth = 1.0;"))


@pytest.mark.parametrize("case", CASES)
def test_skipping_free_tiles_keeps_the_image_bit_for_bit(renderer, tracing_all, case):
    scene = CASES[case]
    img, ref = renderer.render(scene, W, H), tracing_all.render(scene, W, H)
    for name in FIELDS:
        assert np.array_equal(getattr(img, name), getattr(ref, name)), (case, name)
    assert ref.hit.any() and (ref.iterations == 0).any(), "a view with surfaces and free tiles"


def test_the_levels_walked_are_counted_as_when_tracing_every_pixel(renderer, tracing_all):
    scene = CASES["tree in one pass"]
    levels = renderer.levels(scene, W, H)
    assert np.array_equal(levels, tracing_all.levels(scene, W, H))
    assert levels.any()


@pytest.mark.parametrize("case", ["tree in passes", "tree in one pass"])
def test_the_pixels_skipped_are_the_free_tiles(renderer, tmp_path, case):
    """The tracing variant counts 1000 iterations more (a broken shader), so a pixel below
    1000 was written by the free tiles' pass alone: exactly those whose tile's free distance
    lies past the far limit (NumPy, from the pre-pass's distances), and most of this view."""
    scene = CASES[case]
    marked = Renderer(
        shader_dir=broken_shaders(
            tmp_path, "render.frag", TRACED, TRACED + "\n    iterations += 1000;"
        )
    )
    skipped = marked.render(scene, W, H).iterations < 1000
    tile = scene.render.prepass
    free = renderer.free_distances(scene, W, H)[..., 0] > scene.render.max_distance
    # both run top → bottom, and tiles count from the top row of pixels
    assert np.array_equal(skipped, free[np.arange(H) // tile][:, np.arange(W) // tile])
    assert 0.5 < skipped.mean() < 1.0


def test_a_mark_that_skips_rays_short_of_the_far_limit_loses_hits(renderer, tmp_path):
    """Negative control: free tiles taken as every tile whose cone moved at all."""
    scene = CASES["tree in one pass"]
    wrong = broken_shaders(tmp_path, "render.frag", MARK, "gl_FragDepth = r.t > 0.0 ? 0.0 : 1.0;")
    img, ref = Renderer(shader_dir=wrong).render(scene, W, H), renderer.render(scene, W, H)
    assert img.hit.sum() < ref.hit.sum()
