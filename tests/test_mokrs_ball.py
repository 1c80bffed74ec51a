"""A MöKRS's probe that misses a level's bound is free at once (issue 27, "MöKRS levels too"):
no ball so declared holds a point of the MöKRS (brute force over points found without its
walk, near it and far out), it only adds free balls to Alg. 3's, and on the GPU it walks far
fewer levels for the same image; negative controls: bounds shrunk by a tenth declare balls
free that hold points, and the GPU without the test walks more levels."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from krsview.algebra import mobius
from krsview.compile.camera import primary_rays, view_of
from krsview.compile.mokrs import compile_mokrs
from krsview.gpu.renderer import Renderer
from krsview.reference import mokrs
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders
from .test_distance_bound import ALBEDO
from .test_mokrs_wind import rest_samples

PRESETS = ["palm", "shell", "tree-mokrs", "inversion"]
PROBES = 3000  # near the points, and as many far out


def probes(points: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Balls (centres, radii): half within 3 radii of a point of the MöKRS, radii from 1/1000
    to 1/2 of its size; half anywhere in the cube of 3 sizes around it."""
    mid = points.mean(axis=0)
    size = np.linalg.norm(points - mid, axis=1).max()
    r = np.geomspace(1e-3, 0.5, 2 * PROBES)[rng.permutation(2 * PROBES)] * size
    u = rng.normal(size=(PROBES, 3))
    u *= (r[:PROBES] * rng.uniform(0.0, 3.0, PROBES) / np.linalg.norm(u, axis=1))[:, None]
    near = points[rng.integers(len(points), size=PROBES)] + u
    far = mid + rng.uniform(-3.0, 3.0, size=(PROBES, 3)) * size
    return np.concatenate([near, far]), r


def declared(name: str, shrink: float = 1.0) -> tuple[int, int, int, int]:
    """For the preset's MöKRS, its outermost bound's radius cut to ``shrink`` times the
    farthest point's distance from its centre (1: left as compiled): (balls declared free, of
    those how many hold a point, how many hold one, how many Alg. 3 alone declares free that
    the quick test does not)."""
    rng = np.random.default_rng(sum(map(ord, name)))
    m = load_scene(resolve(name)).mokrs
    c = compile_mokrs(m, ALBEDO)
    points = rest_samples(m, rng, 16, 4000)
    if shrink != 1.0:  # in level n−1's space, where the bound lives
        bounds, top = c.bounds.copy(), c.bounds[-1]
        inner = mobius.apply(c.inverse[-1], points)
        bounds[-1, 3] = shrink * np.linalg.norm(inner - top[:3], axis=1).max()
        c = replace(c, bounds=bounds)
    centres, radii = probes(points, rng)
    holds = cKDTree(points).query(centres)[0] < radii
    free = mokrs.is_unbounding(c, centres, radii)
    alone = mokrs.is_unbounding(c, centres, radii, bound_miss=False)
    return int(free.sum()), int((free & holds).sum()), int(holds.sum()), int((alone & ~free).sum())


@pytest.mark.parametrize("name", PRESETS)
def test_a_ball_missing_a_level_bound_holds_nothing(name):
    """6000 balls near and far: none declared free holds a point of the MöKRS, and every ball
    Alg. 3 alone declares free still is (the test only returns earlier)."""
    free, wrong, holds, lost = declared(name)
    assert wrong == 0 and lost == 0
    assert free > PROBES and holds > 200  # both kinds are there to be told apart


@pytest.mark.parametrize("name", PRESETS)
def test_a_bound_shrunk_by_a_tenth_declares_held_balls_free(name):
    """Negative control: with the outermost bound 10 % short of the farthest point, some
    balls that hold a point miss it and are declared free."""
    assert declared(name, shrink=0.9)[1] > 0


# The quick test in mokrs.glsl, and the walk without it (the LOD cut then tests the miss).
QUICK = (
    "        if (b.w >= 0.0 && length(b.xyz - center) - b.w >= radius) return true;\n"
    "#ifdef KRS_LOD  // a bound below ρ that the probe reaches stands for the levels below\n"
    "        if (b.w >= 0.0 && b.w < lod_per_radius * radius) return false;\n"
)
WITHOUT = (
    "#ifdef KRS_LOD\n"
    "        if (b.w >= 0.0 && b.w < lod_per_radius * radius)\n"
    "            return length(b.xyz - center) - b.w >= radius;\n"
)


def test_rays_far_from_the_mokrs_walk_few_levels(renderer, tmp_path):
    """palm at 64×36: rays that miss the MöKRS's outer world ball walk a few of its 60 levels
    per probe (probes grow past the ball), under a fifth of what the walk without the test
    walks on the same rays (negative control: dozens), and fewer than half the levels in all;
    the image is that walk's, bit for bit."""
    scene = load_scene(resolve("palm"))
    W, H = 64, 36
    v = view_of(scene.camera, W, H)
    ball = compile_mokrs(scene.mokrs, ALBEDO).outer[-1]
    d = primary_rays(v).reshape(H, W, 3)
    to = ball[:3] - v.origin
    miss = np.linalg.norm(to - (d @ to)[..., None] * d, axis=-1) > ball[3]
    assert 0.3 < miss.mean() < 0.95  # both kinds of pixel are in view
    without = Renderer(shader_dir=broken_shaders(tmp_path, "mokrs.glsl", QUICK, WITHOUT))
    per_probe = []
    for r in (renderer, without):
        frame, levels = r.render(scene, W, H), r.levels(scene, W, H)
        per_probe.append(levels[miss].sum() / frame.iterations[miss].sum())
        per_probe.append(levels.sum())
        per_probe.append(frame)
    quick, total, frame, slow, slow_total, slow_frame = per_probe
    assert np.array_equal(frame.color, slow_frame.color)
    assert np.array_equal(frame.hit, slow_frame.hit)
    assert quick < 0.2 * slow and slow > 20.0
    assert total < 0.5 * slow_total
