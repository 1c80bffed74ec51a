"""The nearest component of a compound (distance.glsl, nearest_component), which every shaded
pixel and every shared shadow ray's block asks for its normal: a component whose ball is no
nearer than the best distance so far is not walked. Its distance is at least the ball's, so
it could only tie, and ties go to the first: the same winner, the same image bit for bit."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.gpu.renderer import Renderer
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders

W, H = 96, 54
SKIP = "        if (ball.w >= 0.0 && near >= best) continue;"


def groves():
    grove = load_scene(resolve("grove"))
    return {
        "grove": grove,
        "grove-wind": replace(grove, effects=["wind", *grove.effects]),
        "grove-blocks": replace(grove, render=replace(grove.render, shadow_block=2)),
    }


@pytest.mark.parametrize("name", groves())
def test_the_skip_changes_no_pixel(tmp_path, renderer, name):
    """Against a copy of the shaders that walks every component: colours, normals, depths
    and hits the same bit for bit (a still frame in passes too, and in the wind, where the
    ball is asked at the component's rest point)."""
    scene = groves()[name]
    every = Renderer(shader_dir=broken_shaders(tmp_path, "distance.glsl", SKIP, ""))
    a, b = renderer.render(scene, W, H), every.render(scene, W, H)
    assert a.hit.mean() > 0.3
    for field in ("color", "normal", "depth", "hit"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field


def test_a_ball_too_small_changes_the_normals(tmp_path, renderer):
    """Negative control: with a quarter of each ball's radius the skip drops components that
    were nearest, so some hit pixels take another component's normal and colour."""
    scene = groves()["grove"]
    old = "float near = length(vec3(q) - ball.xyz) - ball.w"
    shaders = broken_shaders(tmp_path, "distance.glsl", old, old.replace("ball.w", "0.25 * ball.w"))
    a, b = renderer.render(scene, W, H), Renderer(shader_dir=shaders).render(scene, W, H)
    assert np.array_equal(a.hit, b.hit)
    assert not np.array_equal(a.normal[a.hit], b.normal[b.hit])
