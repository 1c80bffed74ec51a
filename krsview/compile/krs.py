"""A KRS flattened to arrays, shared by the NumPy reference and the GPU uniform packer.

Each kernel becomes a record of ``RECORD_VEC4`` vec4s (layout below, mirrored in
``shaders/kernels.glsl``). Compiled once per scene in world coordinates; ``relative_to`` moves
the origin to the camera each frame, so the GPU works in camera-relative float32 while the CPU
keeps the camera in float64 (DESIGN.md, Precision).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..scene import KRS, Capsule, Empty, Kernel, Plane, Sphere, ToroidalCapsule, arc_of

# Kernel type codes, equal to the KERNEL_* defines in kernels.glsl.
KERNEL_CODES = {"empty": 0, "sphere": 1, "capsule": 2, "toroidal_capsule": 3, "plane": 4}
RECORD_VEC4 = 6
# record[0] = (colour rgb, type code)
# record[1] = sphere (centre, r) | capsule/arc (start A, r) | plane (normal u, offset w)
# record[2] = capsule/arc (end B, 0)
# record[3] = arc (centre O, major radius R)
# record[4] = arc (e1: unit O→A, cos phi)     phi: arc angle from A to B, in (0, 2π)
# record[5] = arc (e2: unit, in-plane ⟂ e1, sin phi)


CULL_MARGIN = 1e-6  # relative growth of the culling balls, against rounding

# Record slots holding a position (xyz), per kernel type: what moves when the origin moves.
POSITION_SLOTS = {"sphere": (1,), "capsule": (1, 2), "toroidal_capsule": (1, 2, 3)}


UNBOUNDED = np.array([0.0, 0.0, 0.0, -1.0])  # a bound record for "no bounding ball"


def kernel_ball(k: Kernel) -> np.ndarray | None:
    """(centre, radius) of a ball holding the kernel; None for an unbounded plane or empty.
    An arc of at most π stays within the rectangle of its chord c and sagitta h, so within
    √((c/2)² + h²) of the chord's midpoint; a longer arc within R of its circle's centre."""
    if isinstance(k, Sphere):
        return np.array([*k.center, k.radius])
    if isinstance(k, Capsule):
        a, b = np.array(k.a), np.array(k.b)
        return np.array([*(a + b) / 2, np.linalg.norm(b - a) / 2 + k.radius])
    if isinstance(k, ToroidalCapsule):
        arc = arc_of(k)
        a, b = np.array(k.start), np.array(k.end)
        if arc is None:
            return np.array([*(a + b) / 2, np.linalg.norm(b - a) / 2 + k.radius])
        if arc.phi > math.pi:
            return np.array([*arc.center, arc.R + k.radius])
        half = np.linalg.norm(b - a) / 2
        sagitta = arc.R * (1 - math.cos(arc.phi / 2))
        return np.array([*(a + b) / 2, math.hypot(half, sagitta) + k.radius])
    return None


def union_ball(p: np.ndarray | None, q: np.ndarray | None) -> np.ndarray | None:
    """The smallest ball holding balls p and q (None: nothing)."""
    if p is None or q is None:
        return q if p is None else p
    d = float(np.linalg.norm(q[:3] - p[:3]))
    if d + q[3] <= p[3]:
        return p
    if d + p[3] <= q[3]:
        return q
    r = (d + p[3] + q[3]) / 2
    return np.array([*(p[:3] + (r - p[3]) / d * (q[:3] - p[:3])), r])


def level_balls(krs: KRS) -> list[np.ndarray | None]:
    """Per mirror slot i, the ball C_i = S ∪ R_i(S), S = ball(K_i) ∪ C_{i−1} (krs_bounds),
    exactly; None where it is unbounded (a plane kernel at or below i) or holds nothing.
    Each ball holds the finer ones and their mirror images, which the level of detail needs:
    the ball it draws for the levels below slot c then lies inside every C_i above, so a walk
    that culls at C_i gives the same value as one that goes on to the cut."""
    out, below, unbounded = [], None, False
    for k, m in zip(krs.kernels, krs.mirrors):
        ball = kernel_ball(k)
        unbounded |= ball is None and not isinstance(k, Empty)
        if not unbounded:
            S = union_ball(below, ball)
            if S is not None:
                below = union_ball(S, reflected(S[None], np.array(m.normal), m.offset)[0])
        out.append(None if unbounded else below)
    return out


# Levels expanded exactly inside the ball around a whole KRS (2^(EXACT_LEVELS+2) kernel
# balls); the levels below enter as balls of the same kind one step finer. level_balls' union
# of two balls per level compounds its slack: on `tree` its outermost ball has 1.7× the
# radius of the least one, this one's 1.01× [issue 27].
EXACT_LEVELS = 4


def enclosing_balls(sets: list[np.ndarray]) -> np.ndarray:
    """(len(sets), 4): per (m, 4) array of balls, a small ball (centre, radius) holding them
    all. The centre: a few Bădoiu–Clarkson steps from the box's centre, all sets at once (a
    set is padded by repeating its last ball); the radius is exact for the centre chosen."""
    m = max(len(s) for s in sets)
    balls = np.stack([np.vstack([s, np.repeat(s[-1:], m - len(s), axis=0)]) for s in sets])
    lo = (balls[..., :3] - balls[..., 3:]).min(axis=1)
    hi = (balls[..., :3] + balls[..., 3:]).max(axis=1)
    c = (lo + hi) / 2
    best = np.full((len(sets), 4), np.inf)
    rows = np.arange(len(sets))
    for k in range(16):
        v = balls[..., :3] - c[:, None]
        reach = np.sqrt(np.einsum("smk,smk->sm", v, v)) + balls[..., 3]
        far = reach.argmax(axis=1)
        better = reach[rows, far] < best[:, 3]
        best[better] = np.column_stack([c, reach[rows, far]])[better]
        c = c + (balls[rows, far, :3] - c) / (k + 2)
    return best


def reflected(balls: np.ndarray, u: np.ndarray, w: float) -> np.ndarray:
    """(m, 4) balls reflected in the plane u·x = w."""
    out = balls.copy()
    out[:, :3] -= 2.0 * (balls[:, :3] @ u - w)[:, None] * u
    return out


def krs_ball(krs: KRS) -> np.ndarray | None:
    """A small ball (centre, radius) holding the whole KRS, all 2^n instances; None when a
    plane kernel makes it unbounded. What slot i of Alg. 1 still tests, A_i = G_i ∪ R_i(G_i)
    with G_i = K_i ∪ A_{i−1}, is expanded EXACT_LEVELS levels down into its kernels' balls
    (kernel_ball) around the ball of A_{i−EXACT_LEVELS−1} found before, slots in batches of
    EXACT_LEVELS + 1 that each need only earlier batches; the top kernel joins A_{n−1}."""
    if any(kernel_ball(k) is None and not isinstance(k, Empty) for k in krs.kernels):
        return None
    n = len(krs.mirrors)
    kb = [kernel_ball(k) for k in krs.kernels]
    u = np.array([m.normal for m in krs.mirrors]).reshape(-1, 3)
    w = np.array([m.offset for m in krs.mirrors])
    held: list[np.ndarray | None] = [None] * (n + 1)  # held[i + 1]: the ball of A_i

    def expanded(i: int) -> np.ndarray:  # A_i as balls; A_{−1} = ∅; slot n: K_n ∪ A_{n−1}
        first = max(0, i - EXACT_LEVELS)
        balls = np.zeros((0, 4)) if held[first] is None else held[first][None]
        for j in range(first, min(i, n - 1) + 1):
            if kb[j] is not None:
                balls = np.vstack([kb[j][None], balls])
            balls = np.vstack([balls, reflected(balls, u[j], w[j])])
        return balls if i < n or kb[n] is None else np.vstack([kb[n][None], balls])

    for first in range(0, n + 1, EXACT_LEVELS + 1):
        sets = {i: expanded(i) for i in range(first, min(n + 1, first + EXACT_LEVELS + 1))}
        sets = {i: s for i, s in sets.items() if len(s)}
        if sets:
            for i, ball in zip(sets, enclosing_balls(list(sets.values()))):
                if i == n:
                    return ball
                held[i + 1] = ball
    return None


def grown(ball: np.ndarray | None) -> np.ndarray:
    """A ball record for the GPU: ``ball`` grown by CULL_MARGIN against rounding, or
    UNBOUNDED for None."""
    if ball is None:
        return UNBOUNDED.copy()
    return np.array(
        [*ball[:3], ball[3] * (1 + CULL_MARGIN) + CULL_MARGIN * float(np.abs(ball[:3]).max())]
    )


def krs_bounds(krs: KRS) -> np.ndarray:
    """(n, 4): per mirror slot i, a ball C_i holding everything Alg. 1 still tests before
    folding at level i — K_i and the levels below, doubled by R_i: C_i = S ∪ R_i(S),
    S = ball(K_i) ∪ C_{i−1} (radius −1: unbounded, from a plane kernel on). A point x with
    d ≤ dist(x, C_i) cannot lower d any more: the walk stops there with the same value
    [issue 17, exact level culling]. Radii carry a margin of CULL_MARGIN against rounding.
    Slots below only empty kernels get no ball (the walk's d is still ∞ there)."""
    out = [grown(below) for below in level_balls(krs)]
    # where every kernel above slot i is empty the walk still has d = ∞ there and can never
    # stop: no ball, so the test is not paid for (sierpinski: all but K_0 empty)
    solid = np.cumsum([not isinstance(k, Empty) for k in krs.kernels[::-1]])[::-1]
    for i in range(len(out)):
        if solid[i + 1] == 0:
            out[i] = UNBOUNDED
    return np.array(out, dtype=np.float64).reshape(-1, 4)


@dataclass(frozen=True)
class CompiledKRS:
    mirrors: np.ndarray  # (n, 4): u.xyz, w  (the plane u·x = w)
    bounds: np.ndarray  # (n, 4): krs_bounds, the culling ball before fold i (r < 0: none)
    records: np.ndarray  # (n+1, RECORD_VEC4, 4) float64
    types: tuple[str, ...]  # kernel type per level (after arc → capsule degeneration)
    ball: np.ndarray  # (4,): grown(krs_ball), everything drawn (r < 0: unbounded)

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
        bounds[:, :3] -= np.where(bounds[:, 3:] >= 0, o, 0.0)
        ball = self.ball - np.array([*o, 0.0]) if self.ball[3] >= 0 else self.ball
        return CompiledKRS(mirrors, bounds, records, self.types, ball)


def compile_krs(krs: KRS, albedo: tuple[float, float, float]) -> CompiledKRS:
    """Flatten ``krs`` in world coordinates (float64); see :meth:`CompiledKRS.relative_to`."""
    mirrors = np.array([[*m.normal, m.offset] for m in krs.mirrors], dtype=np.float64).reshape(
        -1, 4
    )
    records, types = kernel_records(krs.kernels, albedo)
    return CompiledKRS(mirrors, krs_bounds(krs), records, types, grown(krs_ball(krs)))


def kernel_records(
    kernels: list, albedo: tuple[float, float, float]
) -> tuple[np.ndarray, tuple[str, ...]]:
    """One record per kernel (layout above) and each kernel's drawn type."""
    records = np.zeros((len(kernels), RECORD_VEC4, 4))
    types = []
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
            r[1] = [*k.start, k.radius]
            r[2, :3] = k.end
            arc = arc_of(k)
            if arc is None:
                kind = "capsule"
            else:
                r[3] = [*arc.center, arc.R]
                r[4] = [*arc.e1, np.cos(arc.phi)]
                r[5] = [*arc.e2, np.sin(arc.phi)]
        elif isinstance(k, Plane):
            r[1] = [*k.normal, k.offset]
        else:
            assert isinstance(k, Empty), k
        r[0] = [*color, KERNEL_CODES[kind]]
        types.append(kind)
    return records, tuple(types)


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
