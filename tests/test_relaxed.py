"""Over-relaxed sphere tracing [Keinert et al. 2014]: it never skips a surface (brute force over
the expanded KRS, with a negative control that drops the fallback), and the GPU draws what
the reference draws."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.krs import compile_krs
from krsview.reference import distance, render_reference
from krsview.reference.trace import relaxed_trace
from krsview.scene import SceneError, load_scene, scene_from_toml
from krsview.scene.presets import resolve

from .conftest import check_against_reference, per_pixel
from .test_distance_bound import brute_force_distance, clipped_samples, separated_krs, unit

EPS = 1e-4


def first_surface(krs, origin, d, t_max=40.0, samples=8000) -> float:
    """The first ray distance where the exact (brute-force) distance reaches 0; inf if none."""
    t = np.linspace(0.0, t_max, samples)
    inside = brute_force_distance(krs, origin + t[:, None] * d) <= 0.0
    return float(t[np.argmax(inside)]) if inside.any() else np.inf


def naive_relaxed(dist, origin, dirs, omega, max_iterations=512):
    """Relaxation without the fallback: the negative control."""
    t = np.zeros(len(dirs))
    hit = np.zeros(len(dirs), bool)
    for _ in range(max_iterations):
        with np.errstate(all="ignore"):  # rays that fly off to infinity
            d = dist(origin + t[:, None] * dirs)
        hit |= d <= EPS * t
        t = np.where(hit, t, t + omega * d)
    return hit, t


@pytest.mark.parametrize("seed", range(3))
def test_relaxed_tracing_never_skips_a_surface(seed):
    rng = np.random.default_rng(seed)
    krs = separated_krs(rng, 4)
    c = compile_krs(krs, (0.5,) * 3)
    dist = lambda x: distance(c, x)  # noqa: E731
    origin = unit(rng) * 12.0
    targets = clipped_samples(krs, rng, 30)  # points inside the geometry …
    targets = targets[rng.choice(len(targets), 120)] + rng.normal(0, 0.05, (120, 3))
    dirs = targets - origin  # … and rays that graze or miss them
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    tr = relaxed_trace(dist, origin, dirs, EPS, 4096, 60.0, 1.9)
    truth = np.array([first_surface(krs, origin, d) for d in dirs])
    assert np.isfinite(truth).sum() >= 40, "too few rays meet the geometry to test anything"
    step = 40.0 / 8000
    for k in np.flatnonzero(np.isfinite(truth)):
        assert tr.hit[k] and tr.t[k] <= truth[k] + step, (k, tr.t[k], truth[k])
    # negative control: without the fallback, ω = 1.9 jumps into or past kernels
    hit, t = naive_relaxed(dist, origin, dirs, 1.9)
    sel = np.isfinite(truth)
    overshoot = (~hit[sel]) | (t[sel] > truth[sel] + step)
    assert overshoot.any(), "the negative control never overshot: the test cannot tell"


@pytest.mark.parametrize("preset", ["tree", "rock", "sierpinski"])
def test_gpu_relaxed_tracer_matches_the_reference(renderer, preset):
    scene = load_scene(resolve(preset))
    scene = per_pixel(replace(scene, render=replace(scene.render, tracer="relaxed")))
    gpu, ref = renderer.render(scene, 96, 54), render_reference(scene, 96, 54)
    check_against_reference(f"relaxed-{preset}", gpu, ref)


def test_relaxed_tracing_is_refused_for_a_compound_and_a_mokrs():
    for preset, allowed in (("grove", "'sphere', 'binary'"), ("palm", "'binary'")):
        scene = load_scene(resolve(preset))
        with pytest.raises(SceneError, match=allowed):
            scene.check_tracer("relaxed")
    with pytest.raises(SceneError, match="render.relaxation"):
        scene_from_toml(
            "[render]\nrelaxation = 2.5\n[krs]\nlevels = [{ kernel = { type = 'sphere' } }]\n"
        )
