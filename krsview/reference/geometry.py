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
