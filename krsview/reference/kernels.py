"""Kernel distance functions k_i and their gradients, float64, vectorised over points (N, 3).

Sphere, capsule and toroidal capsule are a point, segment or circular arc swept by a ball, so
k(p) = |p − core(p)| − r is exact outside and the gradient is the unit vector from core(p)
(the hg_sdf discipline: distances never overshoot). Mirrors ``shaders/kernels.glsl``.
"""

from __future__ import annotations

import numpy as np


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def in_wedge(rec: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Whether the angle a of (x, y) from e1 towards e2 lies in [0, phi], without trigonometry:
    y = ρ sin a and s = x sin phi − y cos phi = ρ sin(phi − a) are both ≥ 0 inside an arc of at
    most π; a longer arc excludes only the points where both are negative."""
    cos_phi, sin_phi = rec[4, 3], rec[5, 3]
    s = x * sin_phi - y * cos_phi
    if sin_phi >= 0.0:
        return (y >= 0.0) & (s >= 0.0)
    return (y >= 0.0) | (s >= 0.0)


def _arc_frame(rec: np.ndarray, p: np.ndarray):
    O, e1, e2 = rec[3, :3], rec[4, :3], rec[5, :3]
    q = p - O
    return q, _dot(q, e1), _dot(q, e2)


def core_point(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Nearest point of the kernel's core (point, segment or arc) to each p."""
    if kind == "sphere":
        return np.broadcast_to(rec[1, :3], p.shape)
    A, B = rec[1, :3], rec[2, :3]
    if kind == "capsule":
        ab = B - A
        h = np.clip(_dot(p - A, ab) / max(float(ab @ ab), 1e-300), 0.0, 1.0)
        return A + h[:, None] * ab
    # toroidal capsule: inside the wedge the arc point at p's angle, else the nearer end
    q, x, y = _arc_frame(rec, p)
    rho = np.hypot(x, y)
    radial = (x[:, None] * rec[4, :3] + y[:, None] * rec[5, :3]) / np.where(rho > 0, rho, 1)[
        :, None
    ]
    on_arc = rec[3, :3] + rec[3, 3] * np.where((rho > 0)[:, None], radial, rec[4, :3])
    end = np.where((_dot(p - A, p - A) <= _dot(p - B, p - B))[:, None], A, B)
    return np.where(in_wedge(rec, x, y)[:, None], on_arc, end)


def kernel_distance(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed distance k_i(p) of one kernel (empty: +inf)."""
    if kind == "empty":
        return np.full(len(p), np.inf)
    if kind == "plane":
        return p @ rec[1, :3] - rec[1, 3]
    if kind == "toroidal_capsule":  # see kernels.glsl: |p − core(p)|² = z² + w, in the arc's frame
        q, x, y = _arc_frame(rec, p)
        z = _dot(q, np.cross(rec[4, :3], rec[5, :3]))
        R, cos_phi, sin_phi = rec[3, 3], rec[4, 3], rec[5, 3]
        ring = (np.hypot(x, y) - R) ** 2
        cap = np.minimum((x - R) ** 2 + y**2, (x - R * cos_phi) ** 2 + (y - R * sin_phi) ** 2)
        return np.sqrt(np.where(in_wedge(rec, x, y), ring, cap) + z * z) - rec[1, 3]
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
