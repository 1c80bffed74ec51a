"""Whole-image reference render: the same outputs as the GPU, in float64."""
from __future__ import annotations

import numpy as np

from ..buffers import Buffers
from ..scene import KRS, Scene
from .camera import primary_rays, view_of
from .compiled import compile_krs
from .krs import nearest
from .shade import encode, lambert
from .trace import sphere_trace


def render_reference(scene: Scene, width: int, height: int, krs: KRS | None = None) -> Buffers:
    view = view_of(scene.camera, width, height)
    c = compile_krs(krs or scene.geometry(), scene.material.albedo)
    dirs = primary_rays(view)
    r = scene.render
    tr = sphere_trace(c, view.origin, dirs, view.footprint * r.epsilon_scale,
                      r.max_iterations, r.max_distance)
    N = len(dirs)
    normal = np.zeros((N, 3))
    color = np.broadcast_to(encode(np.array(scene.material.background)), (N, 3)).copy()
    h = np.flatnonzero(tr.hit)
    if h.size:
        _, level, g = nearest(c, view.origin + tr.t[h, None] * dirs[h])
        normal[h] = g
        albedo = c.records[level, 0, :3]
        color[h] = encode(lambert(scene, albedo, g))
    H, W = height, width
    return Buffers(color.reshape(H, W, 3), np.where(tr.hit, tr.t, 0.0).reshape(H, W),
                   normal.reshape(H, W, 3), tr.iterations.reshape(H, W), tr.hit.reshape(H, W))
