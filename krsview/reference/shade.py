"""Lambert + ambient shading of the nearest kernel [KRS17 §8.1], gamma-encoded for display.
Mirrors ``shaders/shade.glsl``."""
from __future__ import annotations

import numpy as np

from ..scene import Scene

GAMMA = 2.2


def encode(linear: np.ndarray) -> np.ndarray:
    return np.power(np.clip(linear, 0.0, 1.0), 1.0 / GAMMA)


def lambert(scene: Scene, albedo: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Linear radiance: albedo × (ambient + Σ intensity · colour · max(0, n·l))."""
    light = np.broadcast_to(np.array(scene.material.ambient), normal.shape).copy()
    for lt in scene.lights:
        cos = np.maximum(normal @ np.array(lt.direction), 0.0)
        light += lt.intensity * cos[:, None] * np.array(lt.color)
    return albedo * light
