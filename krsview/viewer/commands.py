"""What panels and keys return instead of writing state: typed commands. An edit of a scene
field goes through the document (validated, undoable, saved); the others ask the window for
one of its own changes. Panels read the window; only the window changes itself, by looking
a command's class up in its table of handlers (docs/architecture.md, One seam for edits)."""

from __future__ import annotations

from collections.abc import Hashable
from dataclasses import dataclass
from pathlib import Path
from typing import Any


class Command:
    """Base of every command class; a window's handler table names each one it takes."""


def command_classes() -> list[type[Command]]:
    """Every command class defined so far (the viewer's, and the editor's once imported)."""
    out, todo = [], list(Command.__subclasses__())
    while todo:
        c = todo.pop()
        out.append(c)
        todo += c.__subclasses__()
    return sorted(out, key=lambda c: c.__qualname__)


@dataclass(frozen=True)
class Edit(Command):
    path: tuple  # a scene field, as in scene.edits
    value: Any
    interaction: Hashable | None = None  # edits of one drag merge into one undo step
    # the field the person changed and its value, where the edit is a larger one (a MöKRS
    # step's change carried to its linked levels): a refusal is shown there
    field: tuple[tuple, Any] | None = None
    label: str | None = None  # the undo step's name (None: "set" and the path)


@dataclass(frozen=True)
class SetEffect(Command):
    """Switch an effect (an exclusive partner goes off): an edit of the scene's effects."""

    name: str
    on: bool


@dataclass(frozen=True)
class SetPrepass(Command):
    """The scene's pre-pass tile (an edit); the view draws with it from then on."""

    tile: int
    interaction: Hashable | None = None


@dataclass(frozen=True)
class Undo(Command):
    pass


@dataclass(frozen=True)
class Redo(Command):
    pass


@dataclass(frozen=True)
class SetLevels(Command):
    """Draw the coarsest ``levels`` levels (0: all)."""

    levels: int


@dataclass(frozen=True)
class SetViewMode(Command):
    mode: str  # one of compile.constants.VIEW_MODES


@dataclass(frozen=True)
class SetIterationScale(Command):
    """The iterations view: white at this many iterations of a pixel."""

    iterations: int


@dataclass(frozen=True)
class SetTargetFps(Command):
    fps: float


@dataclass(frozen=True)
class SetSupersample(Command):
    factor: int  # 1, or 2 for 2×2 supersampled still images


@dataclass(frozen=True)
class SetMovingEffects(Command):
    on: bool


@dataclass(frozen=True)
class OpenPreset(Command):
    """Open a shipped preset or any scene file (the HUD's list, or its file field)."""

    path: Path


@dataclass(frozen=True)
class SetOpenText(Command):
    """The HUD's "open a file" field, as typed."""

    text: str


@dataclass(frozen=True)
class ResetView(Command):
    """Back to the scene's camera (R)."""


@dataclass(frozen=True)
class ToggleOrbit(Command):
    """Orbit the surface point at the window centre, or fly again (O)."""


@dataclass(frozen=True)
class Screenshot(Command):
    """A full-resolution PNG of the view (F12)."""


@dataclass(frozen=True)
class ToggleHud(Command):
    """Hide or show the HUD (F1)."""


@dataclass(frozen=True)
class Quit(Command):
    """Close the window (Ctrl+Q), as its close button does: the editor asks first when
    there are unsaved edits."""


@dataclass(frozen=True)
class AddBookmark(Command):
    """Keep the current camera as a bookmark of the scene (B)."""


@dataclass(frozen=True)
class GoToBookmark(Command):
    index: int


@dataclass(frozen=True)
class NextBookmark(Command):
    """The next bookmark, round the list (N)."""


@dataclass(frozen=True)
class ToggleRecording(Command):
    """Start recording the camera path, or stop and save it (F5)."""


@dataclass(frozen=True)
class Replay(Command):
    """Fly the recorded camera path again (F6)."""


@dataclass(frozen=True)
class ReloadScene(Command):
    """The scene file changed on disk (from the file watcher)."""


@dataclass(frozen=True)
class ReloadShaders(Command):
    """A shader file changed on disk (from the file watcher)."""


@dataclass(frozen=True)
class TogglePlay(Command):
    """Play or pause the scene's time (Space)."""


@dataclass(frozen=True)
class SetTime(Command):
    """Show the moment ``time`` (seconds; the HUD's time slider)."""

    time: float


@dataclass(frozen=True)
class SetSpeed(Command):
    """Play at ``speed`` × real time."""

    speed: float
