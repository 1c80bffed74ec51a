"""Draws a traced image (the renderer's float buffers) into the current framebuffer, scaled to
it, in one of the view modes of ``display.frag``."""

from __future__ import annotations

import moderngl

from ..compile.constants import VIEW_MODES
from .program import ProgramCache


class Display:
    def __init__(self, ctx: moderngl.Context, programs: ProgramCache):
        self.ctx = ctx
        self.prog = programs.get("fullscreen.vert", "display.frag", {})
        self.vao = ctx.vertex_array(self.prog, [])
        for unit, name in enumerate(("u_color", "u_normal", "u_iterations")):
            self.prog[name].value = unit

    def show(
        self,
        source: moderngl.Framebuffer,
        target: moderngl.Framebuffer,
        size: tuple[int, int],
        view: str,
        iteration_cap: int,
        depth_scale: float,
    ) -> None:
        for unit, tex in enumerate(source.color_attachments):
            tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
            tex.use(location=unit)
        target.use()
        self.ctx.viewport = (0, 0, *size)
        self.prog["u_view"].value = VIEW_MODES.index(view)
        self.prog["u_iteration_cap"].value = float(iteration_cap)
        self.prog["u_depth_scale"].value = depth_scale
        self.prog["u_window"].value = (float(size[0]), float(size[1]))
        self.vao.render(moderngl.TRIANGLES, vertices=3)
