"""Balls around a KRS's kernels and levels: what culling, the level of detail, the rays'
exits, the shadow cone and the mesh's octree test against. A ball is (centre, radius).

Per mirror slot i, Alg. 1 still tests A_i = G_i ∪ R_i(G_i), G_i = K_i ∪ A_{i−1} (A_{−1} = ∅)
[KRS17 Alg. 1]. Its ball is found by expanding A_i EXACT_LEVELS levels down into its
kernels' balls around the ball of the slot below those, and enclosing them: building C_i as
the least ball around two balls, level after level, compounds the slack of each union (on
`tree`, 1.7× the least radius at the top, 1.9× at the level-of-detail cut) [issue 27].
"""

from __future__ import annotations

import math

import numpy as np

from ..scene import KRS, Capsule, Empty, Kernel, Sphere, ToroidalCapsule, arc_of
from ..scene.schema import cached

CULL_MARGIN = 1e-6  # relative growth of the culling balls, against rounding
UNBOUNDED = np.array([0.0, 0.0, 0.0, -1.0])  # a bound record for "no bounding ball"
NO_BALL = np.array([0.0, 0.0, 0.0, -np.inf])  # a row of an expansion that holds nothing
EXACT_LEVELS = 4  # levels expanded below each ball: 2^(EXACT_LEVELS + 2) kernel balls
CENTRE_STEPS = 16  # Bădoiu–Clarkson steps choosing a ball's centre


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


def reflected(balls: np.ndarray, u: np.ndarray, w: np.ndarray | float) -> np.ndarray:
    """(..., m, 4) balls reflected in the planes u·x = w (u (..., 3), w (...)): one plane per
    leading index."""
    out, w = balls.copy(), np.asarray(w)
    out[..., :3] -= (
        2.0
        * (np.einsum("...mk,...k->...m", balls[..., :3], u) - w[..., None])[..., None]
        * u[..., None, :]
    )
    return out


def enclosing_balls(balls: np.ndarray) -> np.ndarray:
    """(s, 4): per set of (s, m, 4) ``balls``, a small ball holding all of its balls; a row
    of radius −∞ is no ball (every set holds at least one). The centre: CENTRE_STEPS
    Bădoiu–Clarkson steps from the box's centre, all sets at once; the radius is exact for
    the best centre met."""
    centres, radii = np.ascontiguousarray(balls[..., :3]), balls[..., 3]
    lo = (centres - radii[..., None]).min(axis=1)
    hi = (centres + radii[..., None]).max(axis=1)
    c = (lo + hi) / 2
    best_c, best_r = c, np.full(len(balls), np.inf)
    rows = np.arange(len(balls))
    for k in range(CENTRE_STEPS):
        v = centres - c[:, None]
        reach = np.sqrt(np.einsum("smk,smk->sm", v, v)) + radii
        far = reach.argmax(axis=1)
        r = reach[rows, far]
        better = r < best_r
        best_c, best_r = np.where(better[:, None], c, best_c), np.where(better, r, best_r)
        c = c + (centres[rows, far] - c) / (k + 2)
    return np.column_stack([best_c, best_r])


def held_balls(krs: KRS) -> tuple[np.ndarray | None, ...]:
    """n + 1 balls: entry i < n holds A_i (module doc), entry n the whole KRS (K_n ∪ A_{n−1});
    None from the first plane kernel on (unbounded) and where nothing is held yet. Made once
    per KRS (frozen): compiling asks for the slots' balls and the whole one."""
    return cached(krs, "_held_balls", lambda: _held_balls(krs))


def _held_balls(krs: KRS) -> tuple[np.ndarray | None, ...]:
    """Slots go in batches of EXACT_LEVELS + 1, each needing only the balls of earlier
    batches."""
    n = len(krs.mirrors)
    e = _Expansion(krs)
    held: list[np.ndarray | None] = [None] * (n + 1)
    for first in range(0, n + 1, EXACT_LEVELS + 1):
        slots = np.arange(first, min(n + 1, first + EXACT_LEVELS + 1))
        below = [held[i - EXACT_LEVELS - 1] if i > EXACT_LEVELS else None for i in slots]
        for i, ball in e.enclosed(slots, below):
            ball.flags.writeable = False
            held[i] = ball
    return tuple(held)


def top_balls(krs: KRS) -> tuple[np.ndarray | None, ...]:
    """n entries: per mirror slot i, a ball around its top EXACT_LEVELS + 1 levels alone
    (i down to i − EXACT_LEVELS, expanded as :func:`held_balls` expands them, without the
    ball of everything below): what the slot looks like at a glance, whatever the depth of
    the tree below it (compile/lod.py). None where those levels hold no bounded kernel."""
    n = len(krs.mirrors)
    out: list[np.ndarray | None] = [None] * n
    for i, ball in _Expansion(krs).enclosed(np.arange(n), [None] * n):
        out[i] = ball
    return tuple(out)


class _Expansion:
    """A KRS's kernel balls and mirrors, expanded EXACT_LEVELS + 1 levels down per slot, many
    slots at once: slot i expands levels i − EXACT_LEVELS .. i, each adding its kernel's ball
    and then the mirror images of everything so far. A level that is not there (below level
    0), a kernel without a ball and the images at level n (which has no mirror) are rows of
    radius −∞, so every slot's rows line up."""

    def __init__(self, krs: KRS):
        n, pad = len(krs.mirrors), EXACT_LEVELS  # level j is row j + pad
        kb = [kernel_ball(k) for k in krs.kernels]
        self.plane = np.cumsum(
            [b is None and not isinstance(k, Empty) for b, k in zip(kb, krs.kernels)]
        )
        self.kb = np.array([NO_BALL] * pad + [NO_BALL if b is None else b for b in kb])
        self.u = np.zeros((pad + n + 1, 3))
        self.w = np.zeros(pad + n + 1)
        for j, m in enumerate(krs.mirrors):
            self.u[pad + j], self.w[pad + j] = m.normal, m.offset
        level = np.arange(pad + n + 1) - pad
        self.mirrored = (level >= 0) & (level < n)

    def balls(self, slots: np.ndarray, below: np.ndarray) -> np.ndarray:
        """(len(slots), m, 4): each slot's kernel balls EXACT_LEVELS levels down, around
        ``below`` (per slot, the held ball of the slot below those; NO_BALL: without it);
        slot n adds the top kernel's."""
        balls = below[:, None].copy()
        for step in range(EXACT_LEVELS + 1):
            row = slots + step  # level slots − EXACT_LEVELS + step
            balls = np.concatenate([self.kb[row][:, None], balls], axis=1)
            images = reflected(balls, self.u[row], self.w[row])
            images[~self.mirrored[row], :, 3] = -np.inf
            balls = np.concatenate([balls, images], axis=1)
        return balls

    def enclosed(self, slots: np.ndarray, below: list) -> list[tuple[int, np.ndarray]]:
        """(slot, ball) for each of ``slots`` above every plane kernel whose expansion
        (:meth:`balls`) holds a ball: the least ball found around it."""
        bounded = self.plane[slots] == 0
        below = np.array([NO_BALL if b is None else b for b in below]).reshape(-1, 4)
        slots, balls = slots[bounded], self.balls(slots[bounded], below[bounded])
        some = (balls[..., 3] > -np.inf).any(axis=1)
        return list(zip(slots[some].tolist(), enclosing_balls(balls[some])))


def krs_ball(krs: KRS) -> np.ndarray | None:
    """A ball holding the whole KRS, all 2^n instances; None when a plane kernel makes it
    unbounded."""
    return held_balls(krs)[-1]


def grown(ball: np.ndarray | None) -> np.ndarray:
    """A ball record for the GPU: ``ball`` grown by CULL_MARGIN against rounding, or
    UNBOUNDED for None."""
    if ball is None:
        return UNBOUNDED.copy()
    return np.array(
        [*ball[:3], ball[3] * (1 + CULL_MARGIN) + CULL_MARGIN * float(np.abs(ball[:3]).max())]
    )


def on_plane(c: np.ndarray, u: np.ndarray, w: float) -> np.ndarray:
    """The point c projected onto the plane u·x = w (u a unit normal)."""
    return c - (c @ u - w) * u


def krs_bounds(krs: KRS) -> np.ndarray:
    """(n, 4): per mirror slot i, the ball C_i of A_i, everything Alg. 1 still tests before
    folding at level i (radius −1: unbounded, from a plane kernel on), grown by CULL_MARGIN
    against rounding. A point x with d ≤ dist(x, C_i) cannot lower d any more: the walk stops
    there with the same value [issue 17, exact level culling]; with the level of detail,
    once d ≤ dist(x, C_i) − 2R, since a ball C_j of radius R drawn for the levels below
    (holding its part of A_i) reaches at most its diameter beyond A_i ⊂ C_i (krs.glsl,
    compile/lod.py). Slots below only empty kernels get no ball (the walk's d is still ∞
    there).

    Every centre lies on its slot's mirror plane, so that a walk that reads the ball at every
    level anyway (the level of detail) folds about it, u·(x − c), and need not read the
    plane's offset w (krs.glsl, fold). That costs no radius: A_i is
    symmetric under R_i, so if (c, r) holds it so does (R_i c, r), and so does (m, r) with m
    their midpoint, on the plane: |x − m| ≤ (|x − c| + |x − R_i c|)/2 ≤ r. A slot without a
    ball keeps radius −1 about the plane's point nearest the origin."""
    held = held_balls(krs)
    # where every kernel above slot i is empty the walk still has d = ∞ there and can never
    # stop: no ball, so the test is not paid for (sierpinski: all but K_0 empty)
    solid = np.cumsum([not isinstance(k, Empty) for k in krs.kernels[::-1]])[::-1]
    out = np.zeros((len(krs.mirrors), 4))
    for i, m in enumerate(krs.mirrors):
        u, ball = np.array(m.normal, dtype=np.float64), held[i] if solid[i + 1] else None
        if ball is None:
            out[i] = [*on_plane(np.zeros(3), u, m.offset), -1.0]
        else:
            out[i] = grown(np.array([*on_plane(ball[:3], u, m.offset), ball[3]]))
    return out
