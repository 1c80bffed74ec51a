"""The reliable oracle [RAA09]: its enclosures contain the true distance, cross-checked with
python-flint's arb balls (an independent arbitrary-precision evaluation of Alg. 1), and it
certifies the holes and false hits it is built to find."""

from __future__ import annotations

import functools

import numpy as np
import pytest
from flint import arb, ctx

from krsview.algebra.quaternion import mul
from krsview.compile.geometry import compile_geometry
from krsview.oracle.certify import count_errors, free_boxes, surfaces_before
from krsview.oracle.distance import on_segments, value
from krsview.scene import load_scene
from krsview.scene.presets import resolve

ctx.prec = 200


# ------------------------------------------------------------- Alg. 1 in arb, independently
def relu(e):
    return (e + abs(e)) / 2


def adot(u, x):
    return sum((arb(float(u[k])) * x[k] for k in range(3)), arb(0))


def anorm(x):
    return sum((v * v for v in x), arb(0)).sqrt()


def akernel(kind, rec, p):
    if kind == "empty":
        return None
    if kind == "plane":
        return adot(rec[1, :3], p) - arb(float(rec[1, 3]))
    r = arb(float(rec[1, 3]))
    if kind == "sphere":
        return anorm([p[k] - arb(float(rec[1, k])) for k in range(3)]) - r
    if kind == "capsule":
        A, B = rec[1, :3], rec[2, :3]
        ab = [arb(float(B[k])) - arb(float(A[k])) for k in range(3)]
        pa = [p[k] - arb(float(A[k])) for k in range(3)]
        h = sum((pa[k] * ab[k] for k in range(3)), arb(0)) / sum((v * v for v in ab), arb(0))
        h = relu(h) - relu(h - 1)
        return anorm([pa[k] - h * ab[k] for k in range(3)]) - r
    # toroidal capsule (compile/krs.py): centre O, the frame's quaternion P with |P|² = 1/R
    # (P̄ q P by Hamilton products), t = tan(phi/4); the ends at angles ±phi/2 from e1
    P = [arb(float(v)) for v in rec[2]]
    q = (arb(0), *(p[k] - arb(float(rec[1, k])) for k in range(3)))
    x, y, z = aqmul(aqmul((P[0], -P[1], -P[2], -P[3]), q), P)[1:]
    t = arb(float(rec[3, 0]))
    c, s = (1 - t * t) / (1 + t * t), 2 * t / (1 + t * t)
    rho = (x * x + y * y).sqrt()
    if float((x - rho * c).mid()) >= 0:
        w = (rho - 1) ** 2
    else:
        wa, wb = (x - c) ** 2 + (y - s) ** 2, (x - c) ** 2 + (y + s) ** 2
        w = (wa + wb - abs(wa - wb)) / 2
    return (w + z * z).sqrt() / sum((v * v for v in P), arb(0)) - r


def arb_distance(c, point):
    if hasattr(c, "parts"):  # a compound: the least over its components
        ds = [arb_distance(part, point) for part in c.parts]
        return functools.reduce(lambda d, k: (d + k - abs(d - k)) / 2, ds)
    x = [arb(float(v)) for v in point]
    d = akernel(c.types[c.n], c.records[c.n], x)
    for i in range(c.n - 1, -1, -1):
        m = c.mirrors[i]
        e = relu(adot(m[:3], x) - arb(float(m[3])))
        x = [x[k] - 2 * e * arb(float(m[k])) for k in range(3)]
        k = akernel(c.types[i], c.records[i], x)
        if k is not None:
            d = k if d is None else (d + k - abs(d - k)) / 2
    return d


def aqmul(p, q):
    """The reference's Hamilton product (algebra/quaternion.py, not the oracle's) on arb balls."""
    return tuple(mul(np.array(p, dtype=object), np.array(q, dtype=object)))


def arb_mokrs(c, point):
    """min_i k_i(x_i) of a MöKRS in arb: x followed inwards through (a q + b)(c q + d)⁻¹."""
    x = [arb(float(v)) for v in point]
    d = None
    for i in range(c.n - 1, -1, -1):
        H = [[[arb(float(v)) for v in c.inverse[i, r, k]] for k in range(2)] for r in range(2)]
        q = (arb(0), *x)
        num = tuple(u + v for u, v in zip(aqmul(H[0][0], q), H[0][1]))
        den = tuple(u + v for u, v in zip(aqmul(H[1][0], q), H[1][1]))
        n2 = sum((v * v for v in den), arb(0))
        x = list(aqmul(num, (den[0] / n2, -den[1] / n2, -den[2] / n2, -den[3] / n2))[1:])
        if c.reflect[i]:
            x[0] = -abs(x[0])
        k = akernel(c.types[i], c.records[i], x)
        if k is not None:
            d = k if d is None else (d + k - abs(d - k)) / 2
    return d


def segments(scene_name, n, length, seed):
    s = load_scene(resolve(scene_name))
    c = compile_geometry(s.geometry(), s.material.albedo)
    rng = np.random.default_rng(seed)
    origin = np.array(s.camera.target, dtype=np.float64)
    starts = rng.normal(size=(n, 3)) * 0.7
    dirs = rng.normal(size=(n, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    a = np.zeros(n)
    b = np.full(n, length)
    return c, origin, starts, dirs, a, b


def enclosures_contain_arb(c, origin, starts, dirs, a, b, arithmetic, samples=4, narrow=False):
    """Count samples t in [a, b] whose arb value is not inside the segment's enclosure."""
    pts = origin + starts
    d = value(c, on_segments(pts, dirs, a, b, arithmetic))
    lo, hi = d.range()
    if narrow:  # negative control: the affine form without its error term
        lo, hi = d.x0 - np.abs(d.x1), d.x0 + np.abs(d.x1)
    from krsview.compile.mokrs import CompiledMoKRS

    exact = arb_mokrs if isinstance(c, CompiledMoKRS) else arb_distance
    outside = 0
    for i in range(len(dirs)):
        for t in np.linspace(a[i], b[i], samples):
            v = exact(c, pts[i] + t * dirs[i])
            if not (arb(float(lo[i])) <= v and v <= arb(float(hi[i]))):
                outside += 1
    return outside


@pytest.mark.parametrize("scene_name", ["sierpinski", "rock", "grass", "tree"])
@pytest.mark.parametrize("arithmetic", ["interval", "affine"])
def test_enclosures_contain_the_arb_value(scene_name, arithmetic):
    """Containment: at points along random segments, Alg. 1 evaluated with arb balls at 200
    bits lies inside the oracle's enclosure of the whole segment."""
    c, *rest = segments(scene_name, 12, 0.05, seed=1)
    assert enclosures_contain_arb(c, *rest, arithmetic) == 0


@pytest.mark.parametrize("scene_name", ["shell", "inversion", "palm"])
@pytest.mark.parametrize("arithmetic", ["interval", "affine"])
def test_mokrs_enclosures_contain_the_arb_value(scene_name, arithmetic):
    """The same for a MöKRS: quaternion Möbius maps (with an inversion in `inversion`) over
    intervals and affine forms contain the arb value of min_i k_i(x_i)."""
    c, origin, starts, dirs, a, b = segments(scene_name, 6, 0.05, seed=4)
    with np.errstate(all="ignore"):
        lo, hi = value(c, on_segments(origin + starts, dirs, a, b, arithmetic)).range()
        assert np.isfinite(lo).all() and np.isfinite(hi).all()  # not vacuously wide
        assert enclosures_contain_arb(c, origin, starts, dirs, a, b, arithmetic, samples=3) == 0


def test_an_enclosure_without_its_error_term_fails_containment():
    """Negative control: the affine forms' centre and slope alone miss the true values."""
    c, *rest = segments("grass", 24, 0.3, seed=2)
    assert enclosures_contain_arb(c, *rest, "affine", narrow=True) > 0


def float_order(x: np.ndarray) -> np.ndarray:
    """Each float's place in the order of all floats (as integers: neighbours differ by 1)."""
    bits = x.view(np.int64)
    return np.where(bits < 0, -(bits & 0x7FFFFFFFFFFFFFFF), bits)


def test_outward_rounding_steps_past_every_float_and_no_further_than_three():
    """Every operation's bounds step outwards by numbers._up and _down: for floats of every
    binade, ±0, the subnormals and the largest, each lands 1 to 3 floats beyond x (counted by
    the floats' bit order, independently of the formula); infinities stay. Negative control:
    without its least-subnormal term the step leaves 0 and the subnormals where they are."""
    from krsview.oracle import numbers

    rng = np.random.default_rng(5)
    powers = 2.0 ** np.arange(-1074, 1024, dtype=np.float64)
    x = np.concatenate(
        [
            rng.standard_normal(20000) * 10.0 ** rng.integers(-322, 306, 20000),
            powers,
            -powers,
            np.nextafter(powers, 0.0),
            [0.0, -0.0, np.finfo(np.float64).max, -np.finfo(np.float64).max],
        ]
    )
    with np.errstate(over="ignore"):
        up, down = numbers._up(x), numbers._down(x)
    big = np.abs(x) == np.finfo(np.float64).max  # the step past them is ±∞
    n_up, n_down = float_order(up) - float_order(x), float_order(x) - float_order(down)
    assert ((n_up >= 1) & (n_up <= 3))[np.abs(x) < np.finfo(np.float64).max].all()
    assert ((n_down >= 1) & (n_down <= 3))[~big].all()
    assert np.isinf(up[x == np.finfo(np.float64).max]).all()
    inf = np.array([np.inf, -np.inf])
    assert np.array_equal(numbers._up(inf), inf) and np.array_equal(numbers._down(inf), inf)
    tiny = np.abs(x) < 2.0**-1022  # 0 and the subnormals
    without = x[tiny] + np.abs(x[tiny]) * numbers._ULP
    assert (without == x[tiny]).any()


def test_affine_forms_avoid_the_wrapping_that_widens_intervals():
    """Through 22 folds, interval boxes widen at every non-axis mirror (the wrapping effect);
    affine forms keep the correlation: on short segments of the tree their enclosures are
    hundreds of times narrower [RAA09 §5]."""
    c, origin, starts, dirs, a, b = segments("tree", 100, 1e-3, seed=3)
    widths = {}
    for arithmetic in ("interval", "affine"):
        lo, hi = value(c, on_segments(origin + starts, dirs, a, b, arithmetic)).range()
        widths[arithmetic] = np.median((hi - lo) / b)
    assert widths["affine"] < 2.0 < 100.0 < widths["interval"]


def test_a_certified_surface_and_certified_empty_space():
    """A ray straight through a sphere of the sierpinski is certified to meet a surface
    before it; one aimed past everything is certified empty; both arithmetics agree."""
    s = load_scene(resolve("sierpinski"))
    c = compile_geometry(s.geometry(), s.material.albedo)
    center = c.records[0, 1, :3]
    eye = center + np.array([0.0, 0.0, -5.0])
    dirs = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
    for arithmetic in ("interval", "affine"):
        cert = surfaces_before(
            c, eye, dirs, np.array([10.0, 10.0]), 4e-4, arithmetic, max_segments=4000
        )
        assert list(cert.surface) == [1, 0], arithmetic


def test_false_hits_are_found_where_a_tracer_stops_in_empty_space():
    s = load_scene(resolve("sierpinski"))
    c = compile_geometry(s.geometry(), s.material.albedo)
    center, r = c.records[0, 1, :3], c.records[0, 1, 3]
    on_surface = center + np.array([r, 0.0, 0.0])
    far = center + np.array([0.0, 0.0, -50.0])
    free = free_boxes(c, np.array([on_surface, far]), np.array([1e-3, 1e-3]))
    assert list(free) == [False, True]


def test_counts_on_a_traced_image(renderer):
    """Sphere and binary tracing of the sierpinski: no hole, no false hit beyond ε, nothing
    undecided at 24×14. Negative control: an image with its hit mask inverted has both."""
    from dataclasses import replace

    from krsview.frame import Frame

    s = load_scene(resolve("sierpinski"))
    for tracer in ("sphere", "binary"):
        t = replace(s, render=replace(s.render, tracer=tracer))
        img = renderer.render(t, 24, 14)
        counts = count_errors(t, img)
        assert (counts.holes, counts.false_hits, counts.undecided) == (0, 0, 0), counts
        assert counts.hits > 20
    img = renderer.render(s, 24, 14)
    fake_t = np.where(img.hit, 0.0, 60.0)
    broken = Frame(img.color, fake_t, img.normal, img.iterations, ~img.hit)
    counts = count_errors(s, broken)
    assert counts.holes > 0 and counts.false_hits > 0


# --------------------------------------------------- the levels' balls and the level of detail
def signs_hold(c, origin, starts, dirs, a, b, arithmetic, lod, samples=3, numeric=True):
    """Count samples whose arb value breaks what the walk with balls certifies: v ≥ lower
    (only its sign for a MöKRS, whose balls live in scaled frames) and v ≤ hi."""
    from krsview.compile.mokrs import CompiledMoKRS
    from krsview.oracle.distance import bounds

    pts = origin + starts
    with np.errstate(all="ignore"):
        e = bounds(c, on_segments(pts, dirs, a, b, arithmetic), lod)
    exact = arb_mokrs if isinstance(c, CompiledMoKRS) else arb_distance
    broken = 0
    for i in range(len(dirs)):
        for t in np.linspace(a[i], b[i], samples):
            v = exact(c, pts[i] + t * dirs[i])
            low = arb(float(e.lower[i])) if numeric else (arb(0) if e.lower[i] > 0 else None)
            if (low is not None and np.isfinite(e.lower[i]) and not low <= v) or (
                np.isfinite(e.hi[i]) and not v <= arb(float(e.hi[i]))
            ):
                broken += 1
    return broken, e


@pytest.mark.parametrize("scene_name", ["tree", "grove", "grass"])
def test_balls_bound_what_the_levels_below_them_hold(scene_name):
    """The walk with balls: v ≥ min(kernels walked, clear balls, balls cut at the level of
    detail) and v ≤ the kernels walked (a subset of the scene), at arb values along segments
    long enough that many walks end at a ball."""
    c, origin, starts, dirs, a, b = segments(scene_name, 16, 0.4, seed=5)
    starts *= 2.0  # reach out of the crown too
    broken, e = signs_hold(c, origin, starts, dirs, a, b, "affine", lod=b - a)
    assert broken == 0
    assert np.isfinite(e.cut).any() and (e.lower > 0).any()  # both kinds of ball were used


@pytest.mark.parametrize("scene_name, reach", [("palm", 4), ("inversion", 60), ("tree-mokrs", 4)])
def test_mokrs_balls_keep_the_sign(scene_name, reach):
    """A MöKRS's level bounds, mapped out past each level's pole: where the walk certifies
    a sign, the arb value has it."""
    c, origin, starts, dirs, a, b = segments(scene_name, 10, 0.3, seed=6)
    starts *= reach  # out of the geometry too
    broken, e = signs_hold(c, origin, starts, dirs, a, b, "interval", lod=b - a, numeric=False)
    assert broken == 0 and (e.lower > 0).any()


def test_a_ball_too_small_breaks_the_bound():
    """Negative control: the tree's culling balls at half their radius claim clear space
    (or a bound) where the levels below them reach lower."""
    from dataclasses import replace

    c, origin, starts, dirs, a, b = segments("tree", 16, 0.4, seed=5)
    starts *= 2.0
    shrunk = c.bounds.copy()
    shrunk[:, 3] = np.where(shrunk[:, 3] >= 0, shrunk[:, 3] / 2, shrunk[:, 3])
    broken, _ = signs_hold(
        replace(c, bounds=shrunk), origin, starts, dirs, a, b, "affine", lod=b - a
    )
    assert broken > 0


def test_the_level_of_detail_decides_a_full_depth_tree(renderer):
    """At full depth (22 levels, twigs a thousandth of a pixel) the exact walk leaves every
    ray undecided; leaving out detail below a quarter pixel decides them, with no hole and
    no false hit beyond ε. Negative control: the image with its hit mask inverted has both."""
    from krsview.frame import Frame

    s = load_scene(resolve("tree"))
    img = renderer.render(s, 16, 9)
    counts = count_errors(s, img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    assert counts.undecided <= 0.02 * counts.rays and counts.hits > 20, counts
    broken = Frame(img.color, np.where(img.hit, 0.0, 60.0), img.normal, img.iterations, ~img.hit)
    counts = count_errors(s, broken, arithmetics=("affine",))
    assert counts.holes > 0 and counts.false_hits > 0, counts


def test_a_ray_through_a_pole_is_decided():
    """In `inversion` a ray through the pole of its outer level: the enclosure of H(x) is
    unbounded there, but the level's bound mapped out by H⁻¹ lies clear of the pole, so the
    ray is certified (before: undecided, NaN)."""
    from krsview.bench.hard_cases import CASES
    from krsview.compile.camera import primary_rays, view_of

    s = CASES["mobius-pole-in-view"].build()
    c = compile_geometry(s.geometry(), s.material.albedo)
    view = view_of(s.camera, 9, 9)
    dirs = primary_rays(view)[40:41]  # the centre ray, at the pole
    for arithmetic in ("interval", "affine"):
        cert = surfaces_before(
            c, view.origin, dirs, np.array([s.render.max_distance]), view.footprint, arithmetic
        )
        assert list(cert.surface) == [0], arithmetic


def test_the_oracle_certifies_a_swaying_frame_and_finds_the_rest_pose_wrong(renderer):
    """Issue 29: a frame of tree-sway at t = 0.9 s (the coarsest mirrors turned) has no
    certified hole or false hit; the rest pose's image judged as that moment's has both."""
    from krsview.api import exact_settings

    s = exact_settings(load_scene(resolve("tree-sway"))).at(0.9)
    img = renderer.render(s, 32, 18)  # as the wind's frames (tests/test_oracle_wind.py)
    counts = count_errors(s, img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    assert counts.hits > 20
    rest = renderer.render(s.at(0.0), 32, 18)  # the negative control: another moment
    wrong = count_errors(s, rest, arithmetics=("affine",))
    assert wrong.holes + wrong.false_hits > 0, wrong
