"""The editor's own commands (the viewer's are in krsview.viewer.commands): what its panels,
keys and modals return; the editor applies them through its EDITOR_HANDLERS."""

from __future__ import annotations

from dataclasses import dataclass

from ..viewer.commands import Command
from .handles import Handle


@dataclass(frozen=True)
class Bake(Command):
    """Grown tree → route (one undo step): every fork becomes a handle; in a compound, the
    tree of component ``component``."""

    component: int | None = None


@dataclass(frozen=True)
class Select(Command):
    handle: Handle | None


@dataclass(frozen=True)
class SelectLevel(Command):
    """Select the first handle of an outline entry."""

    level: int


@dataclass(frozen=True)
class OutlineScrolled(Command):
    """The outline has scrolled to the selection."""


@dataclass(frozen=True)
class SetSnap(Command):
    on: bool


@dataclass(frozen=True)
class SetCarry(Command):
    """A dragged fork takes its subtree along (on) or moves alone (off)."""

    on: bool


@dataclass(frozen=True)
class Save(Command):
    """Ctrl+S: write the scene to its file (atomic)."""


@dataclass(frozen=True)
class SaveAs(Command):
    """Save under the name typed in the panel's save-as field (its button, or Enter)."""


@dataclass(frozen=True)
class AskSaveAs(Command):
    """Ctrl+Shift+S: a dialog asks the name to save under."""


@dataclass(frozen=True)
class SetSaveAsText(Command):
    text: str


@dataclass(frozen=True)
class TakeFile(Command):
    """A conflict: take the file's new contents (the edits stay undoable)."""


@dataclass(frozen=True)
class KeepMine(Command):
    """A conflict: keep the edits; the next save overwrites the file."""


@dataclass(frozen=True)
class Restore(Command):
    """Restore the unsaved edits a crashed session left (an undoable step)."""


@dataclass(frozen=True)
class DiscardRecovery(Command):
    pass


@dataclass(frozen=True)
class AnswerSave(Command):
    """Unsaved edits before closing or opening another scene: save them, then go on."""


@dataclass(frozen=True)
class AnswerDiscard(Command):
    """Unsaved edits: drop them and go on."""


@dataclass(frozen=True)
class AnswerCancel(Command):
    """Unsaved edits: stay."""


@dataclass(frozen=True)
class PlacePanel(Command):
    """The edit panel docks on ``side`` ("left" or "right") and is ``width`` pixels wide."""

    side: str
    width: float


@dataclass(frozen=True)
class FoldPanel(Command):
    """The edit panel was folded to its title bar (``folded``) or unfolded by its arrow."""

    folded: bool


@dataclass(frozen=True)
class LevelOp(Command):
    """A MöKRS level's operation (editor/mokrs_levels.py OPS): "duplicate", "insert",
    "remove", "inward" or "outward"."""

    level: int
    op: str


# ------------------------------------------------------------- structure (editor/structure.py)
@dataclass(frozen=True)
class InsertLevel(Command):
    """Insert a fork along a level's branch (None: the selected level), at the split
    point the structure section shows."""

    level: int | None = None


@dataclass(frozen=True)
class RemoveLevel(Command):
    """Remove a level's fork: its branch and the next finer one merge (None: selected)."""

    level: int | None = None


@dataclass(frozen=True)
class DuplicateLevel(Command):
    """The level once more at its own tip (None: the selected level)."""

    level: int | None = None


@dataclass(frozen=True)
class WholeTree(Command):
    """A whole-route operation with the structure section's value: "taper", "widths",
    "scale" or "base"."""

    op: str


@dataclass(frozen=True)
class SetToolValue(Command):
    """A value of the structure section (split point, taper ratio, factors, base)."""

    name: str
    value: object


@dataclass(frozen=True)
class SetGrowth(Command):
    """Grow the route again with one growth parameter changed (edits kept where they can
    be; otherwise the editor asks first)."""

    name: str
    value: object
    interaction: object = None


@dataclass(frozen=True)
class Regrow(Command):
    """Grow the route again from its growth parameters as they are."""


@dataclass(frozen=True)
class ConfirmRegrow(Command):
    """Re-grow although the listed hand edits will be lost."""


@dataclass(frozen=True)
class CancelRegrow(Command):
    """Keep the route as it is."""


# ------------------------------------------------- a shipped preset's copy (editor/saving.py)
@dataclass(frozen=True)
class SetCopyText(Command):
    """Where the copy of a shipped preset goes (the dialog's field)."""

    text: str


@dataclass(frozen=True)
class SaveCopy(Command):
    """Save the shipped preset's edits to the copy named in the dialog."""


@dataclass(frozen=True)
class CancelCopy(Command):
    """Close the copy dialog without saving."""


@dataclass(frozen=True)
class SetKey(Command):
    """K: a key for the selected value at the moment shown (an edit of the tracks)."""


@dataclass(frozen=True)
class ShowKeys(Command):
    """A click into a panel field that a track moves (or into a grown tree's growth field,
    which has no handle): the timeline strip shows its keys, and K keys it."""

    path: tuple
