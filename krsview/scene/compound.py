"""A compound: the union of up to 8 KRSs, each placed in the world [KRS17 §5.1].

Where one KRS shows its symmetry (two trees that are mirror images of each other), a few
different KRSs side by side hide it. Each component is an explicit KRS or a tree, moved by a
rotation, a uniform scale and a translation; the move is applied to its kernels and mirrors
once, so the tracer sees plain KRSs in world space and keeps one free distance per component.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property
from typing import ClassVar

import numpy as np

from ..messages import SceneError
from .model import (
    KRS,
    MAX_LEVELS,
    Capsule,
    Empty,
    Kernel,
    Level,
    Mirror,
    Plane,
    Sphere,
    ToroidalCapsule,
)
from .route import Route
from .schema import Vec3, cached, param
from .tree import Tree, as_vec3

MAX_COMPONENTS = 8  # [KRS17 §8.3]: "compound of eight KRSs"
COMPOUND_SLOTS = MAX_COMPONENTS * MAX_LEVELS  # kernel slots of the compound uniform block


@dataclass(frozen=True)
class Placement:
    """x ↦ scale · R(axis, angle) x + position: a similarity, so distances scale by ``scale``
    and a distance bound stays a bound."""

    position: Vec3
    axis: Vec3
    angle: float  # degrees
    scale: float

    @cached_property
    def linear(self) -> np.ndarray:
        """scale · R, by Rodrigues' formula."""
        k = np.array(self.axis, dtype=float)
        a = math.radians(self.angle)
        K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
        return self.scale * (np.eye(3) + math.sin(a) * K + (1 - math.cos(a)) * K @ K)

    def point(self, p: Vec3) -> Vec3:
        return as_vec3(self.linear @ np.array(p) + np.array(self.position))

    def plane(self, u: Vec3, w: float) -> tuple[Vec3, float]:
        """The plane u·x = w moved: normal R u (still unit), offset scale·w + R u · position."""
        ru = self.linear @ np.array(u) / self.scale
        return as_vec3(ru / np.linalg.norm(ru)), float(
            self.scale * w + ru @ np.array(self.position)
        )

    def kernel(self, k: Kernel) -> Kernel:
        s = self.scale
        if isinstance(k, Sphere):
            return replace(k, center=self.point(k.center), radius=s * k.radius)
        if isinstance(k, Capsule):
            return replace(k, a=self.point(k.a), b=self.point(k.b), radius=s * k.radius)
        if isinstance(k, ToroidalCapsule):
            return replace(
                k,
                start=self.point(k.start),
                control=self.point(k.control),
                end=self.point(k.end),
                radius=s * k.radius,
            )
        if isinstance(k, Plane):
            u, w = self.plane(k.normal, k.offset)
            return replace(k, normal=u, offset=w)
        assert isinstance(k, Empty), k
        return k

    def krs(self, krs: KRS) -> KRS:
        return KRS(
            [
                Level(
                    self.kernel(lv.kernel),
                    None
                    if lv.mirror is None
                    else Mirror(*self.plane(lv.mirror.normal, lv.mirror.offset)),
                )
                for lv in krs.levels
            ]
        )


@dataclass(frozen=True)
class Component:
    """One member of a ``[[compound]]`` list: a KRS or a tree, rotated by ``angle`` about
    ``axis``, scaled, then moved to ``position``."""

    UNKNOWN_FIELDS: ClassVar[dict[str, str]] = {
        "mokrs": "a MöKRS cannot join a compound: it has no distance function, and the "
        "compound's tracer steps by each component's distance [KRS17 §5.1]"
    }
    krs: KRS | None = param(None, help="explicit kernel–reflection sequence")
    tree: Tree | None = param(None, help="tree growth parameters (instead of krs)")
    route: Route | None = param(None, help="a tree given by its route (instead of krs)")
    position: Vec3 = param((0.0, 0.0, 0.0), help="where the component's origin goes")
    axis: Vec3 = param((0.0, 1.0, 0.0), unit_vector="normalise", help="rotation axis")
    angle: float = param(
        0.0,
        lo=-360.0,
        hi=360.0,
        unit="degrees",
        help="rotation about axis, applied before the move",
    )
    scale: float = param(1.0, lo=1e-3, hi=1e3, help="uniform scale, applied before the move")

    def validate(self, path: str) -> None:
        given = [k for k in ("krs", "tree", "route") if getattr(self, k) is not None]
        if len(given) != 1:
            raise SceneError(
                f"{path}.krs / {path}.tree / {path}.route",
                "<" + (" and ".join(given) or "none") + ">",
                "a compound component has exactly one geometry: a krs, tree or "
                "route table (a MöKRS cannot join a compound: it has no distance)",
            )

    def placed(self) -> KRS:
        """The component's KRS in world space, made once per component (a drag's edit keeps
        the unchanged ones, whose trees would be grown again every frame)."""
        return cached(self, "_placed", self._place)

    def _place(self) -> KRS:
        source = self.tree or self.route
        krs = source.krs() if source is not None else self.krs
        assert krs is not None
        return Placement(self.position, self.axis, self.angle, self.scale).krs(krs)


def check_compound(components: list[Component], path: str = "compound") -> None:
    if len(components) > MAX_COMPONENTS:
        raise SceneError(
            path,
            f"<{len(components)} components>",
            f"allowed: at most {MAX_COMPONENTS} components [KRS17 §5.1]",
        )


@dataclass(frozen=True)
class Compound:
    """The drawn geometry of a compound scene: its components' KRSs in world space. Offers
    what a KRS offers to the viewer, the CLI and the benchmarks."""

    parts: tuple[KRS, ...]

    @property
    def depth(self) -> int:
        """Levels of the deepest component (the range of the levels slider and --levels)."""
        return max(p.depth for p in self.parts)

    @property
    def kernels(self) -> list[Kernel]:
        return [k for p in self.parts for k in p.kernels]

    def instance_count(self) -> int:
        return sum(p.instance_count() for p in self.parts)

    def truncated(self, levels: int) -> Compound:
        """Each component keeps its coarsest ``levels`` levels (all, if it has fewer)."""
        return Compound(tuple(p.truncated(min(levels, p.depth)) for p in self.parts))
