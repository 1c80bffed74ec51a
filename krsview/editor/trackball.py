"""Turning a normal by its arrow tip, as a trackball about its foot (the fork, or the point on
a KRS mirror): the pointer's motion, lifted into the screen plane (right, up), turns the normal
by the rotation vector ω = k · n × D, so the normal changes by k · D⊥ (the drag's part
perpendicular to it). The response is proportional to the pointer and independent of the
arrow's length on screen: a drag of p pixels turns it by at most k · p, and dragging up never
tilts it down. (ImGuizmo's rotate rings measure the angle around the gizmo's centre instead,
so a small drag near the centre is a large turn.)"""

from __future__ import annotations

import math

import numpy as np
from imgui_bundle import imgui

from ..algebra.vectors import cross
from ..compile.camera import View, project
from .gizmo import Snap
from .handles import Handle
from .press import past_click

RADIANS_PER_PIXEL = math.radians(0.5)  # k: a 10-pixel drag turns a normal by at most 5°
GRAB_PIXELS = 12.0  # a press this close to the arrow tip starts turning


def turned(n: np.ndarray, v: View, dx: float, dy: float) -> np.ndarray:
    """Unit normal ``n`` turned by a pointer motion of (dx, dy) window pixels (y down)."""
    d = dx * v.right - dy * v.up
    omega = RADIANS_PER_PIXEL * cross(n, d)
    angle = float(np.linalg.norm(omega))
    if angle == 0.0:
        return n
    a = omega / angle  # Rodrigues: exact rotation, so the normal stays a unit vector
    out = n * math.cos(angle) + cross(a, n) * math.sin(angle) + a * (a @ n) * (1 - math.cos(angle))
    return out / np.linalg.norm(out)


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


class Trackball:
    """The press-and-drag on the selected normal's tip, or on an unselected one's, which the
    press selects (grab.py); each drag is one interaction (one undo step). Snapping rounds
    the direction shown, not the one the drag carries on."""

    def __init__(self, snap: Snap) -> None:
        self.snap = snap
        self.drags = 0
        self.active = False
        self.hovered = False
        self._last = (0.0, 0.0)
        self._free = np.zeros(3)  # the turned normal before snapping
        self._slack = False  # pressed to select it: no turn within a click's slip

    def claims_mouse(self) -> bool:
        """The pointer is on the tip, or turns it: a press there is not the camera's."""
        return self.hovered or self.active

    def update(self, h: Handle, v: View) -> tuple[np.ndarray, tuple] | None:
        """Inside the ImGui frame: while ``h`` (a normal) is turned, where its tip goes
        (world) and the drag's interaction key."""
        io = imgui.get_io()
        x, y = io.mouse_pos.x, io.mouse_pos.y
        tx, ty, z = project(v, h.position)
        free = not io.want_capture_mouse
        self.hovered = free and z > 0 and math.hypot(x - tx, y - ty) <= GRAB_PIXELS
        if not imgui.is_mouse_down(imgui.MouseButton_.left):
            self.active = False
            return None
        if imgui.is_mouse_clicked(imgui.MouseButton_.left) and self.hovered:
            self.start(h, x, y, slack=False)
            return None
        if not self.active or (x, y) == self._last:
            return None
        if self._slack and not past_click():
            return None
        length = float(np.linalg.norm(h.position - h.pivot))
        self._free = turned(self._free, v, x - self._last[0], y - self._last[1])
        self._last = (x, y)
        n = self._free
        if self.snap.on or io.key_shift:
            n = snap_direction(n, self.snap.angle)
        return h.pivot + length * n, ("turn", self.drags)

    def start(self, h: Handle, x: float, y: float, slack: bool = True) -> None:
        """A press at window point (x, y) starts turning normal ``h`` (one new undo step).
        With ``slack`` (the press selects it: grab.py), it turns only once the pointer has
        left the press by more than a click's slip (press.py); on the selected normal's tip,
        at once, for fine steps."""
        arm = h.position - h.pivot
        self.active, self._last, self._free = True, (x, y), arm / float(np.linalg.norm(arm))
        self._slack = slack
        self.drags += 1
