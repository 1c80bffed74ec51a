"""A point handle grabbed where it lies: a left press on a shown point handle that the gizmo
does not claim selects it and drags it at once, in the plane through it that faces the camera
(as the gizmo's centre drags a selected point), so a fork is moved by pressing on it and
dragging, with no click to select it first. It moves once the pointer has left the press by
more than a click's slip (press.py: a click that selects it does not nudge it), then follows
the pointer as long as the button is held; one press-and-drag is one undo step. Its values
land as the gizmo's do (Gizmo.placed): on a decimal step under a twentieth of a pixel, or on
the grid when snapping. A press on a dial handle's point selects it and turns its dial
(dial.py), one on a mirror normal's arrow tip its trackball (trackball.py). A flick,
pressed, dragged and let go before a turn saw the press, lands where it was let go."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..compile.camera import View, pixel_ray
from .dragging import Dragged, drag_edits
from .handles import Handle
from .picking import under
from .press import past_click


@dataclass
class Grab:
    """A press-and-drag of the handle at ``start`` (world), pressed at window point
    ``press``; ``drag`` numbers it (its edits share one undo step)."""

    handle: Handle
    start: np.ndarray
    press: tuple[float, float]
    drag: int

    def target(self, v: View, cursor: tuple[float, float]) -> np.ndarray:
        """Where the pointer at ``cursor`` puts the handle: moved as far as the pointer in the
        plane through ``start`` facing the camera."""
        depth = float((self.start - v.origin) @ v.forward)

        def at(x: float, y: float) -> np.ndarray:
            d = pixel_ray(v, x, y)
            return d * (depth / float(d @ v.forward))

        return self.start + at(*cursor) - at(*self.press)


class Grabbing:
    """The editor's grab, if one is under way."""

    def __init__(self) -> None:
        self.now: Grab | None = None
        self.drags = 0

    def begin(self, shown: list[Handle], v: View, press: tuple[float, float]) -> Handle | None:
        """A left press at ``press``: the shown point handle there, grabbed, or the dial or
        normal handle there, to be turned by its dial or trackball (Editor._grab); None:
        none."""
        h = under([h for h in shown if h.kind in ("point", "dial", "normal")], v, *press)
        if h is not None and h.kind == "point":
            self.drags += 1
            self.now = Grab(h, np.array(h.position, dtype=np.float64), press, self.drags)
        return h

    def follow(self, e: Dragged, cursor: tuple[float, float], held: bool) -> None:
        """One turn of a grab: the handle to the pointer while the button is ``held`` (an
        edit at once, before the turn's image is traced); the grab ends when it is let go or
        the selection has changed."""
        g = self.now
        if g is None:
            return
        sel = e.selected
        if not held or sel is None or not sel.same(g.handle):
            self.now = None
            return
        if past_click():  # a press that selects a handle does not nudge it by a slip
            self._to(e, g, sel, cursor)

    def fling(self, e: Dragged, release: tuple[float, float]) -> None:
        """A grab whose press, drag and release all came before a turn could see the press
        (a quick flick on a slow frame; Input.flick): the handle where it was let go, at once,
        in one undo step."""
        g, self.now = self.now, None
        if g is not None and e.selected is not None and e.selected.same(g.handle):
            self._to(e, g, e.selected, release)

    @staticmethod
    def _to(e: Dragged, g: Grab, sel: Handle, cursor: tuple[float, float]) -> None:
        """Handle ``sel`` of grab ``g`` where the pointer at ``cursor`` puts it: edits."""
        v = e.window_view()
        p = e.gizmo.placed(g.start, g.target(v, cursor) - g.start, v)
        t = e.viewer.drawn.playback.time
        for path, value in drag_edits(e.scene, sel, p, e.carry, t):
            e.edit(path, value, ("grab", g.drag), f"drag {sel.label}")
