"""Distortions of what a KRS draws: twist, a Lipschitz distance distortion [KRS17 §5.2,
Har96], and empty zones [KRS17 §8.4]. Twin of ``shaders/twist.glsl``,
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


@dataclass(frozen=True)
class Distortion:
    twist: float  # radians per unit height; 0 when the effect is off
    center: np.ndarray  # a point on the twist axis (world)
    zones: np.ndarray  # (Z, 4) empty zones: centre, radius (world)

    @staticmethod
    def of(scene: Scene) -> Distortion | None:
        """The scene's distortion, or None when it lists neither twist nor empty_zones."""
        fx = scene.effect_settings
        twist = "twist" in scene.effects
        zones = "empty_zones" in scene.effects
        if not (twist or zones):
            return None
        z = np.array([[*e.center, e.radius] for e in fx.empty_zones]) if zones else ()
        return Distortion(
            np.radians(fx.twist) if twist else 0.0,
            np.array(fx.twist_center, dtype=float),
            np.reshape(z, (-1, 4)),
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
        k = abs(self.twist)
        a = 1.0 + k * np.hypot(p[:, 0] - self.center[0], p[:, 2] - self.center[2])
        step = 2.0 * D / (a + np.sqrt(a * a + 4.0 * k * np.maximum(D, 0.0)))
        return np.where(D <= 0.0, D, step)

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
        """1 / (1 + |k|ρ): the twist's safe step is D / (1 + |k|ρ) to first order, so a ray
        that converged on it at ε(t) stopped up to (1 + |k|ρ)·ε(t) from the surface — far from
        the axis, high above a twisted ground (the horizon rose). Scaling ε by the same factor
        makes it converge where the undistorted distance is within ε(t)."""
        if self.twist == 0.0:
            return np.ones(len(p))
        rho = np.hypot(p[:, 0] - self.center[0], p[:, 2] - self.center[2])
        return 1.0 / (1.0 + abs(self.twist) * rho)

    def undistort(self, p: np.ndarray) -> np.ndarray:
        return self.untwist(p) if self.twist != 0.0 else p

    def distance(self, p: np.ndarray, D: np.ndarray) -> np.ndarray:
        """From the undistorted distance D at undistort(p) to a bound that never overshoots:
        the twist step, then max(·, depth in a zone) (what is left lies outside every zone)."""
        if self.twist != 0.0:
            D = self.twist_step(p, D)
        return np.maximum(D, self.zone_depth(p)[0])

    def normal(self, p: np.ndarray, q: np.ndarray, D: np.ndarray, g: np.ndarray) -> np.ndarray:
        """World normal at p: the twisted kernel normal, or on a zone's cut face the zone's
        inward sphere normal."""
        if self.twist != 0.0:
            g = self.twist_normal(p, q, g)
        depth, k = self.zone_depth(p)
        cut = depth > D
        if cut.any():
            inward = self.zones[k[cut], :3] - p[cut]
            g = g.copy()
            g[cut] = inward / np.linalg.norm(inward, axis=1, keepdims=True)
        return g
