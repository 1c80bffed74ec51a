"""Möbius kernel–reflection sequences [KRS17 §7]: each level is conformally transformed.

Level i holds a kernel K_i, a Möbius transformation G_i (a list of elementary steps from
[KRS17 Table 1]) and whether it reflects. What is drawn is

    L_i = G_i(S_i ∪ R(S_i)),  S_i = K_i ∪ L_{i−1}   (without reflection: L_i = G_i(S_i)),

R the reflection across x = 0 of the level's own space: a reflecting level doubles its own
kernel too. §7's formula writes G_i(K_i ∪ L_{i−1} ∪ R(L_{i−1})), K_i unreflected, but
[KRS17 Alg. 3] — and the tracer here, its twin — makes the level's mirror decision on the
point first and tests k_i after it, which sees K_i on both sides of x = 0. Drawing §7's set
exactly would cost a second kernel test per level; a kernel that is its own mirror image
across x = 0 is drawn the same either way. Kernels are written in
their level's space; G_i maps that space into level i+1's (the last level's G into the world).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import ClassVar

import numpy as np

from ..algebra import mobius
from ..algebra.vectors import cross
from ..messages import SceneError
from .model import Empty, Kernel, Plane, Sphere, check_level_count
from .schema import Tagged, Vec3, cached, cached_each, param

SINGULAR_CONDITION = 1e12  # a composed transformation this ill-conditioned is rejected


def composed(*Hs: np.ndarray) -> np.ndarray:
    """H_1 · H_2 · … as ``mobius.compose``, by products of the real 8×8 forms (one matrix
    product each instead of eight quaternion products)."""
    R = mobius.real_matrix(Hs[0])
    for H in Hs[1:]:
        R = R @ mobius.real_matrix(H)
    return from_real(R)


def from_real(R: np.ndarray) -> np.ndarray:
    """The quaternion matrix of a real 8×8 one (``mobius.real_matrix``'s inverse): each
    block's first column, as ``mobius.inverse`` reads it."""
    return np.array([[R[4 * r : 4 * r + 4, 4 * k] for k in range(2)] for r in range(2)])


class MobiusStep(Tagged):
    """One elementary transformation; ``type`` picks it. Steps apply in the order listed."""

    registry: ClassVar[dict[str, type[MobiusStep]]] = {}
    noun: ClassVar[str] = "Möbius step"

    def matrix(self):
        """The step as a quaternion matrix (read-only, made once)."""
        return cached(self, "_matrix", self.make_matrix)

    def make_matrix(self):
        raise NotImplementedError


@dataclass(frozen=True)
class Translate(MobiusStep):
    """q ↦ q + by."""

    kind: ClassVar[str] = "translate"
    by: Vec3 = param((0.0, 0.0, 0.0), help="translation vector")

    def make_matrix(self):
        return mobius.translation(self.by)


@dataclass(frozen=True)
class Scale(MobiusStep):
    """Dilation q ↦ s q about the origin."""

    kind: ClassVar[str] = "scale"
    factor: float = param(1.0, lo=1e-6, hi=1e6, help="dilation factor s")

    def make_matrix(self):
        return mobius.dilation(self.factor)


@dataclass(frozen=True)
class Rotate(MobiusStep):
    """Rotation q ↦ r q r⁻¹ about an axis through the origin."""

    kind: ClassVar[str] = "rotate"
    axis: Vec3 = param((0.0, 1.0, 0.0), unit_vector="normalise", help="rotation axis")
    degrees: float = param(0.0, lo=-360.0, hi=360.0, unit="degrees", help="angle (right hand)")

    def make_matrix(self):
        return mobius.rotation(self.axis, math.radians(self.degrees))


@dataclass(frozen=True)
class Invert(MobiusStep):
    """q ↦ c + r²(q − c)⁻¹: inversion in the sphere (c, r) composed with the point reflection
    through c (Table 1's q ↦ q⁻¹, moved and scaled). c itself goes to infinity."""

    kind: ClassVar[str] = "invert"
    center: Vec3 = param((0.0, 0.0, 0.0), help="centre c (mapped to infinity)")
    radius: float = param(1.0, lo=1e-6, hi=1e6, help="radius r of the fixed sphere")

    def make_matrix(self):
        M = mobius
        neg = tuple(-v for v in self.center)
        return composed(
            M.translation(self.center),
            M.dilation(self.radius),
            M.inversion(),
            M.dilation(1.0 / self.radius),
            M.translation(neg),
        )


@dataclass(frozen=True)
class MobiusLevel:
    """Level i: kernel K_i in this level's space, transform G_i out of it, reflection R."""

    kernel: Kernel = param(Empty(), help="kernel K_i, in this level's space")
    transform: list[MobiusStep] = param(
        [], help="G_i: steps applied in order, into the next level's space (world for the last)"
    )
    reflect: bool = param(
        True, help="double this level's kernel and the levels below by the reflection across x = 0"
    )

    def matrix(self):
        """G_i as a quaternion matrix: the last step applied last (leftmost); made once."""

        def make():
            return composed(mobius.identity(), *[s.matrix() for s in reversed(self.transform)])

        return cached(self, "_matrix", make)

    def inverse(self):
        """G_i⁻¹, which the tracer applies going inwards, with a rounding-level c zeroed."""
        return cached(self, "_inverse", lambda: mobius.tidy(mobius.inverse(self.matrix())))


@dataclass(frozen=True)
class MoKRS:
    """A Möbius kernel–reflection sequence [KRS17 §7]; traced by binary sphere tracing."""

    levels: list[MobiusLevel] = param([], help="level 0 first (finest), last level coarsest")

    def validate(self, path: str) -> None:
        p = f"{path}.levels"
        check_level_count(self.levels, p, "a MöKRS needs at least one level")
        found = cached_each(  # kept per level (frozen); a new pose's found at once
            self.levels,
            "_condition",
            lambda new: mobius.conditions(np.array([lv.matrix() for lv in new])).tolist(),
        )
        for i, cond in enumerate(found):
            if not cond <= SINGULAR_CONDITION:
                raise SceneError(
                    f"{p}[{i}].transform",
                    f"<condition number {cond:.3g}>",
                    f"numerically singular; allowed: condition ≤ "
                    f"{SINGULAR_CONDITION:g} (avoid extreme scale factors)",
                )

    @property
    def depth(self) -> int:
        """Number of levels (the range of the viewer's levels slider and of --levels)."""
        return len(self.levels)

    @property
    def n(self) -> int:
        """Number of levels the tracer walks (each may reflect)."""
        return len(self.levels)

    @property
    def kernels(self) -> list[Kernel]:
        return [lv.kernel for lv in self.levels]

    def instance_count(self) -> int:
        """K_i is doubled by every reflecting level from i up."""
        total, copies = 0, 1
        for lv in reversed(self.levels):
            copies *= 2 if lv.reflect else 1
            if not isinstance(lv.kernel, Empty):
                total += copies
        return total

    def truncated(self, levels: int) -> MoKRS:
        """Keep the coarsest ``levels`` levels, dropping the finest. If none of them has a
        kernel (an IFS-like MöKRS whose only shape is K_0, as ``inversion``), the nearest
        kernel below the cut is carried into the new finest level's space by G_j … G_{cut−1},
        so something is drawn, as a KRS's truncation promotes a kernel [KRS17 §4]. A sphere
        maps to a sphere under a Möbius map; it must not hold a pole on the way."""
        cut = len(self.levels) - levels
        keep = list(self.levels[cut:])
        below = [j for j in range(cut) if not isinstance(self.levels[j].kernel, Empty)]
        if all(isinstance(lv.kernel, Empty) for lv in keep) and below:
            j = below[-1]
            k = self.levels[j].kernel
            if not isinstance(k, Sphere):
                raise SceneError(
                    "levels",
                    levels,
                    f"the kept levels have no kernel, and "
                    f"level {j}'s {k.kind} cannot be carried up to level {cut} "
                    f"(only a sphere stays a sphere under Möbius maps); allowed: "
                    f"more than {len(self.levels) - 1 - j} levels",
                )
            c, r = np.array([k.center], dtype=np.float64), np.array([k.radius])
            for i in range(j, cut):
                c, r, ok = mobius.map_ball(self.levels[i].matrix(), c, r)
                if not ok[0]:
                    raise SceneError(
                        "levels",
                        levels,
                        f"level {j}'s sphere holds the pole "
                        f"of level {i}'s transformation, so its image is not a "
                        f"ball; allowed: more than {len(self.levels) - 1 - i} "
                        "levels",
                    )
            keep[0] = replace(
                keep[0], kernel=Sphere(tuple(float(v) for v in c[0]), float(r[0]), k.color)
            )
        return MoKRS(keep)


def linked_levels(m: MoKRS, i: int) -> list[int]:
    """Level i and every finer level whose steps equal its own (palm's leaflets, shell's
    turns): the levels a linked step edit changes. The coarser ones stay, so level i's frame,
    and a handle dragged in it, stay where the pointer puts them. A level without steps is
    linked to none: it has no step to share, and the first step it gets is its own (palm's
    30 plain levels, and any level just inserted, took a step added to one all at once)."""
    if not m.levels[i].transform:
        return [i]
    return [j for j in range(i + 1) if m.levels[j].transform == m.levels[i].transform]


def linked_edit(m: MoKRS, path: tuple, value) -> tuple[tuple, object]:
    """The edit that sets a step's field (``path`` = ("mokrs", "levels", i, "transform", j,
    field)) in level i and its linked levels: the whole level list where others follow,
    else the field alone."""
    i, j, name = path[2], path[4], path[5]
    linked = linked_levels(m, i)
    if len(linked) == 1:
        return path, value
    levels = list(m.levels)
    for k in linked:
        steps = list(levels[k].transform)
        steps[j] = replace(steps[j], **{name: value})
        levels[k] = replace(levels[k], transform=steps)
    return path[:2], levels


def linked_steps(m: MoKRS, i: int, steps: list) -> tuple[tuple, object]:
    """The edit that gives level i and its linked levels the step list ``steps`` (a step
    added, removed or moved: they stay linked): the whole level list where others follow,
    else level i's steps alone."""
    linked = linked_levels(m, i)
    if len(linked) == 1:
        return ("mokrs", "levels", i, "transform"), steps
    levels = list(m.levels)
    for k in linked:
        levels[k] = replace(levels[k], transform=list(steps))
    return ("mokrs", "levels"), levels


POLE_DISTANCE = 1e-6  # a viewpoint closer than this (× the level's scale) to a pole is rejected


def check_view(mokrs: MoKRS, position: Vec3, path: str) -> None:
    """Follow a viewpoint into every level (mirror tests on the point, as the tracer does) and
    reject it where a level's inverse transformation sends it to infinity."""
    x = np.array([position], dtype=np.float64)
    for i in range(mokrs.n - 1, -1, -1):
        H = mokrs.levels[i].inverse()
        p = mobius.pole(H)
        if p is not None:
            scale = max(1.0, float(np.linalg.norm(x)))
            if np.linalg.norm(x[0] - p) <= POLE_DISTANCE * scale:
                raise SceneError(
                    path,
                    [float(c) for c in position],  # a NumPy camera prints as plain numbers
                    f"level {i}'s transform sends this point to infinity (its pole, "
                    f"mokrs.levels[{i}].transform); allowed: a viewpoint off the pole: "
                    "move it, or the inversion's centre",
                )
        x = mobius.apply(H, x)
        if mokrs.levels[i].reflect and x[0, 0] > 0.0:
            x[0, 0] = -x[0, 0]


def mokrs_of(krs) -> MoKRS:
    """The same geometry as a plain KRS, written as a MöKRS with rigid transforms: level i's
    space puts mirror R_i on x = 0 (normal along +x), so folding there is Alg. 1's fold
    (used by the tracer cross-check). The top kernel K_n stays in the world, unreflected."""

    def to_x(u):
        """Axis and degrees of the rotation taking unit u to +x."""
        u = np.asarray(u, dtype=np.float64)
        axis = cross(u, [1.0, 0.0, 0.0])
        s, c = float(np.linalg.norm(axis)), float(u[0])
        if s < 1e-12:
            return (0.0, 1.0, 0.0), (0.0 if c > 0 else 180.0)
        return tuple(axis / s), math.degrees(math.atan2(s, c))

    def moved(k: Kernel, rotate: Rotate, o) -> Kernel:
        """Kernel k in the frame y = R (x − o), R the rotation ``rotate``."""
        R = rotate.matrix()
        turn = lambda v: tuple(float(c) for c in mobius.apply(R, np.array([v]))[0])  # noqa: E731
        if isinstance(k, Plane):
            return replace(k, normal=turn(k.normal), offset=k.offset - float(np.dot(k.normal, o)))
        change = {
            f.name: turn(np.asarray(getattr(k, f.name)) - o)
            for f in fields(k)
            if f.name in ("center", "a", "b", "start", "control", "end")
        }
        return replace(k, **change)

    frames = []  # (axis, degrees, origin w·u) of each mirror's frame
    for m in krs.mirrors:
        axis, deg = to_x(m.normal)
        frames.append((axis, deg, m.offset * np.asarray(m.normal)))
    levels = []
    for i, (axis, deg, o) in enumerate(frames):
        steps: list[MobiusStep] = [Rotate(axis, -deg)]
        shift = o - (frames[i + 1][2] if i + 1 < len(frames) else 0.0)
        steps.append(Translate(tuple(float(v) for v in shift)))
        if i + 1 < len(frames):
            steps.append(Rotate(frames[i + 1][0], frames[i + 1][1]))
        levels.append(MobiusLevel(moved(krs.kernels[i], Rotate(axis, deg), o), steps, True))
    levels.append(MobiusLevel(krs.kernels[-1], [], False))
    return MoKRS(levels)
