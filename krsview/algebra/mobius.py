"""Quaternion Möbius transformations [KRS17 §6.2–6.3, App. A–C], float64, vectorised.

A transformation is a 2×2 quaternion matrix H = [[a, b], [c, d]] (array (2, 2, 4)) acting on
q ∈ H_0 ≅ R³ as L_H(q) = (aq + b)(cq + d)⁻¹ (Eq. 1); composition is the matrix product.
Spheres are (α, β, γ) with α q q̄ + βq + q̄β̄ + γ = 0 (Eq. 2); planes have α = 0.
Mirrors ``shaders/quaternion.glsl`` and ``shaders/mobius.glsl``.
"""

from __future__ import annotations

import numpy as np

from . import quaternion as Q

ONE = np.array([1.0, 0.0, 0.0, 0.0])
I = np.array([0.0, 1.0, 0.0, 0.0])
ZERO = np.zeros(4)
AFFINE_TOLERANCE = 1e-12  # |c| below this × the matrix scale is rounding: L_H has no pole


# ------------------------------------------------------------ constructors [KRS17 Table 1]
def matrix(a, b, c, d) -> np.ndarray:
    return np.array([a, b, c, d], dtype=np.float64).reshape(2, 2, 4)


def identity() -> np.ndarray:
    return matrix(ONE, ZERO, ZERO, ONE)


def dilation(s: float) -> np.ndarray:
    """q ↦ s q."""
    return matrix(s * ONE, ZERO, ZERO, ONE)


def translation(v) -> np.ndarray:
    """q ↦ q + v."""
    return matrix(ONE, Q.pure(v), ZERO, ONE)


def rotation(axis, radians: float) -> np.ndarray:
    """q ↦ r q r⁻¹, the rotation by ``radians`` about ``axis``."""
    r = Q.from_axis_angle(axis, radians)
    return matrix(r, ZERO, ZERO, r)


def reflection() -> np.ndarray:
    """[[−i, 0], [0, i]]: the reflection across the plane x = 0 (L_R of [KRS17 §7])."""
    return matrix(-I, ZERO, ZERO, I)


def inversion() -> np.ndarray:
    """q ↦ q⁻¹ = −q/|q|²: inversion in the unit sphere followed by the point reflection."""
    return matrix(ZERO, ONE, ONE, ZERO)


# ------------------------------------------------------------------------ group operations
def compose(*Hs: np.ndarray) -> np.ndarray:
    """compose(G, H) = G·H, the transformation L_G ∘ L_H (H applied first)."""
    out = Hs[0]
    for H in Hs[1:]:
        out = np.array(
            [
                [Q.mul(out[r, 0], H[0, k]) + Q.mul(out[r, 1], H[1, k]) for k in range(2)]
                for r in range(2)
            ]
        )
    return out


def real_matrix(H: np.ndarray) -> np.ndarray:
    """H (..., 2, 2, 4) as the real 8×8 matrix of the left-linear map (q1, q2) ↦ (a q1 + b q2,
    c q1 + d q2): the four blocks quaternion.left_matrix(H[r, k]), built at once (a drag or a
    playing frame asks it of every level)."""
    blocks = Q.left_matrices(np.asarray(H))  # (..., r, k, 4, 4)
    return np.swapaxes(blocks, -3, -2).reshape(*np.shape(H)[:-3], 8, 8)


def conditions(H: np.ndarray) -> np.ndarray:
    """Condition numbers of matrices H (..., 2, 2, 4), ∞ where singular: how much rounding
    each inverse amplifies."""
    with np.errstate(all="ignore"):
        c = np.linalg.cond(real_matrix(H))
    return np.where(np.isfinite(c), c, np.inf)


def condition(H: np.ndarray) -> float:
    """Condition number of one H (:func:`conditions`)."""
    return float(conditions(H))


def inverse(H: np.ndarray) -> np.ndarray:
    """H⁻¹. The real 8×8 inverse commutes with right multiplication by quaternions, so each
    4×4 block is again a left multiplication; its first column is the quaternion."""
    M = np.linalg.inv(real_matrix(H))
    return np.array([[M[4 * r : 4 * r + 4, 4 * k] for k in range(2)] for r in range(2)])


def tidy(H: np.ndarray) -> np.ndarray:
    """Zero a rounding-level c so an affine transformation (a composition of translations,
    rotations and dilations) is recognised as having no pole."""
    H = H.copy()
    if np.abs(H[1, 0]).max() <= AFFINE_TOLERANCE * np.abs(H).max():
        H[1, 0] = 0.0
    return H


# -------------------------------------------------------------------------------- points
def apply(H: np.ndarray, x: np.ndarray) -> np.ndarray:
    """L_H(x) = (aq + b)(cq + d)⁻¹ for points x (N, 3) (Eq. 1)."""
    q = Q.pure(x)
    num = Q.mul(H[0, 0], q) + H[0, 1]
    den = Q.mul(H[1, 0], q) + H[1, 1]
    return Q.mul(num, Q.inv(den))[..., 1:]


def pole(H: np.ndarray) -> np.ndarray | None:
    """The point q with cq + d = 0, sent to infinity; None for an affine H (c = 0)."""
    if not H[1, 0].any():
        return None
    return -Q.mul(Q.inv(H[1, 0]), H[1, 1])[1:]


def gradient(H: np.ndarray, x: np.ndarray, g: np.ndarray) -> np.ndarray:
    """The derivative of L_H at x applied to g [KRS17 App. C, Eq. 3]:
    g_w = (a − L_H(q) c) g (cq + d)⁻¹. Not normalised."""
    q, gq = Q.pure(x), Q.pure(g)
    qw = Q.pure(apply(H, x))
    den = Q.mul(H[1, 0], q) + H[1, 1]
    left = H[0, 0] - Q.mul(qw, H[1, 0])
    return Q.mul(Q.mul(left, gq), Q.inv(den))[..., 1:]


def jacobian(H: np.ndarray, x: np.ndarray) -> np.ndarray:
    """dL_H at points x (N, 3) as matrices (N, 3, 3), columns from App. C; for a conformal
    L_H each is a scaled orthogonal matrix."""
    cols = [gradient(H, x, np.broadcast_to(e, x.shape)) for e in np.eye(3)]
    return np.stack(cols, axis=-1)


# ------------------------------------------------------------------------------- spheres
def sphere_coeffs(center: np.ndarray, radius: np.ndarray):
    """(α, β, γ) of spheres (N,): α = 1, β = κ, γ = |κ|² − ρ² [KRS17 §6.3]."""
    center = np.asarray(center, dtype=np.float64)
    radius = np.asarray(radius, dtype=np.float64)
    return (
        np.ones(radius.shape),
        Q.pure(center),
        np.sum(center * center, axis=-1) - radius * radius,
    )


def sphere_of(alpha, beta, gamma):
    """Centre and radius of α|q|² − 2 β_v·q + γ = 0 (α ≠ 0); for q ∈ H_0 only the vector
    part of β matters, since Re(βq) = −β_v·q."""
    center = beta[..., 1:] / alpha[..., None]
    r2 = np.sum(center * center, axis=-1) - gamma / alpha
    return center, np.sqrt(np.maximum(r2, 0.0))


def transform_sphere(H: np.ndarray, alpha, beta, gamma):
    """The sphere whose image under L_H is (α, β, γ) [KRS17 App. A]:
    α' = α a ā + 2 Re(c̄ β a) + γ c c̄,  β' = α b̄ a + d̄ β a + b̄ β̄ c + γ d̄ c,
    γ' = α b b̄ + 2 Re(d̄ β b) + γ d d̄. The sign of the implicit function is kept, so the
    inside stays the inside: α' < 0 means the preimage of the ball is a ball's exterior."""
    a, b, c, d = H[0, 0], H[0, 1], H[1, 0], H[1, 1]
    bb, cb, db = Q.conj(b), Q.conj(c), Q.conj(d)
    al, ga = np.asarray(alpha)[..., None], np.asarray(gamma)[..., None]
    M = Q.mul
    a2 = al * Q.norm2(a) + 2.0 * M(M(cb, beta), a)[..., :1] + ga * Q.norm2(c)
    b2 = al * M(bb, a) + M(M(db, beta), a) + M(M(bb, Q.conj(beta)), c) + ga * M(db, c)
    g2 = al * Q.norm2(b) + 2.0 * M(M(db, beta), b)[..., :1] + ga * Q.norm2(d)
    return a2[..., 0], b2, g2[..., 0]


def map_ball(M: np.ndarray, center: np.ndarray, radius: np.ndarray, exterior: bool = False):
    """The image of balls (center (N, 3), radius (N,)) under L_M, as (center', radius', ok);
    ok is False where the ball holds the pole of M: its image is a ball's exterior, and with
    ``exterior`` (center', radius') is that ball (the same diameter construction), else 0.

    Same sphere as App. A applied with M⁻¹, computed from two points instead: the diameter
    on the line through the pole maps to a diameter of the image (both are symmetric about
    that line), so the radius comes from a difference of nearby points. App. A instead
    recovers ρ² = |κ|² − γ, which cancels catastrophically in float32 when ρ ≪ |κ|.
    Without a pole L_M is a similarity and one point suffices."""
    p = pole(M)
    if p is None:  # a similarity: the centre maps to the centre, radii scale by |a|/|d|
        return apply(M, center), radius * affine_scale(M), np.ones(len(center), dtype=bool)
    off = center - p
    dist = np.linalg.norm(off, axis=-1)
    ok = dist > radius
    u = np.where(
        (dist > 0)[:, None], off / np.where(dist > 0, dist, 1.0)[:, None], [1.0, 0.0, 0.0]
    )  # a pole at the centre: any diameter passes through it
    r = (radius if exterior else np.where(ok, radius, 0.0))[:, None]
    x1, x2 = apply(M, center + r * u), apply(M, center - r * u)
    return 0.5 * (x1 + x2), 0.5 * np.linalg.norm(x1 - x2, axis=-1), ok


def affine_scale(M: np.ndarray) -> float:
    """The length scale |a|/|d| of an affine L_M(q) = (aq + b)d⁻¹ (c = 0)."""
    return float(np.sqrt(Q.norm2(M[0, 0]) / Q.norm2(M[1, 1])))


def ray_sphere(alpha, beta, gamma, tau: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """Ray parameters t (N, 2), ascending, where τ + ωt meets the sphere or plane (α, β, γ)
    [KRS17 App. B]: α t² + 2(α Re(τω̄) + Re(βω)) t + α ττ̄ + 2 Re(βτ) + γ = 0 for a unit ω.
    NaN where the ray misses (for a plane, the second root is NaN)."""
    t_, w_ = Q.pure(tau), Q.pure(omega)
    A = np.asarray(alpha, dtype=np.float64)
    B = A * Q.mul(t_, Q.conj(w_))[..., 0] + Q.mul(beta, w_)[..., 0]  # half the linear term
    C = A * Q.norm2(t_) + 2.0 * Q.mul(beta, t_)[..., 0] + gamma
    out = np.full(A.shape + (2,), np.nan)
    plane = A == 0.0
    with np.errstate(all="ignore"):
        out[..., 0] = np.where(plane & (B != 0.0), -C / (2.0 * B), np.nan)
        disc = B * B - A * C
        s = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
        quad = ~plane
        # numerically stable roots: q = −(B + sign(B) s), t = q/A and C/q
        qq = -(B + np.copysign(s, B))
        r1, r2 = qq / A, C / qq
        out[..., 0] = np.where(quad, np.minimum(r1, r2), out[..., 0])
        out[..., 1] = np.where(quad, np.maximum(r1, r2), np.nan)
    return out
