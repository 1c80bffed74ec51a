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
safe_step) with k = |a(t)| and this ρ (Distortion.distance applies it). ε shrinks by
1/(1 + |a|ρ) as for the twist (lod_scale: with the largest |a| any time gives, ``most``, so the
shader computes no gust for it). The normal is Dgᵀ ∇D = R_A(θ) ∇D − a [h > 0] up ((A × s)·∇D).

Gusts: a_c(t) = radians(strength)/height · (1 + gust · n(t + c·WIND_PHASE/f)), with
n = Σ w_k sin(2π r_k f t) (scene/effects.py). A compound bends each component about its own
foot, with its own phase; an unbounded component (a ground plane) stands (a_c = 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compile.krs import grown, krs_ball
from ..scene import Compound, Scene
from ..scene.effects import WIND_PHASE, WIND_RATIOS, WIND_WEIGHTS, EffectSettings, wind_feet

UP = np.array([0.0, 1.0, 0.0])


@dataclass(frozen=True)
class Wind:
    axis: np.ndarray  # A, unit and horizontal (3,)
    rates: np.ndarray  # a_c(t) per component, radians per unit height (C,); 0: it stands
    bases: np.ndarray  # each component's foot b_c (C, 3)
    reach: np.ndarray  # how far each component gets from its foot; 0: it stands (C,)
    most: float  # the largest |a_c(t)| at any time: radians(strength)/height · (1 + gust)

    @staticmethod
    def of(scene: Scene) -> Wind:
        fx = scene.effect_settings
        w = np.array([fx.wind_direction[0], 0.0, fx.wind_direction[2]])
        geometry = scene.geometry()
        parts = geometry.parts if isinstance(geometry, Compound) else (geometry,)
        feet = wind_feet(scene, [grown(krs_ball(krs)) for krs in parts])
        reach = np.array([r for _, r in feet])
        phase = WIND_PHASE / fx.wind_frequency if fx.wind_frequency > 0 else 0.0
        return Wind(
            np.cross(UP, w / np.linalg.norm(w)),
            (reach > 0) * wind_rate(fx, scene.time + phase * np.arange(len(feet))),
            np.array([b for b, _ in feet], dtype=float),
            reach,
            float(np.radians(fx.wind_strength) / fx.wind_height * (1.0 + fx.wind_gust)),
        )

    def wind_rho(self, c, p: np.ndarray) -> np.ndarray:
        """Distance from the points p (N, 3) to component c's axis line (c: int or (N,))."""
        return np.linalg.norm(np.cross(self.axis, p - self.bases[c]), axis=-1)

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
        shear = np.einsum("ij,ij->i", np.cross(self.axis, q - self.bases[c]), g)
        n[:, 1] -= np.where(above, a * shear, 0.0)
        return n / np.linalg.norm(n, axis=1, keepdims=True)

    def lod_scale(self, p: np.ndarray) -> np.ndarray:
        """1 / (1 + most·ρ): ε shrinks as the step does to first order (distortion.py,
        lod_scale), at any time. ρ: to the farthest axis of the components within whose
        reach p lies; elsewhere no component can stop a ray, so ε stays (a ground's)."""
        rho2 = np.zeros(len(p))  # squared: ρ² = |r|² − (A·r)²
        for c in np.flatnonzero(self.reach):
            r = p - self.bases[c]
            rr = np.einsum("ij,ij->i", r, r)
            near = rr <= self.reach[c] ** 2
            rho2 = np.where(near, np.maximum(rho2, rr - (r @ self.axis) ** 2), rho2)
        return 1.0 / (1.0 + self.most * np.sqrt(rho2))


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
    return np.cross(axis, v) * s + (np.outer(v @ axis, axis) - v) * (2.0 * h * h)
