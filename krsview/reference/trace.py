"""Sphere tracing [Har96] and binary sphere tracing [KRS17 Alg. 2], with the LOD threshold
ε = footprint × t × ε-scale [KRS17 §4].

Mirrors ``shaders/trace.glsl`` step for step; a ray that passes max_distance or spends the
iteration cap is a miss.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compile.constants import INITIAL_PROBE, MIN_PROBE, RESTART_KEEP
from ..compile.krs import CompiledKRS
from . import krs


@dataclass
class Trace:
    hit: np.ndarray  # bool (N,)
    t: np.ndarray  # ray distance where the ray converged (N,); meaningless on a miss
    iterations: np.ndarray  # distance evaluations (N,)


Distance = Callable[[np.ndarray], np.ndarray]
Test = Callable[[np.ndarray, np.ndarray], np.ndarray]
# The factor of ε(t) at points (N, 3): a distortion's safe step shrinks by its Lipschitz bound,
# and the threshold shrinks with it, so rays converge where the surface is, not where the
# step is small (reference/distortion.py, lod_scale).
Scale = Callable[[np.ndarray], np.ndarray]


def by_component(fns: list, c: np.ndarray, *args: np.ndarray) -> np.ndarray:
    """Row i of the result is ``fns[c[i]]`` applied to row i of each argument: one batch per
    component, for the compound's per-component free distances [KRS17 §5.1]."""
    out: np.ndarray | None = None
    for k, f in enumerate(fns):
        sel = np.flatnonzero(c == k)
        if sel.size:
            v = f(*(a[sel] for a in args))
            if out is None:
                out = np.empty(len(c), dtype=v.dtype)
            out[sel] = v
    assert out is not None
    return out


def front(
    tc: np.ndarray, rays: np.ndarray, max_distance: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """On each of ``rays``, the component with the least free distance in ``tc`` (N, C)
    (ties: the first, as front() in trace.glsl) and that distance; a ray whose least free
    distance is past max_distance has left every component and is dropped.
    Returns (rays still tracing, their component, their free distance)."""
    c = tc[rays].argmin(axis=1)
    t = tc[rays, c]
    live = t <= max_distance
    return rays[live], c[live], t[live]


def lod(scale: Scale | None, points: np.ndarray) -> np.ndarray | float:
    """The LOD threshold's factor at each point (1 without a distortion)."""
    return 1.0 if scale is None else scale(points)


# A step of a tracer that keeps one t per ray: it moves ``t`` of the rays ``active`` and
# returns (the rays that converged, the rays going on).
Step = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def march(n: int, max_iterations: int, max_distance: float, step: Step) -> Trace:
    """The loop of the tracers that keep one t per ray (restart_trace, relaxed_trace): each
    round the rays not past max_distance take ``step`` and count an iteration; a converged
    ray is a hit, one that passes max_distance or spends the iteration cap a miss."""
    trace = Trace(np.zeros(n, dtype=bool), np.zeros(n), np.zeros(n, dtype=np.int64))
    active = np.arange(n)
    for _ in range(max_iterations):
        active = active[trace.t[active] <= max_distance]
        if active.size == 0:
            break
        trace.iterations[active] += 1
        converged, active = step(trace.t, active)
        trace.hit[converged] = True
    return trace


def sphere_trace(
    distances: list[Distance],
    origin: np.ndarray,
    dirs: np.ndarray,
    eps_per_t: float,
    max_iterations: int,
    max_distance: float,
    lod_scale: Scale | None = None,
) -> Trace:
    """Sphere tracing of the components' distance bounds (points (N, 3) → (N,)), each with
    its own free distance t_c along the ray [KRS17 §5.1]: the component with the least t_c
    (ties: the first) takes the step, and the ray converges when that step does. So it
    stops at the nearest of the hits each component would have alone, after at most the sum
    of their iterations. One KRS is the compound of one: plain sphere tracing."""
    N = len(dirs)
    tc = np.zeros((N, len(distances)))
    t = np.zeros(N)
    hit = np.zeros(N, dtype=bool)
    iters = np.zeros(N, dtype=np.int64)
    active = np.arange(N)
    for _ in range(max_iterations):
        active, c, ta = front(tc, active, max_distance)
        if active.size == 0:
            break
        t[active] = ta
        p = origin + ta[:, None] * dirs[active]
        d = by_component(distances, c, p)
        iters[active] += 1
        converged = d <= eps_per_t * ta * lod(lod_scale, p)
        hit[active[converged]] = True
        tc[active, c] = ta + d
        active = active[~converged]
    return Trace(hit, t, iters)


def restart_trace(
    c: CompiledKRS,
    origin: np.ndarray,
    dirs: np.ndarray,
    eps_per_t: float,
    max_iterations: int,
    max_distance: float,
    rho: Callable[[np.ndarray], np.ndarray | float],
) -> tuple[Trace, np.ndarray]:
    """Sphere tracing of one undistorted KRS whose steps restart Alg. 1 below the ray's
    anchor (krs.restart; trace.glsl's restart_distance): Alg. 1's value where the levels
    below the anchor decide; where only the bound of the levels above is known, the ray steps
    by it without a hit test and the next step walks from the top. ``rho``: the level of
    detail at points (N, 3). Returns the trace and the levels walked per ray."""
    N = len(dirs)
    levels = np.zeros(N, dtype=np.int64)
    anchor = krs.Anchor.none(N)
    last = np.full(N, np.inf)  # the last step's length (none before the first)

    def step(t: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        nonlocal anchor
        ta = t[active]
        p = origin + ta[:, None] * dirs[active]
        keep = RESTART_KEEP * last[active]
        d, bounded, a, walked = krs.restart(
            c, p, dirs[active], ta, rho(p), keep, anchor.take(active)
        )
        anchor = anchor.put(active, a)
        levels[active] += walked
        converged = ~bounded & (d <= eps_per_t * ta)
        go = active[~converged]
        t[go] += d[~converged]
        last[go] = d[~converged]
        return active[converged], go

    return march(N, max_iterations, max_distance, step), levels


def relaxed_trace(
    distance: Distance,
    origin: np.ndarray,
    dirs: np.ndarray,
    eps_per_t: float,
    max_iterations: int,
    max_distance: float,
    omega: float,
    lod_scale: Scale | None = None,
) -> Trace:
    """Over-relaxed sphere tracing [Keinert et al. 2014] of one distance bound: from the last
    verified point t_s (free ball of radius d_s) step ω·d; at the new point t, if the two free
    balls no longer cover [t_s, t] (d_s + d < t − t_s) a surface may lie between, so go back
    to t_s + d_s and trace plainly (ω = 1) from there. Every point the ray passes is inside a
    verified free ball, so it never skips a surface; it converges (d ≤ ε(t)) only at a
    covered point. Once ω = 1 the steps are plain sphere tracing, covered by construction, so
    the test is skipped (rounding of t_s + d_s − t_s must not send a ray back forever)."""
    N = len(dirs)
    ts, ds = np.zeros(N), np.zeros(N)  # last verified point and its free radius
    w = np.full(N, omega)

    def step(t: np.ndarray, active: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        ta = t[active]
        d = distance(origin + ta[:, None] * dirs[active])
        gap = (w[active] > 1.0) & (ds[active] + d < ta - ts[active])  # ω = 1: always covered
        back = active[gap]
        t[back], w[back] = ts[back] + ds[back], 1.0
        ok = active[~gap]
        dk = d[~gap]
        converged = dk <= eps_per_t * t[ok] * lod(lod_scale, origin + t[ok, None] * dirs[ok])
        go = ok[~converged]
        ts[go], ds[go] = t[go], dk[~converged]
        t[go] = t[go] + w[go] * dk[~converged]
        return ok[converged], np.concatenate([back, go])

    return march(N, max_iterations, max_distance, step)


def binary_trace(
    tests: list[Test],
    origin: np.ndarray,
    dirs: np.ndarray,
    eps_per_t: float,
    max_iterations: int,
    max_distance: float,
    xi_bonus: float,
    xi_penalty: float,
    lod_scale: Scale | None = None,
) -> Trace:
    """BINARYTRACE [KRS17 Alg. 2]: probe the ball of radius s that touches the free point t;
    if it is unbounding, advance by its diameter 2s and grow s by ξ_bonus, else shrink s by
    ξ_penalty. Iterations count probes. Two departures from the paper's listing: we advance
    before growing s (growing first would step 2ξ_bonus·s, past the verified ball), and a ray
    converges when a *blocked* probe has s ≤ ε(t): a ray passing within δ of a surface then
    hits when δ ≲ ε(t), as in sphere tracing, so both tracers draw the same silhouettes at
    equal ε (the paper tests the shrunk probe, which thickens them by 1/ξ_penalty ≈ 3.3×).
    Each component keeps its own (t_c, s_c) and ``tests`` its unbounding test, chosen as in
    :func:`sphere_trace` [KRS17 §5.1]."""
    N = len(dirs)
    tc = np.zeros((N, len(tests)))
    sc = np.full((N, len(tests)), INITIAL_PROBE)
    t = np.zeros(N)
    hit = np.zeros(N, dtype=bool)
    iters = np.zeros(N, dtype=np.int64)
    active = np.arange(N)
    for _ in range(max_iterations):
        active, c, ta = front(tc, active, max_distance)
        if active.size == 0:
            break
        t[active], sa = ta, sc[active, c]
        free = by_component(tests, c, origin + (ta + sa)[:, None] * dirs[active], sa)
        iters[active] += 1
        eps = eps_per_t * ta * lod(lod_scale, origin + ta[:, None] * dirs[active])
        converged = ~free & (sa <= np.maximum(eps, MIN_PROBE))
        hit[active[converged]] = True
        tc[active, c] = np.where(free, ta + 2.0 * sa, ta)
        sc[active, c] = np.where(free, sa * xi_bonus, sa * xi_penalty)
        active = active[~converged]
    return Trace(hit, t, iters)
