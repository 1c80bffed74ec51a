"""One interface over both geometry families, so tracers and renderers need not know which:
compile, test a ball for being unbounding, find the nearest kernel and its world normal."""
from __future__ import annotations

import numpy as np

from ..scene import KRS, MoKRS
from . import krs, mokrs
from .compiled import CompiledKRS, compile_krs

Compiled = CompiledKRS | mokrs.CompiledMoKRS


def compile_geometry(g: KRS | MoKRS, albedo: tuple[float, float, float]) -> Compiled:
    if isinstance(g, MoKRS):
        return mokrs.compile_mokrs(g, albedo)
    return compile_krs(g, albedo)


def is_unbounding(c: Compiled, center: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Whether each ball is free of geometry: Alg. 3 for a MöKRS; for a KRS the distance
    bound of Alg. 1 at the centre is at least the radius."""
    if isinstance(c, mokrs.CompiledMoKRS):
        return mokrs.is_unbounding(c, center, radius)
    return krs.distance(c, center) >= radius


def nearest(c: Compiled, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(level, unit world normal) of the kernel nearest to each point."""
    if isinstance(c, mokrs.CompiledMoKRS):
        return mokrs.nearest(c, x)
    _, level, g = krs.nearest(c, x)
    return level, g


FREE_RADII = np.geomspace(1e-9, 1e6, 96)  # radii tried by free_radius, ratio ≈ 1.44 apart


def free_radius(c: Compiled, x: np.ndarray) -> float:
    """The radius of an empty ball around the point x (3,): |DISTANCE| for a KRS; for a MöKRS
    (no distance function) the largest of FREE_RADII that is unbounding, found in one batch.
    Used by the viewer to scale flying speed."""
    if isinstance(c, CompiledKRS):
        return abs(float(krs.distance(c, x[None])[0]))
    free = is_unbounding(c, np.broadcast_to(x, (len(FREE_RADII), 3)), FREE_RADII)
    return float(FREE_RADII[free].max()) if free.any() else 0.0
