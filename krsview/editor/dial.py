"""The ring that turns a MöKRS rotation step's dial about its world axis through its pivot: a
circle of fixed size on screen in the plane ⊥ the axis, grabbable anywhere along it (ImGuizmo's
rotate ring draws its whole circle but takes a press only on the half nearer the camera, so a
turn released on the far half could not be taken back from there), and at the dial point
itself, which looks as grabbable as any handle. The angle is the pointer ray's crossing of
that plane measured about the axis, so the dial follows the pointer."""

from __future__ import annotations

import math

import numpy as np
from imgui_bundle import imgui

from ..algebra.vectors import cross
from ..compile.camera import View, pixel_ray, project
from .press import past_click

RING_PIXELS = 60.0  # the ring's radius on screen where it faces the camera
GRAB_PIXELS = 8.0  # a press this close to the drawn ring starts turning
SEGMENTS = 64
EDGE_ON = 1e-3  # |cos| between the pointer ray and the plane below which the angle is unread
RED, HOT = 0xFF3030E0, 0xFF30B0FF  # ImGui's packed ABGR: the ring, hovered or turned


def rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """The 3 × 3 right-handed rotation by ``angle`` (radians) about unit ``axis``."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


class Dial:
    """Press-and-drag on the ring, or on the dial point, of the selected dial handle; each
    drag is one interaction (one undo step)."""

    def __init__(self) -> None:
        self.drags = 0
        self.active = False
        self.hovered = False
        self._last = 0.0  # the pointer's angle about the axis at the last frame
        self._turned = 0.0  # radians turned since the press
        self._start = np.zeros(3)  # the dial point at the press
        self._slack = False  # pressed on the dial point: no turn within a click's slip

    def update(self, h, v: View, snap: float | None) -> tuple[np.ndarray, tuple] | None:
        """Inside the ImGui frame: draw the ring of dial handle ``h``; while it is turned,
        where the dial point goes (world) and the drag's interaction key. With ``snap``
        (degrees), it turns by whole multiples of it from the press."""
        io = imgui.get_io()
        x, y = io.mouse_pos.x, io.mouse_pos.y
        basis = plane_basis(h.axis)
        ring = self._ring(h, v, basis)
        self.hovered = not io.want_capture_mouse and (
            distance_to(ring, x, y) <= GRAB_PIXELS or on_point(h, v, x, y)
        )
        draw = imgui.get_background_draw_list()
        pts = [imgui.ImVec2(px, py) for px, py in ring]
        draw.add_polyline(pts, HOT if self.hovered or self.active else RED, 3.0, 0)
        if not imgui.is_mouse_down(imgui.MouseButton_.left):
            self.active = False
            return None
        angle = pointer_angle(h, v, basis, x, y)
        if imgui.is_mouse_clicked(imgui.MouseButton_.left) and self.hovered:
            self.start(h, v, x, y)
            return None
        if not self.active or angle is None or angle == self._last:
            return None
        self._turned += math.remainder(angle - self._last, 2.0 * math.pi)
        self._last = angle
        if self._slack and not past_click():
            return None
        turned = self._turned
        if snap:
            step = math.radians(snap)
            turned = round(turned / step) * step
        p = h.pivot + rotation(h.axis, turned) @ (self._start - h.pivot)
        return p, ("dial", self.drags)

    def start(self, h, v: View, x: float, y: float) -> bool:
        """A press at window point (x, y) starts turning dial handle ``h`` (one new undo
        step); false where the pointer reads no angle there (the plane seen edge-on). Pressed
        on the dial point (a click there selects it, or lands on the selected one), it turns
        only once the pointer has left the press by more than a click's slip (press.py);
        pressed on the ring, at once, for fine steps."""
        angle = pointer_angle(h, v, plane_basis(h.axis), x, y)
        if angle is None:
            return False
        self.active, self._last, self._turned = True, angle, 0.0
        self._slack = on_point(h, v, x, y)
        self._start = np.array(h.position, dtype=np.float64)
        self.drags += 1
        return True

    @staticmethod
    def _ring(h, v: View, basis: tuple[np.ndarray, np.ndarray]) -> list[tuple[float, float]]:
        """The ring's window points (closed), those in front of the eye."""
        depth = max(float((h.pivot - v.origin) @ v.forward), 1e-12)
        radius = RING_PIXELS * v.footprint * depth
        out = []
        for t in np.linspace(0.0, 2.0 * math.pi, SEGMENTS + 1):
            arm = math.cos(t) * basis[0] + math.sin(t) * basis[1]
            px, py, z = project(v, h.pivot + radius * arm)
            if z > 0:
                out.append((px, py))
        return out


def on_point(h, v: View, x: float, y: float) -> bool:
    """Window point (x, y) lies on the dial point of ``h`` (drawn on its guide circle)."""
    px, py, z = project(v, h.position)
    return z > 0 and math.hypot(px - x, py - y) <= GRAB_PIXELS


def plane_basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors spanning the plane ⊥ ``axis``, right-handed with it."""
    e = cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
    e /= np.linalg.norm(e)
    return e, cross(axis, e)


def distance_to(ring: list[tuple[float, float]], x: float, y: float) -> float:
    """The distance in pixels from (x, y) to the ring's polyline (inf without one)."""
    best = math.inf
    for (ax, ay), (bx, by) in zip(ring, ring[1:]):
        dx, dy = bx - ax, by - ay
        s = ((x - ax) * dx + (y - ay) * dy) / max(dx * dx + dy * dy, 1e-12)
        s = min(1.0, max(0.0, s))
        best = min(best, math.hypot(x - ax - s * dx, y - ay - s * dy))
    return best


def pointer_angle(h, v: View, basis, x: float, y: float) -> float | None:
    """The angle about ``h.axis`` of where the ray through window point (x, y) crosses the
    ring's plane; None where the plane is seen edge-on or lies behind the eye."""
    d = pixel_ray(v, x, y)
    along = float(d @ h.axis)
    if abs(along) < EDGE_ON:
        return None
    t = float((h.pivot - v.origin) @ h.axis) / along
    if t <= 0.0:
        return None
    q = v.origin + t * d - h.pivot
    return math.atan2(float(q @ basis[1]), float(q @ basis[0]))
