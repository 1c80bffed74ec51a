"""Shadow rays and ambient occlusion [KRS17 §8.5]; twin of ``shaders/shadows.glsl`` and
``shaders/occlusion.glsl``.

Shadow rays start SHADOW_OFFSET·ε off the surface and stop at the primary ray's threshold ε.
Soft shadows take the smallest free distance met along the ray as a fraction k·free/t of the
distance travelled (Fig. 11): sphere-traced distances for a KRS, free probe radii for a MöKRS.
In a compound the shadow ray keeps one free distance per component, as the primary ray does
[KRS17 §5.1], so a step costs one component's distance, not all of them.
"""

from __future__ import annotations

import numpy as np

from ..compile.constants import AO_SAMPLES, INITIAL_PROBE, MIN_PROBE
from ..scene import Render
from .trace import Distance, Scale, Test, by_component, front, lod


def shadow_by_distance(
    distances: list[Distance],
    o: np.ndarray,
    l: np.ndarray,
    eps: np.ndarray,
    r: Render,
    k: float | None,
    lod_scale: Scale | None = None,
) -> np.ndarray:
    """Visibility of direction l from points o, sphere tracing each component's distance
    (the least free distance steps, as in :func:`trace.sphere_trace`); k None: hard shadows.
    The ray is blocked when any step converges; soft visibility is the least k·d/t met."""
    N = len(o)
    vis, tc = np.ones(N), np.zeros((N, len(distances)))
    live = np.arange(N)
    for _ in range(r.max_iterations):
        live, c, tl = front(tc, live, r.max_distance)
        if live.size == 0:
            break
        p = o[live] + tl[:, None] * l
        d = by_component(distances, c, p)
        blocked = d <= eps[live] * lod(lod_scale, p)
        vis[live[blocked]] = 0.0
        if k is not None:
            ratio = np.where(tl > 0.0, k * d / np.where(tl > 0.0, tl, 1.0), np.inf)
            vis[live] = np.where(blocked, 0.0, np.minimum(vis[live], ratio))
        tc[live, c] = tl + d
        live = live[~blocked]
    return vis


def shadow_by_probes(
    is_free: Test, o: np.ndarray, l: np.ndarray, eps: np.ndarray, r: Render, k: float | None
) -> np.ndarray:
    """Visibility of direction l from points o by binary probing [KRS17 Alg. 2]."""
    N = len(o)
    vis, t, s = np.ones(N), np.zeros(N), np.full(N, INITIAL_PROBE)
    live = np.arange(N)
    for _ in range(r.max_iterations):
        if live.size == 0:
            break
        tl, sl = t[live], s[live]
        free = is_free(o[live] + (tl + sl)[:, None] * l, sl)
        if k is not None:
            vis[live] = np.where(free, np.minimum(vis[live], k * sl / (tl + sl)), vis[live])
        blocked = ~free & (sl <= np.maximum(eps[live], MIN_PROBE))
        vis[live[blocked]] = 0.0
        t[live] = np.where(free, tl + 2.0 * sl, tl)
        s[live] = np.where(free, sl * r.xi_bonus, sl * r.xi_penalty)
        live = live[~blocked & (t[live] <= r.max_distance)]
    return vis


def ambient_occlusion(
    distance: Distance, p: np.ndarray, n: np.ndarray, step: float, strength: float
) -> np.ndarray:
    """1 − strength·Σ 2^−k·clamp((h_k − d(p + h_k n))/h_k) over h_k = k·step, k = 1..5."""
    occlusion = np.zeros(len(p))
    weight = 0.5
    for k in range(1, AO_SAMPLES + 1):
        h = k * step
        occlusion += weight * np.clip((h - distance(p + h * n)) / h, 0.0, 1.0)
        weight *= 0.5
    return np.clip(1.0 - strength * occlusion, 0.0, 1.0)
