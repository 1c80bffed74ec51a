"""A component leaves a ray once it can no longer stop it (nor, on a shadow ray, lower its
visibility), and the ray ends once every component has left (trace.glsl, bound_ahead): past
the component's ball a lower bound of its distance stays above ε(t) on a primary ray, and
keeps k·d/t at or above the visibility reached on a shadow ray. Misses end early, shadow
rays end early, and the image is the same bit for bit."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from krsview.compile.geometry import compile_geometry
from krsview.compile.krs import compile_krs
from krsview.gpu.renderer import Renderer
from krsview.gpu.uniforms import variant_defines
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders
from .test_distance_bound import ALBEDO, arbitrary_krs, brute_force_distance

W, H = 96, 54
SHADOW_EXIT = "    if (b.x > eps && (!soft"
LEAVE_SHADOW = "&& leave(sh.tc, c))\n        sh.state = SHADOW_DONE;"
RAY_EXIT = "    if (min(b.x / b.y, b.z / u_max_distance) > u_eps_per_t && leave(r.tc, c)) {"


def scenes():
    tree = load_scene(resolve("tree"))
    hard = replace(tree, effects=["shadows", "sky"])
    plain = replace(tree, render=replace(tree.render, prepass=0, culling="off"))
    prepass = replace(tree, render=replace(tree.render, prepass=4))
    smooth = replace(tree, effects=tree.effects + ["smooth_shading", "ambient_occlusion"])
    return {
        "tree": tree,
        "tree-hard": hard,
        "tree-plain": plain,
        "tree-prepass": prepass,
        "tree-smooth": smooth,
        "bent-tree": load_scene(resolve("bent-tree")),
        "grove": load_scene(resolve("grove")),
    }


def shaders_without(tmp: Path, shadow: str | None, ray: str | None) -> Path:
    """The shaders with the shadow exit's and the primary exit's tests replaced (None: kept)."""
    d = broken_shaders(tmp, "trace.glsl", RAY_EXIT, ray if ray is not None else RAY_EXIT)
    if shadow is not None:
        path = d / "shadows.glsl"
        path.write_text(path.read_text().replace(SHADOW_EXIT, shadow, 1))
    return d


@pytest.fixture(scope="module")
def without_exits(tmp_path_factory):
    return Renderer(
        shader_dir=shaders_without(
            tmp_path_factory.mktemp("none"), "    if (false && (!soft", "    if (false) {"
        )
    )


@pytest.mark.parametrize("name", list(scenes()))
def test_the_exits_change_no_pixel(name, renderer, without_exits):
    scene = scenes()[name]
    assert "KRS_BALL_EXIT" in variant_defines(scene, compile_geometry(scene.geometry(), ALBEDO))
    a, b = renderer.render(scene, W, H), without_exits.render(scene, W, H)
    for field in ("color", "depth", "normal", "hit"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    assert (a.iterations <= b.iterations).all()
    if "grove" not in name:  # misses end early (not in a compound: it costs more there)
        assert (a.iterations < b.iterations).any()
    else:
        assert np.array_equal(a.iterations, b.iterations)


def test_the_shadow_exit_is_taken(tmp_path, renderer):
    """Shadow rays that leave by the exit drawn black: the image changes, so the test above
    compares images where the exit ended shadow rays."""
    marked = broken_shaders(
        tmp_path,
        "shadows.glsl",
        LEAVE_SHADOW,
        LEAVE_SHADOW.replace(
            "sh.state = SHADOW_DONE;", "{ sh.vis = 0.0; sh.state = SHADOW_DONE; }"
        ),
    )
    for name in ("tree", "grove"):
        scene = scenes()[name]
        assert not np.array_equal(
            renderer.render(scene, W, H).color,
            Renderer(shader_dir=marked).render(scene, W, H).color,
        ), name


@pytest.mark.parametrize("exit_", ["shadow", "ray"])
def test_a_ball_too_small_changes_the_image(tmp_path, renderer, exit_):
    """Negative control: with a quarter of the components' radius, shadow rays end while a
    branch could still shade them (the ball is loose: at half the radius no pixel changes
    here), and primary rays miss branches they would have hit."""
    shaders = broken_shaders(
        tmp_path, "trace.glsl", "near = rho - ball.w", "near = rho - 0.25 * ball.w"
    )
    scene = scenes()["tree"]
    if exit_ == "shadow":  # the primary exit off, so only the shadows can differ
        path = shaders / "trace.glsl"
        path.write_text(path.read_text().replace(RAY_EXIT, "    if (false) {"))
    good, bad = renderer.render(scene, W, H), Renderer(shader_dir=shaders).render(scene, W, H)
    assert not np.array_equal(good.color, bad.color)
    if exit_ == "ray":
        assert (good.hit & ~bad.hit).any()
    else:
        assert np.array_equal(good.hit, bad.hit)


@pytest.mark.parametrize("name", ["forest", "rock", "palm"])
def test_no_exit_where_no_ball_bounds_it(name):
    """A ground plane (unbounded), a MöKRS, and a twist (which bends the geometry out of its
    ball) compile no exit."""
    scene = load_scene(resolve(name))
    c = compile_geometry(scene.geometry(), ALBEDO)
    assert "KRS_BALL_EXIT" not in variant_defines(scene, c)
    tree = load_scene(resolve("tree"))
    twisted = replace(tree, effects=tree.effects + ["twist"])
    assert "KRS_BALL_EXIT" not in variant_defines(
        twisted, compile_geometry(tree.geometry(), ALBEDO)
    )


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 6))
def test_the_ball_holds_every_instance(seed, n):
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
