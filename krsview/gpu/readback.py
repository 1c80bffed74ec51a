"""A framebuffer's planes read back into NumPy: the renderer's image as a :class:`Frame`
(colour + hit, normal + depth, iterations), rows top → bottom."""

from __future__ import annotations

import moderngl
import numpy as np

from ..frame import Frame


def read_plane(fbo: moderngl.Framebuffer, k: int, width: int, height: int) -> np.ndarray:
    """Colour attachment k as (rows top → bottom, columns, 4) float32: the image's part of it
    (its textures may be a texel larger: context.texture_side)."""
    raw = fbo.read(viewport=(0, 0, width, height), attachment=k, components=4, dtype="f4")
    return np.frombuffer(raw, dtype=np.float32).reshape(height, width, 4)


def read_buffers(fbo: moderngl.Framebuffer, width: int, height: int) -> Frame:
    """The frame the renderer's three targets hold (render.frag's outputs)."""
    c, nd, it = (read_plane(fbo, k, width, height) for k in range(3))
    hit = c[..., 3] > 0.5
    return Frame(
        c[..., :3].astype(np.float64),
        nd[..., 3].astype(np.float64),
        nd[..., :3].astype(np.float64),
        it[..., 0].astype(np.int64),
        hit,
    )
