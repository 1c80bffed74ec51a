"""MöKRS: compiled form, ISUNBOUNDING [KRS17 Alg. 3] and the nearest kernel with its world
normal [KRS17 §8.1, App. C]. Twin of ``shaders/mokrs.glsl``.

The tracer walks levels from the world inwards: the probe ball is mapped by H_i = G_i⁻¹,
folded across x = 0 on its centre, and tested against K_i. A probe that holds H_i's pole maps
to the exterior of a ball; Alg. 3 rejects it outright ("inside-out"), which stops rays that
merely pass near a pole in empty space. Here it is free when everything level i and the
levels below it hold — inside the level's bounding ball, computed once per scene — lies
inside that ball.
"""

from __future__ import annotations

import numpy as np

from ..algebra import mobius
from ..compile.mokrs import CompiledMoKRS
from .kernels import kernel_distance, world_normal
from .wind import Wind


def is_unbounding(
    c: CompiledMoKRS,
    center: np.ndarray,
    radius: np.ndarray,
    pole_bounds: bool = True,
    lod: np.ndarray | float = 0.0,
    wind: Wind | None = None,
    bound_miss: bool = True,
) -> np.ndarray:
    """ISUNBOUNDING(κ_w, ρ_w) [KRS17 Alg. 3] for balls (N, 3), (N,): whether each ball is free
    of the MöKRS. A ball that holds a level's pole maps to a ball's exterior: it is free when
    the level's bound lies inside that ball, else blocked (``pole_bounds=False``: always
    blocked, Alg. 3's inside-out rule). The mirror decision is taken on the ball's centre, as
    in the paper. Level of detail ``lod`` (world lengths per ball, 0: none): mapped into
    level i's space, a bound smaller than lod in the ball's own scale (lod / ρ_w per unit of
    its radius, the map's local scale to first order) stands for the levels below, and the
    ball is free exactly when it misses that bound. In the ``wind`` (one component, c = 0)
    the world ball is free when it misses the swept ball, or when the rest ball holding its
    image under g (Wind.rest_ball) is free; lod stays the world's ρ, so a level is cut where
    its bound is below ρ in the rest ball's scale. A ball that misses level i's bound (in
    level i's space, holding K_i and every level below) is free at once, the outermost first:
    a Möbius map takes balls to balls, so the world ball misses all that is left to test.
    Alg. 3 alone (``bound_miss=False``) walks on and may still call it blocked (a pole inside
    it further in, the mirror decided on its centre, a kernel's lower bound). Twin of
    mokrs.glsl."""
    if wind is not None:
        far = wind.wind_ball_distance(0, center) >= radius
        rest, reach = wind.rest_ball(0, center, radius)
        return far | is_unbounding(c, rest, reach, pole_bounds, lod, bound_miss=bound_miss)
    free = np.ones(len(center), dtype=bool)
    live = np.arange(len(center))  # balls not yet decided (the shader returns early)
    kappa, rho = center, radius
    per_radius = np.broadcast_to(np.asarray(lod, dtype=np.float64) / radius, (len(center),))
    with np.errstate(all="ignore"):
        for i in range(c.n - 1, -1, -1):
            kappa, rho, ok = mobius.map_ball(c.inverse[i], kappa, rho, exterior=True)
            if not ok.all():
                b = c.bounds[i]
                inside = (b[3] >= 0) & (np.linalg.norm(kappa - b[:3], axis=1) + b[3] < rho)
                outside = ~ok
                free[live[outside & ~(inside & pole_bounds)]] = False
                live, kappa, rho = live[ok], kappa[ok], rho[ok]  # decided: leave the walk
                per_radius = per_radius[ok]
            b = c.bounds[i]
            miss = (b[3] >= 0) & (np.linalg.norm(kappa - b[:3], axis=1) - b[3] >= rho)
            cut = (b[3] >= 0) & (b[3] < per_radius * rho)  # the bound stands for the levels
            free[live[cut & ~miss]] = False
            keep = ~((miss & bound_miss) | cut)
            live, kappa, rho, per_radius = live[keep], kappa[keep], rho[keep], per_radius[keep]
            if c.reflect[i]:
                kappa = kappa * np.where(kappa[:, :1] > 0.0, [-1.0, 1.0, 1.0], 1.0)
            if c.types[i] != "empty":
                ok = kernel_distance(c.types[i], c.records[i], kappa) >= rho
                free[live[~ok]] = False
                live, kappa, rho, per_radius = live[ok], kappa[ok], rho[ok], per_radius[ok]
    return free


def nearest(
    c: CompiledMoKRS, xw: np.ndarray, wind: Wind | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The level j whose kernel is nearest to world points xw (N, 3) and the world normal there.
    The world gradient of k_j ∘ (world → level j) is Jᵀ ∇k_j [KRS17 §8.1]; in the ``wind``, the
    walk starts at the rest point q = g(xw) and the normal is Dgᵀ of that (Wind.wind_normal)."""
    q = xw if wind is None else wind.unwind(0, xw)
    _, level, xk, Jk = _walk(c, q)
    g = world_normal(c.types, c.records, level, xk, np.swapaxes(Jk, 1, 2))
    return level, g if wind is None else wind.wind_normal(0, xw, q, g)


def distance_estimate(c: CompiledMoKRS, xw: np.ndarray) -> np.ndarray:
    """The first-order world distance to the nearest kernel (N,): negative inside, zero
    exactly on the surface, but not a bound (a MöKRS has no distance function [KRS17 §7]):
    the scalar field the mesh export samples."""
    return _walk(c, xw)[0]


def _walk(c: CompiledMoKRS, xw: np.ndarray) -> tuple[np.ndarray, ...]:
    """(k_j(x_j)/|J e_x|, j, x_j, J) of the nearest level j. The point is followed inwards
    while J, the Jacobian of world → level space, accumulates (columns from App. C). A
    conformal J scales lengths by |J e_x|, so k_i(x_i)/|J e_x| is the world distance to
    first order, comparable across levels (ties go to the coarser level)."""
    N = len(xw)
    x = xw
    J = np.broadcast_to(np.eye(3), (N, 3, 3)).copy()
    best = np.full(N, np.inf)
    level = np.zeros(N, dtype=np.int64)
    xk, Jk = x.copy(), J.copy()
    flip = np.array([-1.0, 1.0, 1.0])
    with np.errstate(all="ignore"):
        for i in range(c.n - 1, -1, -1):
            J = mobius.jacobian(c.inverse[i], x) @ J
            x = mobius.apply(c.inverse[i], x)
            if c.reflect[i]:
                behind = x[:, 0] > 0.0
                x = np.where(behind[:, None], x * flip, x)
                J = np.where(behind[:, None, None], J * flip[:, None], J)
            if c.types[i] == "empty":
                continue
            d = kernel_distance(c.types[i], c.records[i], x) / np.linalg.norm(J[:, :, 0], axis=1)
            better = d < best
            best = np.where(better, d, best)
            level = np.where(better, i, level)
            xk = np.where(better[:, None], x, xk)
            Jk = np.where(better[:, None, None], J, Jk)
    return best, level, xk, Jk
