"""Pinhole view: basis, primary rays and the pixel footprint used for LOD [KRS17 §4]."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..algebra.vectors import cross
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
    # the height of the image whose pixel sets the detail drawn (ε, the level of detail, the
    # textures' filter, the normals' smoothing); 0: this image's own. A viewer's coarse
    # moving image takes the window's, so it draws and shades the still image's detail,
    # only sampled more coarsely
    detail_height: int = 0

    @property
    def aspect(self) -> float:
        return self.width / self.height

    @property
    def footprint(self) -> float:
        """Pixel size per unit ray distance: ε = footprint × t × ε-scale stays sub-pixel."""
        return 2.0 * self.tan_half / self.height

    @property
    def detail_footprint(self) -> float:
        """The footprint of the pixel whose detail is drawn (``detail_height``)."""
        return 2.0 * self.tan_half / (self.detail_height or self.height)


def view_of(camera: Camera, width: int, height: int, detail_height: int = 0) -> View:
    o = np.array(camera.position, dtype=np.float64)
    f = np.array(camera.target, dtype=np.float64) - o
    f /= np.linalg.norm(f)
    r = cross(f, camera.up)
    r /= np.linalg.norm(r)
    u = cross(r, f)
    tan_half = math.tan(math.radians(camera.fov_y) / 2.0)
    return View(o, f, r, u, tan_half, width, height, detail_height)


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
