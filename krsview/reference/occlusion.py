"""Shadow rays and ambient occlusion [KRS17 §8.5]; twin of ``shaders/shadows.glsl`` and
``shaders/occlusion.glsl``.

Shadow rays start SHADOW_OFFSET·ε off the surface and stop at the primary ray's threshold ε.
Soft shadows take the smallest free distance met along the ray as a fraction k·free/t of the
distance travelled (Fig. 11): sphere-traced distances for a KRS, free probe radii for a MöKRS.
In a compound the shadow ray keeps one free distance per component, as the primary ray does
[KRS17 §5.1], so a step costs one component's distance, not all of them. With the shadow
cone (``[render] shadow_cone``) a component's free distance starts where its bounds meet the
ray's cone (:func:`cone_entry`), not at 0: most of a grove's trees are never stepped.
"""

from __future__ import annotations

import numpy as np

from ..compile.constants import AO_SAMPLES, INITIAL_PROBE, MIN_PROBE
from ..scene import Render
from .geometry import Bounds
from .trace import Distance, Scale, Test, by_component, front, lod

FAR_AWAY = 1e30  # a free distance past every far limit (scene_block.glsl)


def cone_entry(
    bounds: Bounds, o: np.ndarray, l: np.ndarray, eps: np.ndarray, slope: float, far: float
) -> np.ndarray:
    """(N, C): where the shadow ray o + t l (o (N, 3)) first meets each component: the least
    t ≥ 0 at which its ball or half-space, grown by ε, meets the cone of radius slope·t about
    the ray (slope 1/k for soft shadows, 0 for hard ones); FAR_AWAY where neither does before
    the far limit. Before it the component's distance exceeds ε + slope·t: it can neither
    block the ray nor lower its visibility below 1. Twin of cone_entry in shadows.glsl, with
    its float rounding margins."""
    out = np.zeros((len(o), len(bounds.balls)))
    a = 1.0 - slope * slope
    for c, (ball, h) in enumerate(zip(bounds.balls, bounds.half_spaces)):
        v = o - ball[:3]
        R = ball[3] + eps + 1e-6 * (np.linalg.norm(v, axis=1) + np.linalg.norm(o, axis=1))
        b, q = v @ l - R * slope, np.einsum("ij,ij->i", v, v) - R * R
        disc = b * b - a * q
        outside = (ball[3] >= 0.0) & (q > 0.0) & (a > 0.0)
        never = (b >= 0.0) | (disc < 0.0)
        root = q / np.where(never, 1.0, np.sqrt(np.maximum(disc, 0.0)) - b)
        t0 = np.where(outside, np.where(never, FAR_AWAY, root), 0.0)
        s = o @ h[:3] - h[3] - eps - 1e-6 * (np.linalg.norm(o, axis=1) + abs(h[3]))
        g = h[:3] @ l - slope
        t0 = np.where(s > 0.0, np.maximum(t0, FAR_AWAY if g >= 0.0 else s / -g), t0)
        out[:, c] = np.where(t0 > far, FAR_AWAY, t0)
    return out


def shadow_by_distance(
    distances: list[Distance],
    o: np.ndarray,
    l: np.ndarray,
    eps: np.ndarray,
    r: Render,
    k: float | None,
    lod_scale: Scale | None = None,
    cone: Bounds | None = None,
) -> np.ndarray:
    """Visibility of direction l from points o, sphere tracing each component's distance
    (the least free distance steps, as in :func:`trace.sphere_trace`); k None: hard shadows.
    The ray is blocked when any step converges; soft visibility is the least k·d/t met.
    ``cone``: the components' bounds, each stepped from its :func:`cone_entry` on."""
    N = len(o)
    vis, tc = np.ones(N), np.zeros((N, len(distances)))
    if cone is not None:
        slope = 0.0 if k is None else 1.0 / k
        tc = cone_entry(cone, o, l, eps, slope, r.max_distance)
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
