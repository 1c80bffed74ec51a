"""Where the edit panel sits (docked left or right, as wide as the person drags it, at most
half the window, or folded to its title bar) and the camera that frames the scene in the part
of the window it leaves: the scene camera's target is turned to the centre of that part, and
when that part changes (the panel folded, unfolded, docked on the other side or hidden by
F1) what was in its middle stays in the middle of the new part."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..compile.camera import view_of
from ..viewer.camera import FlyCamera
from ..viewer.status import Rect, meets

MARGIN = 8.0  # pixels between the panel and the window's edge
PANEL_WIDTH = 340.0  # at first
MIN_WIDTH, MAX_SHARE = 220.0, 0.5  # the narrowest panel, and the widest share of the window


@dataclass
class Layout:
    side: str = "right"  # where the edit panel docks: "left" or "right"
    width: float = PANEL_WIDTH
    folded: bool = False  # only the panel's title bar shows: the view has the whole width
    hidden: bool = False  # F1 hid the panel with the HUD: the view has the whole width

    def panel(
        self, size: tuple[float, float], hud: float = 0.0, hud_right: float = 0.0
    ) -> tuple[float, float, float, float]:
        """The panel's window rectangle (x, y, width, height) in a window of ``size``; where it
        would overlap the viewer's HUD (its title bar ``hud`` pixels tall at the top left,
        reaching ``hud_right``: docked left, or right in a narrow window), it starts below."""
        w, h = size
        width = self.clamped(w)
        x = MARGIN if self.side == "left" else w - width - MARGIN
        y = MARGIN + (hud + MARGIN if hud and x < hud_right + MARGIN else 0.0)
        return x, y, width, max(h - y - MARGIN, 1.0)

    def clamped(self, window_width: float) -> float:
        return max(min(self.width, MAX_SHARE * window_width), min(MIN_WIDTH, window_width))

    def free(self, size: tuple[float, float]) -> tuple[float, float]:
        """The span (x0, x1) of window columns the panel leaves to the view (all of them
        while it is folded: its title bar covers a strip of the top only; none while F1
        hides it)."""
        if self.folded or self.hidden:
            return 0.0, float(size[0])
        x, _, width, _ = self.panel(size)
        return (x + width + MARGIN, size[0]) if self.side == "left" else (0.0, x - MARGIN)


def hud_clear_of(hud: Rect, panel: Rect, side: str, width: float) -> float | None:
    """The x the viewer's HUD (window rectangle ``hud``) moves to so that it no longer covers
    the edit panel (``panel``) docked on ``side`` of a window ``width`` wide: beside the
    panel, on the view's side, inside the window as far as it fits; None where they do not
    meet (the HUD stays where the person put it) or where it cannot move further."""
    if not meets(hud, panel):
        return None
    w = hud[2] - hud[0]
    x = panel[2] + MARGIN if side == "left" else panel[0] - MARGIN - w
    x = max(min(x, width - MARGIN - w), MARGIN)
    return None if x == hud[0] else x


def frame(
    camera: FlyCamera,
    target: np.ndarray,
    size: tuple[int, int],
    span: tuple[float, float],
    ball: np.ndarray | None = None,
) -> None:
    """Turn ``camera`` about its up axis so that ``target`` lies in the middle of the window
    columns ``span``; with a bounding ``ball`` (centre, radius) wider than the span, step back
    until it fits, at most by the ratio of the window's width to the span's (a close-up
    stays a close-up)."""
    w, h = size
    width = max(span[1] - span[0], 1.0)
    if ball is not None:
        v = view_of(camera.to_camera(), w, h)
        distance = float(np.linalg.norm(np.asarray(target) - v.origin))
        fits = ball[3] / (width / w * v.tan_half * v.aspect)  # the ball's half-width = span's
        back = min(max(fits / distance, 1.0), w / width)
        camera.position = np.asarray(target) + (camera.position - np.asarray(target)) * back
    _turn_to(camera, target, size, 0.5 * (span[0] + span[1]))


def shift(
    camera: FlyCamera, size: tuple[int, int], old: tuple[float, float], new: tuple[float, float]
) -> bool:
    """Turn ``camera`` about its up axis so that what is seen in the middle of the columns
    ``old`` is seen in the middle of ``new`` (the view's part of the window changed); False
    when they are the same."""
    if old == new:
        return False
    w, h = size
    v = view_of(camera.to_camera(), w, h)
    x = 0.5 * (old[0] + old[1])
    ray = v.forward + (2.0 * x / w - 1.0) * v.tan_half * v.aspect * v.right
    _turn_to(camera, v.origin + ray, size, 0.5 * (new[0] + new[1]))
    return True


def _turn_to(camera: FlyCamera, target: np.ndarray, size: tuple[int, int], x: float) -> None:
    """Turn ``camera`` about the world's up so that ``target`` is seen in window column x."""
    w, h = size
    for _ in range(3):  # the turn is about the world's up, the column the screen's: converge
        v = view_of(camera.to_camera(), w, h)
        rel = np.asarray(target, dtype=np.float64) - v.origin
        now = math.atan2(float(rel @ v.right), float(rel @ v.forward))
        want = math.atan((2.0 * x / v.width - 1.0) * v.tan_half * v.aspect)
        camera.look(want - now, 0.0)  # a larger yaw turns the view left
