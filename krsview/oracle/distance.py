"""[KRS17 Alg. 1] over reliable numbers: the same kernels, folds and minimum as
``reference/krs.py``, written once for :class:`Interval` and :class:`Affine` (the operations
they share). A fold is x − 2·max(0, u·x − w)·u, its conditional turned into a max as RAA09
writes them; the toroidal capsule's wedge test takes the hull of both branches where the
range cannot decide it. The result encloses the real-number value of the distance the tracer
approximates, on the compiled scene's exact float64 constants (an arc's frame taken as the
float64 matrix of its record's quaternion). A :class:`Moved` geometry
looks each component up through a map from the world into its rest space (the wind's bend,
``oracle/wind.py``): the walk and its balls then run on the map's enclosure, unchanged."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compile.krs import CompiledCompound, CompiledKRS
from ..compile.lod import cut_depth, krs_lod
from ..compile.mokrs import CompiledMoKRS
from ..reference.kernels import arc_half_angle, arc_local
from .numbers import Affine, Interval, Number

Vec = tuple  # three Numbers


@dataclass(frozen=True)
class Moved:
    """A compiled geometry whose component i is drawn where ``maps[i]`` (world → its rest
    space, over Numbers; None: it stands) takes a world point into it: the world geometry is
    {x : maps[i](x) ∈ component i}, so an enclosure of maps[i](X) is all its walk needs."""

    geometry: CompiledKRS | CompiledCompound | CompiledMoKRS
    maps: tuple[Callable[[Vec], Vec] | None, ...]


def placed(c) -> list[tuple[CompiledKRS | CompiledMoKRS, Callable[[Vec], Vec] | None]]:
    """Each component of ``c`` with the map that takes world points into it (None: none)."""
    moved = isinstance(c, Moved)
    g = c.geometry if moved else c
    parts = g.parts if isinstance(g, CompiledCompound) else (g,)
    return list(zip(parts, c.maps if moved else (None,) * len(parts), strict=True))


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
    if kind == "capsule":
        A, B = rec[1, :3], rec[2, :3]
        ab = B - A
        h = dot(ab, minus(p, A)) * (1.0 / max(float(ab @ ab), 1e-300))
        h = h.relu() - (h - 1.0).relu()  # clamp to [0, 1]
        return norm(tuple(p[k] - float(A[k]) - h * float(ab[k]) for k in range(3))) - r
    # toroidal capsule, in the arc's frame in units of R (reference/kernels.py): the circle
    # inside the wedge x ≥ ρ·cos(phi/2), else the nearer end
    L = arc_local(rec[2], np.eye(3))  # rows: the frame's coordinates of the world's axes
    q = minus(p, rec[1, :3])
    x, y, z = (dot(L[:, k], q) for k in range(3))
    c, s = arc_half_angle(rec)
    rho = (x.sqr() + y.sqr()).sqrt()
    z2 = z.sqr()
    ring = ((rho - 1.0).sqr() + z2).sqrt()
    dx2 = (x - c).sqr() + z2
    cap = (dx2 + (y - s).sqr()).sqrt().minimum((dx2 + (y + s).sqr()).sqrt())
    lo, hi = (x - rho * c).range()
    return ring.select(lo >= 0, hi < 0, cap) * (1.0 / float(rec[2] @ rec[2])) - r


def least(values) -> Number:
    """The minimum of the kernels' values, empty kernels (None) left out."""
    d = None
    for k in values:
        if k is not None:
            d = k if d is None else d.minimum(k)
    if d is None:
        raise ValueError("a scene without kernels")
    return d


def qmul(p, q):
    """Quaternion product; each side four Numbers or four floats (real, i, j, k)."""
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    )


def mobius_apply(H, x: Vec) -> Vec:
    """L_H(x) = (a q + b)(c q + d)⁻¹, q = (0, x) [KRS17 Eq. 1], as algebra/mobius.apply."""
    q = (0.0, *x)
    const = lambda v: tuple(float(c) for c in v)  # noqa: E731
    num = tuple(u + float(v) for u, v in zip(qmul(const(H[0, 0]), q), H[0, 1]))
    den = tuple(u + float(v) for u, v in zip(qmul(const(H[1, 0]), q), H[1, 1]))
    r = (den[0].sqr() + den[1].sqr() + den[2].sqr() + den[3].sqr()).recip()
    inv = (den[0] * r, -den[1] * r, -den[2] * r, -den[3] * r)
    return qmul(num, inv)[1:]


def steps(c: CompiledKRS | CompiledMoKRS):
    """The walk as (ball, cuts, move, kind, record) per kernel, outermost first: ``move``
    takes the point into the kernel's frame; ``ball`` (centre, radius, in the frame before
    ``move``; None: no bound) holds everything this and the later steps test; ``cuts(lod)``
    says per element whether the level of detail ``lod`` (world lengths) ends the walk at
    that ball.

    KRS [KRS17 Alg. 1]: the top kernel, then per level i a fold and k_i; the ball is the
    culling ball C_i (``compile/balls.krs_bounds``), cut at depth k*(lod) below the top
    (``compile/lod.cut_depth``). MöKRS [KRS17 Alg. 3]: per level
    x ← H_i(x), folded to x ≤ 0 where it reflects, then k_i; the ball is the level's bound
    mapped out by G_i = H_i⁻¹ (``reference/mokrs.bounds_in_and_out``), so it is tested before
    H_i, where a pole of H_i is not; it is cut where its radius in world lengths is at most
    lod (never where the frame's scale varies)."""
    if isinstance(c, CompiledMoKRS):
        for i in range(c.n - 1, -1, -1):
            ball = c.outer[i] if c.outer[i, 3] >= 0 else None
            move = lambda x, H=c.inverse[i], r=c.reflect[i]: inwards(H, r, x)  # noqa: E731
            yield ball, lambda lod, s=c.outer_size[i]: s <= lod, move, c.types[i], c.records[i]
        return
    yield None, None, lambda x: x, c.types[c.n], c.records[c.n]
    for i in range(c.n - 1, -1, -1):
        ball = c.bounds[i] if c.bounds[i, 3] >= 0 else None
        yield (
            ball,
            lambda lod, k=c.n - 1 - i: k >= cut_depth(c.lod_cut, lod),
            lambda x, m=c.mirrors[i]: fold(m, x),
            c.types[i],
            c.records[i],
        )


def inwards(H, reflect: bool, x: Vec) -> Vec:
    """One MöKRS level inwards: x ← H(x), then −|x| where the level reflects."""
    x = mobius_apply(H, x)
    if reflect:
        x = (-(x[0].relu() + (-x[0]).relu()), x[1], x[2])  # x ← −|x|
    return x


def value(c: CompiledKRS | CompiledCompound | CompiledMoKRS | Moved, x: Vec) -> Number:
    """The whole walk as one Number: Alg. 1's distance, or for a MöKRS min_i k_i(x_i), x_i
    the point followed inwards as Alg. 3 tests it — not a distance (the maps scale lengths)
    but continuous where the maps are defined (+∞ towards a pole), so its sign certifies
    surfaces and empty space alike. A compound takes the least over its components; a
    :class:`Moved` one walks each from its map's image of x (a sign, not a distance)."""

    def terms(part, x):
        for _, _, move, kind, rec in steps(part):
            x = move(x)
            yield kernel(kind, rec, x)

    return least(k for part, g in placed(c) for k in terms(part, x if g is None else g(x)))


@dataclass
class Bounds:
    """Per batch element, what the walk certifies about the scene's value v (only signs are
    used): ``lo`` ≤ v from the kernels walked and the balls found clear; ``hi`` ≥ v from the
    kernels walked (a subset of the scene); ``cut`` ≤ v from the balls of levels left out
    at the level of detail (+∞ where none), so v ≥ min(lo, cut)."""

    lo: np.ndarray
    hi: np.ndarray
    cut: np.ndarray

    @property
    def lower(self) -> np.ndarray:
        return np.minimum(self.lo, self.cut)


def bounds(
    c: CompiledKRS | CompiledCompound | CompiledMoKRS | Moved,
    x: Vec,
    lod: np.ndarray | None = None,
) -> Bounds:
    """Bounds of the value over the batch ``x`` walked with the levels' balls: where a
    point's ball lies clear (its enclosure > 0) the levels below cannot reach 0 and its
    walk ends (culling, which for a MöKRS also steps around the poles); with ``lod`` (a
    length per element) a walk also ends at the ball where it cuts (:func:`steps`), whose
    distance then stands for the levels below — detail smaller than the level of detail
    asked for.
    A :class:`Moved` component is walked from its map's enclosure of x, in its rest space,
    where its balls are: a ball clear of that enclosure is clear of every mapped point."""
    n = x[0].size
    out = Bounds(np.full(n, np.inf), np.full(n, np.inf), np.full(n, np.inf))
    for part, g in placed(c):
        rows, y = np.arange(n), x if g is None else g(x)
        for ball, cuts, move, kind, rec in steps(part):
            if ball is not None:
                blo = (norm(minus(y, ball[:3])) - float(ball[3])).range()[0]
                # a KRS's balls are not nested (compile/balls.py): with a level of detail, a
                # ball cut below reaches up to its diameter beyond this one; a MöKRS's are
                # nested
                reach = (
                    0.0
                    if lod is None or isinstance(part, CompiledMoKRS)
                    else krs_lod(part, lod[rows])[1]
                )
                clear = blo > reach  # NaN: not clear
                cut = ~clear & cuts(lod[rows]) if lod is not None else np.zeros_like(clear)
                out.lo[rows[clear]] = np.minimum(out.lo[rows[clear]], blo[clear])
                out.cut[rows[cut]] = np.minimum(out.cut[rows[cut]], blo[cut])
                if (clear | cut).any():
                    keep = ~(clear | cut)
                    rows, y = rows[keep], tuple(v.take(keep) for v in y)
                    if not rows.size:
                        break
            y = move(y)
            k = kernel(kind, rec, y)
            if k is not None:
                klo, khi = k.range()
                out.lo[rows] = np.minimum(out.lo[rows], klo)
                out.hi[rows] = np.minimum(out.hi[rows], khi)
    return out


def on_segments(origin, dirs, a, b, arithmetic: str) -> Vec:
    """The points origin + t·dir for t in [a, b] (arrays per segment; origin (3,) or one per
    segment): three intervals, or three affine forms in ε1 = (t − mid)/half."""
    o = np.asarray(origin, dtype=np.float64)
    if arithmetic == "interval":
        t = Interval(a, b)
        return tuple(t * dirs[:, k] + o[..., k] for k in range(3))
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    return tuple(Affine.rounded(o[..., k] + dirs[:, k] * mid, dirs[:, k] * half) for k in range(3))


def in_box(center, half) -> Vec:
    """The box center ± half (arrays (N, 3), (N,)) as three intervals."""
    return tuple(Interval.outward(center[:, k] - half, center[:, k] + half) for k in range(3))
