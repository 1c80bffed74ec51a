"""The editor's file, a part the editor holds (``Editor.file``): save and save as (a shipped
preset asks where its copy goes), a bookmark as an edit saved with the scene, the file
changed on disk (never overwriting unsaved edits: a conflict to answer), the recovery of a
session that did not end cleanly, and the unsaved-edits question before closing or opening
another scene. It knows the viewer only as a ``Window`` and the editor only by two functions
(its edit, and what it does once another scene is opened), so it can be read and tested
alone (tests/test_file_actions.py)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

from ..document.document import ConflictError, Document, copy_target, not_here, user_folder
from ..scene import Bookmark, SceneError, load_scene
from ..viewer import commands as vc
from ..viewer.camera import FlyCamera
from ..viewer.files import ViewerFile
from . import commands as ec

SAVE_AS = "save as: "  # how a refusal of a save-as name starts (it goes with that name)


class Window(Protocol):
    """What the file part reads and calls of the viewer."""

    doc: Document
    file: ViewerFile  # the file's watcher and camera path; taking it, opening another
    camera: FlyCamera  # a bookmark's view
    message: str
    error: str
    hud: bool  # shown for a question

    def sync(self) -> None: ...
    def say(self, text: str) -> None: ...  # in the status line, for a while


@dataclass(frozen=True)
class CopyAsk:
    """The copy dialog: where the copy goes, and the question that wanted the save (closing
    or opening another scene with unsaved edits), answered once the copy is saved."""

    text: str
    then: tuple[str, Path | None] | None = None
    said: str = ""  # why the last save from this dialog was refused (it stays open)
    why: str = ""  # why a shipped preset's copy is proposed in the user's data folder


def copy_ask(doc: Document, text: str, then: tuple[str, Path | None] | None = None) -> CopyAsk:
    """The copy dialog's question: for a shipped preset its copy (copy_target), saying why
    where that is not the working directory; else ``text``, the save-as field's."""
    if not doc.template:
        return CopyAsk(text, then)
    return CopyAsk(str(copy_target(doc.path)), then, why=not_here(doc.path))


def save_as_default(doc: Document) -> str:
    """What the save-as field starts with: the file itself, or for a shipped preset the
    copy's default (``./NAME.toml``, else the user's folder), never the package's folder."""
    return str(copy_target(doc.path) if doc.template else doc.path)


class FileActions:
    """What the editor does with its file. ``edit`` is the editor's edit through the
    document (a bookmark is one); ``opened`` is told when another scene was opened (the
    editor drops its selection and frames the scene)."""

    def __init__(self, viewer: Window, edit: Callable[..., bool], opened: Callable[[], None]):
        self.viewer = viewer
        self._edit = edit
        self._opened = opened
        self.asking: tuple[str, Path | None] | None = None  # unsaved edits: close / open?
        self.copy_to: CopyAsk | None = None  # a shipped preset's copy, being asked for
        self.recovered = self.doc.recovery()  # a recovery file's scene, offered in a modal
        self.conflict = False  # the file changed on disk while there are unsaved edits
        self.unreadable = ""  # why the file's new contents cannot be taken (deleted, bad)
        self.kept = False  # the person kept their edits: the next save overwrites the file
        self.save_as_text = save_as_default(self.doc)
        self.replacing: Path | None = None  # another file save-as was told exists: again replaces
        self.creating: Path | None = None  # a folder save-as was told is missing: again makes it
        self.quit = False  # the question was answered: the window closes

    @property
    def doc(self) -> Document:
        return self.viewer.doc

    def add_bookmark(self) -> None:
        """In the editor a bookmark is an edit like any other (saved with the scene)."""
        scene = self.doc.scene
        b = Bookmark(f"view {len(scene.bookmarks) + 1}", self.viewer.camera.to_camera())
        label = f"add bookmark {b.name!r}"
        if self._edit(("bookmarks",), scene.bookmarks + [b], label=label):  # said too
            self.viewer.message = f"bookmark {b.name!r} added (Ctrl+S saves it)"
            self.viewer.say(self.viewer.message)

    def reload_scene(self) -> None:
        """Unsaved edits are never overwritten by the file's new contents: ask first."""
        if not self.doc.changed_on_disk():
            return
        if self.doc.dirty:
            self._conflict()
        else:
            self.viewer.file.take()

    def _conflict(self) -> None:
        """The file changed on disk under unsaved edits: ask, knowing whether its new
        contents can be taken at all (a file deleted, or no scene any more, cannot)."""
        self.conflict, self.kept = True, False
        try:
            load_scene(self.doc.path)
            self.unreadable = ""
        except SceneError as e:  # a file unread: why alone (its name is said before it)
            self.unreadable = e.allowed if e.path == "<file>" else str(e)

    def save(self, path: str | None = None, overwrite: bool = False) -> bool:
        """Save (atomic); a shipped preset first asks where its copy goes, taking over the
        unsaved-edits question if that is what asked; nothing is saved yet then."""
        v = self.viewer
        if not path and self.doc.template:
            self.copy_to, self.asking = copy_ask(self.doc, "", self.asking), None
            return False
        own = not path or Path(path).resolve() == self.doc.path.resolve()
        try:
            saved = self.doc.save(path or None, overwrite=overwrite or (self.kept and own))
        except ConflictError:
            v.error = f"{self.doc.path.name} changed on disk: take it, or keep yours and save"
            self._conflict()
            return False
        except SceneError as e:
            v.error = str(e)
            return False
        v.file.follow()
        v.error, v.message, self.conflict, self.kept = "", f"saved {saved.resolve()}", False, False
        v.say(v.message)  # over what the foot said before (kept your edits: Ctrl+S …)
        self.save_as_text = str(saved)
        return True

    def set_save_as_text(self, text: str) -> None:
        """The save-as field's text; a refusal of the name it held goes with that name (it
        stood at the window's foot after the person had moved on)."""
        if text != self.save_as_text and self.viewer.error.startswith(SAVE_AS):
            self.viewer.error = ""
        self.save_as_text = text

    def save_as(self, text: str) -> bool:
        """Save to the file named; another file that exists is replaced, and a folder that
        does not exist is made (a typo in a folder's name would make folders), only when
        asked twice: the first time says so (the panel's field, the dialog's button). The
        user's data folder, where a shipped preset's copy may go, is made without a word."""
        target = _target(text)
        if target.suffix != ".toml" or target.is_dir():
            self.viewer.error = f"{SAVE_AS}{text!r}: a scene file needs a name ending in .toml"
            return False
        folder = target.parent.absolute()
        made = folder.exists() or folder == user_folder().absolute()
        if not made and self.creating != folder:
            self.creating = folder
            self.viewer.error = f"{SAVE_AS}no folder {folder}; save again to make it"
            return False
        self.creating = None
        if self.replaces(text) and self.replacing != target.resolve():
            self.replacing = target.resolve()
            self.viewer.error = f"{SAVE_AS}{target} exists; save again to replace it"
            return False
        self.replacing = None
        return self.save(str(target))

    def replaces(self, text: str) -> bool:
        """Whether saving as ``text`` would replace a file other than the document's own."""
        target = _target(text)
        return target.is_file() and target.resolve() != self.doc.path.resolve()

    def replace_asked(self, text: str) -> bool:
        """Whether the next save as ``text`` replaces another file (told once already)."""
        return self.replacing is not None and self.replacing == _target(text).resolve()

    def ask_save_as(self) -> None:
        """Ctrl+Shift+S: the dialog asks where to save (a shipped preset's: its copy)."""
        self.copy_to = copy_ask(self.doc, self.save_as_text)

    def save_copy(self) -> None:
        """Save to the copy named in the dialog; then go on with the question that asked."""
        ask = self.copy_to
        if ask is None:
            return
        if not self.save_as(ask.text):
            self.copy_to = replace(ask, said=self.viewer.error)  # the dialog stays, saying why
            return
        self.copy_to = None
        if ask.then is not None:
            self.asking = ask.then
            self.answer_save()

    def take_file(self) -> None:
        self.conflict = False
        self.viewer.file.take()

    def keep_mine(self) -> None:
        """The person's edits win over the file's new contents: the next save overwrites
        the file (saving elsewhere leaves it)."""
        self.conflict, self.kept = False, True
        self.viewer.message = f"kept your edits: Ctrl+S overwrites {self.doc.path.name}"
        self.viewer.say(self.viewer.message)

    def restore(self) -> None:
        self.doc.restore_recovery()
        self.recovered = None
        self.viewer.sync()
        self.viewer.message = "restored the unsaved edits (Ctrl+Z undoes the restore)"

    def discard_recovery(self) -> None:
        self.doc.discard_recovery()
        self.recovered = None

    def may_close(self) -> bool:
        """The window's close button: close at once, or first ask about unsaved edits."""
        if not self.doc.dirty:
            return True
        self.asking, self.viewer.hud = ("close", None), True
        return False

    def answer_save(self) -> None:
        if self.save():
            self._answered()

    def answer_discard(self) -> None:
        self.doc.discard_recovery()
        self._answered()

    def answer_cancel(self) -> None:
        self.asking = None

    def _answered(self) -> None:
        what, path = self.asking or (None, None)
        self.asking = None
        if what == "close":
            self.quit = True
        elif what == "open" and path is not None:
            self._open(path)

    def open_preset(self, path: Path) -> None:
        if self.doc.dirty:
            self.asking, self.viewer.hud = ("open", Path(path)), True
        else:
            self._open(path)

    def _open(self, path: Path) -> None:
        self.viewer.file.open(path)
        self.recovered, self.conflict = self.doc.recovery(), False
        self.save_as_text = save_as_default(self.doc)
        self._opened()


# The commands about the file, each applied to the file part (the editor's EDITOR_HANDLERS
# hands them over); tests/test_commands.py checks every command class is handled.
FILE_HANDLERS: dict[type[vc.Command], Callable[[FileActions, Any], None]] = {
    ec.Save: lambda f, c: f.save(),
    ec.SaveAs: lambda f, c: f.save_as(f.save_as_text),
    ec.AskSaveAs: lambda f, c: f.ask_save_as(),
    ec.SetSaveAsText: lambda f, c: f.set_save_as_text(c.text),
    ec.SetCopyText: lambda f, c: setattr(f, "copy_to", replace(f.copy_to, text=c.text, said="")),
    ec.SaveCopy: lambda f, c: f.save_copy(),
    ec.CancelCopy: lambda f, c: setattr(f, "copy_to", None),
    ec.TakeFile: lambda f, c: f.take_file(),
    ec.KeepMine: lambda f, c: f.keep_mine(),
    ec.Restore: lambda f, c: f.restore(),
    ec.DiscardRecovery: lambda f, c: f.discard_recovery(),
    ec.AnswerSave: lambda f, c: f.answer_save(),
    ec.AnswerDiscard: lambda f, c: f.answer_discard(),
    ec.AnswerCancel: lambda f, c: f.answer_cancel(),
    vc.AddBookmark: lambda f, c: f.add_bookmark(),
    vc.OpenPreset: lambda f, c: f.open_preset(c.path),
    vc.ReloadScene: lambda f, c: f.reload_scene(),
}


def _target(text: str) -> Path:
    """The file a save-as field's text names."""
    return Path(text.strip()).expanduser()
