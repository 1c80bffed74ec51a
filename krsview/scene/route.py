"""A tree given by its route [KRS17 §9.2]: the modelling parameters an editor moves.

"Forking positions along one route from the trunk to a twig end must be given. Branches along
this route are the kernels. Then, a control point on every such branch can be moved to set
curvature. […] Branch width gives the section radius. Planes of reflection must be placed at
forking positions, with editable normals."

Entry i of ``levels`` (0: the twig, last: the trunk) is kernel K_i, the branch from the fork
below it (entry i + 1's ``fork``, or ``base`` for the trunk) to its own ``fork`` P_i, bent
through ``control``. For i ≥ 1 the entry's ``normal`` is mirror R_{i−1}; its offset follows
from the fork it must pass through (w = u·P_i), so L_{i−1} and its mirror image both grow
from P_i. A growth ``[tree]`` bakes into a route (:meth:`Tree.route`) that expands into
exactly the same KRS.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..messages import SceneError
from .growth import Growth
from .model import (
    KRS,
    MAX_LEVELS,
    Empty,
    Kernel,
    Level,
    Mirror,
    ToroidalCapsule,
    arc_of,
    arcs_of,
    check_mirror_per_level,
)
from .schema import COLOR, Vec3, cached, param

FORK_SEPARATION = 1e-9  # forks closer than this × the route's size are "on top of each other"
CLIP_TOLERANCE = 0.5  # × a child's radius: a shallower crossing stays inside the fork joint
ARC_SAMPLES = 17  # points along a branch checked against its fork's mirror


@dataclass(frozen=True)
class RouteLevel:
    """One fork of the route and the branch that ends there."""

    fork: Vec3 = param(
        (0.0, 1.0, 0.0), help="fork point P_i where this branch ends (the twig tip for level 0)"
    )
    control: Vec3 = param(
        (0.0, 0.5, 0.0),
        help="point the branch's arc passes through (on the chord: a straight branch)",
    )
    radius: float = param(0.05, lo=0.0, lo_open=True, hi=1e6, help="branch section radius")
    color: Vec3 | None = param(None, **COLOR)
    normal: Vec3 | None = param(
        None,
        unit_vector="normalise",
        help="normal of the mirror through this fork (not on level 0)",
    )
    grown: int | None = param(
        None,
        lo=0,
        hi=MAX_LEVELS,
        help="depth (0: the trunk) of the level of [route.growth] this one was baked as; "
        "none for a level made by hand",
    )


@dataclass(frozen=True)
class Route:
    """Fork points, control points, widths and fork mirrors from twig to trunk."""

    base: Vec3 = param((0.0, 0.0, 0.0), help="foot of the trunk (where the last level starts)")
    levels: list[RouteLevel] = param([], help="level 0 (the twig) first, the trunk last")
    forest: list[Mirror] = param(
        [],
        help="extra reflections above the trunk, with empty "
        "kernels: 2^k trees from one [KRS17 §9.2]",
    )
    ground: Kernel | None = param(None, help="kernel of the last forest level: a ground plane, say")
    growth: Growth | None = param(
        None, help="the growth parameters this route was baked from: re-bake grows it again"
    )

    def validate(self, path: str) -> None:
        p = f"{path}.levels"
        if not self.levels:
            raise SceneError(p, [], "a route needs at least one level (the trunk)")
        if len(self.levels) + len(self.forest) > MAX_LEVELS:
            raise SceneError(
                p,
                f"<{len(self.levels)} levels, {len(self.forest)} forest>",
                f"levels + forest mirrors must be ≤ {MAX_LEVELS}",
            )
        check_mirror_per_level(
            self.levels,
            p,
            "normal",
            "level 0 is the twig: no mirror forks there; remove the normal",
            "every level above 0 needs the normal of its fork's mirror",
        )
        forks = np.array([self.base] + [lv.fork for lv in self.levels])
        size = max(float(np.ptp(forks, axis=0).max()), 1.0)
        for i, (start, lv) in enumerate(zip(self.starts(), self.levels)):
            if np.linalg.norm(np.subtract(lv.fork, start)) <= FORK_SEPARATION * size:
                below = f"{path}.base" if i == len(self.levels) - 1 else f"{p}[{i + 1}].fork"
                raise SceneError(
                    f"{p}[{i}].fork",
                    list(lv.fork),
                    f"must differ from {below} (a branch needs a length)",
                )
        if self.ground is not None and not self.forest:
            raise SceneError(
                f"{path}.ground",
                "<kernel>",
                "the ground is the kernel of the last forest level: add at least one forest mirror",
            )
        self._check_grown(p)

    def _check_grown(self, p: str) -> None:
        """Each ``grown`` depth names one level of the growth parameters, at most once."""
        seen: set[int] = set()
        for i, lv in enumerate(self.levels):
            if lv.grown is None:
                continue
            if self.growth is None:
                raise SceneError(
                    f"{p}[{i}].grown",
                    lv.grown,
                    "names a level of [route.growth], which this route does not have; remove it",
                )
            if lv.grown > self.growth.levels or lv.grown in seen:
                raise SceneError(
                    f"{p}[{i}].grown",
                    lv.grown,
                    f"allowed: a depth 0..{self.growth.levels} of [route.growth] "
                    "that no other level names",
                )
            seen.add(lv.grown)

    def starts(self) -> list[Vec3]:
        """Where each level's branch starts: the fork of the level above, the base for the trunk."""
        return [lv.fork for lv in self.levels[1:]] + [self.base]

    def mirror(self, i: int) -> Mirror:
        """Mirror R_{i−1} of level i ≥ 1: through the fork P_i, normal u, offset w = u·P_i."""
        lv = self.levels[i]
        u = np.array(lv.normal)
        return Mirror(lv.normal, float(u @ np.array(lv.fork)))  # type: ignore[arg-type]

    def kernel(self, i: int) -> ToroidalCapsule:
        return self.kernels()[i]

    def kernels(self) -> tuple[ToroidalCapsule, ...]:
        """Each level's branch, from its start through its control point to its fork; made
        once per route (frozen), their arcs together (the route's checks, its clipping and
        its KRS ask for them level by level)."""

        def make():
            starts = self.starts()
            out = tuple(
                ToroidalCapsule(start, lv.control, lv.fork, lv.radius, lv.color)
                for start, lv in zip(starts, self.levels)
            )
            arcs_of(list(out))
            return out

        return cached(self, "_kernels", make)

    def krs(self) -> KRS:
        """Level i: kernel K_i (the branch ending at P_i) and, for i ≥ 1, mirror R_{i−1}."""
        levels = [Level(self.kernel(0), None)]
        levels += [Level(self.kernel(i), self.mirror(i)) for i in range(1, len(self.levels))]
        for k, m in enumerate(self.forest):
            last = k == len(self.forest) - 1
            levels.append(Level(self.ground if last and self.ground is not None else Empty(), m))
        return KRS(levels)

    def sibling(self, i: int, samples: int = ARC_SAMPLES) -> np.ndarray:
        """Points along level i − 1's branch mirrored by R_{i−1} (through fork P_i): the
        centre line of its sibling, the other branch growing from that fork; i ≥ 1."""
        m = self.mirror(i)
        n = np.array(m.normal)
        points = arc_points(self.kernel(i - 1), samples)
        return points - 2.0 * (points @ n - m.offset)[:, None] * n

    def warnings(self) -> list[str]:
        """Where Alg. 1 clips the route: a child branch reaching across the mirror of the
        fork it grows from is cut off there (DISTANCE folds every point into the mirror's
        negative side [KRS14 Fig. 2]), so the drawn tree loses that part; and so is its
        sibling (its mirror image) where it reaches across the mirror of the fork below
        (a fork inserted mid-branch can leave a stub of it, cut square)."""
        out = []
        for i in range(1, len(self.levels)):
            m = self.mirror(i)
            child = self.kernel(i - 1)
            e = arc_points(child) @ np.array(m.normal) - m.offset
            worst = float(e.max())
            if worst > CLIP_TOLERANCE * child.radius:
                out.append(
                    f"{level_name(i - 1)}: the branch crosses mirror R{i - 1} at fork P{i}, where "
                    f"it grows from (levels[{i}].normal), by {worst:.3g}; Alg. 1 clips it there "
                    "— turn the normal or move the branch to the mirror's negative side"
                )
            if i + 1 < len(self.levels):
                up = self.mirror(i + 1)
                worst = float((self.sibling(i) @ np.array(up.normal)).max() - up.offset)
                if worst > CLIP_TOLERANCE * child.radius:
                    out.append(
                        f"{level_name(i - 1)}: its mirror image in R{i - 1} at fork P{i} (the "
                        f"sibling branch) crosses mirror R{i} at fork P{i + 1} by "
                        f"{worst:.3g}; Alg. 1 cuts it off there, leaving a stub — turn "
                        f"R{i - 1} (levels[{i}].normal)"
                    )
        return out


def level_name(k: int) -> str:
    """Level k as the editor names it (L0 the twig), with its path in the file: the names
    the editor's outline and handles use (fork Pk, mirror normal R(k−1) of levels[k])."""
    return f"levels[{k}] (L{k})"


def arc_points(k: ToroidalCapsule, samples: int = ARC_SAMPLES) -> np.ndarray:
    """Points along a branch's centre line, start to end (the arc, or the chord if straight)."""
    return centre_at(k, np.linspace(0.0, 1.0, samples))


def centre_at(k: ToroidalCapsule, s: np.ndarray) -> np.ndarray:
    """Points of a branch's centre line at fractions ``s`` of its length (0: start, 1: end):
    on the arc through start, control and end, or on the chord where that is straight."""
    s = np.asarray(s, dtype=float)[:, None]
    a = arc_of(k)
    if a is None:
        return np.array(k.start) + s * (np.array(k.end) - np.array(k.start))
    ang = s * a.phi
    return np.array(a.center) + a.R * (np.cos(ang) * np.array(a.e1) + np.sin(ang) * np.array(a.e2))
