"""Wind: a time-dependent Lipschitz bend of space [KRS17 §5.2, §10], the main bending of
vegetation in games (GPU Gems 3 ch. 16) as a deformation a distance bound survives. Twin of
``shaders/wind.glsl``.

With w the wind direction made horizontal, up = +y and A = normalize(up × w) (a horizontal
axis; turning about it by a positive angle takes up towards w), component c's world→rest map is

    g(p) = b + R_A(−θ) (p − b),   θ = a_c(t) · max(h, 0),   h = (p − b)·up,

a turn about the axis line through its foot b by an angle growing with the height above it: a
point at height h moves by about a·h², the foot stays, and |g(p) − b| = |p − b| (no stretching).
The world geometry at time t is {x : g(x) ∈ rest geometry}.

Bound. With s = g(p) − b, ∂/∂θ R_A(−θ)(p − b) = −A × s and ∇θ = a·up above the foot (0 below):

    Dg = R_A(−θ) − a [h > 0] (A × s) upᵀ,   ‖Dg‖ ≤ 1 + |a| ρ,

ρ = |A × s| = |A × (p − b)|, the distance from p to the axis line (a turn about A keeps it).
So over the ball of radius δ around p, ‖Dg‖ ≤ 1 + |a|(ρ + δ), and g maps that ball into the
ball of radius D around g(p) when δ(1 + |a|(ρ + δ)) = D: the twist's step (distortion.py,
safe_step) with k = |a(t)| and this ρ (Distortion.distance applies it). Far from the
component that step is shortened for nothing: a bent point lies within its reach of b, so it
turns by at most θ ≤ most·reach, and the rest ball turned by every such angle lies in one
ball (scene/effects.py, swept_ball) whose distance, unshrunk, bounds the step from below
too. ε shrinks by 1/(1 + |a|ρ) as for the twist, at its least (lod_scale: most·reach, the
largest |a| any time gives and the largest ρ near a component). The normal is
Dgᵀ ∇D = R_A(θ) ∇D − a [h > 0] up ((A × s)·∇D).

Tighter. Dg = R_A(−θ)(I + x upᵀ) with x = −a (A × r), r = p − b; so ‖Dg‖ = ‖I + x upᵀ‖, which
in the basis (up, the unit e of x's part ⊥ up) is [[1 + α, 0], [γ, 1]], α = x·up = a (ŵ·r)
(ŵ = A × up, the wind), β = |x| = |a|ρ, γ² = β² − α²: its largest singular value is
(β + √(4 + 4α + β²))/2 (``stretch``), increasing in α and β, and at most 1 + (β + α⁺)/2 + β²/8
(square both sides). Over the ball of radius δ ≤ D, α⁺ ≤ |a|((ŵ·r)⁺ + δ) and β ≤ |a|(ρ + δ) ≤
|a|(ρ + D), so ‖Dg‖ ≤ 1 + |a|(ρ' + δ) with ρ' = (ρ + (ŵ·r)⁺)/2 + |a|(ρ + D)²/8: the step's ρ is
the smaller of ρ and ρ' (``wind_rho``), about half the distance to the axis above the foot.

A MöKRS has no distance [KRS17 §7]: its binary tracer asks whether a world ball B(p, r) is
free. g is L-Lipschitz on the ball, L = 1 + |a|(ρ' + r) (ρ' from ``wind_rho`` with D = r),
so it maps the ball into B(g(p), L·r), and B(p, r) is free of the bent geometry when that
ball is free of the rest geometry (``rest_ball``; mokrs.py, is_unbounding), or when it misses
the swept ball. It is one component, its foot ``wind_base``, its reach from its outermost
level bound (``rest_balls``); its normal is Dgᵀ of the rest normal at g(p), as for a KRS.

Gusts: a_c(t) = radians(strength)/height · (1 + gust · n(t + c·WIND_PHASE/f)), with
n = Σ w_k sin(2π r_k f t) (scene/effects.py). A compound bends each component about its own
foot, with its own phase; an unbounded component (a ground plane) stands (a_c = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algebra.vectors import cross
from ..compile.balls import grown, krs_ball
from ..compile.mokrs import bounds_in_and_out
from ..scene import Compound, MoKRS, Scene
from ..scene.effects import (
    WIND_PHASE,
    WIND_RATIOS,
    WIND_WEIGHTS,
    EffectSettings,
    swept_ball,
    wind_feet,
)

UP = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class Wind:
    axis: np.ndarray  # A, unit and horizontal (3,)
    rates: np.ndarray  # a_c(t) per component, radians per unit height (C,); 0: it stands
    bases: np.ndarray  # each component's foot b_c (C, 3)
    reach: np.ndarray  # how far each component gets from its foot; 0: it stands (C,)
    most: float  # the largest |a_c(t)| at any time: radians(strength)/height · (1 + gust)
    balls: np.ndarray  # per component a ball holding it bent at any time (C, 4); r < 0: none

    @staticmethod
    def of(scene: Scene) -> Wind:
        fx = scene.effect_settings
        w = np.array([fx.wind_direction[0], 0.0, fx.wind_direction[2]])
        balls = rest_balls(scene.geometry())
        feet = wind_feet(scene, balls)
        reach = np.array([r for _, r in feet])
        phase = WIND_PHASE / fx.wind_frequency if fx.wind_frequency > 0 else 0.0
        axis = cross(UP, w / np.linalg.norm(w))
        most = float(np.radians(fx.wind_strength) / fx.wind_height * (1.0 + fx.wind_gust))
        return Wind(
            axis,
            (reach > 0) * wind_rate(fx, scene.time + phase * np.arange(len(feet))),
            np.array([b for b, _ in feet], dtype=float),
            reach,
            most,
            np.array([swept_ball(b, r, ball, axis, most) for (b, r), ball in zip(feet, balls)]),
        )

    def wind_rho(self, c, p: np.ndarray, D: np.ndarray) -> np.ndarray:
        """The ρ of the step's bound 1 + |a|(ρ + δ) at the points p (N, 3) for component c
        (int or (N,)) with free radii D: the distance to the axis line, or where smaller
        (ρ + (ŵ·r)⁺)/2 + |a|(ρ + D⁺)²/8 (module docstring, Tighter)."""
        r = p - self.bases[c]
        rho = np.linalg.norm(cross(self.axis, r), axis=-1)
        along = np.maximum(r @ cross(self.axis, UP), 0.0)
        far = rho + np.maximum(D, 0.0)
        return np.minimum(rho, 0.5 * (rho + along) + 0.125 * np.abs(self.rates[c]) * far**2)

    def rest_ball(self, c, p: np.ndarray, r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """A ball (centres, radii) holding g(B(p, r)) for the balls p (N, 3), r (N,) of
        component c: B(g(p), L·r) with L = 1 + |a|(ρ + r) the bound of ‖Dg‖ over the ball (ρ
        from ``wind_rho`` with D = r), so B(p, r) is free of the bent geometry when that ball
        is free of the rest geometry: the MöKRS's unbounding test (mokrs.py) in the wind."""
        L = 1.0 + np.abs(self.rates[c]) * (self.wind_rho(c, p, r) + r)
        return self.unwind(c, p), L * r

    def stretch(self, c, p: np.ndarray) -> np.ndarray:
        """‖Dg‖ at the points p (N, 3), exactly: (β + √(4 + 4α + β²))/2 (module docstring)."""
        r = p - self.bases[c]
        a = np.where(r[:, 1] > 0.0, self.rates[c], 0.0)
        alpha = a * (r @ cross(self.axis, UP))
        beta = np.abs(a) * np.linalg.norm(cross(self.axis, r), axis=-1)
        return 0.5 * (beta + np.sqrt(4.0 + 4.0 * alpha + beta**2))

    def wind_ball_distance(self, c, p: np.ndarray) -> np.ndarray:
        """Distance from the points p (N, 3) to component c's swept ball, a lower bound of
        the distance to it bent at any time that needs no shrinking (−inf: none)."""
        ball = self.balls[c]
        d = np.linalg.norm(p - ball[..., :3], axis=-1) - ball[..., 3]
        return np.where(ball[..., 3] < 0.0, -np.inf, d)

    def unwind(self, c, p: np.ndarray) -> np.ndarray:
        """g: where component c's rest geometry is looked up for world points p (N, 3)."""
        r = p - self.bases[c]
        theta = self.rates[c] * np.maximum(r[:, 1], 0.0)
        return p + wind_turn(r, self.axis, -theta)

    def wind_normal(self, c, p: np.ndarray, q: np.ndarray, g: np.ndarray) -> np.ndarray:
        """World normal Dgᵀ g from the gradient g at q = g(p) (module docstring)."""
        r = p - self.bases[c]
        a = self.rates[c] * np.ones(len(p))
        above = r[:, 1] > 0.0
        n = g + wind_turn(g, self.axis, a * np.maximum(r[:, 1], 0.0))
        shear = np.einsum("ij,ij->i", cross(self.axis, q - self.bases[c]), g)
        n[:, 1] -= np.where(above, a * shear, 0.0)
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def lod_scale(self, p: np.ndarray) -> np.ndarray:
        """1 / (1 + most·reach), reach the largest: the least the step's shrink 1 / (1 + |a|ρ)
        gets at any time and point, so ε shrinks with it (distortion.py, lod_scale) by one
        factor for the frame, which the shader reads without a loop over the components."""
        return np.full(len(p), 1.0 / (1.0 + self.most * self.reach.max()))


def rest_balls(geometry) -> list[np.ndarray]:
    """The ball around each component at rest (world; radius < 0: unbounded), which sets its
    reach: a KRS's (CompiledKRS.ball), or a MöKRS's outermost level bound mapped out into the
    world (compile/mokrs.py, bounds_in_and_out), which holds all of it."""
    if isinstance(geometry, MoKRS):
        return [bounds_in_and_out(geometry)[1][-1]]
    parts = geometry.parts if isinstance(geometry, Compound) else (geometry,)
    return [grown(krs_ball(krs)) for krs in parts]


def wind_rate(fx: EffectSettings, t: np.ndarray) -> np.ndarray:
    """a(t) = radians(strength)/height · (1 + gust · n(t)), radians per unit height."""
    a0 = np.radians(fx.wind_strength) / fx.wind_height
    return a0 * (1.0 + fx.wind_gust * wind_gust(t, fx.wind_frequency))


def wind_gust(t: np.ndarray, frequency: float) -> np.ndarray:
    """n(t) = Σ w_k sin(2π r_k f t), the gusts' sway about the mean lean, |n| ≤ 1."""
    f = 2.0 * np.pi * frequency * np.array(WIND_RATIOS)
    return np.sin(np.multiply.outer(t, f)) @ np.array(WIND_WEIGHTS)


def wind_turn(v: np.ndarray, axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """How far the vectors v (N, 3) move when turned about the unit axis by ``angle`` (N,):
    Rodrigues' formula less v, with 1 − cos = 2 sin²(angle/2) against cancellation; exactly 0
    at angle 0, so an idle wind leaves every point as it is."""
    s, h = np.sin(angle)[:, None], np.sin(0.5 * angle)[:, None]
    return cross(axis, v) * s + (np.outer(v @ axis, axis) - v) * (2.0 * h * h)


def exit_fall(D: np.ndarray, a: np.ndarray, rho: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The balls' exits' first bound in the wind (trace.glsl, bound_ahead): from a point's
    undistorted distance D, rate |a| and axis distance ρ, (d0, fall) with the stepped distance
    s further along any ray ≥ d0 − fall·s while that is ≥ 0. g moves the rest point by at
    most sΛ, Λ = 1 + |a|ρ, so the undistorted distance stays ≥ E = D − sΛ (D 1-Lipschitz, as
    the exits assume), and the step ≥ E / (1 + |a|(ρ + s + E)) ≥ E / m, m = 1 + |a|(ρ + D/Λ
    + D), for s ≤ D/Λ; d0 = D/m, fall = Λ/m."""
    lam = 1.0 + a * rho
    m = 1.0 + a * (rho + D / lam + D)
    return D / m, lam / m
