"""Level of detail in the walk [issue 27 §1]: at the first culling ball C_i smaller than ρ,
Alg. 1 takes d = min(d, dist(x, C_i)) and stops. What it draws (reference/krs.py) holds the
KRS, so the value is a lower bound of the full walk's (no hole), and lies within 2ρ of it
(every point of C_i is within its diameter of what it holds). Checked against the full walk,
brute force over the expanded instances, the GPU, and the reliable oracle."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from krsview.api import load_dict
from krsview.bench.metrics import COLOR_TOL, DEPTH_REL, NORMAL_DEG, agreement
from krsview.compile.balls import top_balls
from krsview.compile.krs import compile_krs
from krsview.compile.lod import cut_depth
from krsview.gpu.uniforms import variant_defines
from krsview.oracle.certify import count_errors
from krsview.reference import krs
from krsview.scene import load_scene
from krsview.scene.presets import resolve
from krsview.scene.render import DEFAULT_LOD
from krsview.scene.speed import fast_settings

from .conftest import per_pixel
from .test_culling import points
from .test_distance_bound import ALBEDO, arbitrary_krs, clipped_samples, seeds

W, H = 64, 36


def compiled(name: str, levels: int | None = None):
    scene = load_scene(resolve(name))
    g = scene.geometry()
    return scene, compile_krs(g.truncated(levels) if levels else g, ALBEDO)


def radii(c, x: np.ndarray, seed: int = 1) -> np.ndarray:
    """A level of detail per point spanning the balls' radii (a few points get none)."""
    r = c.bounds[:, 3][c.bounds[:, 3] > 0]
    rng = np.random.default_rng(seed)
    rho = np.exp(rng.uniform(np.log(r.min() / 2), np.log(r.max() * 2), len(x)))
    rho[rng.random(len(x)) < 0.1] = 0.0
    return rho


@pytest.mark.parametrize("name", ["tree", "bent-tree", "grass", "rock"])
def test_lod_stays_below_the_full_walk_and_within_its_reach(name):
    scene, c = compiled(name)
    x = points(scene, 4000)
    rho = radii(c, x)
    full, lod = krs.distance(c, x, cull=False), krs.distance(c, x, rho=rho)
    reach = c.lod_cut[2] * rho  # 2Kρ: a cut ball's diameter at most (compile/lod.py)
    assert np.all(lod <= full), "the level of detail lost geometry: a ray could pass it"
    assert np.all(full - lod <= reach + 1e-12), (full - lod - reach).max()
    assert np.array_equal(krs.distance(c, x, rho=0.0), full)  # off: the walk itself
    assert (lod < full).mean() > 0.05  # and it did cut somewhere


def test_negative_controls_a_shrunk_ball_or_a_cut_at_any_size_break_the_bounds():
    scene, c = compiled("tree", 14)
    x = points(scene, 4000)
    rho = radii(c, x)
    full = krs.distance(c, x, cull=False)
    shrunk = c.bounds.copy()
    shrunk[:, 3] *= 0.5  # a ball that no longer holds its levels: geometry lost
    assert np.any(krs.distance(replace(c, bounds=shrunk), x, rho=rho) > full)
    huge = np.full(len(x), 1e9)  # every ball stands in, however large: far from the tree
    assert np.any(full - krs.distance(c, x, rho=huge) > c.lod_cut[2] * rho)


@settings(max_examples=25, deadline=None)
@given(seed=seeds, n=st.integers(1, 6))
def test_lod_never_overshoots_the_expanded_instances(seed, n):
    """Brute force: points sampled inside every clipped kernel instance (test_distance_bound)
    are part of the geometry, so the LOD distance never exceeds the distance to them."""
    rng = np.random.default_rng(seed)
    g = arbitrary_krs(rng, n)
    samples = clipped_samples(g, rng, 300)
    assume(len(samples) > 0)
    c = compile_krs(g, ALBEDO)
    assume((c.bounds[:, 3] > 0).any())
    x = rng.normal(size=(200, 3)) * 3.0
    lod = krs.distance(c, x, rho=radii(c, x, seed % 1000))
    to_samples = np.min(np.linalg.norm(x[:, None] - samples[None], axis=2), axis=1)
    assert np.all(lod <= to_samples + 1e-9), (lod - to_samples).max()


def with_lod(scene, lod: float):
    return replace(scene, render=replace(scene.render, lod=lod))


def test_lod_off_compiles_nothing_new():
    """lod = 0 builds the variant of before the level of detail (the same image, bit for
    bit); the default is DEFAULT_LOD."""
    scene, c = compiled("tree")
    assert scene.render.lod == DEFAULT_LOD > 0
    assert "KRS_LOD" not in variant_defines(with_lod(scene, 0.0), c)
    assert "KRS_LOD" in variant_defines(scene, c)


@pytest.mark.parametrize("name", ["tree", "rock", "grass", "tree-mokrs"])
def test_gpu_matches_the_reference_at_the_level_of_detail(renderer, name):
    """The GLSL and the NumPy twin cut at the same balls: hits and colours (shadow rays
    included) agree but where a cut, a float comparison, falls apart in float32 and
    float64; and (negative control) the reference without LOD differs from it by more hits
    than the GPU does."""
    scene = per_pixel(with_lod(load_scene(resolve(name)), 2.0))
    gpu = renderer.render(scene, W, H)
    from krsview.reference import render_reference

    ref = render_reference(scene, W, H)
    a = agreement(gpu, ref, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert a.hit >= 0.997 and a.color >= 0.99, a  # a cut may fall apart in float32
    plain = render_reference(with_lod(scene, 0.0), W, H)
    if name == "tree":
        assert int((plain.hit != ref.hit).sum()) > int((gpu.hit != ref.hit).sum())


SPARSE = {  # two small spheres 2 apart (one and its mirror image) under a large one
    "camera": {"position": [0.0, 0.0, -50.0], "target": [0.0, 0.0, 0.0], "fov_y": 45.0},
    "krs": {
        "levels": [
            {"kernel": {"type": "sphere", "center": [-1.0, 0.0, 0.0], "radius": 0.05}},
            {
                "kernel": {"type": "sphere", "center": [0.0, 4.0, 0.0], "radius": 0.5},
                "mirror": {"normal": [1.0, 0.0, 0.0], "offset": 0.0},
            },
        ]
    },
}


# Negative controls: the cut drawn with each ball shrunk, so that it no longer holds the
# levels below (shader, the cut, the shrunk cut). A KRS's walk takes the distance to a ball at
# a quarter of its radius. A MöKRS's probe that reaches its bound is blocked; shrunk, it is
# free unless it reaches a tenth of the bound: the bounds are loose (hits at lod 4: 295 with
# the bound, 188 at half its radius, 145 at a quarter, and the rays lost pass no surface, so
# no hole), and at a tenth 112 hits are left and 5 rays pass a certified surface.
SHRUNK_CUT = {
    "tree": (
        "krs.glsl",
        "real k = length(x - b.xyz) - b.w;",
        "real k = length(x - b.xyz) - 0.25 * b.w;",
    ),
    "tree-mokrs": (
        "mokrs.glsl",
        "if (b.w >= 0.0 && b.w < lod_per_radius * radius) return false;",
        "if (b.w >= 0.0 && b.w < lod_per_radius * radius)\n"
        "            return length(b.xyz - center) - 0.1 * b.w >= radius;",
    ),
}


@pytest.mark.parametrize("name", ["tree", "tree-mokrs", "sparse"])
def test_the_oracle_finds_no_hole_and_the_hits_within_the_lod_reach(renderer, tmp_path, name):
    """Certified: the LOD image passes no surface, and every hit lies within hit_reach (ε
    plus the cut ball's diameter). Negative controls: held to plain ε, the two small spheres'
    ball drawn whole makes hits that are certified false — the level of detail does draw
    something else, and the oracle sees it; and a tree, or a MöKRS tree, whose cut balls are
    drawn shrunk (SHRUNK_CUT: no longer holding the levels below) shows certified holes.
    (In the crown a ball drawn too large is not caught at this size: a hit's reach, 9ε at
    lod 4, always holds a twig; the sparse spheres catch that.)"""
    scene = load_dict(SPARSE, "sparse") if name == "sparse" else load_scene(resolve(name))
    scene = with_lod(scene, 4.0)
    # the oracle's cost grows with the rays (a MöKRS's the most); the sparse spheres' whole
    # ball is a false hit beyond plain ε only where its pixels are as small as at W × H
    w, h = {"tree": (48, 27), "tree-mokrs": (32, 18)}.get(name, (W, H))
    img = renderer.render(scene, w, h)
    counts = count_errors(scene, img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    if name == "sparse":
        plain_reach = replace(scene, render=replace(scene.render, lod=0.0))
        assert count_errors(plain_reach, img, arithmetics=("affine",)).false_hits > 0
    if name in SHRUNK_CUT:
        from krsview.gpu.renderer import Renderer

        from .conftest import broken_shaders

        shrunk = Renderer(shader_dir=broken_shaders(tmp_path, *SHRUNK_CUT[name]))
        assert count_errors(scene, shrunk.render(scene, w, h), arithmetics=("affine",)).holes > 0


def test_levels_below_the_pixel_are_not_walked(renderer):
    """The deterministic half of the speed claim, at the tree's view with the fast settings
    (pre-pass): the five finest levels (18 → 23) add less than half as many levels walked
    with LOD as without, and seven more grown below them (→ 30) under 2 % of what they add
    without: the cut asks how large a slot looks, not how deep the tree below it goes
    (compile/lod.py). Cut where the subtree's own ball fell below ρ, as before, the seven
    levels added 4.5 %: a deeper subtree's ball is larger, so its cut came a level later."""
    deep = fast_settings(load_scene(resolve("tree")).edit(("tree", "levels"), 29))
    walked = {}
    for lod in (0.0, 1.0):
        for m in (18, 23, 30):
            s = with_lod(deep, lod)
            walked[lod, m] = renderer.levels(s, W, H, s.geometry().truncated(m)).sum()
    added = {(a, b): walked[1.0, b] - walked[1.0, a] for a, b in ((18, 23), (23, 30))}
    assert added[18, 23] < 0.5 * (walked[0.0, 23] - walked[0.0, 18]), walked
    assert added[23, 30] < 0.02 * (walked[0.0, 30] - walked[0.0, 23]), walked
    assert walked[0.0, 30] > 1.2 * walked[0.0, 23]  # without LOD the finer levels cost


def envelope(c, k: np.ndarray) -> np.ndarray:
    """The cut radii's envelope A·q^k at depths k (compile/lod.py)."""
    return np.exp(c.lod_cut[0] + k / c.lod_cut[1])


def test_the_cut_is_the_first_depth_whose_envelope_is_below_rho():
    """cut_depth's closed form against a search over the depths, and the envelope lies on or
    above every slot's cut radius (the ball of its top levels alone) and under K times it
    every slot's own ball. ρ = 0 never cuts."""
    _, c = compiled("tree")
    rho = np.exp(np.linspace(np.log(1e-4), np.log(20.0), 4001))
    k = np.arange(c.n + 40)
    searched = np.array([int(np.argmax(envelope(c, k) < r)) for r in rho])
    got = cut_depth(c.lod_cut, rho)
    assert np.mean(got == searched) > 0.999 and np.abs(got - searched).max() <= 1
    tops = top_balls(load_scene(resolve("tree")).geometry())
    depth = c.n - 1 - np.arange(c.n)
    assert all(envelope(c, depth[i]) >= 0.999 * tops[i][3] for i in range(c.n))
    assert np.all(c.bounds[:, 3] <= c.lod_cut[2] / 2 * envelope(c, depth))
    assert cut_depth(c.lod_cut, 0.0) > c.n


def test_a_deeper_tree_cuts_where_the_shallower_one_does():
    """Grown from 23 to 30 levels, the tree's slots cut at the same depths for every ρ that
    cuts the 23-level one (or differ at a boundary, one ρ in a thousand); its subtrees'
    balls, each holding seven more levels, would have cut deeper (negative control: the
    first depth whose subtree ball is below ρ)."""
    deep = load_scene(resolve("tree")).edit(("tree", "levels"), 29).geometry()
    c23, c30 = (compile_krs(deep.truncated(m), ALBEDO) for m in (23, 30))
    rho = np.exp(np.linspace(np.log(c23.bounds[0, 3]), np.log(c23.bounds[-1, 3]), 1000))
    assert np.mean(cut_depth(c23.lod_cut, rho) == cut_depth(c30.lod_cut, rho)) > 0.99

    def by_subtree_ball(c):
        radii = c.bounds[::-1, 3]  # by depth below the top
        return np.array([int(np.argmax(radii < r)) for r in rho])

    assert np.mean(by_subtree_ball(c23) == by_subtree_ball(c30)) < 0.9
