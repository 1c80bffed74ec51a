"""Wind (issue 29): a time-dependent Lipschitz bend [KRS17 §5.2] that never overshoots at any
time (brute force over the bent expansion), whose Jacobian stays under the bound it steps by
(finite differences), drawn by the GPU as by the float64 reference at sampled times,
continuous in time, and absent from every scene that does not list it."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from krsview.bench.metrics import COLOR_TOL, DEPTH_REL, NORMAL_DEG, agreement
from krsview.compile.balls import grown, krs_ball
from krsview.compile.camera import view_of
from krsview.compile.geometry import compile_geometry
from krsview.compile.krs import compile_krs
from krsview.gpu.renderer import Renderer, read_buffers
from krsview.gpu.uniforms import variant_defines
from krsview.reference import render_reference
from krsview.reference.distortion import Distortion, safe_step
from krsview.reference.geometry import scene_distance
from krsview.reference.krs import distance as krs_distance
from krsview.reference.wind import Wind, exit_fall, wind_gust
from krsview.scene import (
    KRS,
    EffectSettings,
    Level,
    SceneError,
    Sphere,
    load_scene,
    scene_from_toml,
)
from krsview.scene.effects import wind_feet
from krsview.scene.presets import resolve

from .conftest import assert_finite, broken_shaders, check_against_reference, per_pixel
from .test_ball_exit import H, W, shaders_without
from .test_distance_bound import ALBEDO, arbitrary_krs, clipped_samples, separated_krs

PRESETS = Path(__file__).resolve().parents[1] / "presets"
UP = np.array([0.0, 1.0, 0.0])


def preset(name: str):
    return load_scene(resolve(str(PRESETS / f"{name}.toml")))


def windy(krs: KRS, rng: np.random.Generator):
    """A scene of ``krs`` in a strong, random wind at a random time."""
    fx = EffectSettings(
        wind_direction=tuple(rng.normal(size=3) * (1, 0.3, 1)),
        wind_strength=float(rng.uniform(5.0, 30.0)),
        wind_height=float(rng.uniform(0.5, 3.0)),
        wind_gust=float(rng.uniform(0.0, 1.0)),
        wind_frequency=float(rng.uniform(0.05, 2.0)),
        wind_base=tuple(rng.normal(size=3) * 0.5),
    )
    scene = replace(preset("tree-wind"), tree=None, krs=krs, effect_settings=fx)
    return scene.at(float(rng.uniform(0.0, 100.0)))


def bent_forward(wind: Wind, q: np.ndarray) -> np.ndarray:
    """Rest points q mapped to the world, independently of the reference's g: x − b is q − b
    turned by a·max(h, 0) towards the wind, h = (x − b)·up is a root of h = up·R(a·h⁺)(q − b),
    found by bisection on [−|q − b|, |q − b|] (the left side of the equation minus the right
    is ≤ 0 at the low end and ≥ 0 at the high end, since |up·R v| ≤ |v|)."""
    s = q - wind.bases[0]
    a, A = wind.rates[0], wind.axis

    def turned(h):
        ang = a * np.maximum(h, 0.0)
        cos, sin = np.cos(ang)[:, None], np.sin(ang)[:, None]
        return s * cos + np.cross(A, s) * sin + np.outer(s @ A, A) * (1 - cos)

    r = np.linalg.norm(s, axis=1)
    lo, hi = -r, r.copy()
    for _ in range(60):
        mid = (lo + hi) / 2
        above = mid - turned(mid)[:, 1] > 0
        hi, lo = np.where(above, mid, hi), np.where(above, lo, mid)
    return wind.bases[0] + turned((lo + hi) / 2)


def overshoot(seed: int, lipschitz: bool = True) -> float:
    """The largest amount by which the wind's bound at random points exceeds their distance
    to points sampled in the bent, clipped expansion (≤ 0: no overshoot)."""
    rng = np.random.default_rng(seed)
    krs = arbitrary_krs(rng, int(rng.integers(1, 5)))
    while any(k.kind == "plane" for k in krs.kernels):  # a ground stands in the wind
        krs = arbitrary_krs(rng, int(rng.integers(1, 5)))
    scene = windy(krs, rng)
    dist = Distortion.of(scene)
    rest = clipped_samples(krs, rng, 300)
    if len(rest) == 0:
        return -np.inf
    samples = bent_forward(dist.wind, rest)
    assert np.allclose(dist.undistort(samples), rest, atol=1e-9)  # the two maps agree
    x = dist.wind.bases[0] + rng.normal(size=(300, 3)) * 3.0
    c = compile_krs(krs, ALBEDO)
    # without the bound: the rest distance at g(x) alone, not shrunk
    bound = scene_distance(c, x, dist) if lipschitz else scene_distance(c, dist.undistort(x))
    nearest = np.min(np.linalg.norm(x[:, None] - samples[None], axis=2), axis=1)
    return float((bound - nearest).max())


SEEDS = range(30)


def test_wind_never_overshoots_at_random_times():
    """Random KRSs, winds and times (at least 20 with samples in their expansion): the bound
    is never above the distance to the bent geometry [KRS17 §5.2]."""
    worst = [w for w in map(overshoot, SEEDS) if w > -np.inf]
    assert len(worst) >= 20 and max(worst) <= 1e-9, worst


def test_wind_without_its_bound_would_overshoot():
    """The check above can fail: the rest distance at g(x), not shrunk, overshoots."""
    assert max(overshoot(seed, lipschitz=False) for seed in SEEDS) > 1e-2


def jacobian(f, p: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """(N, 3, 3) central differences of f: (N, 3) → (N, 3)."""
    cols = [(f(p + h * e) - f(p - h * e)) / (2 * h) for e in np.eye(3)]
    return np.stack(cols, axis=2)


@pytest.mark.parametrize("seed", range(4))
def test_the_jacobian_stays_under_the_bound_and_gives_the_normal(seed):
    """‖Dg‖ ≤ 1 + |a|ρ at random points (the bound is tight: it is reached within 10 %) and
    equals ``stretch``, and the normal is Dgᵀ∇ normalised (negative control: a plain rotation
    of ∇ is not)."""
    rng = np.random.default_rng(seed)
    w = Wind.of(windy(KRS([Level(Sphere((0.0, 1.0, 0.0), 0.5))]), rng))
    p = w.bases[0] + rng.normal(size=(400, 3)) * 2.0 + 1.5 * UP
    J = jacobian(lambda x: w.unwind(0, x), p)
    norm = np.linalg.norm(J, ord=2, axis=(1, 2))
    bound = 1 + abs(w.rates[0]) * np.linalg.norm(np.cross(w.axis, p - w.bases[0]), axis=1)
    assert np.all(norm <= bound + 1e-6)
    assert np.max(norm / bound) > 0.9 and np.max(norm) > 1.01
    assert np.abs(norm - w.stretch(0, p)).max() < 1e-6  # the exact norm
    g = rng.normal(size=(400, 3))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    want = np.einsum("nji,nj->ni", J, g)
    want /= np.linalg.norm(want, axis=1, keepdims=True)
    got = w.wind_normal(0, p, w.unwind(0, p), g)
    assert np.abs(got - want).max() < 1e-6
    rotated = w.wind_normal(0, p, w.bases[0] + 0 * p, g)  # the shear's term dropped
    assert np.abs(rotated - want).max() > 1e-2


def step_escape(seed: int, shrink: float = 1.0) -> float:
    """The most by which g takes a point of the step's ball B(p, δ) out of B(g(p), D), over
    random points, free radii D and points of the ball (> 0: the step is not safe); δ is the
    wind's step, with its ρ scaled by ``shrink``."""
    rng = np.random.default_rng(seed)
    w = Wind.of(windy(KRS([Level(Sphere((0.0, 1.0, 0.0), 0.5))]), rng))
    p = w.bases[0] + rng.normal(size=(200, 3)) * 2.0 + 1.5 * UP
    D = rng.uniform(0.0, 3.0, size=200)
    delta = safe_step(D, abs(w.rates[0]), shrink * w.wind_rho(0, p, D))
    u = rng.normal(size=(200, 64, 3))
    u *= (rng.uniform(size=(200, 64, 1)) ** (1 / 3)) / np.linalg.norm(u, axis=2, keepdims=True)
    u[:, 0] = (p - w.bases[0]) / np.linalg.norm(p - w.bases[0], axis=1)[:, None]
    q = (p[:, None] + delta[:, None, None] * u).reshape(-1, 3)
    moved = np.linalg.norm(w.unwind(0, q).reshape(200, 64, 3) - w.unwind(0, p)[:, None], axis=2)
    return float((moved - D[:, None]).max())


def test_the_step_stays_in_the_free_ball():
    """Brute force over the step's ball: g maps B(p, δ) into B(g(p), D), δ from the tighter
    ρ (about half the distance to the axis above the foot); negative control: a quarter of it
    lets points out."""
    assert max(step_escape(seed) for seed in range(8)) <= 1e-9
    assert max(step_escape(seed, 0.25) for seed in range(8)) > 1e-4


def bent_points(seed: int) -> tuple[Wind, np.ndarray, np.ndarray]:
    """A random KRS in a random wind: its Wind at a random time, points of its bent, clipped
    expansion at that time, and its rest ball."""
    rng = np.random.default_rng(seed)
    krs = arbitrary_krs(rng, int(rng.integers(1, 5)))
    while any(k.kind == "plane" for k in krs.kernels):
        krs = arbitrary_krs(rng, int(rng.integers(1, 5)))
    wind = Wind.of(windy(krs, rng))
    return wind, bent_forward(wind, clipped_samples(krs, rng, 200)), grown(krs_ball(krs))


def test_the_swept_ball_holds_the_bent_component_at_any_time():
    """Brute force over the bent expansion at random times: every point lies in the swept
    ball, whose distance the step may take unshrunk; negative control: the rest ball misses
    some."""
    inside, outside = [], []
    for seed in range(30):
        wind, x, rest = bent_points(seed)
        if len(x):
            ball = wind.balls[0]
            inside.append((np.linalg.norm(x - ball[:3], axis=1) - ball[3]).max())
            outside.append((np.linalg.norm(x - rest[:3], axis=1) - rest[3]).max())
    assert len(inside) >= 20 and max(inside) <= 1e-9, inside
    assert max(outside) > 1e-2


def fall_excess(seed: int, wind_aware: bool = True) -> float:
    """The most by which the exits' first bound (exit_fall; the still scene's, D − s, when not
    ``wind_aware``) exceeds the stepped distance brute-forced along random rays of a separated
    KRS (exact, so 1-Lipschitz, distance) in a random wind (> 0: the bound is wrong)."""
    rng = np.random.default_rng(seed)
    krs = separated_krs(rng, int(rng.integers(1, 4)))
    while any(k.kind == "plane" for k in krs.kernels):
        krs = separated_krs(rng, int(rng.integers(1, 4)))
    scene = windy(krs, rng)
    dist, c = Distortion.of(scene), compile_krs(krs, ALBEDO)
    w = dist.wind
    p = w.bases[0] + rng.normal(size=(100, 3)) * 3.0 + 2.0 * UP
    D = krs_distance(c, w.unwind(0, p))
    rho = np.linalg.norm(np.cross(w.axis, p - w.bases[0]), axis=1)
    d0, fall = exit_fall(D, abs(w.rates[0]), rho) if wind_aware else (D, np.ones_like(D))
    u = rng.normal(size=(100, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    worst = -np.inf
    for f in np.linspace(0.0, 1.0, 41):
        s = f * np.maximum(d0, 0.0) / fall  # while the bound is ≥ 0
        stepped = scene_distance(c, p + s[:, None] * u, dist)
        worst = max(worst, float((d0 - fall * s - stepped)[D > 0].max()))
    return worst


def test_the_exits_first_bound_holds_in_the_wind():
    """Brute force along rays: the stepped distance never falls below the wind's first bound
    of the balls' exits; negative control: the still scene's bound (D − s) is not one."""
    assert max(fall_excess(seed) for seed in range(12)) <= 1e-9
    assert max(fall_excess(seed, wind_aware=False) for seed in range(12)) > 1e-3


def test_gusts_are_bounded_and_phases_differ():
    """|n| ≤ 1, so |a(t)| ≤ most; neighbours of the grove do not sway in step."""
    t = np.linspace(0, 1000, 200001)
    n = wind_gust(t, 0.3)
    assert np.abs(n).max() <= 1.0 and n.max() > 0.9 and n.min() < -0.9
    grove = preset("grove-wind")
    rates = np.array([Wind.of(grove.at(t)).rates for t in np.linspace(0, 20, 201)])
    w = Wind.of(grove)
    assert np.abs(rates).max() <= w.most
    sways = rates[:, w.reach > 0]
    corr = np.corrcoef(sways.T)[np.triu_indices(sways.shape[1], 1)]
    assert corr.max() < 0.9, corr
    assert np.all(rates[:, w.reach == 0] == 0)  # the ground stands


def test_a_compound_bends_each_component_about_its_placed_foot():
    """Each foot is moved by its component's placement; the reach holds the component's
    ball, and the ground (unbounded) stands."""
    grove = preset("grove-wind")
    balls = [(1.0, 2.0, 3.0, 0.5)] * 7 + [(0.0, 0.0, 0.0, -1.0)]
    feet = wind_feet(grove, balls)
    assert [f for f, _ in feet][:2] == [(0.0, 0.0, 0.0), (-4.2, 0.0, 3.0)]
    assert feet[0][1] == pytest.approx(np.sqrt(14) + 0.5)
    assert feet[1][1] == pytest.approx(np.sqrt(5.2**2 + 4 + 0) + 0.5)
    assert feet[7][1] == 0.0


def test_a_vertical_wind_is_a_one_line_error():
    text = "[tree]\nlevels = 3\n[effect_settings]\nwind_direction = [0.0, 1.0, 0.0]\n"
    with pytest.raises(SceneError, match=r"effect_settings\.wind_direction.*horizontal part"):
        scene_from_toml(text)
    scene_from_toml(text.replace("[0.0, 1.0, 0.0]", "[0.01, 1.0, 0.0]"))  # a tilt is enough
    with pytest.raises(SceneError, match="'twist' and 'wind' exclude each other"):
        scene_from_toml('effects = ["twist", "wind"]\n[tree]\nlevels = 3\n')


# --------------------------------------------------------------------------- GPU
def small_tree(levels: int = 12):
    s = preset("tree-wind")
    s = replace(s, tree=replace(s.tree, levels=levels))
    return per_pixel(replace(s, render=replace(s.render, lod=0.0)))


def still(scene):
    return replace(scene, effects=[e for e in scene.effects if e != "wind"])


@pytest.mark.parametrize("t", [0.0, 1.7, 6.3, 41.9])
def test_gpu_matches_the_reference_at_sampled_times(renderer, t):
    """The tree in a strong wind at four times (the wind changes ≥ 3 % of the pixels)."""
    s = small_tree()
    s = replace(s, effect_settings=replace(s.effect_settings, wind_strength=12.0)).at(t)
    gpu, ref = renderer.render(s, 48, 32), render_reference(s, 48, 32)
    assert_finite(gpu, s.render.max_iterations)
    plain = render_reference(still(s), 48, 32)
    assert (np.abs(ref.color - plain.color).max(-1) > 4 / 255).mean() > 0.03
    check_against_reference(f"wind-t{t}", gpu, ref)


@pytest.mark.parametrize("t", [0.4, 3.1])
def test_gpu_matches_the_reference_on_the_grove(renderer, t):
    s = per_pixel(preset("grove-wind")).at(t)
    s = replace(s, effect_settings=replace(s.effect_settings, wind_strength=10.0))
    gpu, ref = renderer.render(s, 48, 32), render_reference(s, 48, 32)
    assert_finite(gpu, s.render.max_iterations)
    check_against_reference(f"wind-grove-t{t}", gpu, ref)


@pytest.mark.parametrize(
    "name, knob, value",
    [
        ("tree-wind", "precision", "double"),
        ("tree-wind", "path", "compute"),
        ("tree-wind", "tracer", "binary"),  # its probes ask the wind's unbounding test
        ("grove-wind", "precision", "double"),
        ("grove-wind", "path", "compute"),
    ],
)
def test_every_path_follows_the_wind(renderer, name, knob, value):
    """Double precision, the compute path and the binary tracer's ball probes all step by
    the wind's bound: each matches the reference in a strong wind."""
    s = small_tree() if name == "tree-wind" else per_pixel(preset(name).edit("render.lod", 0.0))
    s = replace(s, effect_settings=replace(s.effect_settings, wind_strength=12.0))
    s = s.edit(("render", knob), value).at(2.2)
    check_against_reference(
        f"wind-{name}-{value}", renderer.render(s, 48, 32), render_reference(s, 48, 32)
    )


@pytest.mark.parametrize("name", ["tree-wind", "grove-wind"])
def test_the_prepass_follows_the_wind(renderer, name):
    """The pre-pass's cones ask the wind's bound (is_unbounding): with it, away from outlines
    every pixel has the same hit state as without it and a depth within about one ε
    (tests/test_prepass.py's check). Negative control: the still
    scene's image does not agree with the windy one."""
    s = replace(preset(name), render=replace(preset(name).render, prepass=0)).at(1.1)
    s = replace(s, effect_settings=replace(s.effect_settings, wind_strength=12.0))
    plain = renderer.render(s, 96, 54)
    img = renderer.render(replace(s, render=replace(s.render, prepass=4)), 96, 54)
    eps_per_t = view_of(s.camera, 96, 54).footprint * s.render.epsilon_scale
    a = agreement(img, plain, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert a.off_edge_hit == 0 and a.off_edge_depth <= 1.5 * eps_per_t, a
    control = agreement(renderer.render(still(s), 96, 54), plain, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    assert control.off_edge_hit > 0


def changed(a, b) -> float:
    """The fraction of pixels whose colour moved by more than 4/255."""
    return float((np.abs(a.color - b.color).max(-1) > 4 / 255).mean())


def test_time_is_continuous(renderer):
    """A 1 ms step changes almost nothing; a 1 s step (the negative control) changes much
    more. The image at t is the same whichever time was drawn before (u_time only)."""
    s = small_tree(14)
    t0 = 2.0
    at = {t: renderer.render(s.at(t), 96, 64) for t in (t0, t0 + 1e-3, t0 + 1.0)}
    small, large = changed(at[t0], at[t0 + 1e-3]), changed(at[t0], at[t0 + 1.0])
    assert small < 0.005 and large > 0.02 and large > 10 * max(small, 1e-3), (small, large)
    again = renderer.render(s.at(t0), 96, 64)
    assert np.array_equal(again.color, at[t0].color)


def test_idle_wind_draws_the_still_scene(renderer):
    """With no lean the bend, its step and ε's factor are exact identities, so the wind's
    variant traces the same rays as the scene without wind, bit for bit (the swept ball is then
    the rest ball); only the normal is normalised once more (a last bit).
    Negative control: half a degree of lean changes the image."""
    s = replace(preset("grove-wind"), render=replace(preset("grove-wind").render, lod=0.0))
    idle = replace(s, effect_settings=replace(s.effect_settings, wind_strength=0.0)).at(3.0)
    base, wind = renderer.render(still(idle), 64, 36), renderer.render(idle, 64, 36)
    for name in ("depth", "hit", "iterations"):
        assert np.array_equal(getattr(wind, name), getattr(base, name)), name
    assert np.abs(wind.normal - base.normal).max() < 1e-6
    assert np.abs(wind.color - base.color).max() < 1e-6
    slight = replace(idle, effect_settings=replace(idle.effect_settings, wind_strength=0.5))
    assert not np.array_equal(renderer.render(slight, 64, 36).depth, base.depth)


@pytest.mark.parametrize("name", ["tree-wind", "grove-wind"])
def test_the_all_effects_variant_switches_the_wind_by_its_bit(renderer, name):
    """The benchmark's variant with every effect compiled (twist and wind both in it, each
    switched by its bit of u_effects) draws the specialised image; with the wind's bit off it
    draws the still one (negative control: that differs). The shadow cone is off: a twist
    compiles none, and a ray that starts at its cone samples its soft shadow elsewhere."""
    s = per_pixel(preset(name)).edit(("render", "shadow_cone"), "off").at(0.7)
    moving, calm = (all_effects_image(renderer, scene) for scene in (s, still(s)))
    assert not np.array_equal(moving.hit, calm.hit)


def all_effects_image(renderer, scene, size=(64, 36)):
    """The specialised image of ``scene``, checked against the variant with every effect
    compiled (each switched by its bit of u_effects): the same hits, colours within 1/255."""
    with renderer.current():
        uber = read_buffers(
            renderer.draw(renderer.prepare(scene, *size, all_effects=True), *size), *size
        )
    special = renderer.render(scene, *size)
    assert (np.abs(uber.color - special.color).max(-1) <= 1 / 255).mean() > 0.999
    assert (uber.hit == special.hit).all()
    return special


@pytest.mark.parametrize("name", ["tree-wind", "grove-wind"])
def test_the_exits_in_the_wind_change_no_pixel(tmp_path, renderer, name):
    """The balls' exits take the swept ball in the wind (trace.glsl, bound_ahead): at sampled
    times the image is the same bit for bit as without exits, and the tree's misses end
    early. Negative control: a quarter of the swept ball's radius changes the image."""
    none = Renderer(
        shader_dir=shaders_without(tmp_path / "none", "    if (false && (!soft", "    if (false) {")
    )
    quarter = "ball = u_wind_ball[c] * vec4(1.0, 1.0, 1.0, 0.25);"
    small = Renderer(
        shader_dir=broken_shaders(
            tmp_path / "small", "trace.glsl", "ball = u_wind_ball[c];", quarter
        )
    )
    for t in (0.4, 2.9):
        s = preset(name).at(t)
        assert "KRS_BALL_EXIT" in variant_defines(s, compile_geometry(s.geometry(), ALBEDO))
        a, b = renderer.render(s, W, H), none.render(s, W, H)
        for field in ("color", "depth", "normal", "hit"):
            assert np.array_equal(getattr(a, field), getattr(b, field)), (t, field)
        assert (a.iterations <= b.iterations).all()
        assert (a.iterations < b.iterations).any() or name == "grove-wind"  # primary: a KRS
    assert not np.array_equal(small.render(s, W, H).color, a.color)
