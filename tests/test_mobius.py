"""The quaternion Möbius algebra [KRS17 §6.2–6.3, App. A–C] against direct evaluation.

Random transformations are products of Table 1's constructors. Tolerances are relative to the
size of the numbers involved and say why; "near-singular" inputs put points close to a pole,
where L_H grows like 1/distance and rounding grows with it.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from krsview.algebra import mobius as M
from krsview.algebra import quaternion as Q

seeds = st.integers(0, 2**32 - 1)
RTOL = 1e-9  # float64 through ~5 constructors and an inverse: far below 1e-9 unless near a pole


def unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def random_transform(rng: np.random.Generator, steps: int = 4) -> np.ndarray:
    """A product of random translations, rotations, dilations, reflections and inversions."""
    makers = [
        lambda: M.translation(rng.normal(size=3)),
        lambda: M.rotation(unit(rng), rng.uniform(-np.pi, np.pi)),
        lambda: M.dilation(np.exp(rng.uniform(-1.0, 1.0))),
        lambda: M.reflection(),
        lambda: M.compose(
            M.translation(rng.normal(size=3)), M.inversion(), M.translation(rng.normal(size=3))
        ),
    ]
    return M.compose(M.identity(), *[makers[rng.integers(len(makers))]() for _ in range(steps)])


def far_from_pole(H, x, margin):
    p = M.pole(M.tidy(H))
    return np.ones(len(x), bool) if p is None else np.linalg.norm(x - p, axis=1) > margin


def test_constructors_act_as_table_1():
    x = np.array([[0.3, -1.2, 2.0]])
    r = Q.from_axis_angle([0, 0, 1], np.pi / 2)
    cases = {
        "identity": (M.identity(), x),
        "dilation": (M.dilation(2.5), 2.5 * x),
        "translation": (M.translation([1, 2, 3]), x + [1, 2, 3]),
        "rotation": (M.matrix(r, M.ZERO, M.ZERO, r), [[1.2, 0.3, 2.0]]),
        "reflection": (M.reflection(), [[-0.3, -1.2, 2.0]]),
        "inversion": (M.inversion(), -x / (x @ x.T)),
    }
    for name, (H, want) in cases.items():
        np.testing.assert_allclose(M.apply(H, x), want, atol=1e-14, err_msg=name)


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_composition_is_sequential_application(seed):
    rng = np.random.default_rng(seed)
    G, H = random_transform(rng), random_transform(rng)
    x = rng.normal(size=(50, 3)) * 2
    y = M.apply(H, x)
    ok = far_from_pole(H, x, 1e-3) & far_from_pole(G, y, 1e-3)
    direct, composed = M.apply(G, y)[ok], M.apply(M.compose(G, H), x)[ok]
    scale = 1.0 + np.abs(direct).max(axis=1, keepdims=True)
    assert (np.abs(direct - composed) <= RTOL * 1e3 * scale).all()  # ≤ 1e3: 1/margin growth


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_inverse_undoes(seed):
    rng = np.random.default_rng(seed)
    H = random_transform(rng)
    x = rng.normal(size=(50, 3))
    y = M.apply(H, x)
    ok = far_from_pole(H, x, 1e-3) & (np.linalg.norm(y, axis=1) < 1e6)
    back = M.apply(M.inverse(H), y)[ok]
    assert np.allclose(back, x[ok], rtol=0, atol=1e-6)  # y up to 1e3·|x|: 1e-16 × 1e3 × cond


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_app_a_preimage_maps_onto_the_sphere(seed):
    """Points on the App. A preimage land on the original sphere under L_H, and the inside
    stays inside (α' > 0 exactly when the pole is outside the image ball)."""
    rng = np.random.default_rng(seed)
    H = random_transform(rng)
    c, r = rng.normal(size=(20, 3)) * 2, rng.uniform(0.05, 1.5, 20)
    a2, b2, g2 = M.transform_sphere(H, *M.sphere_coeffs(c, r))
    Hinv = M.tidy(M.inverse(H))
    _, _, ok = M.map_ball(Hinv, c, r)
    assert ((a2 > 0) == ok)[np.abs(a2) > 1e-9].all()
    proper = a2 > 1e-6
    c2, r2 = M.sphere_of(a2[proper], b2[proper], g2[proper])
    u = rng.normal(size=c2.shape)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    on = c2 + r2[:, None] * u
    image = M.apply(H, on)
    err = np.abs(np.linalg.norm(image - c[proper], axis=1) - r[proper])
    # App. A recovers ρ'² = |κ'|² − γ'/α', which cancels: its relative error is about
    # 1e-16 (1 + |κ'|²)/ρ'² — the reason the tracer maps balls by two points instead
    cancel = 1e-15 * (1 + np.sum(c2 * c2, axis=1)) / r2**2
    assert (err <= 1e-7 * (1 + np.abs(c[proper]).max(1) + r[proper]) + cancel * r[proper]).all()


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_map_ball_equals_app_a(seed):
    """The two-point form the tracer uses gives App. A's sphere (mapped by H⁻¹)."""
    rng = np.random.default_rng(seed)
    H = random_transform(rng)
    c, r = rng.normal(size=(20, 3)) * 2, rng.uniform(0.05, 1.5, 20)
    a2, b2, g2 = M.transform_sphere(H, *M.sphere_coeffs(c, r))
    c3, r3, ok = M.map_ball(M.tidy(M.inverse(H)), c, r)
    good = ok & (a2 > 1e-6)
    c2, r2 = M.sphere_of(a2[good], b2[good], g2[good])
    scale = 1 + np.abs(c2).max(1) + r2
    cancel = 1e-15 * (1 + np.sum(c2 * c2, axis=1)) / r2**2  # App. A's own error, as above
    assert (np.abs(c3[good] - c2).max(1) <= 1e-7 * scale).all()
    assert (np.abs(r3[good] - r2) <= 1e-7 * scale + cancel * r2).all()


def test_map_ball_keeps_a_tiny_probe_in_float32_where_app_a_loses_it():
    """Why the tracer maps balls by two points: at |κ| = 10, ρ = 1e-3 App. A's
    ρ² = |κ|² − γ cancels to noise in float32, the two-point form keeps ρ to ~1e-4."""
    f32 = np.float32
    H = M.compose(
        M.rotation([0, 1, 0], 0.4),
        M.translation([3.0, 1.0, -2.0]),
        M.dilation(100.0),
        M.inversion(),
        M.translation([-20.0, 0, 0]),
    ).astype(f32)
    c, r = np.array([[10.0, 0.5, -0.2]], f32), np.array([1e-3], f32)
    alpha, beta, gamma = (v.astype(f32) for v in M.sphere_coeffs(c, r))
    a2, b2, g2 = (
        v.astype(f32) for v in M.transform_sphere(M.inverse(H).astype(f32), alpha, beta, gamma)
    )
    r_app_a = M.sphere_of(a2, b2, g2)[1].astype(f32)
    r_two_point = M.map_ball(H, c, r)[1]
    exact = M.map_ball(H.astype(np.float64), c.astype(np.float64), r.astype(np.float64))[1]
    assert abs(r_two_point[0] / exact[0] - 1) < 1e-3
    assert abs(r_app_a[0] / exact[0] - 1) > 1e-2


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_app_c_gradient_matches_finite_differences(seed):
    """(a − L(q)c) g (cq + d)⁻¹ is the directional derivative; central differences with
    h = 1e-6 carry O(h²·L''') + O(1e-16/h) error, so 1e-6 relative is the honest bound."""
    rng = np.random.default_rng(seed)
    H = random_transform(rng)
    x, g = rng.normal(size=(30, 3)), rng.normal(size=(30, 3))
    ok = far_from_pole(H, x, 0.3)
    x, g = x[ok], g[ok]
    h = 1e-6
    fd = (M.apply(H, x + h * g) - M.apply(H, x - h * g)) / (2 * h)
    an = M.gradient(H, x, g)
    assert (np.abs(fd - an).max(1) <= 1e-5 * (1 + np.abs(an).max(1))).all()


@settings(max_examples=30, deadline=None)
@given(seeds)
def test_jacobian_is_conformal(seed):
    rng = np.random.default_rng(seed)
    H = random_transform(rng)
    x = rng.normal(size=(20, 3))
    x = x[far_from_pole(H, x, 0.1)]
    J = M.jacobian(H, x)
    JtJ = np.einsum("nij,nik->njk", J, J)
    lam = JtJ[:, 0, 0]
    assert np.allclose(JtJ / lam[:, None, None], np.eye(3), atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(seeds)
def test_app_b_ray_sphere(seed):
    rng = np.random.default_rng(seed)
    c, r = rng.normal(size=(40, 3)), rng.uniform(0.1, 2.0, 40)
    tau, omega = rng.normal(size=(40, 3)) * 3, rng.normal(size=(40, 3))
    omega /= np.linalg.norm(omega, axis=1, keepdims=True)
    t = M.ray_sphere(*M.sphere_coeffs(c, r), tau, omega)
    # geometric solution: closest approach
    b = np.einsum("ni,ni->n", c - tau, omega)
    d2 = np.einsum("ni,ni->n", c - tau, c - tau) - b * b
    hits = d2 < r * r
    assert (np.isfinite(t[:, 0]) == hits).all()
    half = np.sqrt(np.maximum(r * r - d2, 0))[hits]
    assert np.allclose(t[hits], np.stack([b[hits] - half, b[hits] + half], 1), atol=1e-9)


def test_app_b_plane():
    """α = 0: the plane 2 Re(βq) + γ = 0, i.e. −2 β·x + γ = 0; here x = 2."""
    beta = Q.pure(np.array([[1.0, 0.0, 0.0]]))
    t = M.ray_sphere(np.zeros(1), beta, np.array([4.0]), np.zeros((1, 3)), np.array([[1.0, 0, 0]]))
    assert t[0, 0] == pytest.approx(2.0) and np.isnan(t[0, 1])


def test_ball_holding_the_pole_is_inside_out():
    inv = M.inversion()  # pole at the origin
    _, _, ok = M.map_ball(inv, np.array([[0.1, 0, 0], [2.0, 0, 0]]), np.array([0.5, 0.5]))
    assert ok.tolist() == [False, True]


def test_near_pole_points_stay_finite_and_accurate():
    """Approaching the pole, |L(x)| ~ 1/δ; the inverse still recovers x to δ-relative
    rounding (1e-16/δ²)."""
    H = M.compose(M.translation([1.0, 2.0, 3.0]), M.inversion(), M.translation([-0.5, 0, 0]))
    p = M.pole(H)
    for delta in (1e-2, 1e-4, 1e-6):
        x = p + delta * np.array([[0.6, 0.0, 0.8]])
        y = M.apply(H, x)
        assert np.isfinite(y).all() and np.linalg.norm(y) > 0.1 / delta
        assert np.allclose(M.apply(M.inverse(H), y), x, atol=1e-15 / delta)


def test_condition_flags_singular():
    assert M.condition(M.identity()) == pytest.approx(1.0)
    assert (
        M.condition(M.matrix(M.ONE, M.ONE, M.ONE, M.ONE)) == float("inf")
        or M.condition(M.matrix(M.ONE, M.ONE, M.ONE, M.ONE)) > 1e15
    )


def test_the_real_matrix_is_the_four_left_multiplication_blocks():
    """M.real_matrix (built at once from a sign pattern) against its definition, block
    by block from quaternion.left_matrix; a swapped block is the negative control."""
    rng = np.random.default_rng(7)
    for _ in range(50):
        H = rng.normal(size=(2, 2, 4))
        blocks = [[Q.left_matrix(H[r, k]) for k in range(2)] for r in range(2)]
        assert np.array_equal(M.real_matrix(H), np.block(blocks))
        swapped = np.block([blocks[0][::-1], blocks[1]])
        assert not np.array_equal(M.real_matrix(H), swapped)


def test_a_stack_of_matrices_has_each_ones_real_matrix_and_condition():
    """real_matrix and conditions over a stack (a pose's levels at once) are those of each
    matrix alone; a singular one in the stack is ∞ there and nowhere else."""
    rng = np.random.default_rng(11)
    H = np.stack([random_transform(rng) for _ in range(6)] + [M.matrix(*[M.ONE] * 4)])
    assert np.array_equal(M.real_matrix(H), np.stack([M.real_matrix(h) for h in H]))
    got = M.conditions(H)
    alone = [M.condition(h) for h in H]
    assert np.array_equal(got[:-1], alone[:-1]) and np.isfinite(got[:-1]).all()
    assert got[-1] > 1e15 and alone[-1] > 1e15


@settings(max_examples=50, deadline=None)
@given(seeds, st.sampled_from([(), (1,), (2,), (16,), (17,), (300,)]))
def test_the_hamilton_product_is_the_left_matrix_times_q_for_one_or_many(seed, shape):
    """Q.mul, by p's left matrix for a few quaternions and by component for many, against
    quaternion.left_matrix (written out from the Hamilton table) one pair at a time; each
    factor alone or broadcast. Negative control: the product the other way round, qp."""
    rng = np.random.default_rng(seed)
    p, q = rng.normal(size=(*shape, 4)), rng.normal(size=(*shape, 4))
    one = rng.normal(size=4)
    for a, b in ((p, q), (one, q), (p, one)):
        got = Q.mul(a, b)
        A, B = np.broadcast_to(a, got.shape), np.broadcast_to(b, got.shape)
        want = np.array([Q.left_matrix(x) @ y for x, y in zip(A.reshape(-1, 4), B.reshape(-1, 4))])
        assert np.allclose(got.reshape(-1, 4), want, rtol=0, atol=1e-12)
        flipped = np.array(
            [Q.left_matrix(y) @ x for x, y in zip(A.reshape(-1, 4), B.reshape(-1, 4))]
        )
        assert not np.allclose(got.reshape(-1, 4), flipped, rtol=0, atol=1e-6)
