"""The editor's overlay, as shapes for gpu/overlay.py: the route (a compound's component
routes, placed), the handles shown (larger on the selected level, with its arrows and its
mirror as a translucent disc), and in red the part of each branch that Alg. 1 clips (a
warning of the route), all depth-composited with the traced image."""

from __future__ import annotations

import numpy as np

from ..gpu.overlay import Shapes
from ..scene import Scene
from .handles import Handle, polylines
from .mokrs_handles import MobiusHandle, guide_lines

FORK, CONTROL, NORMAL, SELECTED = (
    (1.0, 0.6, 0.15, 1.0),
    (0.3, 0.85, 1.0, 1.0),
    (1.0, 0.3, 0.8, 1.0),
    (1.0, 1.0, 0.3, 1.0),
)
ROUTE = (1.0, 0.9, 0.5, 0.9)
DISC = (0.5, 0.8, 1.0, 0.25)
CLIPPED = (1.0, 0.1, 0.05, 1.0)
CLIPPED_DOT = 6.0  # pixels: dots along a clipped part, so it reads thicker than a line


def editor_shapes(
    scene: Scene,
    shown: list[Handle],
    selected: Handle | None,
    clipped: list[tuple[int, np.ndarray]],
) -> Shapes:
    """``clipped``: the route's clipped parts (clipped.clipped_parts, made once per scene)."""
    s = Shapes()
    for route in polylines(scene):
        s.lines += [(a, b, ROUTE) for a, b in zip(route[:-1], route[1:])]
    for h in shown:
        colour = {"normal": NORMAL}.get(h.kind, CONTROL if h.path[-1] == "control" else FORK)
        big = selected is not None and h.level == selected.level
        if h.same(selected):
            colour = SELECTED
        s.points.append((h.position, colour, 13.0 if big else 8.0))
        if h.kind == "normal" and (big or h.path[-1] == "mirror"):
            s.lines.append((h.pivot, h.position, NORMAL))
    if selected is not None:
        _mirror_disc(s, shown, selected)
    if isinstance(selected, MobiusHandle):  # a MöKRS step's circle, sphere or vector
        s.lines += guide_lines(selected, NORMAL)
    for _, line in clipped:  # last: over the handles
        s.lines += [(a, b, CLIPPED) for a, b in zip(line[:-1], line[1:])]
        s.points += [(p, CLIPPED, CLIPPED_DOT) for p in line]
    return s


def _mirror_disc(s: Shapes, shown: list[Handle], sel: Handle) -> None:
    """The selected level's mirror as a translucent disc through its arrow's foot."""
    arrow = next((h for h in shown if h.level == sel.level and h.kind == "normal"), None)
    if arrow is None:
        return
    d = arrow.position - arrow.pivot
    r = float(np.linalg.norm(d))
    if r > 0:
        s.disc(arrow.pivot, d / r, 1.6 * r, DISC)
