"""Shading of hits [KRS17 §8]: Lambert + ambient with the scene's effects (texture, shadows,
ambient occlusion, fog), then tone mapping and gamma. Twin of ``shaders/shade.glsl``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compile.constants import GAMMA, SHADOW_OFFSET
from ..compile.geometry import Compiled
from ..compile.mokrs import CompiledMoKRS
from ..scene import Scene
from . import atmosphere, mokrs, occlusion, texture
from .distortion import Distortion
from .geometry import Lod, component_distances, rho_at, scene_distance, shadow_bounds


def encode(scene: Scene, linear: np.ndarray) -> np.ndarray:
    if "tone_mapping" in scene.effects:
        linear = atmosphere.tone_map(scene, linear)
    return np.power(np.clip(linear, 0.0, 1.0), 1.0 / GAMMA)


@dataclass
class Hits:
    """What shading needs of each hit: world point, ray direction and distance, the nearest
    kernel level, world normal and kernel-space point."""

    p: np.ndarray
    dirs: np.ndarray
    t: np.ndarray
    level: np.ndarray
    normal: np.ndarray
    xk: np.ndarray


def albedo(scene: Scene, c: Compiled, h: Hits, footprint: np.ndarray) -> np.ndarray:
    """Kernel colour, modulated by the scene's textures (filtered by the footprint)."""
    a = c.records[h.level, 0, :3]
    fx = scene.effect_settings
    if "triplanar_texture" in scene.effects:
        pattern = texture.triplanar(h.p, h.normal, footprint, fx.texture_scale)
        a = a * texture.modulation(pattern, fx.texture_strength)[:, None]
    if "kernel_texture" in scene.effects:
        pattern = np.zeros(len(h.p))
        for j in np.unique(h.level):
            sel = h.level == j
            pattern[sel] = texture.kernel_texture(
                c.types[j], c.records[j], h.xk[sel], footprint[sel], fx.texture_scale
            )
        a = a * texture.modulation(pattern, fx.texture_strength)[:, None]
    return a


def shade(
    scene: Scene,
    c: Compiled,
    dist: Distortion | None,
    h: Hits,
    footprint: float,
    eps_per_t: float,
    lod: Lod | None = None,
) -> np.ndarray:
    """Linear radiance of each hit: albedo × (ambient·AO + Σ visibility·cos·light), fogged;
    shadow rays and occlusion meet the geometry at the level of detail ``lod``."""
    fx = scene.effect_settings
    fp = footprint * h.t

    def distance(x: np.ndarray) -> np.ndarray:
        return scene_distance(c, x, dist, lod)  # type: ignore[arg-type]

    ambient = np.broadcast_to(np.array(scene.material.ambient), h.p.shape).copy()
    if "ambient_occlusion" in scene.effects:
        ao = occlusion.ambient_occlusion(distance, h.p, h.normal, fx.ao_step, fx.ao_strength)
        ambient *= ao[:, None]
    light = ambient
    soft = "soft_shadows" in scene.effects
    shadows = soft or "shadows" in scene.effects
    eps = eps_per_t * h.t
    for lt in scene.lights:
        l = np.array(lt.direction)
        cos = np.maximum(h.normal @ l, 0.0)
        if shadows:
            lit = np.flatnonzero(cos > 0.0)
            o = h.p[lit] + SHADOW_OFFSET * eps[lit, None] * h.normal[lit]
            k = fx.shadow_softness if soft else None
            if isinstance(c, CompiledMoKRS):
                vis = occlusion.shadow_by_probes(
                    lambda x, s: mokrs.is_unbounding(
                        c, x, s, lod=rho_at(lod, x, s), wind=None if dist is None else dist.wind
                    ),
                    o,
                    l,
                    eps[lit],
                    scene.render,
                    k,
                )
            else:
                vis = occlusion.shadow_by_distance(
                    component_distances(c, dist, lod),
                    o,
                    l,  # type: ignore[arg-type]
                    eps[lit],
                    scene.render,
                    k,
                    dist.lod_scale if dist is not None else None,
                    shadow_bounds(scene, c, dist),
                )
            cos[lit] *= vis
        light = light + lt.intensity * cos[:, None] * np.array(lt.color)
    color = albedo(scene, c, h, fp) * light
    if "fog" in scene.effects:
        color = atmosphere.fog(scene, color, h.dirs, h.t)
    return color
