"""Scene → GPU: the variant's defines and the uniform values, camera-relative, in float32 or
(the geometry of a double-precision variant) float64."""

from __future__ import annotations

import numpy as np

from ..algebra.vectors import cross
from ..compile.balls import UNBOUNDED
from ..compile.camera import View
from ..compile.constants import MOBIUS_RECORD
from ..compile.geometry import Compiled, walk_restarts
from ..compile.krs import KERNEL_CODES, RECORD_VEC4, CompiledCompound
from ..compile.lod import NO_CUT
from ..compile.mokrs import CompiledMoKRS
from ..scene import EFFECTS, MAX_COMPONENTS, MAX_LEVELS, Scene
from ..scene.compound import COMPOUND_SLOTS
from ..scene.effects import (
    MAX_EMPTY_ZONES,
    WIND_PHASE,
    WIND_RATIOS,
    WIND_WEIGHTS,
    allowed_effects,
    swept_ball,
    wind_feet,
)
from ..scene.scene import MAX_LIGHTS
from .coarse import free_stride


def variant_defines(
    scene: Scene, c: Compiled, all_effects: bool = False
) -> dict[str, str | int | None]:
    """One define per kernel type present, per enabled effect, for the tracer, culling, the
    pre-pass, the Möbius geometry family and a compound: nothing else is compiled. ``all_effects``
    compiles every effect the geometry allows, each switched by its bit of ``u_effects``
    (the benchmark's baseline). The constants every variant shares are the builder's."""
    defines: dict[str, str | int | None] = {"KRS_SLOTS": slots(c)}
    for kind in set(c.types) - {"empty"}:
        defines[f"KRS_KERNEL_{kind.upper()}"] = None
    if not isinstance(c, CompiledMoKRS):
        parts = [part for part, _ in component_slots(c)]
        defines["KRS_TOP_KERNELS"] = kernel_mask(part.types[-1] for part in parts)
        defines["KRS_LEVEL_KERNELS"] = kernel_mask(k for part in parts for k in part.types[:-1])
    if all_effects:
        defines["KRS_ALL_EFFECTS"] = None
        for name in allowed_effects(isinstance(c, CompiledMoKRS)):
            defines[f"KRS_{name.upper()}"] = None
            defines[f"KRS_{name.upper()}_BIT"] = EFFECTS[name].bit
    else:
        for effect in scene.effects:
            defines[f"KRS_{effect.upper()}"] = None
    if scene.render.tracer != "sphere":
        defines[f"KRS_TRACER_{scene.render.tracer.upper()}"] = None
    if scene.render.precision == "double":
        defines["KRS_DOUBLE"] = None
    balls = any(
        (part.bounds[:, 3] >= 0).any()
        for part, _ in component_slots(c)
        if not isinstance(part, CompiledMoKRS)
    )  # only where some level has a ball to test
    if scene.render.culling == "on" and balls:
        defines["KRS_CULLING"] = None
    if scene.render.lod > 0 and (balls or (isinstance(c, CompiledMoKRS) and has_bounds(c))):
        defines["KRS_LOD"] = None  # subtrees below the level of detail end the walk (krs.glsl)
    if scene.render.prepass:
        defines["KRS_PREPASS"] = None
    if (
        scene.render.path == "compute"
        and scene.render.shadow_tasks == "on"
        and {"shadows", "soft_shadows"} & set(scene.effects)
    ):
        defines["KRS_SHADOW_TASKS"] = None  # shadow rays traced in rounds (compute.comp)
    if (
        scene.render.path == "compute"
        and scene.render.component_tasks == "on"
        and isinstance(c, CompiledCompound)
    ):
        defines["KRS_COMPONENT_TASKS"] = None  # a task per pixel and component (compute.comp)
    if (
        not isinstance(c, CompiledMoKRS)
        and "KRS_TWIST" not in defines  # moves the geometry out of its balls (the wind's
        # exit takes a ball about each foot instead: trace.glsl, wind_bound_ahead)
        and any(ball[3] >= 0 for ball in component_balls(c))
    ):
        defines["KRS_BALL_EXIT"] = None  # rays leave the components' balls (trace.glsl)
    if (
        "KRS_BALL_EXIT" in defines
        and scene.render.shadow_cone == "on"
        and {"shadows", "soft_shadows"} & set(scene.effects)
    ):
        defines["KRS_SHADOW_CONE"] = None  # shadow rays meet components late (shadows.glsl)
    if walk_restarts(scene, c) and not all_effects:
        defines["KRS_WALK_RESTART"] = None  # steps restart Alg. 1 below their anchor (krs.glsl)
    if isinstance(c, CompiledMoKRS):
        defines["KRS_MOBIUS"] = None
    if isinstance(c, CompiledCompound):
        defines["KRS_COMPOUND"] = None
    return defines


def has_bounds(c: CompiledMoKRS) -> bool:
    """Some level of the MöKRS has a bounding ball (a level of detail to cut at)."""
    return bool((c.bounds[:, 3] >= 0).any())


def kernel_mask(kinds) -> int:
    """Bit KERNEL_CODES[kind] set per kind, empty included (kernels.glsl's
    kernel_distance_of): a call that can only meet these kinds compiles no other kind's code,
    and one that meets a single kind reads no type. llvmpipe runs the code of every branch,
    taken or not, so a level loop that compiled the trunk's capsule beside the branches' arcs
    paid for both at every level (docs/speed.md)."""
    return sum(1 << KERNEL_CODES[k] for k in set(kinds))


def slots(c: Compiled) -> int:
    """Level slots in the uniform block: fixed per geometry family, so that edits (levels,
    components' depths) never change the variant. A compound has room for 8 × 64 levels."""
    return COMPOUND_SLOTS if isinstance(c, CompiledCompound) else MAX_LEVELS


def krs_block(c: Compiled, precision: str = "float") -> bytes:
    """The std140 KRSBlock: mirrors and culling balls, each centred on its mirror (the walk
    folds about it), or Möbius records; then kernel records, as float32 or, for
    ``precision = "double"`` (dvec4 arrays), float64."""
    return b"".join(a.tobytes() for a in block_arrays(c, precision, slots(c)).values())


def block_arrays(c: Compiled, precision: str, n: int) -> dict[str, np.ndarray]:
    """KRSBlock's members in order, each (vec4s, 4), for ``n`` level slots (at least
    ``len(c.records)``, the slots in use; unused slots stay zero, balls −1: none)."""
    dtype = np.float64 if precision == "double" else np.float32
    kernels = np.zeros((n, RECORD_VEC4, 4), dtype=dtype)
    kernels[: len(c.records)] = c.records
    if isinstance(c, CompiledMoKRS):
        head = np.zeros((n, MOBIUS_RECORD, 4), dtype=dtype)
        head[: c.n, :4] = c.inverse.reshape(c.n, 4, 4)
        head[: c.n, 4] = c.poles
        head[: c.n, 5] = c.bounds
        return {"u_mobius": head.reshape(-1, 4), "u_kernels": kernels.reshape(-1, 4)}
    mirrors, bounds = np.zeros((n, 4), dtype=dtype), np.zeros((n, 4), dtype=dtype)
    bounds[:, 3] = -1.0
    for part, first in component_slots(c):
        mirrors[first : first + part.n] = part.mirrors
        bounds[first : first + part.n] = part.bounds
    return {"u_mirrors": mirrors, "u_bounds": bounds, "u_kernels": kernels.reshape(-1, 4)}


def component_slots(c: Compiled) -> list[tuple]:
    """(compiled KRS, first slot) per component."""
    if isinstance(c, CompiledCompound):
        return list(zip(c.parts, c.bases))
    return [(c, 0)]


NO_HALF_SPACE = (0.0, 0.0, 0.0, 1.0)  # u = 0: no half-space (0·x ≤ 1 holds everywhere)


def component_balls(c: Compiled) -> list[tuple[float, ...]]:
    """Each component's ball (CompiledKRS.ball), one per slot of a compound's component
    arrays (MAX_COMPONENTS); unbounded for a MöKRS and unused slots."""
    if isinstance(c, CompiledMoKRS):
        return [tuple(UNBOUNDED)]
    balls = [tuple(float(v) for v in part.ball) for part, _ in component_slots(c)]
    return (
        balls + [tuple(UNBOUNDED)] * (MAX_COMPONENTS - len(balls))
        if isinstance(c, CompiledCompound)
        else balls
    )


def component_lod_cuts(c: Compiled) -> list[tuple[float, ...]]:
    """Each component's level-of-detail cut (CompiledKRS.lod_cut), one per slot as in
    component_balls; NO_CUT for a MöKRS (its levels cut by their own bounds) and unused
    slots."""
    if isinstance(c, CompiledMoKRS):
        return [tuple(NO_CUT)]
    rows = [tuple(float(v) for v in part.lod_cut) for part, _ in component_slots(c)]
    if isinstance(c, CompiledCompound):
        rows += [tuple(NO_CUT)] * (MAX_COMPONENTS - len(rows))
    return rows


def component_half_spaces(c: Compiled) -> list[tuple[float, ...]]:
    """Each component's half-space u·x ≤ w (CompiledKRS.half_space), one per slot as in
    component_balls; NO_HALF_SPACE (u = 0) where it has none. Shadow rays' cones read them
    (shadows.glsl, cone_entry)."""
    if isinstance(c, CompiledMoKRS):
        return [NO_HALF_SPACE]
    rows = [
        NO_HALF_SPACE if part.half_space is None else tuple(float(v) for v in part.half_space)
        for part, _ in component_slots(c)
    ]
    if isinstance(c, CompiledCompound):
        rows += [NO_HALF_SPACE] * (MAX_COMPONENTS - len(rows))
    return rows


def rest_balls(c: Compiled) -> list[np.ndarray]:
    """The ball around each component at rest, camera-relative, which the wind's reach and
    swept ball start from: CompiledKRS.ball, or a MöKRS's outermost bound in the world
    (reference/wind.py, rest_balls)."""
    if isinstance(c, CompiledMoKRS):
        return [c.outer[-1]]
    return [part.ball for part, _ in component_slots(c)]


def wind_uniforms(scene: Scene, view: View, c: Compiled) -> dict[str, object]:
    """The wind's uniforms (wind.glsl; reference/wind.py derives them): time is ``u_time``
    alone, so an animated frame changes one value and compiles nothing."""
    fx = scene.effect_settings
    w = np.array([fx.wind_direction[0], 0.0, fx.wind_direction[2]])
    a0 = np.radians(fx.wind_strength) / fx.wind_height
    phase = WIND_PHASE / fx.wind_frequency if fx.wind_frequency > 0 else 0.0
    axis = cross((0.0, 1.0, 0.0), w / np.linalg.norm(w))
    most = a0 * (1.0 + fx.wind_gust)
    feet, swept = [], []
    if "wind" in scene.effects:
        balls = [(*(ball[:3] + view.origin), ball[3]) for ball in rest_balls(c)]
        for (b, r), ball in zip(wind_feet(scene, balls), balls):
            feet.append((*(np.array(b) - view.origin), r))
            held = swept_ball(b, r, ball, axis, most)
            swept.append((*(np.array(held[:3]) - view.origin), held[3]))
    feet += [(0.0, 0.0, 0.0, 0.0)] * (MAX_COMPONENTS - len(feet))
    swept += [(0.0, 0.0, 0.0, -1.0)] * (MAX_COMPONENTS - len(swept))
    return {
        "u_time": scene.time,
        "u_wind_axis": tuple(axis),
        "u_wind": (a0, fx.wind_gust, phase, most * max(f[3] for f in feet)),
        "u_wind_freq": tuple(2.0 * np.pi * fx.wind_frequency * np.array(WIND_RATIOS)),
        "u_wind_weight": WIND_WEIGHTS,
        "u_wind_base": per_component(c, feet),
        "u_wind_ball": per_component(c, swept),
    }


def per_component(c: Compiled, rows: list) -> object:
    """A per-component uniform's value: its rows in a compound; for a single KRS its one row,
    as moderngl takes a one-element array (and share/web.py bakes it back into one)."""
    return rows if isinstance(c, CompiledCompound) else rows[0]


def view_uniforms(scene: Scene, view: View, c: Compiled) -> dict[str, object]:
    """Per-frame values; positions are camera-relative (the eye is the origin)."""
    lights = scene.lights
    fx = scene.effect_settings
    zones = [
        tuple(float(v) for v in (*(np.array(z.center) - view.origin), z.radius))
        for z in fx.empty_zones
    ]
    parts = [(int(first), part.n) for part, first in component_slots(c)]
    return {
        "u_n": getattr(c, "n", 0),
        "u_components": len(parts),
        "u_component": parts + [(0, 0)] * (MAX_COMPONENTS - len(parts)),
        "u_footprint": view.footprint,
        "u_detail_footprint": view.detail_footprint,
        "u_eye": tuple(view.origin),
        "u_forward": tuple(view.forward),
        "u_right": tuple(view.right),
        "u_up": tuple(view.up),
        "u_resolution": (float(view.width), float(view.height)),
        "u_tan_half": view.tan_half,
        "u_eps_per_t": view.detail_footprint * scene.render.epsilon_scale,
        "u_lod": scene.render.lod,
        "u_lod_cut": per_component(c, component_lod_cuts(c)),
        "u_max_iterations": scene.render.max_iterations,
        "u_max_distance": scene.render.max_distance,
        "u_xi_bonus": scene.render.xi_bonus,
        "u_xi_penalty": scene.render.xi_penalty,
        "u_relaxation": scene.render.relaxation,
        "u_tile": scene.render.prepass or 0,  # not given: off (api.fast_settings sets one)
        "u_free_stride": free_stride(view, scene.render.prepass or 0),
        "u_light_count": len(lights),
        "u_light_dir": [lt.direction for lt in lights]
        + [(0.0, 0.0, 0.0)] * (MAX_LIGHTS - len(lights)),
        "u_light_color": [tuple(c * lt.intensity for c in lt.color) for lt in lights]
        + [(0.0, 0.0, 0.0)] * (MAX_LIGHTS - len(lights)),
        "u_ambient": scene.material.ambient,
        "u_background": scene.material.background,
        "u_effects": sum(EFFECTS[e].bit for e in scene.effects),
        "u_smooth_width": fx.smooth_width,
        "u_shadow_softness": fx.shadow_softness,
        "u_bounding_ball": per_component(c, component_balls(c)),
        "u_half_space": per_component(c, component_half_spaces(c)),
        "u_ao_step": fx.ao_step,
        "u_ao_strength": fx.ao_strength,
        "u_texture_scale": fx.texture_scale,
        "u_texture_strength": fx.texture_strength,
        "u_twist": float(np.radians(fx.twist)),
        "u_twist_center": tuple(np.array(fx.twist_center) - view.origin),
        **wind_uniforms(scene, view, c),
        "u_empty_zone_count": len(zones),
        "u_empty_zones": zones + [(0.0, 0.0, 0.0, 0.0)] * (MAX_EMPTY_ZONES - len(zones)),
        "u_sky_zenith": fx.sky_zenith,
        "u_fog_density": fx.fog_density,
        "u_exposure": fx.exposure,
    }
