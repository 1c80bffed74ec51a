"""Tree parameters → toroidal capsules and fork mirrors [KRS17 §9.2], [KRS14 §7.2].

The route from trunk base to one twig end is a list of fork points P_{n+1} (base) … P_0 (tip).
Kernel K_i is the branch P_{i+1} → P_i; mirror R_i passes through the fork P_{i+1} where
the subtree L_i starts, so L_i and its mirror image R_i L_i both grow from that fork.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..algebra.vectors import cross
from .growth import Growth, growth_of
from .model import KRS, Plane
from .route import Route, RouteLevel
from .schema import Vec3


@dataclass(frozen=True)
class Tree(Growth):
    """Growth parameters of a KRS tree; :meth:`krs` expands them into levels."""

    def krs(self) -> KRS:
        """Grow the route and expand it into KRS levels (level 0 = twig tip, level n = trunk)."""
        return self.route().krs()

    def route(self) -> Route:
        """Bake the growth parameters into a route: fork points, control points, radii,
        colours and fork mirror normals, each then editable [KRS17 §9.2]. The route keeps
        the growth parameters and each level its depth in them, to be grown again."""
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
            fork, bend, r = as_vec3(end), as_vec3(control), baked(radius)
            if i == 0:
                entries.append(RouteLevel(fork, bend, r, color, grown=n - i))
                break
            # Mirror R_{i-1} through the fork P_i = end, containing the parent direction.
            u = _rotate(s, d, math.radians(self.divergence))
            entries.append(RouteLevel(fork, bend, r, color, as_vec3(u), n - i))
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
        return Route(self.base, entries[::-1], list(self.forest), ground, growth_of(self))


BAKED_DIGITS = 15  # significant digits a grown radius keeps: no float noise in files


def as_vec3(v: np.ndarray | tuple) -> Vec3:
    """A plain tuple of Python floats (what the scene dataclasses hold)."""
    return tuple(float(c) for c in v)  # type: ignore[return-value]


def baked(x: float) -> float:
    """``x`` to BAKED_DIGITS significant digits: a radius grown as 0.14 × 0.74 × 0.74 is
    written 0.076664, not 0.07666400000000001. (A point's coordinates are sines and cosines
    summed, not decimals: they keep every digit, which the finest twigs need.)"""
    return float(f"{x:.{BAKED_DIGITS}g}")


def perpendicular(d: np.ndarray) -> np.ndarray:
    a = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    s = a - (a @ d) * d
    return s / np.linalg.norm(s)


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues rotation of v around the unit axis."""
    return (
        v * math.cos(angle)
        + cross(axis, v) * math.sin(angle)
        + axis * (axis @ v) * (1 - math.cos(angle))
    )
