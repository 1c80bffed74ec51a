"""KRS distance [KRS17 Alg. 1] and the nearest kernel with its world normal [KRS14 §6.1].

Folding x into the negative half-space of each mirror clips every level to that half-space
[KRS14 Fig. 2], so DISTANCE is a lower bound of the distance to the clipped expansion, and
exact when kernels are separated. Mirrors ``shaders/krs.glsl``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compile.krs import CompiledKRS
from ..compile.lod import krs_lod
from .kernels import kernel_distance, world_normal


def fold(u: np.ndarray, c: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Reflect the points behind the mirror of normal u through c (its slot's ball centre,
    which compile/balls.py puts on the plane); returns (x', e) with e = u·(x − c), the signed
    distance before folding (e > 0: reflected). The shader folds so where it compiles the
    level of detail, else with e = u·x − w: the same plane, in float64 the same to rounding."""
    e = (x - c) @ u
    return np.where((e > 0.0)[:, None], x - 2.0 * e[:, None] * u, x), e


def distance(
    c: CompiledKRS, xw: np.ndarray, cull: bool = True, rho: np.ndarray | float = 0.0
) -> np.ndarray:
    """DISTANCE(x_w) [KRS17 Alg. 1] for points (N, 3). With ``cull``, a point stops walking
    at level i once d ≤ dist(x, C_i), the ball of all it would still test (compile/krs.py,
    krs_bounds): the value is the same, the shader saves the levels below.

    Level of detail ``rho`` (a length per point, 0: none): at the first ball C_i at least
    k*(rho) levels below the top (compile/lod.py, krs_lod) the walk takes
    d = min(d, dist(x, C_i)) and stops. That is Alg. 1 of the *LOD geometry*: the levels
    above i, and in place of levels i..0 the 2^(n−i−1) copies of the solid ball C_i. It holds
    the KRS (C_i holds all below it), so the value stays a lower bound of the full walk's and
    no ray passes the KRS; and every point of C_i is within its diameter (``reach``, less
    than 2K·rho: compile/lod.py) of the geometry it holds. Culling and the level of detail
    are independent switches, as in the shader; since such a ball reaches up to that beyond
    the balls above it (they hold the KRS, not each other: compile/balls.py), culling with
    the level of detail stops only once d ≤ dist(x, C_i) − reach."""
    x = xw
    d = kernel_distance(c.types[c.n], c.records[c.n], x)
    live = np.ones(len(x), dtype=bool)
    rho = np.broadcast_to(np.asarray(rho, dtype=np.float64), (len(x),))
    depth, reach = krs_lod(c, rho)
    for i in range(c.n - 1, -1, -1):
        b = c.bounds[i]
        if b[3] >= 0 and (cull or rho.any()):
            db = np.linalg.norm(x - b[:3], axis=1) - b[3]
            cut = live & (c.n - 1 - i >= depth)
            d = np.where(cut, np.minimum(d, db), d)
            live &= ~cut & ((db - reach < d) | (not cull))
        x, _ = fold(c.mirrors[i, :3], c.bounds[i, :3], x)
        if c.types[i] != "empty":
            d = np.where(live, np.minimum(d, kernel_distance(c.types[i], c.records[i], x)), d)
    return d


@dataclass(frozen=True)
class Anchor:
    """Per ray, Alg. 1's state before level slot ``j`` (−1: none) at ray distance ``t``: the
    point folded by the mirrors above (``x``), the ray's direction folded alike (``u``), the
    least |e| of those folds (``m``) and the least distance of the levels above (``d``).
    Twin of trace.glsl's Ray fields w*."""

    j: np.ndarray
    x: np.ndarray
    u: np.ndarray
    t: np.ndarray
    m: np.ndarray
    d: np.ndarray

    @staticmethod
    def none(n: int) -> Anchor:
        z = np.zeros(n)
        return Anchor(np.full(n, -1), np.zeros((n, 3)), np.zeros((n, 3)), z, z, z)

    def take(self, rows: np.ndarray) -> Anchor:
        return Anchor(*(getattr(self, f)[rows] for f in FIELDS))

    def put(self, rows: np.ndarray, other: Anchor) -> Anchor:
        """This anchor with ``rows`` replaced by ``other``'s (one row each)."""
        out = {}
        for f in FIELDS:
            v = getattr(self, f).copy()
            v[rows] = getattr(other, f)
            out[f] = v
        return Anchor(**out)


FIELDS = ("j", "x", "u", "t", "m", "d")


def restart(
    c: CompiledKRS,
    p: np.ndarray,
    dirs: np.ndarray,
    t: np.ndarray,
    rho: np.ndarray | float,
    keep: np.ndarray,
    a: Anchor,
    margin: bool = True,
) -> tuple[np.ndarray, np.ndarray, Anchor, np.ndarray]:
    """Alg. 1 at the points p = origin + t·dirs, each walk restarted below its ray's anchor
    ``a`` where the folds above cannot have changed (krs.glsl, krs_restart): a point
    s = t − a.t < a.m further folds to a.x + s·a.u (every fold an isometry on its side of its
    mirror), a.d − s bounds the levels above (1-Lipschitz), and where rho cuts no higher
    than a.j no ball above cuts. The value is Alg. 1's where the levels below end under that
    bound; where the bound limits it is only a lower bound (``bounded``) and the anchor is
    dropped. The anchor moves to the deepest level with min(margin, distance above) ≥
    ``keep``. ``margin=False`` ignores the fold margin (a negative control). Returns
    (distance, bounded, new anchors, levels walked per point)."""
    N, n = len(p), c.n
    rho = np.broadcast_to(np.asarray(rho, dtype=np.float64), (N,))
    s = t - a.t
    fits = s < np.minimum(a.m, a.d) if margin else s < a.d
    depth, reach = krs_lod(c, rho)
    again = (a.j >= 0) & fits & (n - 1 - a.j <= depth)
    start = np.where(again, a.j, n - 1)
    x = np.where(again[:, None], a.x + s[:, None] * a.u, p)
    u = np.where(again[:, None], a.u, dirs)
    bound = a.d - s
    d = np.where(again, bound, kernel_distance(c.types[n], c.records[n], p))
    m = np.where(again, a.m - s, np.inf)
    out, levels = a, np.zeros(N, dtype=np.int64)
    live = np.ones(N, dtype=bool)
    for i in range(n - 1, -1, -1):
        act = live & (i <= start)
        sv = np.flatnonzero(act & (np.minimum(m, d) >= keep))
        if sv.size:
            j = np.full(sv.size, i)
            out = out.put(sv, Anchor(j, x[sv], u[sv], t[sv], m[sv], d[sv]))
        levels += act
        b = c.bounds[i]
        if b[3] >= 0:
            db = np.linalg.norm(x - b[:3], axis=1) - b[3]
            cut = act & (n - 1 - i >= depth)
            d = np.where(cut, np.minimum(d, db), d)
            live &= ~(act & (cut | (db - reach >= d)))  # what is cut below reaches
            act = live & (i <= start)
        mu = c.mirrors[i, :3]
        xf, e = fold(mu, c.bounds[i, :3], x)
        x = np.where(act[:, None], xf, x)
        flip = act & (e > 0)
        u = np.where(flip[:, None], u - 2.0 * (u @ mu)[:, None] * mu, u)
        m = np.where(act, np.minimum(m, np.abs(e)), m)
        if c.types[i] != "empty":
            d = np.where(act, np.minimum(d, kernel_distance(c.types[i], c.records[i], x)), d)
    bounded = again & (d >= bound)
    out = out.put(np.flatnonzero(bounded), Anchor.none(int(bounded.sum())))
    return d, bounded, out, levels


def mirror_weight(e: np.ndarray, width: np.ndarray | None) -> np.ndarray:
    """How much of mirror i's reflection the normal takes: 1 where it folded (e > 0), else 0;
    with smooth shading a ramp over a band of ``width`` around the plane [KRS14 Alg. 2]."""
    if width is None:
        return (e > 0.0).astype(float)
    return np.clip(e / width + 0.5, 0.0, 1.0)


def nearest(
    c: CompiledKRS, xw: np.ndarray, width: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Alg. 1 that also keeps the winning level j, its kernel-space point x_j and the world
    normal M ∇k_j(x_j), where M = A_{n−1} ⋯ A_j with A_i = I − 2 w_i u_i u_iᵀ accumulates while
    walking down (w_i from :func:`mirror_weight`) [KRS14 §6.1]. Ties go to the coarser level
    (strict <), as in the shader. Returns (d, level, normal, x_j)."""
    N = len(xw)
    x = xw
    d = kernel_distance(c.types[c.n], c.records[c.n], x)
    level = np.full(N, c.n)
    xk = x.copy()
    M = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
    Mk = M.copy()
    for i in range(c.n - 1, -1, -1):
        u = c.mirrors[i, :3]
        x, e = fold(u, c.bounds[i, :3], x)
        w = mirror_weight(e, width)
        M = M - 2.0 * w[:, None, None] * np.einsum("ni,j->nij", M @ u, u)
        if c.types[i] == "empty":
            continue
        di = kernel_distance(c.types[i], c.records[i], x)
        better = di < d
        d = np.where(better, di, d)
        level = np.where(better, i, level)
        xk = np.where(better[:, None], x, xk)
        Mk = np.where(better[:, None, None], M, Mk)
    return d, level, world_normal(c.types, c.records, level, xk, Mk), xk
