"""Low-index sway (issue 29, [KRS17 §10]: "subtle changes to low-index transformations might
be acceptable"): the mirrors of a tree's coarsest forks turn a little, back and forth, each
about its own fork point, so the mirrored half of the crown swings against the trunk.

A route's mirror R_{i−1} is level i's normal through the fork P_i (``Route.mirror``); the
sway turns that normal about P_i by θ_k(t) = A sin(2π f t + k φ) (k = 0 at the trunk's
fork), about the axis d × u (d: level i's branch direction into the fork, u: the normal),
which tilts the plane towards the branch. A turned mirror must not cut the child branch
(level i − 1) that grows from its fork: the rule of what Alg. 1 clips (``Route.warnings``,
``editor/clipped.py``): no point of the child's centre line deeper than CLIP_TOLERANCE × its
radius on the mirror's positive side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..algebra.vectors import cross
from ..messages import SceneError
from .route import CLIP_TOLERANCE, Route, arc_points
from .schema import param
from .tree import as_vec3, perpendicular

SAFETY = 0.05  # first samples: the crossing grows by at most this fraction of its limit between
MAX_SAMPLES = 100_000  # samples of one period (a huge amplitude × branch is refused anyway)


@dataclass(frozen=True)
class Sway:
    """``[animation.sway]``: the coarsest mirrors of a tree turning back and forth."""

    levels: int = param(2, lo=1, hi=8, help="mirrors turned, from the trunk's fork upwards")
    amplitude: float = param(
        2.0, lo=0.0, hi=45.0, unit="degrees", help="largest turn of each mirror"
    )
    frequency: float = param(
        0.4, lo=0.0, lo_open=True, hi=10.0, unit="Hz", help="turns back and forth per second"
    )
    phase_step: float = param(
        137.5,
        lo=0.0,
        hi=360.0,
        unit="degrees",
        help="phase of the k-th mirror from the trunk: k × this (the golden angle: no two "
        "levels in step)",
    )

    def angle(self, k: int, t: float | np.ndarray) -> float | np.ndarray:
        """θ_k(t) in radians: the turn of the k-th mirror from the trunk's fork at time t."""
        phase = math.radians(k * self.phase_step)
        return math.radians(self.amplitude) * np.sin(2 * math.pi * self.frequency * t + phase)


def turned(route: Route, i: int, theta: float | np.ndarray) -> np.ndarray:
    """Level i's normal turned by ``theta`` (radians; an array gives one row per angle) about
    the axis d × u through its fork P_i."""
    lv = route.levels[i]
    u = np.array(lv.normal)
    d = np.subtract(lv.fork, route.starts()[i])
    axis = cross(d, u)
    n = np.linalg.norm(axis)
    axis = axis / n if n > 1e-12 * np.linalg.norm(d) else perpendicular(u)
    th = np.asarray(theta, dtype=float)[..., None]
    v = u * np.cos(th) + cross(axis, u) * np.sin(th)  # axis ⟂ u: a unit vector
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def crossing(route: Route, i: int, normal: np.ndarray) -> tuple[np.ndarray, float, float]:
    """How deep the child branch (level i − 1) reaches across a mirror with ``normal``
    (one per row) through fork P_i, the allowed depth (CLIP_TOLERANCE × the child's
    radius), and the child's reach from the fork (the depth's change per radian of turn)."""
    rel = arc_points(route.kernel(i - 1)) - np.array(route.levels[i].fork)
    depth = (np.atleast_2d(normal) @ rel.T).max(axis=1)
    reach = float(np.linalg.norm(rel, axis=1).max())
    return depth, CLIP_TOLERANCE * route.levels[i - 1].radius, reach


def swayed_levels(route: Route, sway: Sway, path: str) -> list[int]:
    """The route levels whose mirrors turn (trunk first), or an error if there are too few."""
    mirrors = len(route.levels) - 1
    if sway.levels > mirrors:
        raise SceneError(
            f"{path}.levels",
            sway.levels,
            f"this tree has {mirrors} fork mirrors; allowed: 1..{max(mirrors, 1)}",
        )
    return [len(route.levels) - 1 - k for k in range(sway.levels)]


def _refuse(path: str, sway: Sway, i: int, k: int, t: float, depth: float, limit: float):
    return SceneError(
        f"{path}.amplitude",
        sway.amplitude,
        f"at t = {t:.6g} s the mirror of route.levels[{i}] (sway level {k}, from the trunk) "
        f"turns across the branch of route.levels[{i - 1}] by {depth:.3g} "
        f"(allowed {limit:.3g}, {CLIP_TOLERANCE:g} × its radius): Alg. 1 would clip it; "
        "allowed: a smaller amplitude",
    )


def check_sway(route: Route, sway: Sway, path: str) -> None:
    """No turned mirror crosses its child branch at any time of a period. The depth changes
    by at most L = the child's reach × max|dθ/dt| (= A · 2π f) per second, so on [a, b] it
    stays below the mean of its ends + L (b − a) / 2: sampled, and an interval where that
    bound is not below the limit is halved until a sample crosses or the bound holds."""
    period = 1.0 / sway.frequency
    amp = math.radians(sway.amplitude)
    for k, i in enumerate(swayed_levels(route, sway, path)):
        _, limit, reach = crossing(route, i, route.levels[i].normal)
        slope = reach * amp * 2 * math.pi * sway.frequency

        def depth(t: float, k: int = k, i: int = i) -> float:
            return float(crossing(route, i, turned(route, i, sway.angle(k, t)))[0][0])

        samples = min(MAX_SAMPLES, max(16, math.ceil(slope * period / (SAFETY * limit))))
        times = np.arange(samples + 1) * (period / samples)
        depths = crossing(route, i, turned(route, i, sway.angle(k, times)))[0]
        for a, b, da, db in zip(times, times[1:], depths, depths[1:]):
            hit = _first_crossing(depth, float(a), float(b), da, db, slope, limit)
            if hit is not None:
                raise _refuse(path, sway, i, k, hit[0], hit[1], limit)


def _first_crossing(depth, a: float, b: float, da: float, db: float, slope: float, limit: float):
    """(time, depth) of a crossing in [a, b], or None where the Lipschitz bound rules it out;
    an interval narrower than a microsecond whose bound still fails counts as crossing."""
    if max(da, db) > limit:
        return (a, da) if da > limit else (b, db)
    if 0.5 * (da + db) + 0.5 * slope * (b - a) <= limit:
        return None
    m = 0.5 * (a + b)
    dm = depth(m)
    if b - a < 1e-6:
        return m, dm
    return _first_crossing(depth, a, m, da, dm, slope, limit) or _first_crossing(
        depth, m, b, dm, db, slope, limit
    )


def swayed(route: Route, sway: Sway, t: float, path: str) -> Route:
    """The route at time t with its coarsest mirrors turned; a turn that crosses its child
    branch there (tracks may have moved the route since it was checked at load) is refused."""
    levels = list(route.levels)
    for k, i in enumerate(swayed_levels(route, sway, path)):
        normal = turned(route, i, sway.angle(k, t))
        (depth,), limit, _ = crossing(route, i, normal)
        if depth > limit:
            raise _refuse(path, sway, i, k, t, float(depth), limit)
        levels[i] = replace(levels[i], normal=as_vec3(normal))
    return replace(route, levels=levels)
