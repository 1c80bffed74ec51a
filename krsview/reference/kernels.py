"""Kernel distance functions k_i and their gradients, float64, vectorised over points (N, 3).

Sphere, capsule and toroidal capsule are a point, segment or circular arc swept by a ball, so
k(p) = |p − core(p)| − r is exact outside and the gradient is the unit vector from core(p)
(the hg_sdf discipline: distances never overshoot). Mirrors ``shaders/kernels.glsl``.
"""

from __future__ import annotations

import numpy as np

from ..algebra.quaternion import conj
from ..algebra.vectors import cross


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def arc_local(P: np.ndarray, q: np.ndarray) -> np.ndarray:
    """P̄ q P for offsets q (N, 3) from the arc's centre: q in the arc's frame (x along the
    bisector e1, y along e2, z along n), in units of R = 1/|P|² (compile/krs.py's layout)."""
    w, u = P[0], P[1:]
    return (w * w - u @ u) * q + 2.0 * (q @ u)[:, None] * u + 2.0 * w * cross(q, u)


def arc_world(P: np.ndarray, v: np.ndarray) -> np.ndarray:
    """The inverse of arc_local: frame coordinates v (N, 3), in units of R, as a world offset
    R·F v from the arc's centre (P v P̄ = F v / R, divided by |P|⁴)."""
    return arc_local(conj(P), v) / float(P @ P) ** 2  # P v P̄: the sandwich by P̄


def arc_half_angle(rec: np.ndarray) -> tuple[float, float]:
    """cos and sin of half the arc's angle, from t = tan(phi/4): exact rational functions, so
    accurate in float32 for every arc (kernels.glsl)."""
    t = rec[3, 0]
    return (1.0 - t * t) / (1.0 + t * t), 2.0 * t / (1.0 + t * t)


def in_wedge(x: np.ndarray, rho: np.ndarray, c: float) -> np.ndarray:
    """Whether the point (x, y) at ρ = |(x, y)| of the arc's frame lies within half the arc's
    angle of its bisector e1: cos a = x/ρ ≥ c = cos(phi/2), one test for every arc angle."""
    return x >= rho * c


def core_point(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Nearest point of the kernel's core (point, segment or arc) to each p."""
    if kind == "sphere":
        return np.broadcast_to(rec[1, :3], p.shape)
    if kind == "capsule":
        A, B = rec[1, :3], rec[2, :3]
        ab = B - A
        h = np.clip(_dot(p - A, ab) / max(float(ab @ ab), 1e-300), 0.0, 1.0)
        return A + h[:, None] * ab
    # toroidal capsule: inside the wedge the arc point at p's angle, else the end on p's side
    a = arc_local(rec[2], p - rec[1, :3])
    rho = np.hypot(a[:, 0], a[:, 1])
    c, s = arc_half_angle(rec)
    radial = np.where((rho > 0)[:, None], a[:, :2] / np.where(rho > 0, rho, 1)[:, None], [1, 0])
    end = np.stack([np.full(len(a), c), np.where(a[:, 1] >= 0.0, s, -s)], axis=1)
    on = np.where(in_wedge(a[:, 0], rho, c)[:, None], radial, end)
    return rec[1, :3] + arc_world(rec[2], np.concatenate([on, np.zeros((len(a), 1))], axis=1))


def kernel_distance(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed distance k_i(p) of one kernel (empty: +inf)."""
    if kind == "empty":
        return np.full(len(p), np.inf)
    if kind == "plane":
        return p @ rec[1, :3] - rec[1, 3]
    if kind == "toroidal_capsule":  # see kernels.glsl: |p − core(p)|² = z² + w, in the arc's frame
        P = rec[2]
        a = arc_local(P, p - rec[1, :3])
        x, y, z = a[:, 0], a[:, 1], a[:, 2]
        c, s = arc_half_angle(rec)
        rho = np.hypot(x, y)
        w = np.where(in_wedge(x, rho, c), (rho - 1.0) ** 2, (x - c) ** 2 + (np.abs(y) - s) ** 2)
        return np.sqrt(w + z * z) / float(P @ P) - rec[1, 3]
    return np.linalg.norm(p - core_point(kind, rec, p), axis=1) - rec[1, 3]


def kernel_gradient(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Unit gradient of k_i at p (the outward surface normal)."""
    if kind == "plane":
        return np.broadcast_to(rec[1, :3], p.shape).copy()
    if kind == "empty":
        return np.zeros_like(p)
    g = p - core_point(kind, rec, p)
    n = np.linalg.norm(g, axis=1, keepdims=True)
    return np.where(n > 0.0, g / np.where(n > 0.0, n, 1.0), np.array([0.0, 0.0, 1.0]))


def world_normal(
    types: tuple[str, ...],
    records: np.ndarray,
    level: np.ndarray,
    xk: np.ndarray,
    to_world: np.ndarray,
) -> np.ndarray:
    """Unit world normals to_world[n] · ∇k_j(x_j) of each point's winning kernel j = level[n]
    at its kernel-space point xk[n]; the kernel gradient itself where the map degenerates."""
    g = np.zeros((len(xk), 3))
    for j in np.unique(level):
        sel = level == j
        g[sel] = kernel_gradient(types[j], records[j], xk[sel])
    gw = np.einsum("nij,nj->ni", to_world, g)
    n = np.linalg.norm(gw, axis=1, keepdims=True)
    return np.where(n > 0.0, gw / np.where(n > 0.0, n, 1.0), g)
