"""Tree parameters → toroidal capsules and fork mirrors [KRS17 §9.2], [KRS14 §7.2].

The route from trunk base to one twig end is a list of fork points P_{n+1} (base) … P_0 (tip).
Kernel K_i is the branch P_{i+1} → P_i; mirror R_i passes through the fork P_{i+1} where
the subtree L_i starts, so L_i and its mirror image R_i L_i both grow from that fork.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .model import _COLOR, KRS, Mirror, Plane
from .route import Route, RouteLevel
from .schema import SceneError, Vec3, param


@dataclass(frozen=True)
class Tree:
    """Growth parameters of a KRS tree; :meth:`krs` expands them into levels."""

    levels: int = param(20, lo=1, hi=63, help="forks from trunk to twig (2^levels twigs)")
    base: Vec3 = param((0.0, 0.0, 0.0), help="foot of the trunk")
    up: Vec3 = param((0.0, 1.0, 0.0), unit_vector="normalise", help="trunk direction")
    trunk_length: float = param(1.5, lo=0.0, lo_open=True, help="length of the trunk")
    trunk_radius: float = param(0.12, lo=0.0, lo_open=True, help="section radius of the trunk")
    length_ratio: float = param(0.8, lo=0.05, hi=1.0, help="child / parent branch length")
    radius_ratio: float = param(0.72, lo=0.05, hi=1.0, help="child / parent branch radius")
    branch_angle: float = param(
        32.0, lo=0.0, hi=89.0, unit="degrees", help="angle between a branch and each child"
    )
    divergence: float = param(
        90.0,
        lo=0.0,
        hi=180.0,
        unit="degrees",
        help="turn of successive fork planes around the branch",
    )
    bend: float = param(0.08, lo=-0.5, hi=0.5, help="upward bow of a branch, × its length")
    bark: Vec3 = param((0.30, 0.20, 0.12), **_COLOR)
    leaf: Vec3 = param((0.20, 0.45, 0.10), **_COLOR)
    leaf_levels: int = param(5, lo=0, hi=63, help="finest levels coloured as leaves")
    forest: list[Mirror] = param(
        [],
        help="extra reflections above the trunk, with empty "
        "kernels: 2^k trees from one [KRS17 §9.2]",
    )
    ground: Vec3 | None = param(
        None,
        lo=0.0,
        hi=1.0,
        help="colour of a ground plane through the base (kernel of the last forest level)",
    )

    def validate(self, path: str) -> None:
        if self.levels + 1 + len(self.forest) > 64:
            raise SceneError(
                f"{path}.forest",
                f"<{len(self.forest)} mirrors>",
                f"levels + 1 + forest mirrors must be ≤ 64; allowed: at most "
                f"{63 - self.levels} forest mirrors with {self.levels} levels",
            )
        if self.ground is not None and not self.forest:
            raise SceneError(
                f"{path}.ground",
                list(self.ground),
                "the ground is the kernel of the last forest level: add at least one forest mirror",
            )

    def krs(self) -> KRS:
        """Grow the route and expand it into KRS levels (level 0 = twig tip, level n = trunk)."""
        return self.route().krs()

    def route(self) -> Route:
        """Bake the growth parameters into a route: fork points, control points, radii,
        colours and fork mirror normals, each then editable [KRS17 §9.2]."""
        n = self.levels
        theta = math.radians(self.branch_angle)
        up = np.array(self.up)
        d = up.copy()  # branch direction d_i
        s = perpendicular(d)  # in-plane side vector, ⟂ d
        P = np.array(self.base, dtype=float)  # fork P_{i+1}: where K_i starts
        length, radius = self.trunk_length, self.trunk_radius
        entries: list[RouteLevel] = []
        for i in range(n, -1, -1):
            end = P + length * d
            side = up - (up @ d) * d
            side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-6 else np.zeros(3)
            control = P + 0.5 * length * d + self.bend * length * side
            color = self.leaf if i < self.leaf_levels else self.bark
            if i == 0:
                entries.append(RouteLevel(as_vec3(end), as_vec3(control), radius, color))
                break
            # Mirror R_{i-1} through the fork P_i = end, containing the parent direction.
            u = _rotate(s, d, math.radians(self.divergence))
            entries.append(RouteLevel(as_vec3(end), as_vec3(control), radius, color, as_vec3(u)))
            d_child = math.cos(theta) * d - math.sin(theta) * u  # child on the negative side
            s = math.sin(theta) * d + math.cos(theta) * u
            d, P = d_child / np.linalg.norm(d_child), end
            length *= self.length_ratio
            radius *= self.radius_ratio
        ground = (
            Plane(as_vec3(up), float(up @ np.array(self.base)), self.ground)
            if self.ground is not None
            else None
        )
        return Route(self.base, entries[::-1], list(self.forest), ground)


def as_vec3(v: np.ndarray | tuple) -> Vec3:
    """A plain tuple of Python floats (what the scene dataclasses hold)."""
    return tuple(float(c) for c in v)  # type: ignore[return-value]


def perpendicular(d: np.ndarray) -> np.ndarray:
    a = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    s = a - (a @ d) * d
    return s / np.linalg.norm(s)


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues rotation of v around the unit axis."""
    return (
        v * math.cos(angle)
        + np.cross(axis, v) * math.sin(angle)
        + axis * (axis @ v) * (1 - math.cos(angle))
    )
