"""Pinhole view: basis, primary rays and the pixel footprint used for LOD [KRS17 §4]."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..scene import Camera


@dataclass(frozen=True)
class View:
    origin: np.ndarray  # eye position, float64 world
    forward: np.ndarray
    right: np.ndarray
    up: np.ndarray
    tan_half: float  # tan(fov_y / 2)
    width: int
    height: int

    @property
    def aspect(self) -> float:
        return self.width / self.height

    @property
    def footprint(self) -> float:
        """Pixel size per unit ray distance: ε = footprint × t × ε-scale stays sub-pixel."""
        return 2.0 * self.tan_half / self.height


def view_of(camera: Camera, width: int, height: int) -> View:
    o = np.array(camera.position, dtype=np.float64)
    f = np.array(camera.target, dtype=np.float64) - o
    f /= np.linalg.norm(f)
    r = np.cross(f, camera.up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    return View(o, f, r, u, math.tan(math.radians(camera.fov_y) / 2.0), width, height)


def primary_rays(v: View) -> np.ndarray:
    """Unit directions (H·W, 3) through pixel centres, rows top → bottom (as the shader's
    gl_FragCoord, flipped)."""
    cols = np.arange(v.width) + 0.5
    rows = v.height - (np.arange(v.height) + 0.5)  # gl_FragCoord.y of each image row
    fx, fy = np.meshgrid(cols, rows)
    nx = (2.0 * fx / v.width - 1.0) * v.tan_half * v.aspect
    ny = (2.0 * fy / v.height - 1.0) * v.tan_half
    d = v.forward + nx.reshape(-1, 1) * v.right + ny.reshape(-1, 1) * v.up
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def pixel_ray(v: View, x: float, y: float) -> np.ndarray:
    """Unit direction through window point (x, y), measured from the top-left corner in
    pixels (what a mouse reports); pixel centres sit at .5 as in :func:`primary_rays`."""
    nx = (2.0 * x / v.width - 1.0) * v.tan_half * v.aspect
    ny = (1.0 - 2.0 * y / v.height) * v.tan_half
    d = v.forward + nx * v.right + ny * v.up
    return d / np.linalg.norm(d)


def project(v: View, p: np.ndarray) -> tuple[float, float, float]:
    """Window point (x, y from the top-left, pixels) and distance along the view axis of the
    world point p; the inverse of :func:`pixel_ray` (z ≤ 0: behind the eye)."""
    rel = np.asarray(p, dtype=np.float64) - v.origin
    z = float(rel @ v.forward)
    if z <= 0:
        return (math.nan, math.nan, z)
    nx = float(rel @ v.right) / (z * v.tan_half * v.aspect)
    ny = float(rel @ v.up) / (z * v.tan_half)
    return ((nx + 1.0) * 0.5 * v.width, (1.0 - ny) * 0.5 * v.height, z)
