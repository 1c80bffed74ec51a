"""The ImGuizmo translate gizmo on the selected point handle: camera-relative matrices (float32
stays precise at any zoom), its axes the world's (never flipped to face the camera, so the Y
arrow points up and the tripod stays right-handed), snapping to the absolute grid, and values
free of float32 noise; each press-and-drag is one interaction, so its edits merge into one undo
step. (A normal is turned by the trackball, trackball.py.)"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from imgui_bundle import imgui, imguizmo

from ..compile.camera import View
from ..gpu.overlay import camera_matrices
from .handles import Handle

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

    @staticmethod
    def begin_frame() -> None:
        gizmo.begin_frame()
        gizmo.allow_axis_flip(False)  # flipped, the tree's Y arrow pointed down (issue 28)

    @staticmethod
    def claims_mouse() -> bool:
        """The pointer is on the gizmo, or drags it: a press there is not the camera's."""
        return bool(gizmo.is_over() or gizmo.is_using())

    def manipulate(self, h: Handle, v: View) -> tuple[np.ndarray, tuple] | None:
        """Draw the gizmo on ``h``; while it is dragged, where ``h`` goes (world) and the
        drag's interaction key."""
        if h.kind == "dial":  # a MöKRS rotation step: a ring about its axis
            return self.turn(h, v)
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
        using = gizmo.is_using()
        if using and not self._was_using:
            self.drags += 1  # a new drag: a new undo step
        self._was_using = using
        if not (changed and using):
            return None
        delta = np.array(m.values[12:15], dtype=np.float64) - before
        quantum = decimal_step(QUANTUM_PIXELS * v.footprint * depth)
        grid = self.snap.grid if self.snap.on or io.key_shift else None
        return moved(h.position, delta, quantum, grid), ("gizmo", self.drags)

    def turn(self, h, v: View) -> tuple[np.ndarray, tuple] | None:
        """The ImGuizmo rotate ring about a dial handle's world ``axis`` through its ``pivot``
        (a MöKRS rotation step); while it is dragged, where the dial point turns to and the
        drag's interaction key. Shift or snap turns in steps of the snap angle."""
        io = imgui.get_io()
        gizmo.set_drawlist(imgui.get_background_draw_list())
        gizmo.set_rect(0.0, 0.0, io.display_size.x, io.display_size.y)
        near = 1e-3 * max(float(np.linalg.norm(h.pivot - v.origin)), 1e-12)
        view, proj = camera_matrices(v, near, 1e6 * near)
        x = h.axis
        y = np.cross(x, [1.0, 0.0, 0.0] if abs(x[0]) < 0.9 else [0.0, 1.0, 0.0])
        y /= np.linalg.norm(y)
        obj = np.eye(4)
        obj[:3, 0], obj[:3, 1], obj[:3, 2] = x, y, np.cross(x, y)
        obj[:3, 3] = h.pivot - v.origin  # camera-relative: float32 stays precise
        m = gizmo.Matrix16(list(obj.T.flatten()))
        snap = self.snap.on or bool(io.key_shift)
        step = gizmo.Matrix3([self.snap.angle] * 3) if snap else None
        changed = gizmo.manipulate(
            gizmo.Matrix16(list(view.T.flatten())),
            gizmo.Matrix16(list(proj.T.flatten())),
            gizmo.OPERATION.rotate_x,
            gizmo.MODE.local,
            m,
            None,
            step,
        )
        using = gizmo.is_using()
        if using and not self._was_using:
            self.drags += 1  # a new drag: a new undo step
        self._was_using = using
        if not (changed and using):
            return None
        turned = np.array(m.values, dtype=np.float64).reshape(4, 4).T[:3, :3] @ obj[:3, :3].T
        return h.pivot + turned @ (h.position - h.pivot), ("gizmo", self.drags)


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
