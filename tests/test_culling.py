"""Exact level culling [issue 17 §1]: the walk of Alg. 1 stops once d ≤ dist(x, C_i), the
ball of everything levels i..0 still test; the distance is the same as the full walk's."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.balls import krs_bounds
from krsview.compile.krs import compile_krs
from krsview.reference import krs
from krsview.scene import load_scene
from krsview.scene.presets import resolve


def points(scene, n=3000, seed=0):
    rng = np.random.default_rng(seed)
    c = np.array(scene.camera.target)
    return c + rng.normal(size=(n, 3)) * np.linalg.norm(np.subtract(scene.camera.position, c)) / 3


@pytest.mark.parametrize("name", ["tree", "sierpinski", "grass", "rock", "bent-tree"])
def test_culled_distance_equals_the_full_walk(name):
    scene = load_scene(resolve(name))
    c = compile_krs(scene.geometry(), (1.0, 1.0, 1.0))
    x = points(scene)
    full, culled = krs.distance(c, x, cull=False), krs.distance(c, x, cull=True)
    assert np.array_equal(full, culled)


def one_union_per_level(g):
    """Negative control: the balls as built before issue 27, C_i = S ∪ R_i(S) with S the
    least ball around K_i's ball and C_{i−1}, and the whole KRS's K_n ∪ C_{n−1}: the slack
    of each union of two balls compounds level after level."""
    from krsview.compile.balls import kernel_ball, reflected, union_ball

    out, below = [], None
    for k, m in zip(g.kernels, g.mirrors):
        s = union_ball(below, kernel_ball(k))
        below = union_ball(s, reflected(s[None], np.array(m.normal), m.offset)[0])
        out.append(below)
    return [*out, union_ball(kernel_ball(g.kernels[-1]), below)]


def expanded(g, i):
    """Brute force: every copy of every kernel's ball (kernel_ball, tested against sampled
    arcs in test_mokrs) that slot i of Alg. 1 still tests — levels ≤ i under the reflection
    products R_i^b_i ⋯ R_j^b_j; i = n: the whole KRS, the top kernel too."""
    from krsview.compile.balls import kernel_ball, reflected

    balls = np.zeros((0, 4))
    for k, m in list(zip(g.kernels, g.mirrors))[: i + 1]:
        b = kernel_ball(k)
        balls = balls if b is None else np.vstack([balls, b])
        balls = np.vstack([balls, reflected(balls, np.array(m.normal), m.offset)])
    top = kernel_ball(g.kernels[-1]) if i == g.n else None
    return balls if top is None else np.vstack([top, balls])


def least_radius(balls, steps=3000):
    """The radius of a ball around ``balls`` close to the least: Bădoiu–Clarkson's steps
    from the centroid toward the farthest ball, 1/(k + 2) of the way [converges as 1/√k]."""
    c, best = balls[:, :3].mean(axis=0), np.inf
    for k in range(steps):
        reach = np.linalg.norm(balls[:, :3] - c, axis=1) + balls[:, 3]
        best = min(best, reach.max())
        c = c + (balls[reach.argmax(), :3] - c) / (k + 2)
    return best


@pytest.mark.parametrize(
    "name, levels", [("tree", 12), ("bent-tree", 11), ("sierpinski", 12), ("rock", None)]
)
def test_every_ball_holds_what_it_claims_and_is_tight(name, levels):
    """Each culling ball C_i and the ball around the whole KRS hold every copy of every
    kernel's ball they claim to (brute force), and lie within 1.15× of the least ball that
    could (3,000 Bădoiu–Clarkson steps over all the copies; the rock's top is a plane, so it
    has no whole ball). Negative control: the balls built one union of two balls per level,
    as before, are over 1.3× that on every scene but the rock (tree 1.59×)."""
    from krsview.compile.balls import krs_ball

    g = load_scene(resolve(name)).geometry()
    g = g.truncated(levels) if levels else g
    balls = [*krs_bounds(g), krs_ball(g)]
    slack = []
    for i, (ball, loose) in enumerate(zip(balls, one_union_per_level(g))):
        if ball is None or ball[3] < 0:  # unbounded, or empty above (sierpinski's slots)
            continue
        held = expanded(g, i)
        reach = np.linalg.norm(held[:, :3] - ball[:3], axis=1) + held[:, 3]
        least = least_radius(held)
        assert reach.max() <= ball[3] * (1 + 1e-12) and ball[3] <= 1.15 * least, (name, i)
        slack.append(loose[3] / least)
    assert slack and (name == "rock" or max(slack) > 1.3), slack


@pytest.mark.parametrize(
    "name, levels", [("tree", 12), ("bent-tree", 11), ("rock", None), ("grass", None)]
)
def test_every_ball_is_centred_on_its_mirror_and_still_holds_its_slot(name, levels):
    """The walk folds about each slot's ball centre, u·(x − c) (krs.glsl, fold), so every
    centre lies on its slot's mirror plane, and the ball still holds every copy of every
    kernel's ball the slot tests (brute force). Negative controls: the centres as enclosed
    (held_balls, before projection) lie off their planes, and a centre projected onto the
    plane of the slot below instead no longer holds its slot somewhere."""
    from krsview.compile.balls import held_balls, on_plane

    g = load_scene(resolve(name)).geometry()
    g = g.truncated(levels) if levels else g
    bounds, enclosed = krs_bounds(g), held_balls(g)
    off, elsewhere = [], []
    for i, (ball, m) in enumerate(zip(bounds, g.mirrors)):
        u = np.array(m.normal)
        assert abs(ball[:3] @ u - m.offset) <= 1e-12 * (1.0 + np.abs(ball[:3]).max()), (name, i)
        if ball[3] < 0:
            continue
        held = expanded(g, i)
        assert (np.linalg.norm(held[:, :3] - ball[:3], axis=1) + held[:, 3]).max() <= ball[3]
        off.append(abs(enclosed[i][:3] @ u - m.offset) / ball[3])
        if i > 0:
            below = g.mirrors[i - 1]
            c = on_plane(ball[:3], np.array(below.normal), below.offset)
            elsewhere.append((np.linalg.norm(held[:, :3] - c, axis=1) + held[:, 3]).max() / ball[3])
    assert max(off) > 1e-3 and max(elsewhere) > 1.0, (off, elsewhere)


def test_folding_about_the_centres_is_folding_in_the_mirrors():
    """Alg. 1 folding about the balls' centres (reference/krs.py, as the shader where it
    compiles the level of detail) gives the value of Alg. 1 folding in the planes u·x = w,
    written out here, to rounding; negative control: folding about the centres as enclosed,
    before projection, does not."""
    from krsview.compile.balls import UNBOUNDED, grown, held_balls
    from krsview.reference.kernels import kernel_distance

    scene = load_scene(resolve("tree"))
    g = scene.geometry().truncated(12)
    c = compile_krs(g, (1.0, 1.0, 1.0))
    x = points(scene)
    y, planes = x, kernel_distance(c.types[c.n], c.records[c.n], x)
    for i in range(c.n - 1, -1, -1):
        e = y @ c.mirrors[i, :3] - c.mirrors[i, 3]
        y = y - 2.0 * np.maximum(e, 0.0)[:, None] * c.mirrors[i, :3]
        planes = np.minimum(planes, kernel_distance(c.types[i], c.records[i], y))
    walk = krs.distance(c, x, cull=False)
    assert np.allclose(walk, planes, rtol=0.0, atol=1e-12)
    enclosed = [UNBOUNDED if b is None else grown(b) for b in held_balls(g)[:-1]]
    loose = replace(c, bounds=np.array(enclosed))
    assert np.abs(krs.distance(loose, x, cull=False) - planes).max() > 1e-3


def test_a_ball_one_kernel_too_small_changes_the_distance():
    """Negative control: leaving K_i out of C_i (a ball one kernel too small) culls walks
    that still had a smaller value: the distance differs from the full walk somewhere."""
    scene = load_scene(resolve("tree"))
    c = compile_krs(scene.geometry(), (1.0, 1.0, 1.0))
    shrunk = c.bounds.copy()
    shrunk[:, 3] *= 0.5
    broken = replace(c, bounds=shrunk)
    x = points(scene)
    assert not np.array_equal(krs.distance(c, x, cull=False), krs.distance(broken, x))


def test_culling_walks_fewer_levels_far_from_the_tree():
    scene = load_scene(resolve("tree"))
    c = compile_krs(scene.geometry(), (1.0, 1.0, 1.0))
    x = points(scene)
    walked = np.zeros(len(x))
    d = krs.distance(c, x, cull=False)
    for i in range(c.n - 1, -1, -1):
        b = c.bounds[i]
        live = np.linalg.norm(x - b[:3], axis=1) - b[3] < d
        walked += live
    assert walked.mean() < 0.8 * c.n


def test_levels_walked_on_the_gpu_match_the_walks_and_drop_with_culling(renderer):
    """The GPU's count of levels walked while tracing (Renderer.levels): without culling
    every step walks all n levels of the tree, so the count is exactly iterations × n;
    with culling no pixel walks more and many walk fewer — far more in `forest`, whose
    steps are mostly far from the finer levels, than in `tree`, whose are in the crown."""
    share = {}
    for name in ("tree", "forest"):
        scene = load_scene(resolve(name))  # every level: the level of detail also cuts walks
        off = replace(scene, render=replace(scene.render, culling="off", lod=0.0))
        scene = replace(scene, render=replace(scene.render, culling="on", lod=0.0))
        walked_off, walked_on = renderer.levels(off, 64, 36), renderer.levels(scene, 64, 36)
        if name == "tree":
            n = len(scene.geometry().mirrors)
            assert np.array_equal(walked_off, renderer.render(off, 64, 36).iterations * n)
        assert (walked_on <= walked_off).all() and (walked_on < walked_off).any()
        share[name] = walked_on.sum() / walked_off.sum()
    assert share["forest"] < 0.8 < share["tree"]


@pytest.mark.parametrize("name", ["tree", "bent-tree", "forest"])
def test_with_the_level_of_detail_culling_still_changes_no_value(name):
    """Culling with the level of detail (ρ per point, as lod 0.5 and 2 at a tree's distance
    give): the same values as the walk without culling, bit for bit. The balls drawn below a
    cut reach up to 2Kρ beyond the balls above them, and culling waits for that."""
    scene = load_scene(resolve(name))
    c = compile_krs(scene.geometry(), (1.0, 1.0, 1.0))
    x = points(scene)
    for rho in (0.02, 0.08):
        full = krs.distance(c, x, cull=False, rho=rho)
        assert np.array_equal(full, krs.distance(c, x, cull=True, rho=rho)), rho


def test_culling_that_ignores_the_reach_of_the_balls_below_changes_the_image(renderer, tmp_path):
    """Negative control on the GPU: culling on and off draw `tree` at lod 0.5 bit for bit
    (tests/test_prepass.py, every preset); a shader whose culling test leaves out the 2Kρ
    that a ball drawn below may reach beyond C_i draws some pixels differently."""
    from krsview.gpu.renderer import Renderer

    from .conftest import broken_shaders

    cut = "length(x - b.xyz) - b.w - lod.reach >= d"
    naive = Renderer(
        shader_dir=broken_shaders(tmp_path, "krs.glsl", cut, "length(x - b.xyz) - b.w >= d")
    )
    scene = load_scene(resolve("tree"))
    on, off = (replace(scene, render=replace(scene.render, culling=v)) for v in ("on", "off"))
    assert np.array_equal(renderer.render(on, 96, 54).depth, renderer.render(off, 96, 54).depth)
    assert not np.array_equal(naive.render(on, 96, 54).depth, naive.render(off, 96, 54).depth)


@pytest.mark.parametrize("culling", ["on", "off"])
def test_the_cut_ball_drawn_after_the_walk_equals_the_cut_in_place(renderer, tmp_path, culling):
    """The level of detail's cut notes its slot and draws the ball once the walk is over
    (krs.glsl, krs_lod_cut); the image is the cut's in place (the ball's distance taken at the
    level, as Alg. 1 reads), bit for bit, with and without culling. Negative control:
    deferring the ball of the slot above draws another image."""
    from krsview.gpu.renderer import Renderer

    from .conftest import broken_shaders

    test = "if (b.w >= 0.0 && top - i >= lod.depth)"
    deferred = test + " { cut = i; return false; }"
    in_place = (  # and it tells the shading that the ball won where it did (g_cut)
        test + " { real k = length(x - b.xyz) - b.w; g_cut = k < d ? i : -1; d = min(d, k); "
        "return false; }"
    )
    inline = Renderer(shader_dir=broken_shaders(tmp_path / "a", "krs.glsl", deferred, in_place))
    above = test + " { cut = i + 1; return false; }"
    wrong = Renderer(shader_dir=broken_shaders(tmp_path / "b", "krs.glsl", deferred, above))
    scene = load_scene(resolve("tree"))
    scene = replace(scene, render=replace(scene.render, culling=culling, lod=2.0))
    img = renderer.render(scene, 96, 54)
    ref = inline.render(scene, 96, 54)
    for field in ("color", "depth", "normal", "iterations", "hit"):
        assert np.array_equal(getattr(img, field), getattr(ref, field)), field
    assert not np.array_equal(wrong.render(scene, 96, 54).depth, img.depth)
