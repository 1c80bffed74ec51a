"""Scene dataclasses of the geometry: kernels, mirrors, levels, KRS, and a toroidal capsule's arc.

Names follow [KRS17 §3]: a KRS is (K_0..K_n; R_0..R_{n-1}); level i ≥ 1 holds mirror R_{i-1}
(unit normal u, offset w: the plane u·x = w) and kernel K_i; level 0 holds K_0 only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from ..algebra.vectors import cross, dot
from ..messages import SceneError
from .schema import COLOR, Tagged, Vec3, cached_each, param, to_dict

MAX_LEVELS = 64  # kernels K_0..K_63, mirrors R_0..R_62; sized for the shader's uniform block


# ----------------------------------------------------------------------------------- kernels
class Kernel(Tagged):
    """Base of all kernel shapes; ``type`` in the file picks the subclass."""

    registry: ClassVar[dict[str, type[Kernel]]] = {}
    noun: ClassVar[str] = "kernel"


@dataclass(frozen=True)
class Empty(Kernel):
    """No geometry: a level that only reflects (e.g. the forest construction [KRS17 §9.2])."""

    kind: ClassVar[str] = "empty"


@dataclass(frozen=True)
class Sphere(Kernel):
    """Ball of ``radius`` around ``center``."""

    kind: ClassVar[str] = "sphere"
    center: Vec3 = param((0.0, 0.0, 0.0), help="centre")
    radius: float = param(1.0, lo=0.0, lo_open=True, help="radius")
    color: Vec3 | None = param(None, **COLOR)


@dataclass(frozen=True)
class Capsule(Kernel):
    """Segment a–b swept by a ball of ``radius``."""

    kind: ClassVar[str] = "capsule"
    a: Vec3 = param((0.0, 0.0, 0.0), help="first end")
    b: Vec3 = param((0.0, 1.0, 0.0), help="second end")
    radius: float = param(0.1, lo=0.0, lo_open=True, help="section radius")
    color: Vec3 | None = param(None, **COLOR)


@dataclass(frozen=True)
class ToroidalCapsule(Kernel):
    """Circular arc start → control → end swept by a ball: a torus segment with two capping
    spheres [KRS17 §9.2]. Nearly collinear points give a straight capsule."""

    kind: ClassVar[str] = "toroidal_capsule"
    start: Vec3 = param((0.0, 0.0, 0.0), help="where the arc starts (a tree branch: its fork)")
    control: Vec3 = param((0.1, 0.5, 0.0), help="point the arc passes through (sets curvature)")
    end: Vec3 = param((0.0, 1.0, 0.0), help="where the arc ends (a tree branch: the next fork)")
    radius: float = param(0.1, lo=0.0, lo_open=True, help="section radius")
    color: Vec3 | None = param(None, **COLOR)

    def validate(self, path: str) -> None:
        if math.dist(self.end, self.start) < 1e-9:
            raise SceneError(f"{path}.end", list(self.end), "must differ from start")


@dataclass(frozen=True)
class Plane(Kernel):
    """Half-space u·x ≤ offset (solid below the plane)."""

    kind: ClassVar[str] = "plane"
    normal: Vec3 = param((0.0, 1.0, 0.0), unit_vector="require", help="outward unit normal")
    offset: float = param(0.0, help="plane offset w in u·x = w")
    color: Vec3 | None = param(None, **COLOR)


def kernel_as(k: Kernel, kind: str) -> Kernel:
    """``k`` as a kernel of ``kind`` (the editor's kernel choice), keeping what carries
    over: its colour and radius, and its place: a capsule's ends a, b are a toroidal
    capsule's start and end (straight: the control point half way), a sphere sits at their
    middle and becomes an upright segment of its diameter."""
    new = Kernel.registry[kind]()
    names = set(new.__dataclass_fields__)
    ends = next(
        (
            (np.array(getattr(k, a)), np.array(getattr(k, b)))
            for a, b in (("a", "b"), ("start", "end"))
            if hasattr(k, a)
        ),
        None,
    )
    radius = getattr(k, "radius", None)
    if isinstance(k, Sphere):
        half = np.array([0.0, k.radius / 2, 0.0])
        ends, radius = (np.array(k.center) - half, np.array(k.center) + half), k.radius / 2
    keep: dict = {n: getattr(k, n) for n in ("color",) if n in names and hasattr(k, n)}
    if radius is not None and "radius" in names:
        keep["radius"] = radius
    if ends is not None:
        a, b = (tuple(float(c) for c in e) for e in ends)
        mid = tuple(float(c) for c in (ends[0] + ends[1]) / 2)
        if "a" in names:
            keep.update(a=a, b=b)
        elif "start" in names and math.dist(a, b) >= 1e-9:
            keep.update(start=a, control=mid, end=b)
        elif "center" in names:
            keep["center"] = mid
    return replace(new, **keep)


# ---------------------------------------------------------------------------------- KRS
@dataclass(frozen=True)
class Mirror:
    """Reflection plane u·x = w; points with u·x − w > 0 are folded [KRS17 Alg. 1]."""

    normal: Vec3 = param((1.0, 0.0, 0.0), unit_vector="require", help="unit normal u")
    offset: float = param(0.0, lo=-1e9, hi=1e9, help="offset w")


@dataclass(frozen=True)
class Level:
    """Expansion level i: L_i = K_i ∪ L_{i-1} ∪ R_{i-1} L_{i-1}; level 0 has no mirror."""

    kernel: Kernel = param(Empty(), help="kernel K_i added at this level")
    mirror: Mirror | None = param(None, help="mirror R_{i-1} that doubles the level below")


def check_level_count(levels: list, path: str, empty: str) -> None:
    """1..MAX_LEVELS levels (the shader's uniform block is sized for MAX_LEVELS)."""
    if not levels:
        raise SceneError(path, [], empty)
    if len(levels) > MAX_LEVELS:
        raise SceneError(
            path, f"<{len(levels)} levels>", f"too many levels; allowed: at most {MAX_LEVELS}"
        )


def check_mirror_per_level(
    levels: list, path: str, name: str, none_at_0: str, needed_above: str
) -> None:
    """A KRS's shape [KRS17 §3]: level 0 has no mirror, every level above has one (field
    ``name`` of each level)."""
    if getattr(levels[0], name) is not None:
        raise SceneError(f"{path}[0].{name}", to_dict(getattr(levels[0], name)), none_at_0)
    for i, lv in enumerate(levels[1:], 1):
        if getattr(lv, name) is None:
            raise SceneError(f"{path}[{i}].{name}", "<missing>", needed_above)


@dataclass(frozen=True)
class KRS:
    """A kernel–reflection sequence (K_0..K_n; R_0..R_{n-1}) [KRS17 §3]."""

    levels: list[Level] = param([], help="level 0 first (finest), level n last (coarsest)")

    def validate(self, path: str) -> None:
        p = f"{path}.levels"
        check_level_count(self.levels, p, "a KRS needs at least one level (level 0: a kernel)")
        check_mirror_per_level(
            self.levels,
            p,
            "mirror",
            "level 0 has no mirror (it holds only kernel K_0)",
            "every level above 0 needs a mirror {normal, offset}",
        )

    @property
    def depth(self) -> int:
        """Number of levels (the range of the viewer's levels slider and of --levels)."""
        return len(self.levels)

    @property
    def n(self) -> int:
        """Number of reflections; the expansion has up to 2^n instances of K_0."""
        return len(self.levels) - 1

    @property
    def kernels(self) -> list[Kernel]:
        return [lv.kernel for lv in self.levels]

    @property
    def mirrors(self) -> list[Mirror]:
        return [lv.mirror for lv in self.levels[1:]]  # type: ignore[misc]

    def instance_count(self) -> int:
        """Kernel instances in the expansion: K_i is doubled by R_i..R_{n-1}, so it appears
        2^(n−i) times (empty kernels excluded)."""
        return sum(
            2 ** (self.n - i) for i, k in enumerate(self.kernels) if not isinstance(k, Empty)
        )

    def truncated(self, levels: int) -> KRS:
        """Keep the coarsest ``levels`` levels (K_{n-levels+1}..K_n), dropping the finest.
        If the kernel at the cut is empty (an IFS-like KRS whose only shape is K_0), the
        nearest non-empty kernel below the cut becomes the new K_0, so something is drawn."""
        cut = len(self.levels) - levels
        keep = self.levels[cut:]
        k0 = next(
            (
                lv.kernel
                for lv in reversed(self.levels[: cut + 1])
                if not isinstance(lv.kernel, Empty)
            ),
            keep[0].kernel,
        )
        return KRS([Level(k0, None)] + list(keep[1:]))


# ------------------------------------------------------------------------------ arc geometry
STRAIGHT_RATIO = (
    200.0  # arcs with radius > 200 × chord are drawn as capsules (sagitta < chord/1600)
)


@dataclass(frozen=True)
class Arc:
    """Circular arc of a toroidal capsule: centre O, in-plane unit axes e1 (towards start) and e2,
    radius R, arc angle phi from start to end (counter-clockwise around e1 × e2)."""

    center: Vec3
    e1: Vec3
    e2: Vec3
    R: float
    phi: float


PASSES = ("start", "control", "end")  # the three points an arc passes through


def arc_of(k: ToroidalCapsule) -> Arc | None:
    """The arc through start, control, end; None when nearly straight (draw as a capsule).
    Made once per kernel (kernels are frozen)."""
    return arcs_of([k])[0]


def arcs_of(kernels: list[ToroidalCapsule]) -> list[Arc | None]:
    """:func:`arc_of` of each kernel, those not made before made together (a posed tree's
    arcs all at once: one NumPy step per operation, not one per kernel)."""
    return cached_each(kernels, "_arc", _arcs)


def _arcs(kernels: list[ToroidalCapsule]) -> list[Arc | None]:
    A, C, B = (np.array([getattr(k, p) for k in kernels], dtype=float) for p in PASSES)
    a, b = A - C, B - C
    axb = cross(a, b)
    chord = np.linalg.norm(B - A, axis=-1)
    denom = 2.0 * dot(axb, axb)
    with np.errstate(divide="ignore", invalid="ignore"):
        O = C + cross(dot(a, a)[:, None] * b - dot(b, b)[:, None] * a, axb) / denom[:, None]
        R = np.linalg.norm(A - O, axis=-1)
        N = cross(C - A, B - C)
        N /= np.linalg.norm(N, axis=-1)[:, None]
        e1 = (A - O) / R[:, None]
        e2 = cross(N, e1)
        phi = np.arctan2(dot(B - O, e2), dot(B - O, e1)) % (2 * math.pi)
    drawn = (denom > 0.0) & np.isfinite(R) & (STRAIGHT_RATIO * chord >= R)
    return [
        Arc(tuple(O[i]), tuple(e1[i]), tuple(e2[i]), float(R[i]), float(phi[i]))  # type: ignore[arg-type]
        if drawn[i]
        else None
        for i in range(len(kernels))
    ]
