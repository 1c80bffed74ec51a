"""Reliable numbers for the oracle [RAA09]: intervals with outward rounding, and revised affine
forms x̂ = x0 + x1·ε1 ± e with one noise symbol ε1 ∈ [−1, 1] (the ray parameter over a
segment) and an accumulated error e ≥ 0. Both are vectorised (every field an array over a
batch of segments) and offer the same operations, so Alg. 1 is written once for both
(``oracle/distance.py``). Every operation's result contains every value the real operation
can take on its arguments (the inclusion property), float64 rounding included: intervals step
one ulp outwards (+, −, ×, √ are correctly rounded to within half an ulp), affine forms add
ROUNDING × their magnitude to e. sin and cos come from the platform's libm, trusted to within
TRIG_ROUNDING of their value (a few ulps; IEEE 754 leaves them unrounded), and widened by it.

Non-affine operations of the affine forms use the min-range (√) and Chebyshev (|x|, max(0, x))
approximations: f(x) ≈ αx + ζ ± δ over the argument's range [a, b], with f − αx monotone or
bounded by hand on [a, b] [RAA09 §3.4, dS97]; sin and cos take their tangent at the centre,
the remainder bounded by |f''| ≤ 1. Conditionals whose outcome the range cannot decide take
the hull of both branches, as RAA09 does.
"""

from __future__ import annotations

import numpy as np

ROUNDING = 2.0**-49  # relative error added per affine operation (≥ a few ulps of float64)
TRIG_ROUNDING = (2.0**-49, 2.0**-56)  # libm's sin/cos: within rel·|f| + abs of the true value
TRIG_RANGE = 2.0**20  # |x| past this: sin and cos are only known to lie in [−1, 1]


# Outward rounding by arithmetic: |x|·2⁻⁵² is at least x's ulp (exactly so, or a subnormal
# no smaller), and the least subnormal keeps 0 and subnormals moving, so in round-to-nearest
# x ± step is at least one float past x (two at most; three just above the subnormals). Nine
# times faster than np.nextafter, which was half of the oracle's time. Infinities stay where
# they are (|x| is capped first).
_ULP = 2.0**-52
_LEAST = float(np.finfo(np.float64).smallest_subnormal)
_LARGEST = float(np.finfo(np.float64).max)


def _step(x):
    return np.minimum(np.abs(x), _LARGEST) * _ULP + _LEAST


def _down(x):
    """A float below x (the infinities and NaN stay)."""
    return x - _step(x)


def _up(x):
    """A float above x (the infinities and NaN stay)."""
    return x + _step(x)


def _trig_slack(f):
    """How far libm's sin or cos value ``f`` may be from the true one (TRIG_ROUNDING)."""
    return np.abs(f) * TRIG_ROUNDING[0] + TRIG_ROUNDING[1]


def _holds(lo, hi, at: float) -> np.ndarray:
    """Whether [lo, hi] may hold a point at + 2πk (k an integer): the float64 test leans to
    yes by a slack larger than its rounding, which only widens what uses it."""
    slack = 1e-12 * (1.0 + np.abs(lo) + np.abs(hi))
    k = np.ceil((lo - slack - at) / (2.0 * np.pi))
    return at + 2.0 * np.pi * k <= hi + slack


def _periodic(lo, hi, f, peak: float) -> tuple[np.ndarray, np.ndarray]:
    """The range of f (sin or cos, 2π-periodic, f = 1 at ``peak``, −1 at peak + π) over
    [lo, hi]: its ends' values, and ±1 where a peak or trough may lie inside."""
    with np.errstate(invalid="ignore"):
        fa, fb = f(lo), f(hi)
        out_lo, out_hi = np.minimum(fa, fb), np.maximum(fa, fb)
        out_lo = np.maximum(out_lo - _trig_slack(out_lo), -1.0)
        out_hi = np.minimum(out_hi + _trig_slack(out_hi), 1.0)
        wide = ~(np.maximum(np.abs(lo), np.abs(hi)) <= TRIG_RANGE) & ~np.isnan(lo + hi)
        out_lo = np.where(_holds(lo, hi, peak + np.pi) | wide, -1.0, out_lo)
        out_hi = np.where(_holds(lo, hi, peak) | wide, 1.0, out_hi)
    return out_lo, out_hi


class Interval:
    """[lo, hi] per element; constants (float arrays) are exact degenerate intervals."""

    __slots__ = ("lo", "hi")

    def __init__(self, lo, hi=None):
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=np.float64)

    @staticmethod
    def outward(lo, hi) -> Interval:
        """[lo, hi] widened by an ulp each way (for bounds computed in float64)."""
        return Interval(_down(lo), _up(hi))

    @staticmethod
    def lift(x) -> Interval:
        return x if isinstance(x, Interval) else Interval(x)

    def range(self) -> tuple[np.ndarray, np.ndarray]:
        return self.lo, self.hi

    @property
    def size(self) -> int:
        return np.broadcast(self.lo, self.hi).size

    def take(self, keep: np.ndarray) -> Interval:
        """The elements where ``keep``."""
        return Interval(self.lo[keep], self.hi[keep])

    def __add__(self, o):
        o = Interval.lift(o)
        return Interval(_down(self.lo + o.lo), _up(self.hi + o.hi))

    __radd__ = __add__

    def __neg__(self):
        return Interval(-self.hi, -self.lo)

    def __sub__(self, o):
        return self + (-Interval.lift(o))

    def __rsub__(self, o):
        return Interval.lift(o) + (-self)

    def __mul__(self, o):
        o = Interval.lift(o)
        p = [self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi]
        return Interval(_down(np.minimum.reduce(p)), _up(np.maximum.reduce(p)))

    __rmul__ = __mul__

    def sqr(self):
        a, b = np.abs(self.lo), np.abs(self.hi)
        straddle = (self.lo < 0) & (self.hi > 0)
        lo = np.where(straddle, 0.0, np.minimum(a, b) ** 2)
        return Interval(np.maximum(_down(lo), 0.0), _up(np.maximum(a, b) ** 2))

    def sqrt(self):
        return Interval(
            np.maximum(_down(np.sqrt(np.maximum(self.lo, 0.0))), 0.0),
            _up(np.sqrt(np.maximum(self.hi, 0.0))),
        )

    def relu(self):
        return Interval(np.maximum(self.lo, 0.0), np.maximum(self.hi, 0.0))

    def recip(self):
        """1/x; the whole line where the interval holds 0."""
        safe = (self.lo > 0) | (self.hi < 0)
        lo = np.where(safe, _down(1.0 / np.where(safe, self.hi, 1.0)), -np.inf)
        hi = np.where(safe, _up(1.0 / np.where(safe, self.lo, 1.0)), np.inf)
        return Interval(lo, hi)

    def sin(self):
        return Interval(*_periodic(self.lo, self.hi, np.sin, 0.5 * np.pi))

    def cos(self):
        return Interval(*_periodic(self.lo, self.hi, np.cos, 0.0))

    def minimum(self, o):
        o = Interval.lift(o)
        return Interval(np.minimum(self.lo, o.lo), np.minimum(self.hi, o.hi))

    def hull(self, o):
        return Interval(np.minimum(self.lo, o.lo), np.maximum(self.hi, o.hi))

    def select(self, yes: np.ndarray, no: np.ndarray, other: Interval) -> Interval:
        """Where ``yes``: self; where ``no``: other; elsewhere the hull of both."""
        h = self.hull(other)
        return Interval(
            np.where(yes, self.lo, np.where(no, other.lo, h.lo)),
            np.where(yes, self.hi, np.where(no, other.hi, h.hi)),
        )


class Affine:
    """x0 + x1·ε1 ± e per element (revised affine form with one noise symbol)."""

    __slots__ = ("x0", "x1", "e")

    def __init__(self, x0, x1=0.0, e=0.0):
        self.x0 = np.asarray(x0, dtype=np.float64)
        self.x1 = np.broadcast_to(np.asarray(x1, dtype=np.float64), self.x0.shape)
        self.e = np.broadcast_to(np.asarray(e, dtype=np.float64), self.x0.shape)

    @staticmethod
    def lift(x) -> Affine:
        return x if isinstance(x, Affine) else Affine(x)

    @staticmethod
    def rounded(x0, x1, e=0.0) -> Affine:
        """The form with e grown by the rounding of the float64 computation of its parts."""
        return Affine(x0, x1, e + ROUNDING * (np.abs(x0) + np.abs(x1) + e))

    def range(self) -> tuple[np.ndarray, np.ndarray]:
        r = _up(np.abs(self.x1) + self.e)
        r = _up(r + ROUNDING * (np.abs(self.x0) + r))
        return _down(self.x0 - r), _up(self.x0 + r)

    @property
    def size(self) -> int:
        return self.x0.size

    def take(self, keep: np.ndarray) -> Affine:
        """The elements where ``keep``."""
        return Affine(self.x0[keep], self.x1[keep], self.e[keep])

    def interval(self) -> Interval:
        return Interval(*self.range())

    @staticmethod
    def of_interval(i: Interval) -> Affine:
        mid = 0.5 * (i.lo + i.hi)
        return Affine.rounded(mid, 0.0, np.maximum(i.hi - mid, mid - i.lo))

    def __add__(self, o):
        o = Affine.lift(o)
        return Affine.rounded(self.x0 + o.x0, self.x1 + o.x1, self.e + o.e)

    __radd__ = __add__

    def __neg__(self):
        return Affine(-self.x0, -self.x1, self.e)

    def __sub__(self, o):
        return self + (-Affine.lift(o))

    def __rsub__(self, o):
        return Affine.lift(o) + (-self)

    def __mul__(self, o):
        if not isinstance(o, Affine):  # by a constant: exact up to rounding
            c = np.asarray(o, dtype=np.float64)
            return Affine.rounded(c * self.x0, c * self.x1, np.abs(c) * self.e)
        # (x0 + x1ε + η)(y0 + y1ε + θ): the ε² term x1·y1·ε² lies in ±|x1·y1|
        e = (
            np.abs(self.x0) * o.e
            + np.abs(o.x0) * self.e
            + (np.abs(self.x1) + self.e) * (np.abs(o.x1) + o.e)
        )
        return Affine.rounded(self.x0 * o.x0, self.x0 * o.x1 + self.x1 * o.x0, e)

    __rmul__ = __mul__

    def sqr(self):
        # (x0 + x1ε + η)² = x0² + 2x0x1ε + x1²ε² + 2(x0 + x1ε)η + η², x1²ε² ∈ x1²/2 ± x1²/2
        h = 0.5 * self.x1 * self.x1
        e = h + 2.0 * (np.abs(self.x0) + np.abs(self.x1)) * self.e + self.e * self.e
        return Affine.rounded(self.x0 * self.x0 + h, 2.0 * self.x0 * self.x1, e)

    def _linearised(self, alpha, zeta, delta) -> Affine:
        """f(x) ≈ αx + ζ ± δ applied to this form."""
        return Affine.rounded(
            alpha * self.x0 + zeta, alpha * self.x1, np.abs(alpha) * self.e + delta
        )

    def sqrt(self):
        """Min-range: α = f'(b); f − αx increases on [a, b], so it spans [g(a), g(b)]."""
        a, b = self.range()
        a, b = np.maximum(a, 0.0), np.maximum(b, 0.0)
        pos = b > 0
        alpha = np.where(pos, 0.5 / np.sqrt(np.where(pos, b, 1.0)), 0.0)
        ga, gb = np.sqrt(a) - alpha * a, np.sqrt(b) - alpha * b
        lo, hi = np.minimum(ga, gb), np.maximum(ga, gb)
        return self._linearised(alpha, 0.5 * (lo + hi), 0.5 * (hi - lo))

    def recip(self):
        """Min-range on a range [a, b] without 0: α = f′ at the end farther from 0, where |f′|
        is least, so 1/x − αx is monotone on [a, b]; unbounded where the range holds 0."""
        a, b = self.range()
        safe = (a > 0) | (b < 0)
        far = np.where(safe, np.where(a > 0, b, a), 1.0)  # the end with the smaller |f'|
        near = np.where(safe, np.where(a > 0, a, b), 1.0)
        alpha = -1.0 / (far * far)
        g_far, g_near = 1.0 / far - alpha * far, 1.0 / near - alpha * near
        lo, hi = np.minimum(g_far, g_near), np.maximum(g_far, g_near)
        out = self._linearised(alpha, 0.5 * (lo + hi), 0.5 * (hi - lo))
        return Affine(
            np.where(safe, out.x0, 0.0), np.where(safe, out.x1, 0.0), np.where(safe, out.e, np.inf)
        )

    def sin(self):
        return self._trig(np.sin, np.cos, Interval.sin)

    def cos(self):
        return self._trig(np.cos, lambda x: -np.sin(x), Interval.cos)

    def _trig(self, f, df, of_range) -> Affine:
        """f(x) = f(x0) + f'(x0)(x − x0) ± r²/2 over x0 ± r (|f''| ≤ 1), where that is
        narrower than the interval form of f over the range (wide ranges)."""
        r = _up(np.abs(self.x1) + self.e)
        fx, alpha = f(self.x0), df(self.x0)
        slack = _trig_slack(fx) + _trig_slack(alpha) * r  # libm's f(x0) and f'(x0)
        tangent = Affine.rounded(fx, alpha * self.x1, np.abs(alpha) * self.e + 0.5 * r * r + slack)
        flat = Affine.of_interval(of_range(self.interval()))
        narrow = np.abs(tangent.x1) + tangent.e <= flat.e

        def pick(k: str) -> np.ndarray:
            return np.where(narrow, getattr(tangent, k), getattr(flat, k))

        return Affine(pick("x0"), pick("x1"), pick("e"))

    def relu(self):
        """Chebyshev: on a < 0 < b, max(0, x) − αx with α = b/(b − a) spans [0, −ab/(b − a)]."""
        a, b = self.range()
        straddle = (a < 0) & (b > 0)
        w = np.where(straddle, b - a, 1.0)
        alpha = np.where(straddle, b / w, np.where(a >= 0, 1.0, 0.0))
        top = np.where(straddle, -a * b / w, 0.0)
        return self._linearised(alpha, 0.5 * top, 0.5 * top)

    def minimum(self, o):
        """min(x, y) = x − max(0, x − y): exact where the ranges decide it."""
        o = Affine.lift(o)
        return self - (self - o).relu()

    def select(self, yes: np.ndarray, no: np.ndarray, other: Affine) -> Affine:
        """Where ``yes``: self; where ``no``: other; elsewhere the hull of both (as an
        interval, turned back into a form)."""
        h = Affine.of_interval(self.interval().hull(other.interval()))

        def pick(f: str) -> np.ndarray:
            return np.where(yes, getattr(self, f), np.where(no, getattr(other, f), getattr(h, f)))

        return Affine(pick("x0"), pick("x1"), pick("e"))


Number = Interval | Affine
