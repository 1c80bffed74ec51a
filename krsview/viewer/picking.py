"""Picking from the traced image: its second attachment holds the ray distance of each pixel
(0 where the ray missed), so a point under the cursor costs one pixel read."""

from __future__ import annotations

import moderngl
import numpy as np

from .camera import FlyCamera


def depth_at(fbo: moderngl.Framebuffer, x: int, y: int) -> float:
    """The traced ray distance at image pixel (x, y), rows top → bottom; ≤ 0 on a miss."""
    raw = fbo.read(viewport=(x, y, 1, 1), attachment=1, components=4, dtype="f4")
    return float(np.frombuffer(raw, np.float32)[3])


def pick_center(
    camera: FlyCamera, image: tuple[moderngl.Framebuffer, tuple[int, int]] | None, free: float
) -> np.ndarray:
    """The surface point under the window centre, from the last traced image; else a point
    ahead at ``free``, the distance of the nearest surface."""
    if image is not None:
        fbo, (w, h) = image
        depth = depth_at(fbo, w // 2, h // 2)
        if depth > 0:
            return camera.position + depth * camera.forward()
    return camera.position + max(free, 1e-9) * camera.forward()
