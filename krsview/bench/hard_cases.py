"""The catalogue of hard cases: named scenes, each with the behaviour expected of it written
beside it (DESIGN.md: hard cases are inputs, not accidents). Tests and ``krsview check
--stability`` run the invariants over them; docs/stability.md reports the outcomes."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from ..presets import resolve
from ..reference.camera import pixel_ray, view_of
from ..reference.geometry import compile_geometry, nearest, scene_distance
from ..reference.trace import sphere_trace
from ..reference.geometry import component_distances
from ..scene import Scene, load_scene


@dataclass(frozen=True)
class HardCase:
    name: str
    build: Callable[[], Scene]
    expect: str             # what must hold, in words
    precision_limit: str = ""   # where float32 on the GPU cannot follow, and the mitigation


def surface_point(scene: Scene, x: float, y: float, width: int = 64, height: int = 36
                  ) -> tuple[np.ndarray, np.ndarray]:
    """The surface point seen through window point (x, y) of the scene's camera, and its
    world normal: the reference traces the ray (at the view's own level of detail), then Newton
steps p ← p − d(p)·n(p) put p on
    the surface to float64 rounding (the traced hit is only within ε of it)."""
    view = view_of(scene.camera, width, height)
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    d = pixel_ray(view, x, y)[None]
    tr = sphere_trace(component_distances(c, None), view.origin, d, view.footprint, 4096, 1e3)
    if not tr.hit[0]:
        raise ValueError(f"{scene.name}: no surface at window point ({x}, {y})")
    p = view.origin + tr.t[0] * d[0]
    for _ in range(32):
        _, n, _ = nearest(c, p[None])
        p = p - scene_distance(c, p[None])[0] * n[0]
    return p, n[0]


def zoomed(scene: Scene, x: float, y: float, scale: float) -> Scene:
    """The camera about ``scale`` scene units from the surface point at window point (x, y),
    looking at it at a grazing 14°, so the surface's horizon crosses the image: a deep zoom
    when ``scale`` is 1e-6 of the scene's size."""
    p, n = surface_point(scene, x, y)
    side = np.cross(n, scene.camera.up)
    if np.linalg.norm(side) < 1e-9:
        side = np.cross(n, (1.0, 0.0, 0.0))
    eye = p + scale * (0.25 * n + side / np.linalg.norm(side))
    return replace(scene, name=f"{scene.name}-zoom-{scale:g}",
                   camera=replace(scene.camera, position=tuple(eye), target=tuple(p)))


def tree() -> Scene:
    return load_scene(resolve("tree"))


# The tree's twig at window point (27.5, 0.5) of a 64×36 view: level 0, behind all 22 folds.
TWIG = (27.5, 0.5)

CASES: dict[str, HardCase] = {c.name: c for c in [
    HardCase("deep-zoom-1e-6", lambda: zoomed(tree(), *TWIG, 1e-6),
             "a twig seen from 1e-6 scene units: depths and normals as the reference's",
             "float32 kernel records and folds are off by ~1e-7 × scene size, a tenth of "
             "this view: precision = \"double\" follows the reference (depth to 1e-7)"),
    HardCase("deep-zoom-1e-9", lambda: zoomed(tree(), *TWIG, 1e-9),
             "a twig seen from 1e-9 scene units: depths and normals as the reference's",
             "float32 is off by 100× the view; precision = \"double\" follows the reference"),
]}
