"""KRS distance [KRS17 Alg. 1] and the nearest kernel with its world normal [KRS14 §6.1].

Folding x into the negative half-space of each mirror clips every level to that half-space
[KRS14 Fig. 2], so DISTANCE is a lower bound of the distance to the clipped expansion, and
exact when kernels are separated. Mirrors ``shaders/krs.glsl``.
"""
from __future__ import annotations

import numpy as np

from .compiled import CompiledKRS
from .kernels import kernel_distance, kernel_gradient


def fold(m: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reflect the points behind mirror m = (u, w) (u·x − w > 0); returns (x', reflected)."""
    s = x @ m[:3] - m[3]
    flip = s > 0.0
    return np.where(flip[:, None], x - 2.0 * s[:, None] * m[:3], x), flip


def distance(c: CompiledKRS, xw: np.ndarray) -> np.ndarray:
    """DISTANCE(x_w) [KRS17 Alg. 1] for points (N, 3)."""
    x = xw
    d = kernel_distance(c.types[c.n], c.records[c.n], x)
    for i in range(c.n - 1, -1, -1):
        x, _ = fold(c.mirrors[i], x)
        if c.types[i] != "empty":
            d = np.minimum(d, kernel_distance(c.types[i], c.records[i], x))
    return d


def nearest(c: CompiledKRS, xw: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Alg. 1 that also keeps the winning level j and the world-space normal: the kernel
    gradient at x_j reflected back through the mirrors that folded x [KRS14 §6.1].
    Ties go to the coarser level (strict <), as in the shader."""
    N = len(xw)
    x = xw
    d = kernel_distance(c.types[c.n], c.records[c.n], x)
    level = np.full(N, c.n)
    xk = x.copy()
    flips = np.zeros((max(c.n, 1), N), dtype=bool)
    for i in range(c.n - 1, -1, -1):
        x, flips[i] = fold(c.mirrors[i], x)
        if c.types[i] == "empty":
            continue
        di = kernel_distance(c.types[i], c.records[i], x)
        better = di < d
        d = np.where(better, di, d)
        level = np.where(better, i, level)
        xk = np.where(better[:, None], x, xk)
    g = np.zeros((N, 3))
    for j in np.unique(level):
        sel = level == j
        g[sel] = kernel_gradient(c.types[j], c.records[j], xk[sel])
    for i in range(c.n):  # apply M_j first, M_{n-1} last
        u = c.mirrors[i, :3]
        back = flips[i] & (level <= i)
        g = np.where(back[:, None], g - 2.0 * (g @ u)[:, None] * u, g)
    return d, level, g
