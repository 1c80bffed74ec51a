"""A component leaves a shadow ray once it can no longer change the visibility, and the ray
ends once every component has left (shadows.glsl, shadow_clear): past the component's ball a
lower bound of its distance keeps every later step's k·d/t at or above the visibility
reached, and above ε. The image is the same bit for bit."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from krsview.gpu.renderer import Renderer
from krsview.gpu.uniforms import variant_defines
from krsview.presets import resolve
from krsview.reference.compiled import compile_krs
from krsview.reference.geometry import compile_geometry
from krsview.scene import load_scene

from .conftest import broken_shaders
from .test_distance_bound import ALBEDO, arbitrary_krs, brute_force_distance

W, H = 96, 54
EXIT = "    if (shadow_clear(c, o + t * l, t, d, l, eps, sh.vis, soft)) {"


def scenes():
    tree = load_scene(resolve("tree"))
    hard = replace(tree, effects=["shadows", "sky"])
    plain = replace(tree, render=replace(tree.render, prepass=0, culling="off"))
    smooth = replace(tree, effects=tree.effects + ["smooth_shading", "ambient_occlusion"])
    return {"tree": tree, "tree-hard": hard, "tree-plain": plain, "tree-smooth": smooth,
            "bent-tree": load_scene(resolve("bent-tree")), "grove": load_scene(resolve("grove"))}


@pytest.fixture(scope="module")
def without_exit(tmp_path_factory):
    return Renderer(shader_dir=broken_shaders(tmp_path_factory.mktemp("noexit"), "shadows.glsl",
                                              EXIT, "    if (false) {"))


@pytest.mark.parametrize("name", list(scenes()))
def test_the_exit_changes_no_pixel(name, renderer, without_exit):
    scene = scenes()[name]
    assert "KRS_SHADOW_EXIT" in variant_defines(scene, compile_geometry(scene.geometry(), ALBEDO))
    assert np.array_equal(renderer.render(scene, W, H).color,
                          without_exit.render(scene, W, H).color)


def test_the_exit_is_taken(tmp_path, renderer):
    """Rays that leave by the exit drawn black: the image changes, so the test above compares
    images where the exit ended shadow rays."""
    marked = broken_shaders(tmp_path, "shadows.glsl", EXIT, EXIT + " sh.vis = 0.0;")
    scene = scenes()["tree"]
    assert not np.array_equal(renderer.render(scene, W, H).color,
                              Renderer(shader_dir=marked).render(scene, W, H).color)


def test_a_ball_too_small_changes_the_image(tmp_path, renderer):
    """Negative control: with a quarter of the scene's radius, rays end while a branch could
    still shade them (the ball is loose: at half the radius no pixel changes here)."""
    small = broken_shaders(tmp_path, "shadows.glsl", "near = rho - ball.w",
                           "near = rho - 0.25 * ball.w")
    scene = scenes()["tree"]
    assert not np.array_equal(renderer.render(scene, W, H).color,
                              Renderer(shader_dir=small).render(scene, W, H).color)


@pytest.mark.parametrize("name", ["forest", "rock", "palm"])
def test_no_exit_where_no_ball_bounds_it(name):
    """A ground plane (unbounded), a MöKRS, and a twist (which bends the geometry out of its
    ball) compile no exit."""
    scene = load_scene(resolve(name))
    c = compile_geometry(scene.geometry(), ALBEDO)
    assert "KRS_SHADOW_EXIT" not in variant_defines(scene, c)
    tree = load_scene(resolve("tree"))
    twisted = replace(tree, effects=tree.effects + ["twist"])
    assert "KRS_SHADOW_EXIT" not in variant_defines(twisted, compile_geometry(tree.geometry(),
                                                                             ALBEDO))


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 6))
def test_the_scene_ball_holds_every_instance(seed, n):
    """Brute force over all 2^n instances: outside the ball the distance is at least the
    distance to the ball; half the radius (negative control) fails somewhere."""
    rng = np.random.default_rng(seed)
    krs = arbitrary_krs(rng, n)
    ball = compile_krs(krs, ALBEDO).ball
    if ball[3] < 0:
        return
    x = ball[:3] + rng.normal(size=(400, 3)) * ball[3]
    brute = brute_force_distance(krs, x)
    gap = np.linalg.norm(x - ball[:3], axis=1)
    assert np.all(brute >= gap - ball[3] - 1e-9)
    # negative control: a ball of half the radius misses some instance
    assert np.any(brute < gap - 0.5 * ball[3] - 1e-9) or ball[3] < 1e-9
