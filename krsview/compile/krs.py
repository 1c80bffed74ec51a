"""A KRS flattened to arrays, shared by the NumPy reference and the GPU uniform packer.

Each kernel becomes a record of ``RECORD_VEC4`` vec4s (layout below, mirrored in
``shaders/kernels.glsl``). Compiled once per scene in world coordinates; ``relative_to`` moves
the origin to the camera each frame, so the GPU works in camera-relative float32 while the CPU
keeps the camera in float64 (docs/architecture.md, Precision).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..algebra.vectors import cross
from ..scene import KRS, Arc, Capsule, Empty, Plane, Sphere, ToroidalCapsule, arcs_of
from .balls import UNBOUNDED, grown, krs_ball, krs_bounds, union_ball
from .lod import lod_cut

# Kernel type codes, equal to the KERNEL_* defines in kernels.glsl.
KERNEL_CODES = {"empty": 0, "sphere": 1, "capsule": 2, "toroidal_capsule": 3, "plane": 4}
RECORD_VEC4 = 4
# record[0] = (colour rgb, type code)
# record[1] = sphere (centre, r) | capsule (start A, r) | arc (centre O, r) | plane (u, w)
# record[2] = capsule (end B, 0) | arc (quaternion P = (real, i, j, k) of the arc's frame)
# record[3] = arc (t = tan(phi/4), 0, 0, 0)   phi: arc angle from start to end, in (0, 2π)
# The arc's frame [e1 e2 n]: e1 the bisector of the arc, e2 in its plane, n = e1 × e2 its
# normal; P is that rotation's unit quaternion divided by √R, so P̄ q P is q in the frame in
# units of R, and R = 1/|P|². The arc is then the unit circle's points at angles within ±phi/2
# of e1, its ends (cos, ±sin)(phi/2) = ((1 − t²), ±2t)/(1 + t²): 9 numbers where Alg. 1's
# level reads the arc (kernels.glsl), against 13 for O, R, e1, e2, cos and sin phi; and the
# rational half angle stays accurate in float32 for the shortest arcs (STRAIGHT_RATIO), where
# sin(phi/2) = √(1 − cos²) would not.


# Record slots holding a position (xyz), per kernel type: what moves when the origin moves.
POSITION_SLOTS = {"sphere": (1,), "capsule": (1, 2), "toroidal_capsule": (1,)}


@dataclass(frozen=True)
class CompiledKRS:
    mirrors: np.ndarray  # (n, 4): u.xyz, w  (the plane u·x = w)
    bounds: np.ndarray  # (n, 4): krs_bounds, the culling ball before fold i (r < 0: none),
    # centred on mirror i's plane (the walk folds about that centre)
    records: np.ndarray  # (n+1, RECORD_VEC4, 4) float64
    types: tuple[str, ...]  # kernel type per level (after arc → capsule degeneration)
    ball: np.ndarray  # (4,): grown(krs_ball), everything drawn (r < 0: unbounded)
    lod_cut: np.ndarray  # (4,): where the level of detail cuts the walk (compile/lod.py)

    @property
    def n(self) -> int:
        return len(self.mirrors)

    @property
    def half_space(self) -> np.ndarray | None:
        """(u, w): the half-space u·x ≤ w that a KRS of one plane kernel is, which holds
        everything it draws as ``ball`` does for a bounded KRS; None for any other KRS."""
        return self.records[0, 1].copy() if self.n == 0 and self.types[0] == "plane" else None

    def relative_to(self, origin: np.ndarray | tuple) -> CompiledKRS:
        """The same KRS with every position taken relative to ``origin`` (float64): the
        per-frame step of camera-relative rendering; the rest is compiled once per scene."""
        o = np.asarray(origin, dtype=np.float64)
        mirrors = self.mirrors.copy()
        mirrors[:, 3] -= mirrors[:, :3] @ o
        records = self.records.copy()
        for i, kind in enumerate(self.types):
            for slot in POSITION_SLOTS.get(kind, ()):
                records[i, slot, :3] -= o
            if kind == "plane":
                records[i, 1, 3] -= records[i, 1, :3] @ o
        bounds = self.bounds.copy()
        bounds[:, :3] -= o  # every centre, with or without a ball: it stays on its plane
        ball = self.ball - np.array([*o, 0.0]) if self.ball[3] >= 0 else self.ball
        return CompiledKRS(mirrors, bounds, records, self.types, ball, self.lod_cut)


def compile_krs(krs: KRS, albedo: tuple[float, float, float]) -> CompiledKRS:
    """Flatten ``krs`` in world coordinates (float64); see :meth:`CompiledKRS.relative_to`."""
    mirrors = np.array([[*m.normal, m.offset] for m in krs.mirrors], dtype=np.float64).reshape(
        -1, 4
    )
    records, types = kernel_records(krs.kernels, albedo)
    bounds = krs_bounds(krs)
    return CompiledKRS(mirrors, bounds, records, types, grown(krs_ball(krs)), lod_cut(krs, bounds))


def kernel_records(
    kernels: list, albedo: tuple[float, float, float]
) -> tuple[np.ndarray, tuple[str, ...]]:
    """One record per kernel (layout above) and each kernel's drawn type."""
    records = np.zeros((len(kernels), RECORD_VEC4, 4))
    types = []
    at = [i for i, k in enumerate(kernels) if isinstance(k, ToroidalCapsule)]
    arcs = {i: arc for i, arc in zip(at, arcs_of([kernels[i] for i in at])) if arc is not None}
    quaternions = dict(zip(arcs, arc_quaternions(list(arcs.values())))) if arcs else {}
    for i, k in enumerate(kernels):
        kind = k.kind
        r = records[i]
        color = getattr(k, "color", None) or albedo
        if isinstance(k, Sphere):
            r[1] = [*k.center, k.radius]
        elif isinstance(k, Capsule):
            r[1] = [*k.a, k.radius]
            r[2, :3] = k.b
        elif isinstance(k, ToroidalCapsule):
            arc = arcs.get(i)
            if arc is None:
                kind = "capsule"
                r[1] = [*k.start, k.radius]
                r[2, :3] = k.end
            else:
                r[1] = [*arc.center, k.radius]
                r[2] = quaternions[i]
                r[3, 0] = np.tan(arc.phi / 4.0)
        elif isinstance(k, Plane):
            r[1] = [*k.normal, k.offset]
        else:
            assert isinstance(k, Empty), k
        r[0] = [*color, KERNEL_CODES[kind]]
        types.append(kind)
    return records, tuple(types)


def arc_quaternions(arcs: list[Arc]) -> np.ndarray:
    """(len(arcs), 4): P of each arc's record (layout above), the unit quaternion of the
    rotation whose columns are the bisector e1, e2 and n, divided by √R; of the four ways to
    read it from the matrix F, Shepperd's takes the one with the largest term (of 1 + trace and
    1 + 2 F_aa − trace), so no square root of a small difference."""
    half = np.array([arc.phi for arc in arcs])[:, None] / 2.0
    e1, e2 = np.array([arc.e1 for arc in arcs]), np.array([arc.e2 for arc in arcs])
    b1 = np.cos(half) * e1 + np.sin(half) * e2
    b2 = -np.sin(half) * e1 + np.cos(half) * e2
    F = np.stack([b1, b2, cross(b1, b2)], axis=-1)  # columns e1, e2, n
    (f00, f01, f02), (f10, f11, f12), (f20, f21, f22) = F.transpose(1, 2, 0)
    trace = f00 + f11 + f22
    ways = np.stack(
        [
            [1.0 + trace, f21 - f12, f02 - f20, f10 - f01],
            [f21 - f12, 1.0 + 2.0 * f00 - trace, f10 + f01, f20 + f02],
            [f02 - f20, f01 + f10, 1.0 + 2.0 * f11 - trace, f21 + f12],
            [f10 - f01, f02 + f20, f12 + f21, 1.0 + 2.0 * f22 - trace],
        ]
    )  # (way, component, arc)
    way = np.argmax(np.stack([trace, f00, f11, f22]), axis=0)
    q = ways[way, :, np.arange(len(arcs))]
    R = np.array([arc.R for arc in arcs])
    return q / (np.linalg.norm(q, axis=-1) * np.sqrt(R))[:, None]


@dataclass(frozen=True)
class CompiledCompound:
    """A compound's components [KRS17 §5.1], each a CompiledKRS. Their levels share one row of
    slots, as in the GPU's uniform block: level i of component c is slot ``bases[c] + i``, so
    a slot names a kernel record across the whole compound (shading looks colours up by it)."""

    parts: tuple[CompiledKRS, ...]

    @cached_property
    def bases(self) -> tuple[int, ...]:
        return tuple(int(b) for b in np.cumsum([0] + [p.n + 1 for p in self.parts[:-1]]))

    @cached_property
    def records(self) -> np.ndarray:
        return np.concatenate([p.records for p in self.parts])

    @cached_property
    def types(self) -> tuple[str, ...]:
        return tuple(t for p in self.parts for t in p.types)

    @cached_property
    def ball(self) -> np.ndarray:
        """Everything drawn, as CompiledKRS.ball: the least ball around the parts' balls."""
        if any(p.ball[3] < 0 for p in self.parts):
            return UNBOUNDED.copy()
        out = None
        for p in self.parts:
            out = union_ball(out, p.ball)
        return out

    def relative_to(self, origin: np.ndarray | tuple) -> CompiledCompound:
        return CompiledCompound(tuple(p.relative_to(origin) for p in self.parts))
