"""Sky, fog and tone mapping; twin of ``shaders/atmosphere.glsl``."""

from __future__ import annotations

import numpy as np

from ..compile.constants import SUN_SHARPNESS
from ..scene import Scene


def sky(scene: Scene, dirs: np.ndarray) -> np.ndarray:
    """Horizon (the material's background) to zenith above, darkening below; a glow towards
    the first light."""
    horizon = np.array(scene.material.background)
    zenith = np.array(scene.effect_settings.sky_zenith)
    y = dirs[:, 1:2]
    above = horizon + (zenith - horizon) * np.sqrt(np.maximum(y, 0.0))
    below = horizon * (1.0 - 0.4 * np.minimum(-3.0 * y, 1.0))
    c = np.where(y >= 0.0, above, below)
    if scene.lights:
        lt = scene.lights[0]
        glow = np.maximum(dirs @ np.array(lt.direction), 0.0) ** SUN_SHARPNESS
        c = c + 2.0 * lt.intensity * np.array(lt.color) * glow[:, None]
    return c


def background(scene: Scene, dirs: np.ndarray) -> np.ndarray:
    if "sky" in scene.effects:
        return sky(scene, dirs)
    return np.broadcast_to(np.array(scene.material.background), dirs.shape).copy()


def fog(scene: Scene, color: np.ndarray, dirs: np.ndarray, t: np.ndarray) -> np.ndarray:
    f = 1.0 - np.exp(-scene.effect_settings.fog_density * t)
    return color + (background(scene, dirs) - color) * f[:, None]


def tone_map(scene: Scene, linear: np.ndarray) -> np.ndarray:
    """The ACES filmic curve fitted by Narkowicz (2015), after the exposure scale."""
    x = scene.effect_settings.exposure * linear
    return np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
