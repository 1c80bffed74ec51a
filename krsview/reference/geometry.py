"""One interface over both geometry families, so tracers and renderers need not know which:
compile, test a ball for being unbounding, find the nearest kernel and its world normal."""
from __future__ import annotations

import numpy as np

from ..scene import KRS, MoKRS
from . import krs, mokrs
from .compiled import CompiledKRS, compile_krs
from .distortion import Distortion

Compiled = CompiledKRS | mokrs.CompiledMoKRS


def compile_geometry(g: KRS | MoKRS, albedo: tuple[float, float, float]) -> Compiled:
    if isinstance(g, MoKRS):
        return mokrs.compile_mokrs(g, albedo)
    return compile_krs(g, albedo)


def scene_distance(c: CompiledKRS, x: np.ndarray, dist: Distortion | None = None
                   ) -> np.ndarray:
    """The distance bound of what a KRS draws: Alg. 1, through the scene's distortion."""
    if dist is None:
        return krs.distance(c, x)
    return dist.distance(x, krs.distance(c, dist.undistort(x)))


def is_unbounding(c: Compiled, center: np.ndarray, radius: np.ndarray,
                  dist: Distortion | None = None) -> np.ndarray:
    """Whether each ball is free of geometry: Alg. 3 for a MöKRS; for a KRS the distance
    bound at the centre is at least the radius."""
    if isinstance(c, mokrs.CompiledMoKRS):
        return mokrs.is_unbounding(c, center, radius)
    return scene_distance(c, center, dist) >= radius


def nearest(c: Compiled, x: np.ndarray, width: np.ndarray | None = None,
            dist: Distortion | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(level, unit world normal, kernel-space point) of the kernel nearest to each point;
    ``width`` is the smooth-shading band per point (None: no smoothing)."""
    if isinstance(c, mokrs.CompiledMoKRS):
        level, g = mokrs.nearest(c, x)
        return level, g, x
    q = x if dist is None else dist.undistort(x)
    D, level, g, xk = krs.nearest(c, q, width)
    if dist is not None:
        g = dist.normal(x, q, D, g)
    return level, g, xk


FREE_RADII = np.geomspace(1e-9, 1e6, 96)  # radii tried by free_radius, ratio ≈ 1.44 apart


def free_radius(c: Compiled, x: np.ndarray) -> float:
    """The radius of an empty ball around the point x (3,): |DISTANCE| for a KRS; for a MöKRS
    (no distance function) the largest of FREE_RADII that is unbounding, found in one batch.
    Used by the viewer to scale flying speed."""
    if isinstance(c, CompiledKRS):
        return abs(float(krs.distance(c, x[None])[0]))
    free = is_unbounding(c, np.broadcast_to(x, (len(FREE_RADII), 3)), FREE_RADII)
    return float(FREE_RADII[free].max()) if free.any() else 0.0
