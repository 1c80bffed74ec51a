"""What Alg. 1 clips off a route [KRS17 Alg. 1, KRS14 Fig. 2]: DISTANCE folds every point into
the negative side of each mirror, so the part of a child branch that reaches across the mirror
of the fork it grows from is not drawn. Here that part is found exactly on the branch's centre
line (a circular arc, or the chord when straight), for the editor to draw it in red where
`Route.warnings` names the level (in a compound, on each component's route, placed)."""

from __future__ import annotations

import math

import numpy as np

from ..scene import Route, Scene
from ..scene.model import arc_of
from ..scene.route import CLIP_TOLERANCE, arc_points
from .handles import component_routes

DRAW_STEP = 1.0 / 64  # the clipped arc is drawn in pieces of at most this fraction of the branch


def positive_spans(route: Route, i: int) -> list[tuple[float, float]]:
    """The parameter spans s ∈ [0, 1] (start → end, uniform in angle along the arc) where
    the centre line of level i − 1's branch lies on the positive side of mirror R_{i−1}
    (level i's normal, through fork P_i), i.e. what Alg. 1 removes; i ≥ 1."""
    m = route.mirror(i)
    n, w = np.array(m.normal), m.offset
    k = route.kernel(i - 1)
    a = arc_of(k)
    if a is None:  # g(s) = g0 + s (g1 − g0) along the chord
        g0 = float(n @ np.array(k.start)) - w
        g1 = float(n @ np.array(k.end)) - w
        roots = [g0 / (g0 - g1)] if g0 != g1 and 0.0 < g0 / (g0 - g1) < 1.0 else []
        g = lambda s: g0 + s * (g1 - g0)  # noqa: E731
    else:  # g(s) = A cos(s φ) + B sin(s φ) + C on the arc
        A = a.R * float(n @ np.array(a.e1))
        B = a.R * float(n @ np.array(a.e2))
        C = float(n @ np.array(a.center)) - w
        rho = math.hypot(A, B)
        roots = []
        if rho > 0 and abs(C) <= rho:
            t0, dt = math.atan2(B, A), math.acos(-C / rho)
            for t in (t0 - dt, t0 + dt):
                s = (t % (2 * math.pi)) / a.phi
                if 0.0 < s < 1.0:
                    roots.append(s)
        g = lambda s: A * math.cos(s * a.phi) + B * math.sin(s * a.phi) + C  # noqa: E731
    cuts = [0.0, *sorted(roots), 1.0]
    return [(s0, s1) for s0, s1 in zip(cuts[:-1], cuts[1:]) if s1 > s0 and g(0.5 * (s0 + s1)) > 0]


def centre_line(route: Route, i: int, s: np.ndarray) -> np.ndarray:
    """Points of level i's branch centre line at parameters s (the parametrisation of
    :func:`positive_spans`)."""
    k = route.kernel(i)
    a = arc_of(k)
    s = np.asarray(s, dtype=np.float64)[:, None]
    if a is None:
        return np.array(k.start) + s * (np.subtract(k.end, k.start))
    ang = s * a.phi
    return np.array(a.center) + a.R * (np.cos(ang) * np.array(a.e1) + np.sin(ang) * np.array(a.e2))


def clipped_parts(route: Route) -> list[tuple[int, np.ndarray]]:
    """(level, polyline) for every piece Alg. 1 clips off a branch that `Route.warnings`
    names (its samples cross deeper than CLIP_TOLERANCE × its radius: the same test), and
    off a branch's sibling (its mirror image at its fork) across the mirror below."""
    out = []
    for i in range(1, len(route.levels)):
        m = route.mirror(i)
        worst = float((arc_points(route.kernel(i - 1)) @ np.array(m.normal)).max()) - m.offset
        if worst > CLIP_TOLERANCE * route.levels[i - 1].radius:
            for s0, s1 in positive_spans(route, i):
                pieces = max(2, math.ceil((s1 - s0) / DRAW_STEP) + 1)
                out.append((i - 1, centre_line(route, i - 1, np.linspace(s0, s1, pieces))))
        if i + 1 < len(route.levels):
            out += [(i - 1, line) for line in _sibling_cut(route, i)]
    return out


def _sibling_cut(route: Route, i: int) -> list[np.ndarray]:
    """The runs of the sibling of level i − 1's branch on the positive side of the mirror
    at fork P_{i+1}, where it crosses deeper than the tolerance (sampled: the sibling is
    drawn in pieces of DRAW_STEP anyway)."""
    up = route.mirror(i + 1)
    points = route.sibling(i, round(1 / DRAW_STEP) + 1)
    e = points @ np.array(up.normal) - up.offset
    if e.max() <= CLIP_TOLERANCE * route.levels[i - 1].radius:
        return []

    def crossing(a: int, b: int) -> np.ndarray:  # where the line between samples a, b meets it
        f = e[a] / (e[a] - e[b])
        return points[a] + f * (points[b] - points[a])

    runs, start = [], None
    for k, out in enumerate([*(e > 0), False]):
        if out and start is None:
            start = k
        elif not out and start is not None:
            head = [crossing(start - 1, start)] if start > 0 else []
            tail = [crossing(k - 1, k)] if k < len(points) else []
            runs.append(np.array([*head, *points[start:k], *tail]))
            start = None
    return [r for r in runs if len(r) >= 2]


def scene_clipped(scene: Scene) -> list[tuple[int, np.ndarray]]:
    """The clipped parts of the scene's route, or of each compound component's route placed
    in the world (then numbered by component)."""
    if scene.route is not None:
        return clipped_parts(scene.route)
    return [
        (k, np.array([placement.point(p) for p in line]))
        for k, _, route, placement in component_routes(scene)
        for _, line in clipped_parts(route)
    ]
