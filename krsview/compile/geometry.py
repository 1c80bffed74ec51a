"""One compiled form per geometry family: a KRS, a compound of KRSs, or a MöKRS; a single
KRS or MöKRS is the compound of one [KRS17 §5.1]."""

from __future__ import annotations

import numpy as np

from ..scene import Compound, Geometry, MoKRS
from .krs import CompiledCompound, CompiledKRS, compile_krs
from .mokrs import CompiledMoKRS, compile_mokrs

Compiled = CompiledKRS | CompiledCompound | CompiledMoKRS


def compile_geometry(g: Geometry, albedo: tuple[float, float, float]) -> Compiled:
    if isinstance(g, MoKRS):
        return compile_mokrs(g, albedo)
    if isinstance(g, Compound):
        return CompiledCompound(tuple(compile_krs(p, albedo) for p in g.parts))
    return compile_krs(g, albedo)


def components(c: CompiledKRS | CompiledCompound) -> tuple[CompiledKRS, ...]:
    return c.parts if isinstance(c, CompiledCompound) else (c,)


def scene_ball(c: Compiled) -> np.ndarray | None:
    """A world ball (centre, radius) holding everything ``c`` draws; None when it is unbounded
    (a plane kernel, or a MöKRS whose outermost bound is not a ball)."""
    if isinstance(c, CompiledMoKRS):
        top = c.outer[-1]
        return top.copy() if top[3] >= 0 and np.isfinite(top).all() else None
    return c.ball.copy() if c.ball[3] >= 0 else None
