"""Structure edits of a route [KRS17 §9.2], as pure functions of the route: insert a fork
(split a branch), remove one (merge two branches), duplicate a level; taper, scale the widths
or the whole tree, move its foot. Each returns a new Route; the caller validates it with the
scene's schema and commits it as one undo step (re-growing from the growth parameters is
``scene/regrow.py``).

Indices are those of ``route.levels``: 0 is the twig, the last the trunk; level i's branch
runs from the fork below (level i + 1's, or the base) to its own fork P_i.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..algebra.vectors import cross
from ..messages import SceneError
from .model import Mirror, Plane, ToroidalCapsule
from .retrack import Moves, shifted
from .route import Route, RouteLevel, centre_at
from .schema import Vec3
from .tree import as_vec3

NORMAL_CANDIDATES = 360  # directions around the branch tried for a new fork's mirror
TILTS = np.radians(np.arange(0.0, 46.0, 2.5))  # … at these angles back from ⟂ the branch
KEEP_OUT = 0.01  # the share of the doubled subtree a new mirror may leave on its far side
TAPER_RANGE = (0.05, 1.0)  # child / parent radius, as the growth parameters allow
LINE = np.linspace(0.0, 1.0, 33)  # points along a new mirror's child branch
SUBTREE_SAMPLES = 4000  # points of the subtree a new mirror doubles, weighed to place it


def _check_index(route: Route, i: int) -> None:
    n = len(route.levels)
    if not (isinstance(i, int) and 0 <= i < n):
        raise SceneError("route.levels", i, f"no such level; allowed: 0..{n - 1}")


def tangent_at(k: ToroidalCapsule, s: float) -> np.ndarray:
    """The unit direction of a branch's centre line at fraction ``s``, start to end."""
    h = 1e-6
    a, b = centre_at(k, np.array([max(s - h, 0.0), min(s + h, 1.0)]))
    t = b - a
    return t / np.linalg.norm(t)


def subtree_points(kernels: list[ToroidalCapsule], mirrors: list[Mirror]) -> np.ndarray:
    """Points of the subtree L_i that ``kernels`` K_0..K_i and ``mirrors`` R_0..R_{i−1}
    expand into [KRS17 Alg. 1], sampled (fixed seed): a branch, a point on its centre line,
    and a random choice at each mirror above it; the same number from every level."""
    rng = np.random.default_rng(0)
    j = rng.integers(0, len(kernels), SUBTREE_SAMPLES)
    pts = np.empty((SUBTREE_SAMPLES, 3))
    for level, k in enumerate(kernels):
        at = j == level
        pts[at] = centre_at(k, rng.random(int(at.sum())))
    for level, m in enumerate(mirrors):  # R_level doubles L_level: branches 0..level
        u = np.array(m.normal)
        flip = (j <= level) & (rng.random(SUBTREE_SAMPLES) < 0.5)
        pts[flip] -= 2.0 * (pts[flip] @ u - m.offset)[:, None] * u
    return pts


def free_normal(
    fork: np.ndarray,
    t: np.ndarray,
    child: np.ndarray,
    subtree: np.ndarray,
    hint,
    below: Mirror | None = None,
) -> Vec3:
    """The normal of a new mirror through ``fork`` on a branch of direction ``t``. Alg. 1
    folds away what the mirror's positive side holds, so it keeps the ``child`` branch's
    centre line on the negative side, and the child's mirror image (the sibling it grows)
    on the negative side of the mirror ``below`` (the fork the branch grows from: past it,
    Alg. 1 cut the sibling off, leaving a stub), and as much of the ``subtree`` it doubles
    as it can: a plane containing ``t`` if one leaves at most KEEP_OUT of the subtree's
    points outside, else tilted back from ``t`` by the least angle that does (its mirror
    image of the crown then leaves the branch at twice that angle, as a fork does); among
    equally good directions the nearest to ``hint``."""
    a = cross(t, hint if hint is not None else (0.0, 0.0, 0.0))
    if np.linalg.norm(a) < 1e-9:
        a = cross(t, [1.0, 0.0, 0.0] if abs(t[0]) < 0.9 else [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    b = cross(t, a)  # the hint projected ⟂ t is ±b
    phi = np.linspace(0.0, 2.0 * np.pi, NORMAL_CANDIDATES, endpoint=False)
    around = np.cos(phi)[:, None] * b + np.sin(phi)[:, None] * a
    size = max(float(np.ptp(np.concatenate([child, subtree]), axis=0).max()), 1e-9)
    best, best_out = around[0], np.inf
    for tilt in TILTS:
        u = np.cos(tilt) * around - np.sin(tilt) * t
        ec = (child - fork) @ u.T  # (points, candidates)
        worst = ec.max(axis=0)
        if below is not None:  # the sibling: the child mirrored by each candidate
            n = np.asarray(below.normal)
            sibling = (child @ n)[:, None] - 2.0 * ec * (u @ n)[None, :] - below.offset
            worst = np.maximum(worst, sibling.max(axis=0))
        e = (subtree - fork) @ u.T
        clipped = np.where(
            worst <= worst.min() + 1e-6 * size, np.maximum(e, 0.0).mean(axis=0), np.inf
        )
        ok = clipped <= clipped.min() + 1e-9 * size
        hint_dot = u @ np.asarray(hint if hint is not None else b, dtype=float)
        k = int(np.argmax(np.where(ok, hint_dot, -np.inf)))
        out = float((e[:, k] > 1e-6 * size).mean())
        if out < best_out:
            best, best_out = u[k], out
        if out <= KEEP_OUT:
            break
    return as_vec3(best / np.linalg.norm(best))


def split_level(route: Route, i: int, s: float = 0.5) -> Route:
    """Insert a fork at fraction ``s`` (0 < s < 1) along level i's branch: the lower half
    becomes a new level i + 1 ending at the new fork, the upper half stays level i. Both
    halves lie on the old curve (their control points are their arcs' midpoints), and the
    new fork's mirror keeps the subtree it doubles on its negative side
    (:func:`free_normal`)."""
    _check_index(route, i)
    if not 0.0 < s < 1.0:
        raise SceneError(f"route.levels[{i}]", s, "a split point lies inside the branch: 0 < s < 1")
    k = route.kernel(i)
    lv = route.levels[i]
    q, mid_low, mid_up = centre_at(k, np.array([s, s / 2.0, (1.0 + s) / 2.0]))
    upper = replace(lv, control=as_vec3(mid_up))
    upper_k = replace(k, start=as_vec3(q), control=as_vec3(mid_up))
    child = centre_at(upper_k, LINE)
    subtree = subtree_points(
        [route.kernel(j) for j in range(i)] + [upper_k], [route.mirror(j) for j in range(1, i + 1)]
    )
    below = route.mirror(i + 1) if i + 1 < len(route.levels) else None
    normal = free_normal(q, tangent_at(k, s), child, subtree, lv.normal, below)
    lower = RouteLevel(as_vec3(q), as_vec3(mid_low), lv.radius, lv.color, normal, None)
    levels = route.levels[:i] + [upper, lower] + route.levels[i + 1 :]
    return replace(route, levels=levels)


def merge_level(route: Route, i: int) -> Route:
    """Remove fork P_i: level i's branch and level i − 1's become one, bent through the old
    fork (its control point is the merged arc's midpoint); level 0 (the twig) is dropped and
    level 1 becomes the twig. The inverse of :func:`split_level` (i + 1 after a split at i)."""
    _check_index(route, i)
    levels = route.levels
    if len(levels) == 1:
        raise SceneError("route.levels[0]", "<remove>", "a route needs at least one level")
    if i == 0:
        return replace(route, levels=[replace(levels[1], normal=None)] + levels[2:])
    start = route.starts()[i]
    through = ToroidalCapsule(start, levels[i].fork, levels[i - 1].fork, 1.0)
    (mid,) = centre_at(through, np.array([0.5]))
    merged = replace(
        levels[i - 1], control=as_vec3(mid), radius=levels[i].radius, color=levels[i].color
    )
    return replace(route, levels=levels[: i - 1] + [merged] + levels[i + 1 :])


def duplicate_level(route: Route, i: int) -> Route:
    """Level i once more, at its own tip: the copy takes the branch and the mirror of level
    i, translated along the branch, with the finer levels carried along; the original's fork
    takes the mirror of the fork below it (so the copy sits to it as level i to its parent)."""
    _check_index(route, i)
    levels = route.levels
    lv = levels[i]
    start = np.array(route.starts()[i])
    v = np.array(lv.fork) - start

    def moved(x: RouteLevel, grown: int | None) -> RouteLevel:
        return replace(
            x,
            fork=as_vec3(np.array(x.fork) + v),
            control=as_vec3(np.array(x.control) + v),
            grown=grown,
        )

    if i + 1 < len(levels):
        normal = levels[i + 1].normal
    else:  # the trunk: its foot has no mirror to borrow
        subtree = subtree_points(
            [route.kernel(j) for j in range(i + 1)], [route.mirror(j) for j in range(1, i + 1)]
        )  # the copy's, less v
        child = centre_at(route.kernel(i), LINE) + v
        normal = free_normal(np.array(lv.fork), v / np.linalg.norm(v), child, subtree + v, None)
    original = replace(lv, normal=normal)
    copy = moved(lv, None)
    finer_levels = [moved(x, x.grown) for x in levels[:i]]
    return replace(route, levels=finer_levels + [copy, original] + levels[i + 1 :])


def split_moves(route: Route, i: int) -> Moves:
    """Where :func:`split_level` at ``i`` puts each level's tracks: the coarser ones one up."""
    return shifted(i + 1, len(route.levels), 1)


def merge_moves(route: Route, i: int) -> Moves:
    """Where :func:`merge_level` of ``i`` puts each level's tracks: level i's go with its
    fork, the coarser ones one down."""
    return {i: [], **shifted(i + 1, len(route.levels), -1)}


def duplicate_moves(route: Route, i: int) -> Moves:
    """Where :func:`duplicate_level` of ``i`` puts each level's tracks: the original's one
    up, the copy (at i) and the finer levels carried along the branch keep their keys at
    the same offsets from their moved rest positions, the coarser levels one up."""
    v = tuple(np.subtract(route.levels[i].fork, route.starts()[i]).tolist())
    carried = {j: [(j, v)] for j in range(i)}
    return {**carried, i: [(i + 1, None), (i, v)], **shifted(i + 1, len(route.levels), 1)}


# --------------------------------------------------------------------------- whole tree
def taper(route: Route, ratio: float) -> Route:
    """Radii from the trunk's: each level ``ratio`` × its parent's."""
    lo, hi = TAPER_RANGE
    if not lo <= ratio <= hi:
        raise SceneError("taper", ratio, f"allowed: {lo:g} ≤ child / parent radius ≤ {hi:g}")
    n = len(route.levels)
    r0 = route.levels[-1].radius
    return replace(
        route,
        levels=[replace(lv, radius=r0 * ratio ** (n - 1 - i)) for i, lv in enumerate(route.levels)],
    )


def _check_factor(name: str, f: float) -> None:
    if not (np.isfinite(f) and f > 0.0):
        raise SceneError(name, f, "allowed: a factor > 0")


def scale_widths(route: Route, f: float) -> Route:
    """Every branch's radius × ``f``."""
    _check_factor("scale widths", f)
    return replace(route, levels=[replace(lv, radius=lv.radius * f) for lv in route.levels])


def _mapped(route: Route, point, plane) -> Route:
    """The route with every point mapped by ``point`` and every plane (u, w) by ``plane``."""
    levels = [
        replace(
            lv, fork=as_vec3(point(np.array(lv.fork))), control=as_vec3(point(np.array(lv.control)))
        )
        for lv in route.levels
    ]
    forest = [Mirror(m.normal, plane(m.normal, m.offset)) for m in route.forest]
    ground = route.ground
    if isinstance(ground, Plane):
        ground = replace(ground, offset=plane(ground.normal, ground.offset))
    return replace(
        route,
        base=as_vec3(point(np.array(route.base))),
        levels=levels,
        forest=forest,
        ground=ground,
    )


def scale_tree(route: Route, f: float) -> Route:
    """The whole tree × ``f`` about its foot: forks, control points, widths and the forest's
    planes (a ground plane through the foot stays where it is)."""
    _check_factor("scale tree", f)
    b = np.array(route.base)
    scaled = _mapped(
        route,
        lambda p: b + f * (p - b),
        lambda u, w: float(np.array(u) @ b + f * (w - np.array(u) @ b)),
    )
    return replace(scaled, levels=[replace(lv, radius=lv.radius * f) for lv in scaled.levels])


def move_base(route: Route, base: Vec3) -> Route:
    """The whole tree moved so that its foot is at ``base`` (the forest's planes with it)."""
    d = np.array(base, dtype=float) - np.array(route.base)
    return _mapped(route, lambda p: p + d, lambda u, w: float(w + np.array(u) @ d))
