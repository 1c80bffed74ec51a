"""Kernel distance functions k_i and their gradients, float64, vectorised over points (N, 3).

Sphere, capsule and toroidal capsule are a point, segment or circular arc swept by a ball, so
k(p) = |p − core(p)| − r is exact outside and the gradient is the unit vector from core(p)
(the hg_sdf discipline: distances never overshoot). Mirrors ``shaders/kernels.glsl``.
"""
from __future__ import annotations

import numpy as np

TWO_PI = 2.0 * np.pi


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", a, b)


def core_point(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Nearest point of the kernel's core (point, segment or arc) to each p."""
    if kind == "sphere":
        return np.broadcast_to(rec[1, :3], p.shape)
    A, B = rec[1, :3], rec[2, :3]
    if kind == "capsule":
        ab = B - A
        h = np.clip(_dot(p - A, ab) / max(float(ab @ ab), 1e-300), 0.0, 1.0)
        return A + h[:, None] * ab
    # toroidal capsule: nearest of (arc point at p's angle if inside the wedge, A, B)
    O, R = rec[3, :3], rec[3, 3]
    e1, phi, e2 = rec[4, :3], rec[4, 3], rec[5, :3]
    q = p - O
    x, y = _dot(q, e1), _dot(q, e2)
    a = np.arctan2(y, x)
    a = np.where(a < 0.0, a + TWO_PI, a)
    on_arc = O + R * (np.cos(a)[:, None] * e1 + np.sin(a)[:, None] * e2)
    dA, dB = np.linalg.norm(p - A, axis=1), np.linalg.norm(p - B, axis=1)
    d_arc = np.where(a <= phi, np.linalg.norm(p - on_arc, axis=1), np.inf)
    best = np.where((dA <= dB)[:, None], A, B)
    return np.where((d_arc < np.minimum(dA, dB))[:, None], on_arc, best)


def kernel_distance(kind: str, rec: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed distance k_i(p) of one kernel (empty: +inf)."""
    if kind == "empty":
        return np.full(len(p), np.inf)
    if kind == "plane":
        return p @ rec[1, :3] - rec[1, 3]
    if kind == "toroidal_capsule":  # the torus formula directly, as the shader does
        O, R = rec[3, :3], rec[3, 3]
        e1, phi, e2 = rec[4, :3], rec[4, 3], rec[5, :3]
        q = p - O
        x, y = _dot(q, e1), _dot(q, e2)
        z2 = np.maximum(_dot(q, q) - x * x - y * y, 0.0)
        a = np.arctan2(y, x)
        a = np.where(a < 0.0, a + TWO_PI, a)
        d_arc = np.where(a <= phi, np.sqrt((np.hypot(x, y) - R) ** 2 + z2), np.inf)
        dA = np.linalg.norm(p - rec[1, :3], axis=1)
        dB = np.linalg.norm(p - rec[2, :3], axis=1)
        return np.minimum(d_arc, np.minimum(dA, dB)) - rec[1, 3]
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
