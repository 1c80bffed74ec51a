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


def reflected(balls: np.ndarray, u: np.ndarray, w: float) -> np.ndarray:
    """(m, 4) balls reflected in the plane u·x = w."""
    out = balls.copy()
    out[:, :3] -= 2.0 * (balls[:, :3] @ u - w)[:, None] * u
    return out


def enclosing_balls(sets: list[np.ndarray]) -> np.ndarray:
    """(len(sets), 4): per (m, 4) array of balls, a small ball holding them all. The centre:
    CENTRE_STEPS Bădoiu–Clarkson steps from the box's centre, all sets at once (a set is padded
    by repeating its last ball); the radius is exact for the best centre met."""
    m = max(len(s) for s in sets)
    balls = np.stack([np.vstack([s, np.repeat(s[-1:], m - len(s), axis=0)]) for s in sets])
    lo = (balls[..., :3] - balls[..., 3:]).min(axis=1)
    hi = (balls[..., :3] + balls[..., 3:]).max(axis=1)
    c = (lo + hi) / 2
    best = np.full((len(sets), 4), np.inf)
    rows = np.arange(len(sets))
    for k in range(CENTRE_STEPS):
        v = balls[..., :3] - c[:, None]
        reach = np.sqrt(np.einsum("smk,smk->sm", v, v)) + balls[..., 3]
        far = reach.argmax(axis=1)
        better = reach[rows, far] < best[:, 3]
        best[better] = np.column_stack([c, reach[rows, far]])[better]
        c = c + (balls[rows, far, :3] - c) / (k + 2)
    return best


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
        batch = range(first, min(n + 1, first + EXACT_LEVELS + 1))
        sets = {i: e.balls(i, held) for i in batch if not e.plane[i]}
        sets = {i: s for i, s in sets.items() if len(s)}
        for i, ball in zip(sets, enclosing_balls(list(sets.values())) if sets else ()):
            ball.flags.writeable = False
            held[i] = ball
    return tuple(held)


def top_balls(krs: KRS) -> tuple[np.ndarray | None, ...]:
    """n entries: per mirror slot i, a ball around its top EXACT_LEVELS + 1 levels alone
    (i down to i − EXACT_LEVELS, expanded as :func:`held_balls` expands them, without the
    ball of everything below): what the slot looks like at a glance, whatever the depth of
    the tree below it (compile/lod.py). None where those levels hold no bounded kernel."""
    e = _Expansion(krs)
    sets = {i: e.balls(i) for i in range(len(krs.mirrors)) if not e.plane[i]}
    sets = {i: s for i, s in sets.items() if len(s)}
    out: list[np.ndarray | None] = [None] * len(krs.mirrors)
    for i, ball in zip(sets, enclosing_balls(list(sets.values())) if sets else ()):
        out[i] = ball
    return tuple(out)


class _Expansion:
    """A KRS's kernel balls and mirrors, expanded a few levels down per slot."""

    def __init__(self, krs: KRS):
        self.n = len(krs.mirrors)
        self.kb = [kernel_ball(k) for k in krs.kernels]
        self.plane = np.cumsum(
            [b is None and not isinstance(k, Empty) for b, k in zip(self.kb, krs.kernels)]
        )
        self.u = np.array([m.normal for m in krs.mirrors]).reshape(-1, 3)
        self.w = np.array([m.offset for m in krs.mirrors])

    def balls(self, i: int, held: list | None = None) -> np.ndarray:
        """(m, 4): slot i's kernel balls EXACT_LEVELS levels down, around the held ball of
        the slot below those (``held``; None: without it); i = n adds the top kernel's."""
        first = max(0, i - EXACT_LEVELS)
        below = held[first - 1] if held is not None and first > 0 else None
        balls = np.zeros((0, 4)) if below is None else below[None]
        for j in range(first, min(i, self.n - 1) + 1):
            if self.kb[j] is not None:
                balls = np.vstack([self.kb[j][None], balls])
            balls = np.vstack([balls, reflected(balls, self.u[j], self.w[j])])
        kb = self.kb[self.n] if i == self.n else None
        return balls if kb is None else np.vstack([kb[None], balls])


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
