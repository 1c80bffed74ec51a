"""[KRS17 Alg. 1] over reliable numbers: the same kernels, folds and minimum as
``reference/krs.py``, written once for :class:`Interval` and :class:`Affine` (the operations
they share). A fold is x − 2·max(0, u·x − w)·u, its conditional turned into a max as RAA09
writes them; the toroidal capsule's wedge test takes the hull of both branches where the
range cannot decide it. The result encloses the real-number value of the distance the tracer
approximates, on the compiled scene's exact float64 constants."""
from __future__ import annotations

import numpy as np

from ..reference.compiled import CompiledCompound, CompiledKRS
from ..reference.mokrs import CompiledMoKRS
from .numbers import Affine, Interval, Number

Vec = tuple  # three Numbers


def dot(u, x: Vec) -> Number:
    """u (three floats) · x."""
    return x[0] * float(u[0]) + x[1] * float(u[1]) + x[2] * float(u[2])


def dot_self(x: Vec) -> Number:
    return x[0].sqr() + x[1].sqr() + x[2].sqr()


def minus(x: Vec, c) -> Vec:
    return tuple(x[k] - float(c[k]) for k in range(3))


def norm(x: Vec) -> Number:
    return dot_self(x).sqrt()


def fold(m, x: Vec) -> Vec:
    r = (dot(m[:3], x) - float(m[3])).relu()
    return tuple(x[k] - r * (2.0 * float(m[k])) for k in range(3))


def kernel(kind: str, rec, p: Vec) -> Number | None:
    """k_i(p); None for an empty kernel (no contribution to the minimum)."""
    if kind == "empty":
        return None
    if kind == "plane":
        return dot(rec[1, :3], p) - float(rec[1, 3])
    r = float(rec[1, 3])
    if kind == "sphere":
        return norm(minus(p, rec[1, :3])) - r
    A, B = rec[1, :3], rec[2, :3]
    if kind == "capsule":
        ab = B - A
        h = dot(ab, minus(p, A)) * (1.0 / max(float(ab @ ab), 1e-300))
        h = h.relu() - (h - 1.0).relu()                       # clamp to [0, 1]
        return norm(tuple(p[k] - float(A[k]) - h * float(ab[k]) for k in range(3))) - r
    # toroidal capsule: torus formula inside the wedge, else the nearer cap
    q = minus(p, rec[3, :3])
    x, y = dot(rec[4, :3], q), dot(rec[5, :3], q)
    cos_phi, sin_phi = float(rec[4, 3]), float(rec[5, 3])
    s = x * sin_phi - y * cos_phi
    planar = x.sqr() + y.sqr()
    z2 = (dot_self(q) - planar).relu()
    ring = ((planar.sqrt() - float(rec[3, 3])).sqr() + z2).sqrt()
    cap = norm(minus(p, A)).minimum(norm(minus(p, B)))
    ylo, yhi = y.range()
    slo, shi = s.range()
    if sin_phi >= 0.0:
        yes, no = (ylo >= 0) & (slo >= 0), (yhi < 0) | (shi < 0)
    else:
        yes, no = (ylo >= 0) | (slo >= 0), (yhi < 0) & (shi < 0)
    return ring.select(yes, no, cap) - r


def least(values) -> Number:
    """The minimum of the kernels' values, empty kernels (None) left out."""
    d = None
    for k in values:
        if k is not None:
            d = k if d is None else d.minimum(k)
    if d is None:
        raise ValueError("a scene without kernels")
    return d


def krs_distance(c: CompiledKRS, x: Vec) -> Number:
    def walk(x):
        yield kernel(c.types[c.n], c.records[c.n], x)
        for i in range(c.n - 1, -1, -1):
            x = fold(c.mirrors[i], x)
            yield kernel(c.types[i], c.records[i], x)
    return least(walk(x))


def qmul(p, q):
    """Quaternion product; each side four Numbers or four floats (real, i, j, k)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz, pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx, pw * qz + px * qy - py * qx + pz * qw)


def mobius_apply(H, x: Vec) -> Vec:
    """L_H(x) = (a q + b)(c q + d)⁻¹, q = (0, x) [KRS17 Eq. 1], as algebra/mobius.apply."""
    q = (0.0, *x)
    const = lambda v: tuple(float(c) for c in v)  # noqa: E731
    num = tuple(u + float(v) for u, v in zip(qmul(const(H[0, 0]), q), H[0, 1]))
    den = tuple(u + float(v) for u, v in zip(qmul(const(H[1, 0]), q), H[1, 1]))
    r = (den[0].sqr() + den[1].sqr() + den[2].sqr() + den[3].sqr()).recip()
    inv = (den[0] * r, -den[1] * r, -den[2] * r, -den[3] * r)
    return qmul(num, inv)[1:]


def mokrs_value(c: CompiledMoKRS, x: Vec) -> Number:
    """What a MöKRS draws, as a sign: min_i k_i(x_i), x_i the point followed inwards through
    H_i = G_i⁻¹ and folded to x ≤ 0 where the level reflects, as ISUNBOUNDING [KRS17 Alg. 3]
    tests it. Not a distance (the maps scale lengths) but continuous where the maps are
    defined (+∞ towards a pole), so its sign certifies surfaces and empty space alike."""
    def walk(x):
        for i in range(c.n - 1, -1, -1):
            x = mobius_apply(c.inverse[i], x)
            if c.reflect[i]:
                x = (-(x[0].relu() + (-x[0]).relu()), x[1], x[2])     # x ← −|x|
            yield kernel(c.types[i], c.records[i], x)
    return least(walk(x))


def scene_distance(c: CompiledKRS | CompiledCompound | CompiledMoKRS, x: Vec) -> Number:
    """The least over a compound's components, as the tracer draws it (a MöKRS: the sign
    function of :func:`mokrs_value`)."""
    if isinstance(c, CompiledMoKRS):
        return mokrs_value(c, x)
    parts = c.parts if isinstance(c, CompiledCompound) else (c,)
    d = krs_distance(parts[0], x)
    for part in parts[1:]:
        d = d.minimum(krs_distance(part, x))
    return d


def on_segments(origin, dirs, a, b, arithmetic: str) -> Vec:
    """The points origin + t·dir for t in [a, b] (arrays per segment; origin (3,) or one per
    segment): three intervals, or three affine forms in ε1 = (t − mid)/half."""
    o = np.asarray(origin, dtype=np.float64)
    if arithmetic == "interval":
        t = Interval(a, b)
        return tuple(t * dirs[:, k] + o[..., k] for k in range(3))
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    return tuple(Affine.rounded(o[..., k] + dirs[:, k] * mid, dirs[:, k] * half)
                 for k in range(3))


def in_box(center, half) -> Vec:
    """The box center ± half (arrays (N, 3), (N,)) as three intervals."""
    return tuple(Interval.outward(center[:, k] - half, center[:, k] + half) for k in range(3))
