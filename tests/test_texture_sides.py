"""No texture the renderer samples has a side that is a power of two (gpu/context.texture_side):
llvmpipe compiles a shader variant for each pattern of power-of-two sides among the textures
a shader samples, and the viewer's adaptive resolution passing 128 or 64 stalled a turn for
0.4–0.6 s while the tracer compiled anew (docs/speed.md). Images are read and drawn from the
part of their textures that holds them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from krsview.bench.metrics import gpu_reference_agreement, tolerance_failures
from krsview.gpu.context import texture_side
from krsview.gpu.passes import Targets
from krsview.reference import render_reference
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import check_against_reference, per_pixel

PLANES = ("color", "depth", "normal", "iterations", "hit")


def power_of_two(n: int) -> bool:
    return n & (n - 1) == 0


def test_a_side_that_is_a_power_of_two_grows_to_the_next_that_is_none():
    for n in range(1, 1100):
        side = texture_side(n)
        assert not power_of_two(side) and side >= n
        assert side == n or power_of_two(n)  # only powers of two grow
    assert (texture_side(1), texture_side(2), texture_side(64), texture_side(65)) == (3, 3, 65, 65)


def test_every_texture_of_an_image_at_power_of_two_sizes_is_made_without_them(renderer):
    """tree in passes (shadow blocks, pre-pass) at sizes whose image, pre-pass and blocks
    images have sides 64, 32, 16: every texture made has no power-of-two side, and the image
    read back has the size asked."""
    scene = load_scene(resolve("tree")).edit(("tree", "levels"), 6)
    scene = scene.edit(("render", "prepass"), 4).edit(("render", "shadow_block"), 2)
    renderer._pass_targets = Targets(renderer.ctx)  # this test's textures alone
    asked = [(64, 36), (128, 64), (96, 32)]
    for w, h in asked:
        frame = renderer.render(scene, w, h)
        assert frame.color.shape == (h, w, 3) and frame.hit.any()
    made = [
        tex.size
        for fbo in (*renderer._targets.values(), *renderer._pass_targets._kept.values())
        for tex in fbo.color_attachments
    ]
    assert made and not any(power_of_two(s) for size in made for s in size)
    # negative control: textures were asked for at power-of-two sides (the keys are the sizes
    # asked), and made larger
    asked_for = [key[:2] for key in (*renderer._targets, *renderer._pass_targets._kept)]
    assert any(power_of_two(s) for size in asked_for for s in size)


def test_an_image_at_power_of_two_sides_matches_the_reference(renderer):
    """rock at 64×32, its image's textures 65×33, against the float64 reference: the same
    pixel comparison as tests/test_gpu_vs_reference.py, so no texel of the extra row or
    column leaks into the image read back. Negative control: the reference one row off."""
    scene = per_pixel(load_scene(resolve("rock")))
    ref = render_reference(scene, 64, 32)
    gpu = renderer.render(scene, 64, 32)
    check_against_reference("rock-64x32", gpu, ref)
    shifted = replace(ref, **{k: np.roll(getattr(ref, k), 1, axis=0) for k in PLANES})
    assert tolerance_failures(gpu_reference_agreement(gpu, shifted))
