"""Draws editor overlays (lines, round points, translucent triangles) over the displayed
image, composited with the traced depth so that what is behind a surface shows faint."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import moderngl
import numpy as np

from ..algebra.vectors import cross
from ..compile.camera import View
from .context import image_uniforms
from .program import ProgramCache

HIDDEN_ALPHA = 0.22  # strength of overlay fragments behind traced geometry
NEAR, FAR = 1e-5, 1e7  # clip planes of the overlay's projection (no depth buffer is used)


@dataclass
class Shapes:
    """Overlay geometry in world coordinates (float64), with RGBA colours."""

    lines: list[tuple[np.ndarray, np.ndarray, tuple]] = field(default_factory=list)
    points: list[tuple[np.ndarray, tuple, float]] = field(default_factory=list)
    triangles: list[tuple[np.ndarray, tuple]] = field(default_factory=list)  # (3, 3) corners

    def disc(
        self, centre: np.ndarray, normal: np.ndarray, radius: float, rgba: tuple, segments: int = 48
    ) -> None:
        a = cross(normal, [1.0, 0.0, 0.0] if abs(normal[0]) < 0.9 else [0.0, 1.0, 0.0])
        a /= np.linalg.norm(a)
        b = cross(normal, a)
        ang = np.linspace(0.0, 2.0 * math.pi, segments + 1)
        rim = centre + radius * (np.cos(ang)[:, None] * a + np.sin(ang)[:, None] * b)
        for k in range(segments):
            self.triangles.append((np.array([centre, rim[k], rim[k + 1]]), rgba))


def camera_matrices(v: View, near: float, far: float) -> tuple[np.ndarray, np.ndarray]:
    """Camera-relative view matrix (the eye at the origin, as the tracer sees the world) and
    an OpenGL perspective projection, both row-major 4×4."""
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = v.right, v.up, -v.forward
    f = 1.0 / v.tan_half
    proj = np.array(
        [
            [f / v.aspect, 0, 0, 0],
            [0, f, 0, 0],
            [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
            [0, 0, -1, 0],
        ]
    )
    return view, proj


class Overlay:
    def __init__(self, ctx: moderngl.Context, programs: ProgramCache):
        self.ctx = ctx
        self.prog = programs.get("overlay.vert", "overlay.frag", {})
        self.prog["u_color"].value = 0
        self.prog["u_normal"].value = 1
        self.prog["u_hidden_alpha"].value = HIDDEN_ALPHA

    def draw(
        self,
        shapes: Shapes,
        source: moderngl.Framebuffer,
        target: moderngl.Framebuffer,
        size: tuple[int, int],
        matrix: np.ndarray,
        eye: np.ndarray,
        image: tuple[int, int],
    ) -> None:
        """Draw ``shapes`` into ``target``; ``source`` holds the traced colour and depth of an
        ``image``-sized image, ``matrix`` is projection × view (:func:`camera_matrices`),
        ``eye`` the camera position (float64)."""
        batches = [
            (moderngl.TRIANGLES, [(p, c, 1.0) for tri, c in shapes.triangles for p in tri]),
            (moderngl.LINES, [(p, c, 1.0) for a, b, c in shapes.lines for p in (a, b)]),
            (moderngl.POINTS, [(p, c, s) for p, c, s in shapes.points]),
        ]
        source.color_attachments[0].use(location=0)
        source.color_attachments[1].use(location=1)
        target.use()
        self.ctx.viewport = (0, 0, *size)
        image_uniforms(self.prog, source, size, image)
        self.prog["u_view_projection"].write(matrix.T.astype("f4").tobytes())
        self.ctx.enable(moderngl.BLEND | moderngl.PROGRAM_POINT_SIZE)
        self.ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        for mode, verts in batches:
            if not verts:
                continue
            data = np.array([[*(np.asarray(p) - eye), *c, s] for p, c, s in verts], dtype="f4")
            vbo = self.ctx.buffer(data.tobytes())
            vao = self.ctx.vertex_array(
                self.prog, [(vbo, "3f 4f 1f", "in_position", "in_color", "in_size")]
            )
            self.prog["u_points"].value = mode == moderngl.POINTS
            vao.render(mode)
            vao.release()
            vbo.release()
        self.ctx.disable(moderngl.BLEND | moderngl.PROGRAM_POINT_SIZE)
