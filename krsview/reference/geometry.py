"""One interface over the compiled geometry families, so tracers and renderers need not
know which: give each component's distance or unbounding test to the tracer, find the nearest
kernel and its world normal. A single KRS or MöKRS is the compound of one [KRS17 §5.1]."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compile.geometry import Compiled, components
from ..compile.krs import CompiledCompound, CompiledKRS
from ..scene import Scene
from . import krs, mokrs
from .distortion import Distortion
from .trace import Distance, Test


@dataclass(frozen=True)
class Lod:
    """The level of detail as a field over space, ρ(x) = per_t · |x − eye| with per_t =
    render.lod × ε_per_t: the camera's pixel footprint there, so primary rays, shadow rays
    and occlusion meet the same geometry (krs.distance says which); a test of a ball takes
    ρ at its far side, the most any of its points has. Twin of lod_radius in lod.glsl."""

    eye: np.ndarray
    per_t: float

    @staticmethod
    def of(lod: float, eye: np.ndarray, eps_per_t: float) -> Lod | None:
        return Lod(np.asarray(eye, dtype=np.float64), lod * eps_per_t) if lod > 0 else None

    def radius(self, x: np.ndarray, reach: np.ndarray | float = 0.0) -> np.ndarray:
        """ρ at the points x (N, 3), or at the far side of balls of radius ``reach``."""
        return self.per_t * (np.linalg.norm(x - self.eye, axis=1) + reach)


@dataclass(frozen=True)
class Bounds:
    """Per component, what holds everything it draws: a ball (C, 4; radius < 0: none) and a
    half-space u·x ≤ w (C, 4; u = 0: none), as the GPU's u_bounding_ball (the wind's swept
    ball) and u_half_space; shadow rays' cones read them (occlusion.cone_entry)."""

    balls: np.ndarray
    half_spaces: np.ndarray


NO_HALF_SPACE = (0.0, 0.0, 0.0, 1.0)  # u = 0: 0·x ≤ 1 holds everywhere


def shadow_bounds(scene: Scene, c: Compiled, dist: Distortion | None) -> Bounds | None:
    """The bounds the shadow cone meets (``[render] shadow_cone``), or None where the GPU
    compiles none (uniforms.variant_defines): off, a MöKRS, a twist, no component's ball."""
    if (
        scene.render.shadow_cone != "on"
        or isinstance(c, mokrs.CompiledMoKRS)
        or "twist" in scene.effects
    ):
        return None
    parts = components(c)
    if all(p.ball[3] < 0 for p in parts):
        return None
    wind = dist is not None and dist.wind is not None
    balls = dist.wind.balls if wind else np.array([p.ball for p in parts])  # type: ignore[union-attr]
    half = [NO_HALF_SPACE if p.half_space is None else p.half_space for p in parts]
    return Bounds(np.asarray(balls, dtype=np.float64), np.array(half, dtype=np.float64))


def rho_at(lod: Lod | None, x: np.ndarray, reach: np.ndarray | float = 0.0):
    """ρ at the points x (or the far side of balls of radius ``reach``); 0 without LOD."""
    return 0.0 if lod is None else lod.radius(x, reach)


def component_distance(
    part: CompiledKRS,
    x: np.ndarray,
    dist: Distortion | None = None,
    lod: Lod | None = None,
    reach: np.ndarray | float = 0.0,
    k: int = 0,
) -> np.ndarray:
    """The distance bound of one KRS (component ``k``): Alg. 1 at the level of detail,
    through the scene's distortion."""
    rho = rho_at(lod, x, reach)
    if dist is None:
        return krs.distance(part, x, rho=rho)
    return dist.distance(x, krs.distance(part, dist.undistort(x, k), rho=rho), k)


def scene_distance(
    c: CompiledKRS | CompiledCompound,
    x: np.ndarray,
    dist: Distortion | None = None,
    lod: Lod | None = None,
) -> np.ndarray:
    """The distance bound of everything drawn: the least over the components (a distortion
    is monotone in the distance, so it may be applied once, after the minimum; the wind
    bends each component about its own foot, so it is applied per component)."""
    if dist is not None and dist.wind is not None:
        return np.min(
            [component_distance(p, x, dist, lod, k=k) for k, p in enumerate(components(c))],
            axis=0,
        )
    q = x if dist is None else dist.undistort(x)
    rho = rho_at(lod, x)
    D = np.min([krs.distance(p, q, rho=rho) for p in components(c)], axis=0)
    return D if dist is None else dist.distance(x, D)


def component_distances(
    c: CompiledKRS | CompiledCompound, dist: Distortion | None, lod: Lod | None = None
) -> list[Distance]:
    """One distance bound per component, for the sphere tracer's free distances."""
    return [
        lambda x, p=p, k=k: component_distance(p, x, dist, lod, k=k)
        for k, p in enumerate(components(c))
    ]


def component_tests(c: Compiled, dist: Distortion | None, lod: Lod | None = None) -> list[Test]:
    """One unbounding test per component, for the binary tracer's free distances."""
    if isinstance(c, mokrs.CompiledMoKRS):
        wind = None if dist is None else dist.wind
        return [lambda x, s: mokrs.is_unbounding(c, x, s, lod=rho_at(lod, x, s), wind=wind)]
    return [
        lambda x, s, p=p, k=k: component_distance(p, x, dist, lod, reach=s, k=k) >= s
        for k, p in enumerate(components(c))
    ]


def nearest(
    c: Compiled, x: np.ndarray, width: np.ndarray | None = None, dist: Distortion | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(level slot, unit world normal, kernel-space point) of the kernel nearest to each
    point; ``width`` is the smooth-shading band per point (None: no smoothing). In a compound
    the component nearest to the point is asked (ties: the first), and its level is offset
    to the compound's slot."""
    if isinstance(c, mokrs.CompiledMoKRS):
        level, g = mokrs.nearest(c, x, None if dist is None else dist.wind)
        return level, g, x
    q = x if dist is None else dist.undistort(x)
    win = np.zeros(len(x), dtype=int)
    if isinstance(c, CompiledKRS):
        D, level, g, xk = krs.nearest(c, q, width)
    else:
        qs = [q if dist is None else dist.undistort(x, k) for k in range(len(c.parts))]
        win = np.argmin([krs.distance(p, qk) for p, qk in zip(c.parts, qs)], axis=0)
        q = np.choose(win[:, None], qs)
        D, level, g, xk = (
            np.empty(len(q)),
            np.empty(len(q), int),
            np.empty_like(q),
            np.empty_like(q),
        )
        for k, (part, base) in enumerate(zip(c.parts, c.bases)):
            sel = win == k
            D[sel], level[sel], g[sel], xk[sel] = krs.nearest(
                part, q[sel], None if width is None else width[sel]
            )
            level[sel] += base
    if dist is not None:
        g = dist.normal(x, q, D, g, win)
    return level, g, xk


FREE_RADII = np.geomspace(1e-9, 1e6, 96)  # radii tried by free_radius, ratio ≈ 1.44 apart


def free_radius(c: Compiled, x: np.ndarray) -> float:
    """The radius of an empty ball around the point x (3,): |DISTANCE| for a KRS; for a MöKRS
    (no distance function) the largest of FREE_RADII that is unbounding, found in one batch.
    Used by the viewer to scale flying speed."""
    if not isinstance(c, mokrs.CompiledMoKRS):
        return abs(float(scene_distance(c, x[None])[0]))
    free = mokrs.is_unbounding(c, np.broadcast_to(x, (len(FREE_RADII), 3)), FREE_RADII)
    return float(FREE_RADII[free].max()) if free.any() else 0.0


def surface_field(
    c: Compiled, dist: Distortion | None = None
) -> tuple[Callable[[np.ndarray], np.ndarray], Callable[[np.ndarray, np.ndarray], np.ndarray]]:
    """(value, is_empty) for sampling the surface: value(x) is negative inside and zero on
    the surface (a KRS's distance bound; for a MöKRS, which has no distance function, the
    first-order world distance to the nearest kernel, mokrs.distance_estimate); is_empty(x, r)
    certifies balls free of the surface (the distance bound, or Alg. 3)."""
    if isinstance(c, mokrs.CompiledMoKRS):  # Alg. 3 certifies free balls only
        return lambda x: mokrs.distance_estimate(c, x), lambda x, r: mokrs.is_unbounding(c, x, r)

    def is_empty(x: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Free (d ≥ r), or inside one kernel instance (d ≤ −r: kernels' distances are exact
        and reflections are isometries); a distortion certifies only the free side."""
        d = scene_distance(c, x, dist)
        return (d >= r) | ((d <= -r) & (dist is None))

    return lambda x: scene_distance(c, x, dist), is_empty
