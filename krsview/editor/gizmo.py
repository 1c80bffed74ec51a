"""The ImGuizmo translate gizmo on the selected handle: camera-relative matrices (float32
stays precise at any zoom), snapping to a grid or, for a normal's arrow tip, to angles; each
press-and-drag is one interaction, so its edits merge into one undo step."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from imgui_bundle import imgui, imguizmo

from ..compile.camera import View
from ..gpu.overlay import camera_matrices
from .handles import Handle

gizmo = imguizmo.im_guizmo


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
        near = 1e-3 * max(float(np.linalg.norm(h.position - v.origin)), 1e-12)
        view, proj = camera_matrices(v, near, 1e6 * near)
        obj = np.eye(4)
        obj[:3, 3] = h.position - v.origin  # camera-relative: float32 stays precise
        m = gizmo.Matrix16(list(obj.T.flatten()))
        snap = self.snap.on or bool(io.key_shift)
        step = gizmo.Matrix3([self.snap.grid] * 3) if snap and h.kind == "point" else None
        changed = gizmo.manipulate(
            gizmo.Matrix16(list(view.T.flatten())),
            gizmo.Matrix16(list(proj.T.flatten())),
            gizmo.OPERATION.translate,
            gizmo.MODE.world,
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
        p = np.array(m.values[12:15], dtype=np.float64) + v.origin
        if snap and h.kind == "normal":
            p = h.pivot + snap_direction(p - h.pivot, self.snap.angle)
        return p, ("gizmo", self.drags)

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


def snap_direction(d: np.ndarray, degrees: float) -> np.ndarray:
    """d with its polar angles (from +y, around y) rounded to multiples of ``degrees``."""
    r = float(np.linalg.norm(d))
    if r == 0:
        return d
    step = math.radians(degrees)
    theta = round(math.acos(max(-1.0, min(1.0, d[1] / r))) / step) * step
    phi = round(math.atan2(d[2], d[0]) / step) * step
    return r * np.array(
        [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
    )
