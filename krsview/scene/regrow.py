"""Growing a baked route again from its growth parameters, keeping what was changed by hand
(as SpeedTree keeps hand edits over its generators).

A baked route keeps the growth parameters it came from (``route.growth``) and each level the
depth of the grown level it was baked as (``grown``, 0: the trunk). A level's edit is its
difference from that grown level: the branch vector and control point relative to the fork
below, in the branch's own frame and in units of its length, the radius as a ratio, the
mirror normal in the branch's frame, and a colour of its own. Re-growing with new parameters
bakes them and puts each edit back on the level of the same depth, so a branch bent by hand
stays bent after the branch angle changes. What cannot come back (a fork inserted by hand, a
removed one, a depth the new parameters no longer grow) is listed, for the editor to ask.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..algebra.vectors import cross
from ..messages import SceneError
from .growth import Growth, growth_of
from .route import Route, RouteLevel, level_name
from .schema import Vec3
from .tree import Tree, as_vec3, perpendicular

SAME = 1e-9  # an edit smaller than this (relative) is no edit


@dataclass(frozen=True)
class LevelEdit:
    """One level's difference from its grown level (see the module's docstring)."""

    branch: np.ndarray  # local, ÷ the branch's length
    control: np.ndarray  # local, ÷ the branch's length
    radius: float  # ratio
    normal: np.ndarray | None  # local unit vector; None: the grown one
    color: Vec3 | None  # the level's own colour, where it differs

    def shape_changed(self, baked_normal: np.ndarray | None) -> bool:
        moved = max(np.abs(self.branch).max(), np.abs(self.control).max()) > SAME
        turned = self.normal is not None and baked_normal is not None
        turned = turned and float(np.abs(self.normal - baked_normal).max()) > SAME
        return moved or turned or abs(self.radius - 1.0) > SAME or self.color is not None


def grow(growth: Growth) -> Route:
    """The route the growth parameters bake into."""
    return Tree(**{f.name: getattr(growth, f.name) for f in fields(Growth)}).route()


def frame(route: Route, k: int) -> np.ndarray:
    """Columns: level k's branch direction, its mirror normal (else its parent's, else any)
    made ⟂ to it, and their cross product."""
    d = np.subtract(route.levels[k].fork, route.starts()[k])
    d = d / np.linalg.norm(d)
    normals = [route.levels[j].normal for j in (k, k + 1) if j < len(route.levels)]
    for n in [*normals, perpendicular(d)]:
        if n is None:
            continue
        a = np.asarray(n, dtype=float) - (np.asarray(n) @ d) * d
        if np.linalg.norm(a) > 1e-6:
            a = a / np.linalg.norm(a)
            break
    return np.column_stack([d, a, cross(d, a)])


def level_edit(route: Route, k: int, baked: Route, shape: bool) -> LevelEdit:
    """Level k's edit against the baked level of the same depth; ``shape``: its fork below
    is that of the grown level below (else its branch and control are not comparable)."""
    lv = route.levels[k]
    b = len(baked.levels) - 1 - lv.grown
    blv = baked.levels[b]
    F = frame(baked, b)
    start, bstart = np.array(route.starts()[k]), np.array(baked.starts()[b])
    length = float(np.linalg.norm(np.subtract(blv.fork, bstart)))
    zero = np.zeros(3)

    def local(cur, base) -> np.ndarray:
        return F.T @ ((np.subtract(cur, start) - np.subtract(base, bstart)) / length)

    same = lv.normal is None or lv.normal == blv.normal
    normal = None if same else F.T @ np.array(lv.normal)
    return LevelEdit(
        local(lv.fork, blv.fork) if shape else zero,
        local(lv.control, blv.control) if shape else zero,
        lv.radius / blv.radius,
        normal,
        lv.color if lv.color != blv.color else None,
    )


def rebake(route: Route, growth: Growth) -> tuple[Route, list[str]]:
    """The route grown from ``growth`` with this route's edits put back, and what could not
    be kept (one line each; empty: nothing is lost)."""
    if route.growth is None:
        raise SceneError("route.growth", "<none>", "this route was not baked from a tree")
    old, new = grow(route.growth), grow(growth)
    edits, lost = _edits(route, old, growth.levels)
    present = {lv.grown for lv in route.levels}
    for g in range(min(len(old.levels), len(new.levels))):
        if g not in present:
            lost.append(f"the fork grown at depth {g} was removed by hand: it grows again")
    disp = np.subtract(route.base, old.base)  # how far the fork below has moved
    levels: list[RouteLevel] = []
    n = len(new.levels)
    for g in range(n):
        k = n - 1 - g
        blv, F = new.levels[k], frame(new, k)
        length = float(np.linalg.norm(np.subtract(blv.fork, new.starts()[k])))
        e = edits.get(g)
        if e is None:
            lv = blv
        else:
            normal = blv.normal
            if normal is not None and e.normal is not None:
                u = F @ e.normal
                normal = tuple(float(c) for c in u / np.linalg.norm(u))
            lv = RouteLevel(
                as_vec3(np.array(blv.fork) + F @ e.branch * length),
                as_vec3(np.array(blv.control) + F @ e.control * length),
                blv.radius * e.radius,
                e.color if e.color is not None else blv.color,
                normal,  # type: ignore[arg-type]
                g,
            )
        fork_moved = np.subtract(lv.fork, blv.fork)
        lv = RouteLevel(
            as_vec3(np.array(lv.fork) + disp),
            as_vec3(np.array(lv.control) + disp),
            lv.radius,
            lv.color,
            lv.normal,
            g,
        )
        disp = disp + fork_moved
        levels.append(lv)
    forest = route.forest if route.forest != old.forest else new.forest
    ground = route.ground if route.ground != old.ground else new.ground
    base = as_vec3(np.array(new.base) + np.subtract(route.base, old.base))
    return Route(base, levels[::-1], forest, ground, growth_of(growth)), lost


def _edits(route: Route, old: Route, depth: int) -> tuple[dict[int, LevelEdit], list[str]]:
    """Each grown level's edit, by depth, and the lines saying what will not be kept."""
    edits: dict[int, LevelEdit] = {}
    lost: list[str] = []
    n = len(route.levels)
    for k, lv in enumerate(route.levels):
        if lv.grown is None:
            lost.append(f"{level_name(k)}: a fork made by hand (inserted or duplicated) is dropped")
            continue
        below = route.levels[k + 1].grown if k + 1 < n else -1
        shape = below == lv.grown - 1
        e = level_edit(route, k, old, shape)
        baked = old.levels[len(old.levels) - 1 - lv.grown].normal
        bn = None if baked is None else frame(old, len(old.levels) - 1 - lv.grown).T @ baked
        if lv.grown > depth:
            if e.shape_changed(bn):
                lost.append(
                    f"{level_name(k)}: its edits are dropped (the tree now has {depth} forks)"
                )
            continue
        if not shape and level_edit(route, k, old, True).shape_changed(bn):
            lost.append(
                f"{level_name(k)}: its branch goes back to the grown shape (a fork next to it "
                "was added or removed by hand)"
            )
        edits[lv.grown] = e
    return edits, lost
