"""The editor's file, one job of the editor window (a mixin of ``Editor``): save and save
as (a shipped preset asks where its copy goes, saving.py), a bookmark as an edit saved with
the scene, the file changed on disk (never overwriting unsaved edits: a conflict to answer),
the recovery of a session that did not end cleanly, and the unsaved-edits question before
closing or opening another scene."""

from __future__ import annotations

from pathlib import Path

from ..document.document import ConflictError
from ..scene import Bookmark, Scene, SceneError
from ..viewer.window import Viewer
from .saving import ask_copy, save_as_default


class FileActions:
    """What the editor does with its file. Mixed into ``Editor``, which gives it the state
    below, its ``doc`` and ``scene``, ``edit`` (an edit through the document) and ``frame``
    (the camera framing the scene beside the panel)."""

    viewer: Viewer
    asking: tuple[str, Path | None] | None  # unsaved edits: close / open?
    recovered: Scene | None  # a recovery file's scene, offered in a modal
    conflict: bool  # the file changed on disk while there are unsaved edits
    save_as_text: str
    selected: object
    _quit: bool

    def add_bookmark(self) -> None:
        """In the editor a bookmark is an edit like any other (saved with the scene)."""
        b = Bookmark(f"view {len(self.scene.bookmarks) + 1}", self.viewer.camera.to_camera())
        if self.edit(("bookmarks",), self.scene.bookmarks + [b]):
            self.viewer.message = f"bookmark {b.name!r} added (Ctrl+S saves it)"

    def reload_scene(self) -> None:
        """Unsaved edits are never overwritten by the file's new contents: ask first."""
        if not self.doc.changed_on_disk():
            return
        if self.doc.dirty:
            self.conflict = True
        else:
            self.viewer.take_file()

    def save(self, path: str | None = None, overwrite: bool = False) -> bool:
        v = self.viewer
        if not path and self.doc.template:
            return ask_copy(self)
        try:
            saved = self.doc.save(path or None, overwrite=overwrite)
        except ConflictError as e:
            v.error, self.conflict = str(e), True
            return False
        except SceneError as e:
            v.error = str(e)
            return False
        v.follow_file()
        v.error, v.message, self.conflict = "", f"saved {saved.resolve()}", False
        self.save_as_text = str(saved)
        return True

    def save_as(self, text: str) -> None:
        target = Path(text.strip()).expanduser()
        if target.suffix != ".toml" or target.is_dir():
            self.viewer.error = f"save as: {text!r}: a scene file needs a name ending in .toml"
            return
        self.save(str(target))

    def take_file(self) -> None:
        self.conflict = False
        self.viewer.take_file()

    def keep_mine(self) -> None:
        self.conflict = False
        self.viewer.message = "kept your edits; saving will ask to overwrite"

    def restore(self) -> None:
        self.doc.restore_recovery()
        self.recovered = None
        self.viewer.sync()
        self.viewer.message = "restored the unsaved edits (Ctrl+Z undoes the restore)"

    def discard_recovery(self) -> None:
        self.doc.discard_recovery()
        self.recovered = None

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
            self._quit = True
        elif what == "open" and path is not None:
            self._open(path)

    def open_preset(self, path: Path) -> None:
        if self.doc.dirty:
            self.asking, self.viewer.hud = ("open", Path(path)), True
        else:
            self._open(path)

    def _open(self, path: Path) -> None:
        self.viewer.open_preset(path)
        self.selected, self.recovered, self.conflict = None, self.doc.recovery(), False
        self.save_as_text = save_as_default(self.doc)
        self.frame()
