"""What panels return instead of writing state: an edit of a scene field (applied through the
document, so it is validated and undoable) or a call of one of the window's own methods.
Panels read the window; only the window changes itself (DESIGN.md, One seam for edits)."""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True)
class Edit:
    path: tuple  # a scene field, as in scene.edits
    value: Any
    interaction: Hashable | None = None  # edits of one drag merge into one undo step


@dataclass(frozen=True, init=False)
class Do:
    """Call the window's method ``action`` with ``args``."""

    action: str
    args: tuple

    def __init__(self, action: str, *args: Any):
        object.__setattr__(self, "action", action)
        object.__setattr__(self, "args", args)


Command = Edit | Do
