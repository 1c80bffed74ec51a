"""Wind on a MöKRS (issue 29 §1): the binary tracer's probes are mapped through the bend, a
world ball B(p, r) free when B(g(p), L·r) is free at rest, so a ball declared free holds none
of the bent geometry at random times (brute force over points of the bent, clipped
geometry), and the normal is the bent field's gradient; the GPU draws what the float64
reference draws at sampled times, on every path and MöKRS preset, continuously in time; and
a MöKRS without wind compiles and draws nothing of it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.algebra import mobius
from krsview.bench.metrics import (
    COLOR_TOL,
    DEPTH_REL,
    NORMAL_DEG,
    agreement,
    gpu_reference_agreement,
    tolerance_failures,
)
from krsview.compile.balls import kernel_ball
from krsview.compile.camera import view_of
from krsview.compile.geometry import compile_geometry
from krsview.compile.mokrs import compile_mokrs
from krsview.gpu.renderer import Renderer
from krsview.gpu.uniforms import variant_defines
from krsview.reference import mokrs, render_reference
from krsview.reference.kernels import kernel_distance
from krsview.reference.wind import Wind
from krsview.scene import KRS, Level, SceneError, Sphere, scene_from_toml

from .conftest import assert_finite, broken_shaders, check_against_reference, per_pixel
from .test_distance_bound import ALBEDO
from .test_wind import PRESETS, all_effects_image, bent_forward, changed, preset, still, windy


def palm_in(rng: np.random.Generator):
    """The palm in test_wind's random strong wind (a foot near the palm's, up to 30° per
    half a unit of height) at its random time."""
    gusty = windy(KRS([Level(Sphere((0.0, 1.0, 0.0), 0.5))]), rng)
    palm = preset("palm")
    return replace(palm, effects=["wind"], effect_settings=gusty.effect_settings).at(gusty.time)


def rest_samples(m, rng: np.random.Generator, levels: int, tries: int) -> np.ndarray:
    """Points of the MöKRS's clipped geometry at rest, found without its walk: points inside
    the kernel of a few random levels j, carried out by G_j, G_{j+1}, … to the world; at each
    reflecting level a point on the far side of x = 0 is dropped (the walk folds before it
    tests, so that side is clipped) and the rest are mirrored or not at random."""
    c = compile_mokrs(m, ALBEDO)
    out = []
    for j in rng.choice([i for i in range(c.n) if c.types[i] != "empty"], levels):
        b = kernel_ball(m.levels[j].kernel)
        y = b[:3] + rng.uniform(-b[3], b[3], size=(tries, 3))
        y = y[kernel_distance(c.types[j], c.records[j], y) < 0.0]
        for i in range(j, c.n):
            if c.reflect[i]:
                y = y[y[:, 0] <= 0.0]
                y = y * np.where(rng.random((len(y), 1)) < 0.5, [-1.0, 1.0, 1.0], 1.0)
            y = mobius.apply(m.levels[i].matrix(), y)
        out.append(y)
    return np.concatenate(out)


SEEDS = range(20)
BALLS = 1200  # per seed


def held_free(seed: int, lipschitz: bool = True) -> tuple[int, int, int]:
    """Balls near points of the bent palm at a random time and wind, each holding a point
    or not: (how many the test declares free, how many of those hold a bent point, how many
    hold one). Without ``lipschitz`` the ball is mapped to B(g(p), r), not B(g(p), L·r)."""
    rng = np.random.default_rng(seed)
    scene = palm_in(rng)
    wind, c = Wind.of(scene), compile_mokrs(scene.mokrs, ALBEDO)
    rest = rest_samples(scene.mokrs, rng, 12, 6000)
    assert (mokrs.distance_estimate(c, rest[:200]) < 1e-9).all()  # the walk agrees
    bent = bent_forward(wind, rest)
    assert np.allclose(wind.unwind(0, bent), rest, atol=1e-9)  # the two maps agree
    n = BALLS // 2
    x0 = bent[rng.integers(len(bent), size=2 * n)]
    r = np.geomspace(3e-3, 0.5, 2 * n)[rng.permutation(2 * n)]
    u = rng.normal(size=(2 * n, 3))
    f = np.concatenate([rng.uniform(0.0, 4.0, n), rng.uniform(0.8, 1.0, n)])  # and a rim
    p = x0 + u / np.linalg.norm(u, axis=1, keepdims=True) * (r * f)[:, None]
    if lipschitz:
        free = mokrs.is_unbounding(c, p, r, wind=wind)
    else:
        far = wind.wind_ball_distance(0, p) >= r
        free = far | mokrs.is_unbounding(c, wind.unwind(0, p), r)
    holds = (np.linalg.norm(p[:, None] - bent[None], axis=2) < r[:, None]).any(axis=1)
    return int(free.sum()), int((free & holds).sum()), int(holds.sum())


def test_a_ball_declared_free_holds_no_bent_geometry():
    """20 random winds and times, 1200 balls each within 4 radii of a point of the bent
    palm (half of them just inside it): none declared free holds one of its points [KRS17
    Alg. 3 through the bend]; the check is not empty (many declared free, many hold one)."""
    counts = np.array([held_free(seed) for seed in SEEDS])
    assert counts[:, 1].max() == 0, counts
    assert counts[:, 0].min() >= 20 and counts[:, 2].min() >= 20, counts


def test_without_the_lipschitz_factor_a_free_ball_holds_geometry():
    """Negative control: the rest ball B(g(p), r), not grown by L, declares balls free that
    hold bent leaflets."""
    assert sum(held_free(seed, lipschitz=False)[1] for seed in SEEDS) > 0


@pytest.mark.parametrize("seed", range(101, 105))
def test_the_normal_is_the_gradient_of_the_bent_field(seed):
    """At points of the bent palm the normal (the rest walk's at g(x), through Dgᵀ) is the
    direction of the central differences of x ↦ estimate(g(x)) (the palm's maps are
    similarities, so the first-order estimate's gradient is the kernel's); negative
    control: the rest normal at g(x), not turned back, is off by degrees."""
    rng = np.random.default_rng(seed)
    scene = palm_in(rng)
    wind, c = Wind.of(scene), compile_mokrs(scene.mokrs, ALBEDO)
    x = bent_forward(wind, rest_samples(scene.mokrs, rng, 12, 6000))[:300]

    def angle(n: np.ndarray) -> np.ndarray:
        h, f = 1e-6, lambda y: mokrs.distance_estimate(c, wind.unwind(0, y))
        fd = np.stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
        cos = (n * fd).sum(1) / np.linalg.norm(fd, axis=1)
        return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))

    assert angle(mokrs.nearest(c, x, wind)[1]).max() < 1e-3
    assert angle(mokrs.nearest(c, wind.unwind(0, x))[1]).max() > 5.0


# --------------------------------------------------------------------------- GPU
def palm_wind(strength: float = 12.0):
    """The palm-wind preset drawn exactly (every level, a shadow ray per pixel), in a
    stronger wind."""
    s = per_pixel(preset("palm-wind").edit("render.lod", 0.0))
    return s.edit("effect_settings.wind_strength", strength)


@pytest.mark.parametrize("t", [0.0, 1.7, 6.3, 41.9])
def test_gpu_matches_the_reference_at_sampled_times(renderer, t):
    """The palm in wind at four times, 48×32: the wind moves ≥ 3 % of the pixels."""
    s = palm_wind().at(t)
    gpu, ref = renderer.render(s, 48, 32), render_reference(s, 48, 32)
    assert_finite(gpu, s.render.max_iterations)
    plain = render_reference(still(s), 48, 32)
    assert (np.abs(ref.color - plain.color).max(-1) > 4 / 255).mean() > 0.03
    check_against_reference(f"palm-wind-t{t}", gpu, ref)


def test_a_gpu_without_the_lipschitz_factor_fails_the_comparison(tmp_path):
    """Negative control of the comparisons above: with the probe's radius not grown by L in
    mokrs.glsl, rays pass leaflets and the image leaves the reference's tolerances."""
    shaders = broken_shaders(tmp_path, "mokrs.glsl", "        radius *= L;\n", "\n")
    s = palm_wind().at(1.7)
    gpu = Renderer(shader_dir=shaders).render(s, 48, 32)
    assert tolerance_failures(gpu_reference_agreement(gpu, render_reference(s, 48, 32)))


@pytest.mark.parametrize("name", ["shell", "tree-mokrs", "inversion"])
def test_every_mokrs_preset_bends(renderer, name):
    """The shell, the tree as a MöKRS and the inversion (poles) in wind: the GPU draws the
    reference's image, and the wind moves ≥ 3 % of the pixels."""
    s = per_pixel(preset(name).edit("render.lod", 0.0))
    s = replace(s, effects=[*s.effects, "wind"]).edit("effect_settings.wind_strength", 12.0)
    s = s.at(2.3)
    gpu, ref = renderer.render(s, 48, 32), render_reference(s, 48, 32)
    assert_finite(gpu, s.render.max_iterations)
    assert changed(ref, render_reference(still(s), 48, 32)) > 0.03
    check_against_reference(f"{name}-wind", gpu, ref)


@pytest.mark.parametrize("knob, value", [("precision", "double"), ("path", "compute")])
def test_every_path_follows_the_wind(renderer, knob, value):
    """Double precision and the compute path (its shadow rays as tasks) probe through the
    bend as the fragment path does: each draws the reference's image."""
    s = palm_wind().edit(("render", knob), value).at(2.2)
    gpu = renderer.render(s, 48, 32)
    assert_finite(gpu, s.render.max_iterations)
    check_against_reference(f"palm-wind-{value}", gpu, render_reference(s, 48, 32))


def test_the_prepass_follows_the_wind(renderer):
    """The pre-pass's cones probe through the bend (is_unbounding): away from outlines every
    pixel has the same hit state as without it, a depth within 2ε (binary tracing), and on
    outlines ≤ 1.5 % flip (tests/test_gpu_vs_reference.py's check). Negative control: the
    still palm's image is further off (the leaflets are thin, so it differs on outlines)."""
    s = palm_wind().at(1.1)
    plain = renderer.render(s, 96, 54)
    img = renderer.render(s.edit("render.prepass", 4), 96, 54)
    eps_per_t = view_of(s.camera, 96, 54).footprint * s.render.epsilon_scale
    a = agreement(img, plain, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert a.off_edge_hit == 0 and a.off_edge_depth <= 2.0 * eps_per_t and a.hit >= 0.985, a
    control = agreement(renderer.render(still(s), 96, 54), plain, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert control.hit < 0.975, control


def test_time_is_continuous(renderer):
    """A 1 ms step changes almost nothing; a 1 s step (the negative control) changes much
    more; the image at t is the same whichever time was drawn before."""
    s, t0 = palm_wind(), 2.0
    at = {t: renderer.render(s.at(t), 96, 64) for t in (t0, t0 + 1e-3, t0 + 1.0)}
    small, large = changed(at[t0], at[t0 + 1e-3]), changed(at[t0], at[t0 + 1.0])
    assert small < 0.005 and large > 0.02 and large > 10 * max(small, 1e-3), (small, large)
    assert np.array_equal(renderer.render(s.at(t0), 96, 64).color, at[t0].color)


def test_idle_wind_draws_the_still_palm(renderer):
    """No lean: the bend is the identity, L = 1 and ε's factor 1, so the wind's variant
    probes as the palm without wind, bit for bit; only the normal is normalised once more.
    Negative control: half a degree of lean changes the image."""
    idle = palm_wind(0.0).at(3.0)
    base, wind = renderer.render(still(idle), 64, 36), renderer.render(idle, 64, 36)
    for name in ("depth", "hit", "iterations"):
        assert np.array_equal(getattr(wind, name), getattr(base, name)), name
    assert np.abs(wind.normal - base.normal).max() < 1e-6
    assert np.abs(wind.color - base.color).max() < 1e-6
    assert not np.array_equal(renderer.render(palm_wind(0.5).at(3.0), 64, 36).depth, base.depth)


def test_a_palm_without_wind_compiles_none_of_it(tmp_path, renderer):
    """Specialisation: with wind.glsl broken, the palm without wind draws the same image bit
    for bit (no wind code is compiled); the palm in wind no longer builds (the control)."""
    broken = Renderer(
        shader_dir=broken_shaders(tmp_path, "wind.glsl", "uniform float u_time;", "broken")
    )
    palm = per_pixel(preset("palm"))
    assert "KRS_WIND" not in variant_defines(palm, compile_geometry(palm.geometry(), ALBEDO))
    a, b = renderer.render(palm, 64, 36), broken.render(palm, 64, 36)
    for name in ("color", "depth", "normal", "hit", "iterations"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    with pytest.raises(Exception, match="wind.glsl"):
        broken.render(palm_wind(), 64, 36)


def test_the_all_effects_variant_switches_the_wind_by_its_bit(renderer):
    """A MöKRS's variant with every effect it allows (the wind now among them) draws the
    specialised images, windy and still; the two differ (the control)."""
    s = palm_wind().at(0.7)
    moving, calm = (all_effects_image(renderer, scene) for scene in (s, still(s)))
    assert not np.array_equal(moving.hit, calm.hit)


# --------------------------------------------------------------------------- the scene
def palm_toml(effects: str, settings: str = "") -> str:
    text = (PRESETS / "palm.toml").read_text().replace("effects = []", f"effects = {effects}", 1)
    return text.replace("\n[mokrs]\n", f"\n[effect_settings]\n{settings}\n[mokrs]\n", 1)


def test_a_mokrs_may_list_wind_but_not_twist():
    """The wind is allowed on a MöKRS; the twist and empty zones still need a KRS distance,
    and a bad wind setting is the same one-line error as for a KRS."""
    assert scene_from_toml(palm_toml('["wind"]')).effects == ["wind"]
    for effect in ("twist", "empty_zones"):
        with pytest.raises(SceneError, match=f"{effect}.*allowed on a MöKRS: .*wind"):
            scene_from_toml(palm_toml(f'["{effect}"]'))
    bad = palm_toml('["wind"]', "wind_direction = [0.0, 1.0, 0.0]")
    with pytest.raises(SceneError, match=r"effect_settings\.wind_direction.*horizontal part"):
        scene_from_toml(bad)
    with pytest.raises(SceneError, match=r"effect_settings\.wind_height"):
        scene_from_toml(palm_toml('["wind"]', "wind_height = 0.0"))
