"""Whole-image reference render: the same outputs as the GPU, in float64."""
from __future__ import annotations

import numpy as np

from ..buffers import Buffers
from ..scene import KRS, MoKRS, Scene
from .camera import primary_rays, view_of
from .geometry import compile_geometry, is_unbounding, nearest
from .shade import encode, lambert
from .trace import binary_trace, sphere_trace


def render_reference(scene: Scene, width: int, height: int,
                     geometry: KRS | MoKRS | None = None) -> Buffers:
    view = view_of(scene.camera, width, height)
    c = compile_geometry(geometry or scene.geometry(), scene.material.albedo)
    dirs = primary_rays(view)
    r = scene.render
    eps = view.footprint * r.epsilon_scale
    if r.tracer == "binary":
        tr = binary_trace(lambda x, s: is_unbounding(c, x, s), view.origin, dirs, eps,
                          r.max_iterations, r.max_distance, r.xi_bonus, r.xi_penalty)
    else:
        tr = sphere_trace(c, view.origin, dirs, eps, r.max_iterations, r.max_distance)
    N = len(dirs)
    normal = np.zeros((N, 3))
    color = np.broadcast_to(encode(np.array(scene.material.background)), (N, 3)).copy()
    h = np.flatnonzero(tr.hit)
    if h.size:
        level, g = nearest(c, view.origin + tr.t[h, None] * dirs[h])
        normal[h] = g
        albedo = c.records[level, 0, :3]
        color[h] = encode(lambert(scene, albedo, g))
    H, W = height, width
    return Buffers(color.reshape(H, W, 3), np.where(tr.hit, tr.t, 0.0).reshape(H, W),
                   normal.reshape(H, W, 3), tr.iterations.reshape(H, W), tr.hit.reshape(H, W))
