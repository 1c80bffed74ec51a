"""Handles: the points of a scene a person can grab in the 3D view, each tied to the field it
edits. A route shows its base, forks, control points and fork mirror normals [KRS17 §9.2];
a plain KRS its kernels' points and its mirrors (a point on the plane and a normal arrow);
a compound its components' placements, and the forks of a component's route placed by the
component's placement (their edits go to ``compound[k].route``, in its own space). Pure NumPy:
the window draws and drags them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..scene import KRS, Capsule, Kernel, Mirror, Route, Scene, Sphere, ToroidalCapsule
from ..scene.compound import Placement
from ..scene.edits import Path, get_at
from .mokrs_handles import mokrs_handles, mokrs_outline

ARROW = 0.6  # a normal arrow's length, × its level's branch length (route) or kernel size


@dataclass(frozen=True)
class Handle:
    path: Path  # the field it edits
    kind: str  # "point": moves to where it is dragged; "normal": its arrow
    position: np.ndarray  # where it is drawn and grabbed (world, float64)
    level: int  # the outline entry (level or component) it belongs to
    label: str
    owner: Path  # the table the selection panel shows (a level, a component)
    pivot: np.ndarray | None = None  # "normal": the arrow's foot (a fork, a point on a mirror)
    placement: Placement | None = None  # a compound component's: world = placement(field's)

    @property
    def carries(self) -> bool:
        """A route's fork or trunk foot: a drag can take its subtree along."""
        return self.kind == "point" and "route" in self.path and self.path[-1] in ("fork", "base")

    @property
    def route_path(self) -> Path:
        """The route a fork, control point or normal handle belongs to."""
        return self.path[: self.path.index("route") + 1]

    def local(self, p: np.ndarray, direction: bool = False) -> np.ndarray:
        """World point (or ``direction``) ``p`` in the space of the field edited."""
        if self.placement is None:
            return np.asarray(p, dtype=np.float64)
        origin = 0.0 if direction else np.array(self.placement.position)
        return np.linalg.solve(self.placement.linear, np.asarray(p) - origin)

    def edit_to(self, scene: Scene, p: np.ndarray, carry: bool = True) -> tuple[Path, Any]:
        """The edit (field path, new value) that puts the handle at ``p``. With ``carry``, a
        route fork takes its subtree along (the finer forks and control points move with
        it, the branch's own control by half, so its bend stays) and the trunk's foot the
        whole tree: the mirrors at the moved forks move with them, so nothing that grew
        on the negative side of a mirror crosses it (a bone chain, as people expect)."""
        if carry and self.carries:
            return self._carry(scene, p)
        return self.path, self.value_at(scene, p)

    def _carry(self, scene: Scene, p: np.ndarray) -> tuple[Path, Any]:
        at = self.route_path
        route = get_at(scene, at)
        delta = self.local(p - self.position, direction=True)
        i = len(route.levels) if self.path[-1] == "base" else self.path[-2]

        def moved(v: tuple, f: float = 1.0) -> tuple:
            return tuple(float(c) for c in np.array(v) + f * delta)

        levels = [
            replace(lv, fork=moved(lv.fork), control=moved(lv.control))
            if j < i
            else replace(lv, fork=moved(lv.fork), control=moved(lv.control, 0.5))
            if j == i
            else lv
            for j, lv in enumerate(route.levels)
        ]
        if self.path[-1] == "base":
            return at, replace(route, base=moved(route.base), levels=levels)
        return (*at, "levels"), levels

    def value_at(self, scene: Scene, p: np.ndarray) -> Any:
        """The field's new value when the handle is dragged to ``p``."""
        if self.kind == "point" and self.path[-1] == "mirror":  # slides a KRS mirror
            m = get_at(scene, self.path)  # along its normal, by the drag's part along it
            return Mirror(m.normal, m.offset + float(np.array(m.normal) @ (p - self.position)))
        if self.kind == "point":
            return tuple(float(c) for c in self.local(p))
        d = self.local(p - self.pivot, direction=True)
        n = float(np.linalg.norm(d))
        u = tuple(float(c) for c in (d / n if n > 0 else d))  # zero: the schema says why
        if self.path[-1] == "mirror":  # keep the plane on the pivot
            return Mirror(u, float(np.array(u) @ self.pivot)) if n > 0 else Mirror(u, 0.0)
        return u

    def same(self, other: Handle | None) -> bool:
        return other is not None and (self.path, self.kind) == (other.path, other.kind)


def handles(scene: Scene) -> list[Handle]:
    if scene.mokrs is not None:
        return mokrs_handles(scene.mokrs, ("mokrs",))  # type: ignore[return-value]
    if scene.route is not None:
        return route_handles(scene.route, ("route",))
    if scene.krs is not None:
        return krs_handles(scene.krs, ("krs",))
    out = [
        Handle(
            ("compound", k, "position"),
            "point",
            np.array(c.position),
            k,
            f"component {k}",
            ("compound", k),
        )
        for k, c in enumerate(scene.compound)
    ]
    for k, at, route, placement in component_routes(scene):
        out += [
            replace(
                h,
                position=np.array(placement.point(h.position)),
                pivot=None if h.pivot is None else np.array(placement.point(h.pivot)),
                level=k,
                label=f"C{k} {h.label}",
                placement=placement,
            )
            for h in route_handles(route, at)
        ]
    return out


def component_routes(scene: Scene) -> list[tuple[int, Path, Route, Placement]]:
    """A compound's components given by a route: (component, the route's path, the route,
    its placement in the world)."""
    return [
        (k, ("compound", k, "route"), c.route, Placement(c.position, c.axis, c.angle, c.scale))
        for k, c in enumerate(scene.compound)
        if c.route is not None
    ]


def route_handles(route: Route, at: Path) -> list[Handle]:
    out = [
        Handle(
            (*at, "base"), "point", np.array(route.base), len(route.levels) - 1, "trunk foot", at
        )
    ]
    starts = route.starts()
    for i, lv in enumerate(route.levels):
        fork = np.array(lv.fork)
        lev = (*at, "levels", i)
        out.append(Handle((*lev, "fork"), "point", fork, i, f"fork P{i}", lev))
        out.append(Handle((*lev, "control"), "point", np.array(lv.control), i, f"control {i}", lev))
        if lv.normal is not None:
            length = ARROW * float(np.linalg.norm(fork - np.array(starts[i])))
            out.append(
                Handle(
                    (*lev, "normal"),
                    "normal",
                    fork + length * np.array(lv.normal),
                    i,
                    f"mirror normal R{i - 1} at P{i}",  # levels[i].normal, as errors say
                    lev,
                    pivot=fork,
                )
            )
    return out


def krs_handles(krs: KRS, at: Path) -> list[Handle]:
    """A kernel's points, and per mirror an arrow from the kernel's centre projected onto the
    plane (a kernel without points: the KRS's centre) with a slider half way up it. The arrows
    are as long as the kernel is big, or the KRS where the kernel is empty, so the rock's twelve
    mirrors fan out around it instead of sitting in one cluster."""
    out: list[Handle] = []
    points = [_kernel_points(lv.kernel) for lv in krs.levels]
    every = [p for _, p in sum(points, [])]
    middle = np.mean(every, axis=0) if every else np.zeros(3)
    sizes = [_size(lv.kernel, [p for _, p in pts]) for lv, pts in zip(krs.levels, points)]
    for i, (lv, pts) in enumerate(zip(krs.levels, points)):
        kp, lev = (*at, "levels", i, "kernel"), (*at, "levels", i)
        out += [Handle((*kp, f), "point", p, i, f"K{i} {f}", lev) for f, p in pts]
        if lv.mirror is None:
            continue
        u, w = np.array(lv.mirror.normal), lv.mirror.offset
        centre = np.mean([p for _, p in pts], axis=0) if pts else middle
        foot = centre - (u @ centre - w) * u  # the centre, projected onto the plane
        length = ARROW * (sizes[i] if pts else max(sizes))
        mp = (*at, "levels", i, "mirror")
        slider = foot + 0.5 * length * u
        out.append(Handle(mp, "point", slider, i, f"mirror R{i - 1} offset", lev))
        tip = foot + length * u
        out.append(Handle(mp, "normal", tip, i, f"mirror R{i - 1} normal", lev, pivot=foot))
    return out


def _kernel_points(k: Kernel) -> list[tuple[str, np.ndarray]]:
    """A kernel's points a person can grab, by field name (none for empty and plane kernels)."""
    names = {
        Sphere: ("center",),
        Capsule: ("a", "b"),
        ToroidalCapsule: ("start", "control", "end"),
    }.get(type(k), ())
    return [(f, np.array(getattr(k, f))) for f in names]


def _size(k: Kernel, pts: list[np.ndarray]) -> float:
    """A kernel's size, for the length of its mirror's arrow."""
    return max(
        float(getattr(k, "radius", 0.0)) * 4.0,
        float(np.ptp(np.array(pts), axis=0).max()) if len(pts) > 1 else 0.0,
        0.25,
    )


def outline(scene: Scene) -> list[str]:
    """One line per selectable entry, in handle ``level`` order."""
    if scene.mokrs is not None:
        return mokrs_outline(scene.mokrs)
    if scene.route is not None:
        return route_outline(scene.route)
    if scene.krs is not None:
        return [f"L{i} {lv.kernel.kind}" for i, lv in enumerate(scene.krs.levels)]
    return [
        f"component {k}: {'tree' if c.tree else 'route' if c.route else 'KRS'}"
        for k, c in enumerate(scene.compound)
    ]


def route_outline(route: Route) -> list[str]:
    """A route's levels by name, twig first."""
    n = len(route.levels)
    return [
        f"L{i} " + ("trunk" if i == n - 1 else "twig" if i == 0 else "branch") for i in range(n)
    ]


def polyline(scene: Scene) -> np.ndarray:
    """The route from the trunk's foot to the twig tip (empty for other scenes)."""
    if scene.route is None:
        return np.zeros((0, 3))
    return _line(scene.route)


def polylines(scene: Scene) -> list[np.ndarray]:
    """The route's polyline, or each compound component's route's placed in the world."""
    if scene.route is not None:
        return [_line(scene.route)]
    return [
        np.array([placement.point(p) for p in _line(route)])
        for _, _, route, placement in component_routes(scene)
    ]


def _line(route: Route) -> np.ndarray:
    return np.array([route.base] + [lv.fork for lv in route.levels][::-1])


def level_handle(handles: list[Handle], level: int) -> Handle | None:
    """A level's first handle, the level's own before the route's (the trunk's fork before
    the trunk foot), so the panel shows the level's fields; None: the level has none."""
    at = [h for h in handles if h.level == level]
    own = [h for h in at if h.owner and h.owner[-1] == level]
    return (own or at or [None])[0]
