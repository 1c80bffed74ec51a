"""The walk restart [issue 27]: a sphere-traced ray's step restarts Alg. 1 below its anchor,
the levels whose folds the ray cannot have changed since. Every fold is an isometry on each
side of its mirror, so the restarted walk is Alg. 1's value (up to rounding): checked against
the full walk along random rays, the GPU against itself without the restart and against the
NumPy twin, the oracle on its image, and the levels it walks inside the crown."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.bench.metrics import COLOR_TOL, DEPTH_REL, NORMAL_DEG, agreement
from krsview.bench.zoom import stops
from krsview.compile.constants import RESTART_KEEP
from krsview.compile.geometry import compile_geometry
from krsview.compile.krs import compile_krs
from krsview.frame import Frame
from krsview.gpu.uniforms import variant_defines
from krsview.oracle.certify import count_errors
from krsview.reference import krs
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import per_pixel
from .test_distance_bound import ALBEDO, arbitrary_krs

W, H = 64, 36


def geometry(name: str):
    """(scene, compiled KRS) of a preset, or of a random KRS ("random")."""
    scene = load_scene(resolve("tree"))
    if name == "random":
        return scene, compile_krs(arbitrary_krs(np.random.default_rng(7), 6), ALBEDO)
    scene = load_scene(resolve(name))
    return scene, compile_krs(scene.geometry(), ALBEDO)


def walk_rays(c, n=400, steps=40, seed=0, lod=0.02, margin=True):
    """Rays from random points towards the geometry's ball, stepped by random fractions of
    the distance (each step carries its anchor, as trace.glsl's Ray does), the LOD growing
    along the ray. Returns (restarted values, bounded, full walks' values, levels restarted,
    levels of full walks). ``margin=False`` ignores the anchors' fold margins."""
    rng = np.random.default_rng(seed)
    centre, radius = c.ball[:3], c.ball[3]
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    origin = centre - dirs * radius * rng.uniform(1.0, 2.0, (n, 1))
    dirs = centre + rng.normal(size=(n, 3)) * radius * 0.3 - origin
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    t, last = np.zeros(n), np.full(n, np.inf)
    anchor, none = krs.Anchor.none(n), krs.Anchor.none(n)
    got, bounds, want, walked, full = [], [], [], 0, 0
    for _ in range(steps):
        p = origin + t[:, None] * dirs
        rho = lod * t
        keep = RESTART_KEEP * last
        d, bounded, anchor, levels = krs.restart(c, p, dirs, t, rho, keep, anchor, margin)
        _, _, _, plain = krs.restart(c, p, dirs, t, rho, np.full(n, np.inf), none)
        got.append(d)
        bounds.append(bounded)
        want.append(krs.distance(c, p, rho=rho))
        walked, full = walked + levels.sum(), full + plain.sum()
        step = np.maximum(d, 1e-4 * radius) * rng.uniform(0.3, 1.0, n)
        t, last = t + step, step
    return np.concatenate(got), np.concatenate(bounds), np.concatenate(want), walked, full


def error(got, want, c) -> np.ndarray:
    """Each value's error relative to its size and the geometry's."""
    return np.abs(got - want) / (np.abs(want) + c.ball[3])


@pytest.mark.parametrize("name", ["tree", "bent-tree", "random"])
def test_restarted_walks_equal_the_full_walk(name):
    """At every step of every ray the restarted walk gives Alg. 1's value where the levels
    below the anchor decide, and a lower bound of it where the bound of the levels above
    limits (a step without a hit test); on a tree it walks fewer levels in all."""
    _, c = geometry(name)
    got, bounded, want, walked, full = walk_rays(c)
    exact = ~bounded
    assert error(got[exact], want[exact], c).max() < 1e-12, error(got, want, c)[exact].max()
    assert np.all(got[bounded] <= want[bounded] + 1e-12 * (np.abs(want[bounded]) + c.ball[3]))
    assert bounded.mean() < 0.2, bounded.mean()
    if name != "random":  # six levels: little to restart below
        assert walked < 0.8 * full, (walked, full)


@pytest.mark.parametrize("name", ["tree", "random"])
def test_a_restart_past_its_fold_margin_gives_a_wrong_value(name):
    """Negative control: restarting below the anchor however far the ray moved (a fold above
    it changed side) gives values, taken as exact, that are not Alg. 1's."""
    _, c = geometry(name)
    got, bounded, want, *_ = walk_rays(c, margin=False)
    assert error(got[~bounded], want[~bounded], c).max() > 1e-3


def test_the_restart_is_compiled_only_where_folds_are_isometries_along_the_ray():
    """Off by default; on, for a sphere-traced single KRS, and not for the binary tracer,
    under a twist, nor in a compound."""
    scene, c = geometry("tree")
    assert scene.render.walk_restart == "off"  # the default: the plain walk
    assert "KRS_WALK_RESTART" not in variant_defines(scene, c)
    scene = on(scene)
    assert "KRS_WALK_RESTART" in variant_defines(scene, c)
    for field, value in (("walk_restart", "off"), ("tracer", "binary")):
        assert "KRS_WALK_RESTART" not in variant_defines(scene.edit(("render", field), value), c)
    twisted = replace(scene, effects=(*scene.effects, "twist"))
    assert "KRS_WALK_RESTART" not in variant_defines(twisted, c)
    grove = load_scene(resolve("grove"))
    grove_c = compile_geometry(grove.geometry(), ALBEDO)
    assert "KRS_WALK_RESTART" not in variant_defines(on(grove), grove_c)


def on(scene):
    return scene.edit(("render", "walk_restart"), "on")


def off(scene):
    return scene.edit(("render", "walk_restart"), "off")


def crown(stop: int = 4):
    """tree seen from inside its crown (a stop of bench zoom), a shadow ray per pixel, the
    walk restarted."""
    return on(per_pixel(stops(load_scene(resolve("tree")), 12)[stop]))


@pytest.mark.parametrize("stop", [0, 4, 9])
def test_gpu_images_with_and_without_the_restart_agree(renderer, stop):
    """The same hits and depths but where a bounded step (no hit test) sent a grazing ray
    along other steps; a few more iterations for those steps. Negative control: the image
    at half ε differs from the plain one in more hits."""
    scene = crown(stop)
    a, b = renderer.render(scene, W, H), renderer.render(off(scene), W, H)
    agree = agreement(a, b, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert agree.hit >= 0.998 and agree.depth_close >= 0.98, agree
    assert b.iterations.sum() <= a.iterations.sum() <= 1.05 * b.iterations.sum()
    finer = renderer.render(off(scene).edit(("render", "epsilon_scale"), 0.5), W, H)
    assert (finer.hit != b.hit).sum() > (a.hit != b.hit).sum()


def test_gpu_matches_its_numpy_twin(renderer):
    """GLSL and NumPy take the same restarted steps (float32 against float64)."""
    from krsview.reference import render_reference

    scene = crown()
    gpu, ref = renderer.render(scene, W, H), render_reference(scene, W, H)
    a = agreement(gpu, ref, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert a.hit >= 0.997 and a.color >= 0.99, a


def test_the_oracle_finds_no_hole_in_the_restarted_image(renderer):
    """No certified hole nor false hit; negative control: the same image with every ray
    stopped 20 % further (as a walk that overshot) has holes."""
    scene = crown()
    img = renderer.render(scene, 24, 14)  # the oracle's cost grows with every hit
    counts = count_errors(scene, img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    past = Frame(img.color, img.depth * 1.2, img.normal, img.iterations, img.hit)
    assert count_errors(scene, past, arithmetics=("affine",)).holes > 0


def test_levels_walked_fall_inside_the_crown(renderer):
    """The counting variant: inside the crown the restart walks at most 75 % of the levels
    of the plain walk, its few added iterations included; negative control: the whole-tree
    view, where few steps fit under an anchor, saves much less."""
    scene = crown()
    on, plain = renderer.levels(scene, W, H), renderer.levels(off(scene), W, H)
    assert on.sum() < 0.75 * plain.sum(), (on.sum(), plain.sum())
    far = crown(0)
    assert renderer.levels(far, W, H).sum() > 0.85 * renderer.levels(off(far), W, H).sum()


def test_bench_zoom_shows_the_other_walk_beside():
    """bench zoom's rows carry the other walk beside: for a scene with the restart on, the
    plain walk, with more levels per iteration at the stops inside the crown; negative
    control: for a scene with it off (the default), the column is the restarted walk, with
    fewer."""
    from krsview.bench.zoom import bench_zoom

    tree = on(load_scene(resolve("tree")))
    m = bench_zoom(tree, (24, 14), rounds=1, stops_count=3)
    inside = m.rows[1:]
    assert all(r["levels_other_walk"] > r["levels_per_iteration"] for r in inside), inside
    plain = bench_zoom(off(tree), (24, 14), rounds=1, stops_count=3)
    assert all(r["levels_other_walk"] < r["levels_per_iteration"] for r in plain.rows[1:])


@pytest.mark.parametrize("precision", ["float", "double"])
def test_the_compute_path_takes_the_same_restarted_steps(renderer, precision):
    """The anchor lives in the Ray between rounds (compile/std430.py): the compute path's
    image equals the fragment path's, bit for bit; negative control: the image without the
    restart is not that image."""
    from .conftest import same
    from .test_compute import on_path

    scene = on_path(crown(), "fragment", precision=precision)
    fragment = renderer.render(scene, W, H)
    assert same(fragment, renderer.render(on_path(scene, "compute", steps=3), W, H))
    assert not same(fragment, renderer.render(off(scene), W, H))
