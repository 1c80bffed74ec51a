"""The edit panel's last words: its error line, the structure section's message and the
values its fields refused. They stay while the scene, the selection and the saved version
are those they were said of; an undo, a redo, another edit, another selection or a save
makes them stale, and they go (a 'select a level first' stayed with a level selected, an
'insert a fork' after its undo and after a save, a refused value came back red when its
level was selected again)."""

from __future__ import annotations

from typing import Any


class Words:
    def __init__(self) -> None:
        # the words, and the (scene, selection, saved version) they were said of
        self._said: tuple = ((), None)

    def forget_stale(
        self, viewer: Any, structure: Any, scene: Any, selected: Any, saved: Any
    ) -> None:
        """Once a turn: ``viewer``'s error and refused values and ``structure``'s message
        go when ``scene`` or ``saved`` (by identity) or ``selected`` is no longer what they
        were said of."""
        words = (viewer.error, structure.message, tuple(viewer.interactions.refused))
        of = (scene, selected.path if selected is not None else None, saved)
        if words != self._said[0]:
            self._said = (words, of)
        elif any(words) and (
            of[0] is not self._said[1][0]
            or of[1] != self._said[1][1]
            or of[2] is not self._said[1][2]
        ):
            viewer.error, structure.message = "", ""
            viewer.interactions.refused.clear()
            self._said = (("", "", ()), of)
