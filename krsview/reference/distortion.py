"""Distortions of what a KRS draws: twist and wind (wind.py), Lipschitz distance distortions
[KRS17 §5.2, Har96], and empty zones [KRS17 §8.4]. Twin of ``shaders/twist.glsl``,
``shaders/empty_zones.glsl`` and ``shaders/distance.glsl``.

A twist turns the point at height h above the axis point by k·h around the vertical axis.
Its inverse g has Jacobian ‖Dg‖ ≤ 1 + |k|ρ at axis distance ρ (a shear of size |k|ρ), so the
KRS distance D at g(p) becomes a safe step δ at p by solving δ(1 + |k|(ρ + δ)) = D: every
point of the ball of radius δ around p maps into the free ball of radius D around g(p).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import Scene
from .wind import Wind


@dataclass(frozen=True)
class Distortion:
    twist: float  # radians per unit height; 0 when the effect is off
    center: np.ndarray  # a point on the twist axis (world)
    zones: np.ndarray  # (Z, 4) empty zones: centre, radius (world)
    wind: Wind | None = None  # the bend per component at the scene's time (wind.py)

    @staticmethod
    def of(scene: Scene) -> Distortion | None:
        """The scene's distortion, or None when it lists none of twist, wind, empty_zones."""
        fx = scene.effect_settings
        twist = "twist" in scene.effects
        zones = "empty_zones" in scene.effects
        wind = "wind" in scene.effects
        if not (twist or zones or wind):
            return None
        z = np.array([[*e.center, e.radius] for e in fx.empty_zones]) if zones else ()
        return Distortion(
            np.radians(fx.twist) if twist else 0.0,
            np.array(fx.twist_center, dtype=float),
            np.reshape(z, (-1, 4)),
            Wind.of(scene) if wind else None,
        )

    def untwist(self, p: np.ndarray) -> np.ndarray:
        """g = f⁻¹: where the undistorted KRS is looked up for world points p (N, 3)."""
        r = p - self.center
        a = -self.twist * r[:, 1]
        cos, sin = np.cos(a), np.sin(a)
        return self.center + np.stack(
            [r[:, 0] * cos - r[:, 2] * sin, r[:, 1], r[:, 0] * sin + r[:, 2] * cos], axis=1
        )

    def twist_step(self, p: np.ndarray, D: np.ndarray) -> np.ndarray:
        """The safe step at p from the undistorted distance D at g(p) (module docstring)."""
        rho = np.hypot(p[:, 0] - self.center[0], p[:, 2] - self.center[2])
        return safe_step(D, abs(self.twist), rho)

    def twist_normal(self, p: np.ndarray, q: np.ndarray, g: np.ndarray) -> np.ndarray:
        """World normal Dgᵀ g from the gradient g at q = g(p); only Dg's y column (a tangent
        of length |k|ρ) is not a rotation."""
        r, s = p - self.center, q - self.center
        a = self.twist * r[:, 1]  # Rᵀ = rotation by −(−k·h)
        cos, sin = np.cos(a), np.sin(a)
        gy = g[:, 1] - self.twist * (-s[:, 2] * g[:, 0] + s[:, 0] * g[:, 2])
        w = np.stack([g[:, 0] * cos - g[:, 2] * sin, gy, g[:, 0] * sin + g[:, 2] * cos], axis=1)
        return w / np.linalg.norm(w, axis=1, keepdims=True)

    def zone_depth(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """How deep each point is inside its deepest empty zone, r − |p − c| (−inf with no
        zones), and that zone's index."""
        if len(self.zones) == 0:
            return np.full(len(p), -np.inf), np.zeros(len(p), dtype=np.int64)
        depth = self.zones[:, 3] - np.linalg.norm(p[:, None, :] - self.zones[:, :3], axis=2)
        k = np.argmax(depth, axis=1)
        return depth[np.arange(len(p)), k], k

    def lod_scale(self, p: np.ndarray) -> np.ndarray:
        """The wind's (wind.py), or 1 / (1 + |k|ρ): the twist's safe step is D / (1 + |k|ρ)
        to first order, so a ray
        that converged on it at ε(t) stopped up to (1 + |k|ρ)·ε(t) from the surface — far from
        the axis, high above a twisted ground (the horizon rose). Scaling ε by the same factor
        makes it converge where the undistorted distance is within ε(t)."""
        if self.wind is not None:
            return self.wind.lod_scale(p)
        if self.twist == 0.0:
            return np.ones(len(p))
        rho = np.hypot(p[:, 0] - self.center[0], p[:, 2] - self.center[2])
        return 1.0 / (1.0 + abs(self.twist) * rho)

    def undistort(self, p: np.ndarray, c=0) -> np.ndarray:
        """Where component c (an index, or one per point) is looked up for world points p."""
        if self.wind is not None:
            return self.wind.unwind(c, p)
        return self.untwist(p) if self.twist != 0.0 else p

    def distance(self, p: np.ndarray, D: np.ndarray, c=0) -> np.ndarray:
        """From component c's undistorted distance D at undistort(p, c) to a bound that never
        overshoots: the twist's or the wind's step (or, if larger, the distance to the wind's
        swept ball), then max(·, depth in a zone) (what is left lies outside every zone)."""
        if self.twist != 0.0:
            D = self.twist_step(p, D)
        if self.wind is not None:
            D = safe_step(D, np.abs(self.wind.rates[c]), self.wind.wind_rho(c, p, D))
            D = np.maximum(D, self.wind.wind_ball_distance(c, p))
        return np.maximum(D, self.zone_depth(p)[0])

    def normal(self, p: np.ndarray, q: np.ndarray, D: np.ndarray, g: np.ndarray, c=0) -> np.ndarray:
        """World normal at p of component c: the twisted or bent kernel normal, or on a
        zone's cut face the zone's inward sphere normal."""
        if self.twist != 0.0:
            g = self.twist_normal(p, q, g)
        if self.wind is not None:
            g = self.wind.wind_normal(c, p, q, g)
        depth, k = self.zone_depth(p)
        cut = depth > D
        if cut.any():
            inward = self.zones[k[cut], :3] - p[cut]
            g = g.copy()
            g[cut] = inward / np.linalg.norm(inward, axis=1, keepdims=True)
        return g


def safe_step(D: np.ndarray, k, rho: np.ndarray) -> np.ndarray:
    """The δ with δ(1 + k(ρ + δ)) = D, in its cancellation-free form 2D / (a + √(a² + 4kD)),
    a = 1 + kρ: the step that stays in the free ball of radius D through a map whose Jacobian
    is at most 1 + k·(distance to its axis) (module docstring, wind.py); D itself when D ≤ 0."""
    a = 1.0 + k * rho
    step = 2.0 * D / (a + np.sqrt(a * a + 4.0 * k * np.maximum(D, 0.0)))
    return np.where(D <= 0.0, D, step)
