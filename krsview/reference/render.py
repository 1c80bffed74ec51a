"""Whole-image reference render: the same outputs as the GPU, in float64."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..compile.camera import View, primary_rays, view_of
from ..compile.geometry import compile_geometry, walk_restarts
from ..frame import Frame
from ..scene import Geometry, Scene
from .atmosphere import background
from .distortion import Distortion
from .geometry import Lod, component_distances, component_tests, nearest, rho_at
from .shade import Hits, encode, shade
from .trace import binary_trace, relaxed_trace, restart_trace, sphere_trace

PROGRESS_CHUNK = 8192  # rays per chunk when progress is reported


def render_reference(
    scene: Scene,
    width: int,
    height: int,
    geometry: Geometry | None = None,
    progress: Callable[[int, int], None] | None = None,
    detail_height: int = 0,
) -> Frame:
    """The image in float64. With ``progress``, rays go in chunks and progress(done, total)
    is called after each (every ray is independent: the image is the same).
    ``detail_height``: the height of the image whose pixel sets the detail drawn (ε, the level
    of detail, textures, smoothing; compile/camera.View), 0: this one's."""
    scene = scene.posed()  # the static scene drawn at its time (tracks, sway)
    view = view_of(scene.camera, width, height, detail_height)
    c = compile_geometry(geometry or scene.geometry(), scene.material.albedo)
    dist = Distortion.of(scene)
    dirs = primary_rays(view)
    N = len(dirs)
    step = PROGRESS_CHUNK if progress else N
    parts = []
    for k in range(0, N, step):
        parts.append(_trace_and_shade(scene, c, dist, view, dirs[k : k + step]))
        if progress:
            progress(min(k + step, N), N)
    color, depth, normal, iterations, hit = (np.concatenate(a) for a in zip(*parts))
    H, W = height, width
    return Frame(
        color.reshape(H, W, 3),
        depth.reshape(H, W),
        normal.reshape(H, W, 3),
        iterations.reshape(H, W),
        hit.reshape(H, W),
    )


def _trace_and_shade(
    scene: Scene, c, dist: Distortion | None, view: View, dirs: np.ndarray
) -> tuple[np.ndarray, ...]:
    """Colour, depth (0 on a miss), normal, iterations and hit of the rays ``dirs``."""
    r = scene.render
    eps = view.detail_footprint * r.epsilon_scale
    scale = dist.lod_scale if dist is not None else None
    lod = Lod.of(r.lod, view.origin, eps)
    if r.tracer == "binary":
        tr = binary_trace(
            component_tests(c, dist, lod),
            view.origin,
            dirs,
            eps,
            r.max_iterations,
            r.max_distance,
            r.xi_bonus,
            r.xi_penalty,
            scale,
        )
    elif r.tracer == "relaxed":
        (d,) = component_distances(c, dist, lod)  # a single KRS (Scene.check_tracer)
        tr = relaxed_trace(
            d, view.origin, dirs, eps, r.max_iterations, r.max_distance, r.relaxation, scale
        )
    elif walk_restarts(scene, c):
        tr, _ = restart_trace(
            c, view.origin, dirs, eps, r.max_iterations, r.max_distance, lambda p: rho_at(lod, p)
        )
    else:
        tr = sphere_trace(
            component_distances(c, dist, lod),
            view.origin,
            dirs,
            eps,  # type: ignore[arg-type]
            r.max_iterations,
            r.max_distance,
            scale,
        )
    N = len(dirs)
    normal = np.zeros((N, 3))
    color = encode(scene, background(scene, dirs))
    h = np.flatnonzero(tr.hit)
    if h.size:
        p = view.origin + tr.t[h, None] * dirs[h]
        width_ = (
            np.maximum(scene.effect_settings.smooth_width, 2.0 * view.detail_footprint * tr.t[h])
            if "smooth_shading" in scene.effects
            else None
        )
        level, g, xk = nearest(c, p, width_, dist)
        normal[h] = g
        hits = Hits(p, dirs[h], tr.t[h], level, g, xk)
        color[h] = encode(scene, shade(scene, c, dist, hits, view.detail_footprint, eps, lod))
    return color, np.where(tr.hit, tr.t, 0.0), normal, tr.iterations, tr.hit
