"""A drag in the editor's view: the gizmo on a selected point or the trackball on a selected
normal, and the edits a drag step makes. A value a track moves is keyed at the moment shown
(keys.py); its fork's subtree follows through the pose, as bones do. An unkeyed fork dragged
with its subtree takes the subtree's tracks along (keys.py's ``carried_tracks``), so that a
keyed part of the subtree stays on it at every moment; a MöKRS step's change goes to the
linked levels, keyed where tracked (``linked_edits``)."""

from __future__ import annotations

from typing import Any, Protocol

import numpy as np

from ..compile.camera import View
from ..scene import Scene
from ..scene.edits import Path
from ..viewer.window import Viewer
from .gizmo import Gizmo
from .handles import Handle
from .keys import carried_tracks, linked_edits, track_index
from .trackball import Trackball

LINKED = ("by", "factor", "degrees", "axis", "center", "radius")  # a MöKRS step's roles


class Dragged(Protocol):
    """What a drag reads and calls of the editor."""

    selected: Handle | None
    gizmo: Gizmo
    trackball: Trackball
    carry: bool
    viewer: Viewer

    @property
    def scene(self) -> Scene: ...
    def window_view(self) -> View: ...
    def edit(
        self, path: tuple, value: Any, interaction: Any = None, label: str | None = None
    ) -> bool: ...


def drag_edits(
    scene: Scene, h: Handle, p: np.ndarray, carry: bool, t: float
) -> list[tuple[Path, Any]]:
    """The edits that put handle ``h`` at world point ``p`` at time ``t``: with ``carry`` a
    MöKRS step's in its linked levels; a keyed value's own (keyed in ``Editor.edit``; its
    subtree follows in the pose); else the value, with ``carry`` a fork's subtree and the
    tracks in it."""
    if carry and getattr(h, "role", "") in LINKED:
        return linked_edits(scene, h.path, h.value_at(scene, p), t)
    if track_index(scene, h.path) is not None:
        return [h.edit_to(scene, p, carry=False)]
    edits = [h.edit_to(scene, p, carry)]
    if carry and h.carries:
        shifted = carried_tracks(scene, h.path, h.local(p - h.position, direction=True))
        if shifted is not None:
            edits.append((("animation",), shifted))
    return edits


def manipulate(e: Dragged) -> None:
    """Inside the ImGui frame, before the turn's image is traced: the gizmo on a selected
    point or the trackball on a selected normal; a drag's step is an edit at once (its
    edits are one undo step: they share the drag's interaction)."""
    e.gizmo.begin_frame()
    sel = e.selected
    if sel is None:
        return
    tool = e.trackball.update if sel.kind == "normal" else e.gizmo.manipulate
    moved = tool(sel, e.window_view())
    if moved is not None:
        p, drag = moved
        for path, value in drag_edits(e.scene, sel, p, e.carry, e.viewer.drawn.playback.time):
            e.edit(path, value, drag, f"drag {sel.label}")  # not "set mokrs.levels"
