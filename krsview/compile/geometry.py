"""One compiled form per geometry family: a KRS, a compound of KRSs, or a MöKRS; a single
KRS or MöKRS is the compound of one [KRS17 §5.1]."""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from ..scene import KRS, Compound, Geometry, MoKRS, Scene
from .krs import CompiledCompound, CompiledKRS, compile_krs
from .mokrs import CompiledMoKRS, compile_mokrs

Compiled = CompiledKRS | CompiledCompound | CompiledMoKRS


KEPT_PARTS = 64  # compiled compound components kept, by value
KEPT_WHOLE = 8  # compiled single KRSs and MöKRSs kept, by value


def compile_geometry(g: Geometry, albedo: tuple[float, float, float]) -> Compiled:
    """``g`` compiled, or the same value compiled before: a scene posed at a new time whose
    tracks move only the camera or an effect compiles nothing (its geometry is new but
    equal), and playing back and forth over the same moments compiles each once."""
    if isinstance(g, Compound):
        return CompiledCompound(tuple(_compiled_part(p, albedo) for p in g.parts))
    make = compile_mokrs if isinstance(g, MoKRS) else compile_krs
    return _kept(_whole, KEPT_WHOLE, (repr(g), tuple(albedo)), lambda: make(g, albedo))


_parts: OrderedDict[tuple[str, tuple], CompiledKRS] = OrderedDict()
_whole: OrderedDict[tuple[str, tuple], CompiledKRS | CompiledMoKRS] = OrderedDict()


def _compiled_part(krs: KRS, albedo: tuple) -> CompiledKRS:
    """A compound's component compiled, or the same value compiled before: an edit of one
    tree of a grove compiles that tree alone (the text of a KRS costs a fraction of a
    millisecond; compiling it, about 9 ms). Compiled arrays are never written in place."""
    return _kept(_parts, KEPT_PARTS, (repr(krs), tuple(albedo)), lambda: compile_krs(krs, albedo))


def _kept(cache: OrderedDict, size: int, key: tuple, make):
    """``cache[key]``, made by ``make()`` the first time; at most ``size`` kept, the least
    recently used dropped first."""
    if key in cache:
        cache.move_to_end(key)
        return cache[key]
    cache[key] = made = make()
    while len(cache) > size:
        cache.popitem(last=False)
    return made


def components(c: CompiledKRS | CompiledCompound) -> tuple[CompiledKRS, ...]:
    return c.parts if isinstance(c, CompiledCompound) else (c,)


def scene_ball(c: Compiled) -> np.ndarray | None:
    """A world ball (centre, radius) holding everything ``c`` draws; None when it is unbounded
    (a plane kernel, or a MöKRS whose outermost bound is not a ball)."""
    if isinstance(c, CompiledMoKRS):
        top = c.outer[-1]
        return top.copy() if top[3] >= 0 and np.isfinite(top).all() else None
    return c.ball.copy() if c.ball[3] >= 0 else None


def walk_restarts(scene: Scene, c: Compiled) -> bool:
    """The sphere tracer's steps restart Alg. 1 below the ray's anchor (``[render]
    walk_restart``; krs.glsl, reference/krs.py restart): one KRS, whose folds are isometries
    along the ray, so not under a distortion (twist, wind, empty zones) nor in a compound."""
    return (
        scene.render.walk_restart == "on"
        and scene.render.tracer == "sphere"
        and isinstance(c, CompiledKRS)
        and not {"twist", "wind", "empty_zones"} & set(scene.effects)
    )
