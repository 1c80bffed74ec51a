"""What the editor draws in a turn's ImGui frame, after the trace: the overlay over the
image (handles, clipped parts), the viewer's HUD (collapsed at first: the view stays free),
the edit panel, the timeline of a moving scene, and the name of the handle under the
pointer (the gizmo came before the trace: dragging.py). Each part returns commands, which
the editor applies."""

from __future__ import annotations

from collections.abc import Callable

import glfw
import numpy as np
from imgui_bundle import imgui

from ..compile.camera import View
from ..gpu.overlay import FAR, NEAR, Overlay, camera_matrices
from ..viewer import commands as vc
from ..viewer.hud import HUD_TITLE, draw_hud
from ..viewer.status import drawn_rect, status_room, window_rect
from .handles import Handle
from .keys import STRIP_ROOM, Timeline
from .layout import hud_clear_of
from .panels import PANEL_TITLE, Edited, edit_panel
from .picking import hover_label
from .shapes import editor_shapes


class Drawing(Edited):
    """What the drawing reads of the editor besides what the panels do."""

    overlay: Overlay
    timeline: Timeline
    execute: Callable[[list[vc.Command]], None]

    @property
    def clipped(self) -> list[tuple[int, np.ndarray]]: ...
    def window_view(self) -> View: ...
    def shown(self) -> list[Handle]: ...


def draw_ui(e: Drawing, status: str) -> None:
    """The editor's windows over the image; the HUD ends above the timeline and above the
    ``status`` line wrapped into the view's columns (status.py)."""
    v = e.viewer
    view = e.window_view()
    shown = e.shown()
    if v.frames.image is not None:
        fb = glfw.get_framebuffer_size(v.window)
        view_matrix, proj = camera_matrices(view, NEAR, FAR)
        shapes = editor_shapes(e.handled_scene(), shown, e.selected, e.clipped)
        fbo, image = v.frames.image
        e.overlay.draw(shapes, fbo, v.ctx.screen, fb, proj @ view_matrix, view.origin, image)
    _hud_beside_panel(e)
    imgui.set_next_window_collapsed(True, imgui.Cond_.first_use_ever)
    size = glfw.get_window_size(v.window)
    foot = status_room(status, e.layout.free(size), size[0], drawn_rect(HUD_TITLE))
    foot += STRIP_ROOM if e.scene.animated else 0.0
    e.execute(draw_hud(v, v.interactions, foot))
    e.execute(edit_panel(e, v.interactions))
    if e.scene.animated:  # a still scene keeps the whole view (K starts a track)
        free = e.layout.free(glfw.get_window_size(v.window))
        paths = e.timeline.paths(e.scene, e.selected, e.carry)
        e.execute(e.timeline.draw(e.scene, v.drawn.playback, paths, free))
    hover_label(shown, view)


def _hud_beside_panel(e: Drawing) -> None:
    """The HUD opened over the edit panel (docked left, its default place is the panel's)
    moves beside it, as the windows were last drawn; it stays where the person dragged it
    elsewhere."""
    hud, panel = (imgui.internal.find_window_by_name(n) for n in (HUD_TITLE, PANEL_TITLE))
    if hud is None or panel is None or panel.collapsed:
        return
    width = imgui.get_io().display_size.x
    x = hud_clear_of(window_rect(hud), window_rect(panel), e.layout.side, width)
    if x is not None:
        imgui.set_window_pos(HUD_TITLE, imgui.ImVec2(x, hud.pos.y))
