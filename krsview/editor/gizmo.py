"""The ImGuizmo translate gizmo on the selected point handle: camera-relative matrices (float32
stays precise at any zoom), its axes the world's (never flipped to face the camera, so the Y
arrow points up and the tripod stays right-handed), snapping to the absolute grid, and values
free of float32 noise; each press-and-drag is one interaction, so its edits merge into one undo
step. A drag pressed on the handle's own point (within PICK_PIXELS) moves it only once the
pointer has left the press by a click's CLICK_PIXELS, so a click on the selected handle never
nudges it; one pressed on an arrow away from the point moves at once, for fine steps. (A
normal is turned by the trackball, trackball.py; a MöKRS rotation by its ring, dial.py.)"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from imgui_bundle import imgui, imguizmo

from ..compile.camera import View, project
from ..gpu.overlay import camera_matrices
from .dial import Dial
from .handles import Handle
from .picking import PICK_PIXELS
from .press import past_click

gizmo = imguizmo.im_guizmo
QUANTUM_PIXELS = 0.05  # a dragged coordinate is rounded to a decimal step under this on screen


@dataclass
class Snap:
    on: bool = False
    grid: float = 0.05  # units, for a translate drag
    angle: float = 5.0  # degrees (a normal's arrow tip snaps to the grid on its circle)


class Gizmo:
    def __init__(self) -> None:
        self.snap = Snap()
        self.drags = 0  # numbers each drag: one undo step each
        self._was_using = False
        self._over = False  # the pointer is on a part of the gizmo drawn this frame
        self._on_handle = False  # this drag was pressed on the handle itself
        self.dial = Dial()

    def begin_frame(self) -> None:
        gizmo.begin_frame()
        gizmo.allow_axis_flip(False)  # flipped, the tree's Y arrow pointed down (issue 28)
        self._over = False

    def claims_mouse(self) -> bool:
        """The pointer is on the gizmo drawn this frame, or drags it: a press there is not
        the camera's. (ImGuizmo's own ``is_over`` answers for the frame before, so a pointer
        just moved onto or off a ring was claimed wrongly for one frame.)"""
        return self._over or self.dragging()

    def dragging(self) -> bool:
        """The gizmo or the dial is being dragged (wherever the pointer is now)."""
        return self.dial.active or bool(gizmo.is_using())

    def manipulate(self, h: Handle, v: View) -> tuple[np.ndarray, tuple] | None:
        """Draw the gizmo on ``h``; while it is dragged, where ``h`` goes (world) and the
        drag's interaction key."""
        if h.kind == "dial":  # a MöKRS rotation step: a ring about its axis (dial.py)
            snap = self.snap.angle if self.snap.on or imgui.get_io().key_shift else None
            turned = self.dial.update(h, v, snap)
            self._over = self.dial.hovered
            return turned
        io = imgui.get_io()
        gizmo.set_drawlist(imgui.get_background_draw_list())
        gizmo.set_rect(0.0, 0.0, io.display_size.x, io.display_size.y)
        depth = max(float(np.linalg.norm(h.position - v.origin)), 1e-12)
        view, proj = camera_matrices(v, 1e-3 * depth, 1e3 * depth)
        obj = np.eye(4)
        obj[:3, 3] = h.position - v.origin  # camera-relative: float32 stays precise
        m = gizmo.Matrix16(list(obj.T.flatten()))
        before = np.array(m.values[12:15], dtype=np.float64)  # as ImGuizmo holds it
        changed = gizmo.manipulate(
            gizmo.Matrix16(list(view.T.flatten())),
            gizmo.Matrix16(list(proj.T.flatten())),
            gizmo.OPERATION.translate,
            gizmo.MODE.world,
            m,
        )
        drags = self.drags
        using = self._track()
        if self.drags != drags:  # pressed now: on the handle's point, or on an arrow beside it
            x, y, _ = project(v, h.position)
            left = imgui.MouseButton_.left.value
            at, since = imgui.get_io().mouse_pos, imgui.get_mouse_drag_delta(left, 0.0)
            self._on_handle = math.hypot(at.x - since.x - x, at.y - since.y - y) <= PICK_PIXELS
        if not (changed and using):
            return None
        if self._on_handle and not past_click():
            return None  # a click on the handle that slips does not nudge it (as grab.py)
        delta = np.array(m.values[12:15], dtype=np.float64) - before
        return self.placed(h.position, delta, v), ("gizmo", self.drags)

    def placed(self, p: np.ndarray, delta: np.ndarray, v: View) -> np.ndarray:
        """``p`` moved by a drag's ``delta``: on a decimal step under QUANTUM_PIXELS on screen
        at p's distance, or on the grid when snapping (the snap's switch, or Shift held)."""
        depth = max(float(np.linalg.norm(p - v.origin)), 1e-12)
        quantum = decimal_step(QUANTUM_PIXELS * v.footprint * depth)
        grid = self.snap.grid if self.snap.on or imgui.get_io().key_shift else None
        return moved(p, delta, quantum, grid)

    def _track(self) -> bool:
        """Right after ``gizmo.manipulate``: note whether the pointer is on the gizmo now and
        whether a new drag began (a new undo step); whether it is being dragged."""
        self._over = gizmo.get_hovered_handle_type() != gizmo.MOVETYPE.mt_none
        using = bool(gizmo.is_using())
        if using and not self._was_using:
            self.drags += 1
        self._was_using = using
        return using


def decimal_step(size: float) -> float:
    """The largest power of ten not above ``size``."""
    return 10.0 ** math.floor(math.log10(size))


def moved(p: np.ndarray, delta: np.ndarray, quantum: float, grid: float | None) -> np.ndarray:
    """``p`` moved by the gizmo's ``delta``: the coordinates it moves (by more than half a
    ``quantum``; ImGuizmo leaves the others exactly) land on the absolute ``grid`` when
    snapping, else on a multiple of ``quantum``, written as the shortest decimal; the others
    keep their float64 value bit for bit (no float32 noise)."""
    out = np.array(p, dtype=np.float64)
    step = grid if grid is not None else quantum
    digits = max(0, -math.floor(math.log10(step)) + 1)
    for c in range(3):
        if abs(delta[c]) > 0.5 * quantum:
            out[c] = round(round((p[c] + delta[c]) / step) * step, digits)
    return out
