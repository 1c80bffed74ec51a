"""The oracle in the wind (issue 29 §3): sin and cos over reliable numbers contain the true
values (arb at 200 bits), the enclosure of the world→rest map g contains g at sampled points
(g in arb, Rodrigues with its own cos), a MöKRS value goes through the same g, and GPU frames
of tree-wind and grove-wind certify with no hole and no false hit, while the same rays judged
against the still scene, or traced by a tracer that bends the wrong way, have errors."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

import krsview
from krsview.api import exact_settings
from krsview.compile.geometry import compile_geometry
from krsview.gpu.renderer import Renderer
from krsview.oracle.certify import UNCOVERED, count_errors
from krsview.oracle.distance import Bounds, Moved, bounds, in_box, on_segments, value
from krsview.oracle.numbers import Affine, Interval
from krsview.oracle.wind import hit_stretch, unwind, wind_moved
from krsview.reference.wind import Wind
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders
from .test_oracle import arb_distance, arb_mokrs

ctx.prec = 200
W, H = 32, 18


# ----------------------------------------------------------------------- sin and cos
def outside(v, lo, hi) -> bool:
    """Whether the arb ball v lies certainly outside [lo, hi] (arb's own radius, ~2⁻²⁰⁰,
    cannot tell 1 − 10⁻²⁰⁰ from 1)."""
    return bool(v < lo or v > hi)


def trig_outside(lo, hi, name: str, shrink: float = 0.0) -> int:
    """How many true values f(x), x sampled in [lo, hi] (its ends, 7 points between, and
    every peak and trough inside, ±1 exactly), lie outside the Interval's f (narrowed by
    ``shrink`` of its width at each side for the negative control)."""
    out = getattr(Interval(np.array([lo]), np.array([hi])), name)()
    width = out.hi[0] - out.lo[0]
    flo, fhi = arb(float(out.lo[0] + shrink * width)), arb(float(out.hi[0] - shrink * width))
    values = [getattr(arb(float(x)), name)() for x in np.linspace(lo, hi, 9)]
    k = int(np.floor(lo / (np.pi / 2))) - 1
    while float(k * np.pi / 2) <= hi + 1.0:  # sin and cos are ±1 at odd or even k·π/2
        if arb(float(lo)) < arb.pi() * k / 2 < arb(float(hi)) and (k % 2 == 1) == (name == "sin"):
            values.append(arb(1 if (k // 2) % 2 == 0 else -1))
        k += 1
    return sum(outside(v, flo, fhi) for v in values)


intervals = st.tuples(
    st.floats(-50.0, 50.0), st.one_of(st.floats(0.0, 1e-6), st.floats(0.0, 1.0), st.floats(0, 9))
)


@settings(max_examples=150, deadline=None)
@given(intervals, st.sampled_from(["sin", "cos"]))
def test_interval_sin_and_cos_contain_the_true_values(lo_width, name):
    """Narrow, wide (past 2π) and extremum-crossing intervals: arb's f at the samples lies
    inside the enclosure."""
    lo, width = lo_width
    assert trig_outside(lo, lo + width, name) == 0


@settings(max_examples=100, deadline=None)
@given(
    st.floats(-20.0, 20.0),
    st.one_of(st.floats(0.0, 1e-5), st.floats(0.0, 0.5), st.floats(0.0, 4.0)),
    st.floats(0.0, 0.1),
    st.sampled_from(["sin", "cos"]),
)
def test_affine_sin_and_cos_hold_f_at_each_point_of_the_form(x0, x1, e, name):
    """An affine form x0 + x1·ε ± e: for ε and the error η sampled in [−1, 1] and [−e, e],
    arb's f(x0 + x1ε + η) lies within the result's y0 + y1ε ± e_y (pointwise, as the walk
    uses it)."""
    assert affine_outside(x0, x1, e, name) == 0


def affine_outside(x0, x1, e, name: str, narrow: bool = False) -> int:
    """Samples of f over the affine form outside its f (``narrow``: without its error term)."""
    y = getattr(Affine(np.array([x0]), x1, e), name)()
    ey = 0.0 if narrow else float(y.e[0])
    bad = 0
    for eps in np.linspace(-1.0, 1.0, 7):
        for eta in (-e, 0.0, e):
            v = getattr(arb(x0) + arb(x1) * arb(float(eps)) + arb(eta), name)()
            mid = arb(float(y.x0[0])) + arb(float(y.x1[0])) * arb(float(eps))
            bad += outside(v, mid - arb(ey), mid + arb(ey))
    return bad


def test_shrunk_sin_and_cos_enclosures_fail():
    """Negative control: each enclosure narrowed by a hundredth of its width at each side, or
    an affine result without its error term, misses true values."""
    rng = np.random.default_rng(3)
    lows, widths = rng.uniform(-20, 20, 60), rng.uniform(0.0, 3.0, 60)
    for name in ("sin", "cos"):
        assert sum(trig_outside(lo, lo + w, name, 0.01) > 0 for lo, w in zip(lows, widths)) > 30
        assert sum(affine_outside(x, 0.3, 0.0, name, narrow=True) > 0 for x in lows) > 30


# ----------------------------------------------------------------------- the map g
def arb_unwind(wind: Wind, c: int, p) -> list:
    """g_c(p) in arb: p + (A × r) sin θ + (A(A·r) − r)(1 − cos θ), θ = −a·max(r_y, 0)."""
    A = [arb(float(v)) for v in wind.axis]
    x = [arb(float(v)) for v in p]
    r = [x[k] - arb(float(wind.bases[c][k])) for k in range(3)]
    theta = -arb(float(wind.rates[c])) * ((r[1] + abs(r[1])) / 2)
    cross = [A[1] * r[2] - A[2] * r[1], A[2] * r[0] - A[0] * r[2], A[0] * r[1] - A[1] * r[0]]
    along = sum((A[k] * r[k] for k in range(3)), arb(0))
    s, one_cos = theta.sin(), 1 - theta.cos()
    return [x[k] + cross[k] * s + (A[k] * along - r[k]) * one_cos for k in range(3)]


def strong_wind(name: str, strength: float, t: float) -> Wind:
    s = load_scene(resolve(name)).edit("effect_settings.wind_strength", strength).at(t)
    return Wind.of(s)


def map_outside(wind: Wind, c: int, boxes: int, seed: int, rate_scale: float = 1.0) -> int:
    """Samples p of random boxes (interval) and segments (affine) in component c's crown
    whose arb g_c(p) lies outside the enclosure of g_c over their box or segment (the
    enclosure made with the rate × ``rate_scale``, for the negative control)."""
    rng = np.random.default_rng(seed)
    wrong = replace(wind, rates=wind.rates * rate_scale)
    centres = wind.bases[c] + rng.normal(size=(boxes, 3)) * 3.0 + np.array([0.0, 4.0, 0.0])
    half = 10.0 ** rng.uniform(-4, 0, boxes)
    dirs = rng.normal(size=(boxes, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    bad = 0
    for shape in ("box", "segment"):
        if shape == "box":
            g = unwind(wrong, c)(in_box(centres, half))
            pts = centres[:, None] + rng.uniform(-1, 1, (boxes, 6, 3)) * half[:, None, None]
            pts[:, 0] = centres + half[:, None]  # a corner
        else:
            g = unwind(wrong, c)(on_segments(centres, dirs, -half, half, "affine"))
            g = tuple(v.interval() for v in g)
            ts = np.linspace(-1, 1, 6)
            pts = centres[:, None] + (ts[None, :, None] * half[:, None, None]) * dirs[:, None]
        for i in range(boxes):
            for p in pts[i]:
                q = arb_unwind(wind, c, p)
                bad += any(
                    outside(q[k], arb(float(g[k].lo[i])), arb(float(g[k].hi[i]))) for k in range(3)
                )
    return bad


@pytest.mark.parametrize(
    "name, c, strength, t",
    [("tree-wind", 0, 4.0, 1.3), ("tree-wind", 0, 20.0, 7.9), ("grove-wind", 3, 10.0, 0.4)],
)
def test_the_map_encloses_g_at_sampled_points(name, c, strength, t):
    """Boxes and segments from 10⁻⁴ to 1 in size around a crown (a grove's fourth tree: its
    own foot and phase): g at sampled points (a corner of each box among them), in arb, lies
    in the enclosure of g over the box or segment."""
    assert map_outside(strong_wind(name, strength, t), c, 40, seed=int(strength)) == 0


def test_the_map_at_a_wrong_rate_misses_g():
    """Negative control: the enclosure made with the rate 5 % off misses g's true values."""
    assert map_outside(strong_wind("tree-wind", 4.0, 1.3), 0, 40, seed=4, rate_scale=1.05) > 20


def balls_broken(geometry, wind: Wind, seed: int) -> tuple[int, Bounds]:
    """Samples along random segments through the bent tree whose arb value at arb g(p)
    breaks what the walk with balls certifies over the segment: v ≥ lower, v ≤ hi."""
    c = geometry.geometry if isinstance(geometry, Moved) else geometry
    rng = np.random.default_rng(seed)
    starts = wind.bases[0] + np.array([0.0, 5.0, 0.0]) + rng.normal(size=(16, 3)) * 2.0
    dirs = rng.normal(size=(16, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    a, b = np.zeros(16), np.full(16, 0.4)
    e = bounds(geometry, on_segments(starts, dirs, a, b, "affine"), b - a)
    broken = 0
    for i in range(16):
        for t in np.linspace(0.0, 0.4, 3):
            q = arb_unwind(wind, 0, starts[i] + t * dirs[i])
            v = arb_distance(c, [float(x) for x in q])
            broken += bool(np.isfinite(e.lower[i]) and v < arb(float(e.lower[i])))
            broken += bool(np.isfinite(e.hi[i]) and v > arb(float(e.hi[i])))
    return broken, e


def test_balls_tested_on_the_maps_enclosure_bound_the_bent_tree():
    """The culling and level-of-detail balls live in rest space and are tested on the
    enclosure of g(X): over segments through and around tree-wind's bent crown (20°), the
    value at g(p) in arb keeps every bound the walk certifies, and both kinds of ball
    ended walks. Negative control: the walk on X itself (the still tree, no map) breaks
    bounds of the bent one."""
    wind = strong_wind("tree-wind", 20.0, 7.9)
    s = load_scene(resolve("tree-wind"))
    c = compile_geometry(s.geometry(), s.material.albedo)
    broken, e = balls_broken(wind_moved(wind, c), wind, seed=5)
    assert broken == 0
    assert np.isfinite(e.cut).any() and (e.lower > 0).any()
    assert balls_broken(c, wind, seed=5)[0] > 0


def test_a_mokrs_value_goes_through_the_same_map():
    """The map is generic over the compiled kind: the palm (a MöKRS) looked up through g
    (a wind set by hand, the scene cannot list one yet) has enclosures over segments holding
    arb's min_i k_i(x_i) at arb's g(p). Negative control: the palm without g misses it."""
    s = load_scene(resolve("palm"))
    c = compile_geometry(s.geometry(), s.material.albedo)
    wind = Wind(
        axis=np.array([0.0, 0.0, -1.0]),
        rates=np.array([0.15]),
        bases=np.array([[0.0, -1.0, 0.0]]),
        reach=np.array([4.0]),
        most=0.2,
        balls=np.array([[0.0, -1.0, 0.0, 4.0]]),
    )
    rng = np.random.default_rng(8)
    starts = np.array(s.camera.target) + rng.normal(size=(8, 3)) * 0.7
    dirs = rng.normal(size=(8, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    a, b = np.zeros(8), np.full(8, 0.05)
    missed = {}
    for moved in (True, False):
        geometry = Moved(c, (unwind(wind, 0),)) if moved else c
        for arithmetic in ("interval", "affine"):
            with np.errstate(all="ignore"):
                lo, hi = value(geometry, on_segments(starts, dirs, a, b, arithmetic)).range()
            assert np.isfinite(lo).all() and np.isfinite(hi).all()  # not vacuously wide
            missed[moved, arithmetic] = sum(
                outside(v, arb(float(lo[i])), arb(float(hi[i])))
                for i in range(8)
                for t in np.linspace(0.0, 0.05, 3)
                for v in [
                    arb_mokrs(c, [float(q) for q in arb_unwind(wind, 0, starts[i] + t * dirs[i])])
                ]
            )
    assert missed[True, "interval"] == missed[True, "affine"] == 0, missed
    assert missed[False, "affine"] > 0, missed


# ----------------------------------------------------------------------- GPU frames
def frame(renderer, name: str, strength: float, t: float):
    """A windy preset at ``strength`` degrees and time t, every level drawn, and its GPU
    image."""
    s = exact_settings(load_scene(resolve(name))).edit("effect_settings.wind_strength", strength)
    s = s.at(t)
    return s, renderer.render(s, W, H)


def still(scene):
    return replace(scene, effects=[e for e in scene.effects if e != "wind"])


def judged(scene, image):
    return count_errors(scene, image, arithmetics=("affine",))


@pytest.mark.parametrize("t", [1.3, 7.9])
def test_the_oracle_certifies_a_tree_wind_frame(renderer, t):
    """tree-wind in a strong wind (12°, every level drawn) at two times: no hole, no false
    hit beyond the reach, few undecided rays. Negative control: the same rays judged against
    the still tree have errors where the wind moved it."""
    s, img = frame(renderer, "tree-wind", 12.0, t)
    counts = judged(s, img)
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    assert counts.undecided <= 0.02 * counts.rays and counts.hits > 100, counts
    wrong = judged(still(s), img)
    assert wrong.holes + wrong.false_hits > 0, wrong


def test_a_tracer_bending_the_wrong_way_is_caught(tmp_path, renderer):
    """Negative control: a GPU tracer whose wind turns the other way (rate −a) leaves holes
    the oracle certifies."""
    s, _ = frame(renderer, "tree-wind", 12.0, 1.3)
    old = "float a = wind_rate(c);\n        real D"
    wrong = Renderer(
        shader_dir=broken_shaders(tmp_path, "distance.glsl", old, old.replace("= w", "= -w"))
    )
    counts = judged(s, wrong.render(s, W, H))
    assert counts.holes > 0, counts


def test_the_oracle_certifies_a_grove_wind_frame(renderer):
    """grove-wind (seven trees, each its own foot and phase, and a ground that stands) at
    10°: no hole, no false hit. Negative control: judged with every rate turned round (the
    wind reversed), the same rays have holes."""
    s, img = frame(renderer, "grove-wind", 10.0, 1.3)
    counts = judged(s, img)
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    assert counts.undecided <= 0.02 * counts.rays and counts.hits > 200, counts
    fx = s.effect_settings
    back = replace(fx, wind_direction=tuple(-v for v in fx.wind_direction))
    wrong = judged(replace(s, effect_settings=back), img)
    assert wrong.holes + wrong.false_hits > 0, wrong


def test_the_api_certifies_the_wind_and_still_refuses_the_twist():
    """krsview.certify takes a windy preset (its fast settings: the pre-pass and the level of
    detail) and certifies it; the twist stays out of the oracle (negative control)."""
    counts = krsview.certify("tree-wind", (W, H))
    assert (counts.holes, counts.false_hits) == (0, 0) and counts.hits > 100, counts
    assert "wind" not in UNCOVERED and "twist" in UNCOVERED
    with pytest.raises(krsview.SceneError, match="twist"):
        krsview.certify("hard:twist-ground", (8, 4))


def test_a_wind_the_oracle_cannot_judge_is_a_one_line_error():
    """A shear past 0.5 at a hit (the strongest wind the schema allows, at the crown): the
    error names the scene, the field and its value."""
    s = load_scene(resolve("tree-wind")).edit("effect_settings.wind_strength", 30.0).at(1.0)
    wind = Wind.of(s)
    crown = wind.bases[0] + np.array([[0.0, 8.0, 0.0]])
    with pytest.raises(ValueError, match=r"tree-wind: effect_settings.wind_strength = 30.0"):
        hit_stretch(s, wind, crown, np.array([0.1]))
    assert hit_stretch(s, replace(wind, rates=wind.rates / 40), crown, np.array([0.1]))[0] > 1.0
