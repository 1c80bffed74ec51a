"""What the pointer finds in the editor's view: the handles shown (the selected level's and
its neighbours' in full, elsewhere only each level's points, so clusters of arrows stay
apart), the one under the pointer (a hover label names it), and, off the handles, the level
of the kernel nearest to the traced surface point."""

from __future__ import annotations

import math
from typing import Protocol

from imgui_bundle import imgui

from ..compile.camera import View, pixel_ray, project
from ..reference.geometry import nearest
from ..scene import Scene
from ..viewer.picking import depth_at
from ..viewer.window import Viewer
from .handles import Handle

LABEL = 0xFFFFFFFF  # hover labels: white (ImGui's packed ABGR)
PICK_PIXELS = 12.0  # a click this close to a handle grabs it
NEIGHBOURS = 1  # levels either side of the selected one whose handles show in full


class Picked(Protocol):
    """What picking reads of the editor."""

    viewer: Viewer
    selected: Handle | None

    @property
    def scene(self) -> Scene: ...
    @property
    def handles(self) -> list[Handle]: ...


def secondary(h: Handle) -> bool:
    """A handle shown only near the selection: a control point, an arrow, a mirror's slider."""
    return h.kind == "normal" or h.path[-1] in ("control", "mirror")


def visible(hs: list[Handle], selected: Handle | None) -> list[Handle]:
    """The handles drawn and picked: near the selected level all; elsewhere a level's main
    points, or its arrows where it has none (the rock's empty levels)."""
    near = (
        set()
        if selected is None
        else set(range(selected.level - NEIGHBOURS, selected.level + NEIGHBOURS + 1))
    )
    main = {h.level for h in hs if not secondary(h)}
    return [
        h
        for h in hs
        if h.level in near or not secondary(h) or (h.level not in main and h.kind == "normal")
    ]


def under(hs: list[Handle], v: View, x: float, y: float) -> Handle | None:
    """The handle nearest to window point (x, y) within PICK_PIXELS."""
    best, best_d = None, PICK_PIXELS
    for h in hs:
        px, py, z = project(v, h.position)
        d = math.hypot(px - x, py - y) if z > 0 else math.inf
        if d < best_d:
            best, best_d = h, d
    return best


def pick(e: Picked, v: View, x: float, y: float) -> Handle | None:
    """What a click at window point (x, y) selects: a shown handle, else the level of the
    traced surface there."""
    return under(visible(e.handles, e.selected), v, x, y) or _surface(e, v, x, y)


def _surface(e: Picked, v: View, x: float, y: float) -> Handle | None:
    if e.viewer.frames.image is None:
        return None
    fbo, (w, h) = e.viewer.frames.image
    px = min(max(int(x / v.width * w), 0), w - 1)
    py = min(max(int(y / v.height * h), 0), h - 1)
    t = depth_at(fbo, px, py)
    if not t > 0:
        return None
    point = v.origin + t * pixel_ray(v, x, y)
    slot = int(nearest(e.viewer.drawn.world, point[None])[0][0])
    level = _entry_of_slot(e, slot)
    return next((h for h in e.handles if h.level == level), None)


def _entry_of_slot(e: Picked, slot: int) -> int:
    """Outline entry of a compiled level slot: the level itself (shifted by the finest
    levels the levels slider cut away), or a compound's component (slots are numbered
    component after component)."""
    if not e.scene.compound:
        return slot + e.viewer.drawn.geometry.depth - e.viewer.drawn.krs.depth
    bases = list(getattr(e.viewer.drawn.world, "bases", (0,)))
    return max(k for k, b in enumerate(bases) if b <= slot)


def hover_label(shown: list[Handle], view: View) -> None:
    """Inside the ImGui frame: the name of the shown handle under the pointer, beside it
    (none while the pointer is over a panel). Drawn with the view, under ImGui's windows: a
    handle dragged beside a panel does not write its name over the panel."""
    io = imgui.get_io()
    if io.want_capture_mouse:
        return
    h = under(shown, view, io.mouse_pos.x, io.mouse_pos.y)
    if h is not None:
        x, y, _ = project(view, h.position)
        draw = imgui.get_background_draw_list()
        draw.add_text(imgui.ImVec2(x + 10, y - 20), LABEL, h.label)
