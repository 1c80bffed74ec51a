"""Draws a traced image (the renderer's float buffers) into the current framebuffer, scaled to
it, in one of the view modes of ``display.frag``: a variant per mode (``KRS_VIEW``), compiled
on first use, since this pass runs over every window pixel each turn and llvmpipe would run
every mode's texture reads and maths if the mode were a uniform."""

from __future__ import annotations

import moderngl

from ..compile.constants import VIEW_MODES
from .context import image_uniforms
from .program import ProgramCache

UNITS = ("u_color", "u_normal", "u_iterations")  # the source's colour attachments, in order


def view_defines(view: str) -> dict[str, str]:
    """``display.frag``'s defines for view mode ``view``: none for the shaded colour."""
    if view not in VIEW_MODES:
        raise ValueError(f"view mode {view!r}: allowed: {', '.join(VIEW_MODES)}")
    return {} if view == "shaded" else {"KRS_VIEW": f"VIEW_{view.upper()}"}


class Display:
    """The display pass; ``views``: the modes compiled at once (a shader reload checks every
    one), the others on first use."""

    def __init__(self, ctx: moderngl.Context, programs: ProgramCache, views: tuple[str, ...] = ()):
        self.ctx, self.programs = ctx, programs
        self._vaos: dict[str, moderngl.VertexArray] = {}
        for view in views:
            self._vao(view)

    def _vao(self, view: str) -> moderngl.VertexArray:
        if view not in self._vaos:
            prog = self.programs.get("fullscreen.vert", "display.frag", view_defines(view))
            for unit, name in enumerate(UNITS):
                if name in prog:
                    prog[name].value = unit
            self._vaos[view] = self.ctx.vertex_array(prog, [])
        return self._vaos[view]

    def show(
        self,
        source: moderngl.Framebuffer,
        target: moderngl.Framebuffer,
        size: tuple[int, int],
        view: str,
        iteration_scale: float,
        depth_scale: float,
        image: tuple[int, int],
    ) -> None:
        """Draw ``source``'s image of size ``image`` over ``target``'s ``size`` in ``view``;
        the iterations view is white at ``iteration_scale``, the depth view at ``depth_scale``."""
        vao = self._vao(view)
        prog = vao.program
        for unit, tex in enumerate(source.color_attachments):
            if UNITS[unit] in prog:
                tex.filter = (moderngl.LINEAR, moderngl.LINEAR)
                tex.repeat_x = tex.repeat_y = False  # an edge pixel blends its own side only
                tex.use(location=unit)
        target.use()
        self.ctx.viewport = (0, 0, *size)
        for name, value in (("u_iteration_scale", iteration_scale), ("u_depth_scale", depth_scale)):
            if name in prog:
                prog[name].value = float(value)
        image_uniforms(prog, source, size, image)
        vao.render(moderngl.TRIANGLES, vertices=3)
