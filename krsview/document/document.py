"""The document: the one seam through which every scene change passes (docs/architecture.md).

It owns the scene, its file, the undo history and the saved version. A drag, a panel field,
an effect toggle, a render knob, a bookmark or a reload from disk is an edit applied here:
validated by the scene schema first (a bad value leaves the last valid scene in place), then
recorded for undo. Saves are atomic and keep the file's mode; while there are unsaved edits a
recovery file beside the scene is rewritten every few seconds, and a file changed on disk is
never overwritten silently. A preset shipped inside the package is a template: it is read,
never written; its copy goes to the user's folder (:func:`copy_target`), its recovery file
to the user's data folder.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Hashable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..files import write_atomic
from ..messages import under_a_file
from ..scene import Bookmark, Camera, Scene, SceneError, load_scene, scene_to_toml
from ..scene.edits import Path as EditPath
from ..scene.edits import apply_edit, path_text, validated
from ..scene.filetext import read_file_text, saved_text
from ..scene.presets import PRESET_DIR
from .bookmarks import with_bookmark, without_bookmark
from .history import History, Step

AUTOSAVE_SECONDS = 3.0  # a crash loses at most this much work
RECOVERY_SUFFIX = ".recovery"


def shipped(path: str | os.PathLike) -> bool:
    """A preset inside the installed package: a template, never written."""
    return Path(os.path.realpath(path)).is_relative_to(os.path.realpath(PRESET_DIR))


def user_folder() -> Path:
    """krsview's folder in the user's data directory (``$XDG_DATA_HOME/krsview``, else
    ``~/.local/share/krsview``): copies of presets where the working directory will not do,
    and the recovery files of presets."""
    data = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(data) / "krsview"


def copy_target(preset: Path, cwd: Path | None = None) -> Path:
    """Where a shipped preset's copy goes unless the user says otherwise: ``NAME.toml`` in
    the working directory if that is free and writable, else in :func:`user_folder`
    (numbered ``NAME-2.toml`` … if taken)."""
    here = (cwd or Path.cwd()) / preset.name
    if not not_here(preset, cwd):
        return here
    folder, k = user_folder(), 1
    while (folder / (preset.name if k == 1 else f"{preset.stem}-{k}.toml")).exists():
        k += 1
    return folder / (preset.name if k == 1 else f"{preset.stem}-{k}.toml")


def not_here(preset: Path, cwd: Path | None = None) -> str:
    """Why a shipped preset's copy does not go to ``NAME.toml`` in the working directory
    (:func:`copy_target`), in words; "" where it does."""
    here = (cwd or Path.cwd()) / preset.name
    if shipped(here):
        return f"{here.parent} holds krsview's own presets"
    if here.exists():
        return f"{here} exists"
    if not os.access(here.parent, os.W_OK):
        return f"{here.parent} is not writable"
    return ""


class ConflictError(RuntimeError):
    """The file changed on disk since it was loaded or saved here; saving would overwrite it."""


@dataclass(frozen=True)
class Stamp:
    """What a file looked like when we last read or wrote it."""

    mtime_ns: int
    size: int

    @staticmethod
    def of(path: Path) -> Stamp | None:
        try:
            st = path.stat()
        except OSError:
            return None
        return Stamp(st.st_mtime_ns, st.st_size)


class Document:
    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        self._scene = load_scene(self.path)  # a bad file is a SceneError, nothing opened
        self.saved = self._scene  # the version on disk
        self.saved_text = read_file_text(self.path)  # as written, comments too
        self.stamp = Stamp.of(self.path)
        self.history = History()
        # the caller's own state kept with each step (the editor: its selection), and what
        # the last undo or redo brought back of it
        self.memo: Callable[[], Hashable] | None = None
        self.restored: Hashable | None = None
        self.version = 0  # bumps on every change: views redraw
        self._autosaved: Scene | None = None
        self._autosave_clock: float | None = None
        self.autosave_error = ""  # why the last autosave could not write ("": it could)
        self.write_error = ""  # why the last undo or redo of a written step could not write

    @property
    def template(self) -> bool:
        """The file is a shipped preset: saving it needs a new name (a copy)."""
        return shipped(self.path)

    # ----------------------------------------------------------------------------- state
    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def dirty(self) -> bool:
        """Unsaved edits: the scene differs from the saved version (undoing back to it is clean)."""
        return self._scene != self.saved

    @property
    def title(self) -> str:
        return f"{'* ' if self.dirty else ''}{self.shown_path} — {self._scene.name}"

    @property
    def shown_path(self) -> str:
        """The file as a person finds it: relative to the working folder when inside it,
        else from the home folder (~/…), else whole; after a save as into another folder
        the name alone would not say which file it is."""
        p = self.path.resolve()
        for base, prefix in ((Path.cwd(), ""), (Path.home(), "~/")):
            if p.is_relative_to(base):
                return prefix + str(p.relative_to(base))
        return str(p)

    def _set(self, scene: Scene) -> None:
        self._scene = scene
        self.version += 1

    # ----------------------------------------------------------------------------- edits
    def apply(
        self,
        path: EditPath,
        value: Any,
        interaction: Hashable | None = None,
        label: str | None = None,
    ) -> None:
        """Set the field at ``path``; one undo step (merged with the previous one when both
        come from the same ``interaction``). A SceneError leaves everything unchanged."""
        scene = apply_edit(self._scene, path, value)
        self.commit(scene, label or f"set {path_text(path)}", interaction)

    def commit(
        self,
        scene: Scene,
        label: str,
        interaction: Hashable | None = None,
        written: bool = False,
    ) -> None:
        """Make ``scene`` (already valid) the document's scene, as one undo step (``written``:
        a step the caller has written to the file; its undo and redo write it too)."""
        if scene == self._scene:
            return
        step = Step(label, self._scene, scene, interaction, self._memo(), written=written)
        self.history.push(step)
        self._set(scene)

    def replace_scene(self, scene: Scene, label: str) -> None:
        """A whole new scene (restoring a recovery, a bake): validated, one undo step."""
        self.commit(validated(scene), label)

    def undo(self) -> Step | None:
        """The scene before the last step, which is returned (None: none);
        :attr:`restored`, the memo taken with it. A step written to the file when taken
        (the viewer's bookmark) is taken out of the file too (:attr:`write_error`)."""
        step = self.history.undo(self._memo())
        if step is not None:
            self.restored = step.memo_before
            self._set(step.before)
            self._rewrite_bookmark(step, keep=False)
        return step

    def redo(self) -> Step | None:
        """The scene after the next step, which is returned (None: none); :attr:`restored`,
        the memo it was undone with; a written step is written again."""
        step = self.history.redo()
        if step is not None:
            self.restored = step.memo_after
            self._set(step.after)
            self._rewrite_bookmark(step, keep=True)
        return step

    def _rewrite_bookmark(self, step: Step, keep: bool) -> None:
        """A bookmark written to the file when added, undone (``keep`` False) or redone: the
        file as it is on disk now, less or plus that bookmark, its own text kept. Where it
        cannot be written, :attr:`write_error` says why and the file stays as it is."""
        self.write_error = ""
        if not step.written:
            return
        bookmark = step.after.bookmarks[-1]
        try:
            on_disk, text = load_scene(self.path), read_file_text(self.path)
            marks = list(on_disk.bookmarks)
            if keep:
                want = replace(on_disk, bookmarks=[*marks, bookmark])
                text = with_bookmark(text, bookmark, want)
            elif bookmark in marks:  # the last one of that name and view
                k = len(marks) - 1 - marks[::-1].index(bookmark)
                want = replace(on_disk, bookmarks=marks[:k] + marks[k + 1 :])
                text = without_bookmark(text, bookmark, on_disk, want)
            else:  # taken out of the file by another program already
                return
            write_atomic(self.path, text)
        except SceneError as e:
            self.write_error = f"the file is as it was: {e}"
            return
        except OSError as e:
            self.write_error = f"{self.path}: the file is as it was: {e.strerror}"
            return
        self.mark_saved(want, text)

    def _memo(self) -> Hashable | None:
        return self.memo() if self.memo is not None else None

    # ------------------------------------------------------------------------------ disk
    def changed_on_disk(self) -> bool:
        """The file is not what we last read or wrote (another program edited it)."""
        stamp = Stamp.of(self.path)
        if stamp == self.stamp:
            return False
        try:
            return read_file_text(self.path) != self.saved_text
        except (OSError, UnicodeDecodeError):
            return True

    def reload(self) -> None:
        """Take the file's new contents as the saved version (an undoable step). Raises
        SceneError for a bad file, keeping the current scene."""
        scene = load_scene(self.path)
        self.commit(scene, f"reload {self.path.name}")
        self.mark_saved(scene, read_file_text(self.path))  # as written

    def save(self, path: str | os.PathLike | None = None, overwrite: bool = False) -> Path:
        """Write the scene atomically (to ``path``: save as). Refuses, with ConflictError, to
        overwrite a file changed on disk since we read it, unless ``overwrite``."""
        target = Path(path) if path is not None else self.path
        if shipped(target):
            raise SceneError(
                "<file>",
                str(target),
                "is a preset shipped with krsview, a template that is never overwritten; "
                f"save a copy instead, e.g. {copy_target(target)}",
            )
        if target == self.path and not overwrite and self.changed_on_disk():
            raise ConflictError(
                f"{self.path} changed on disk since it was opened here; "
                "reload it (your edits stay undoable) or overwrite it"
            )
        if why := under_a_file(target.parent):  # mkdir would say "File exists"
            raise SceneError("<file>", str(target), f"cannot save: {why}")
        try:
            target.parent.mkdir(parents=True, exist_ok=True)  # save as into a new folder
            text = self._text_of(self._scene)
            write_atomic(target, text)
        except OSError as e:
            raise SceneError("<file>", str(target), f"cannot save: {e.strerror}") from None
        old_recovery = self.recovery_path
        self.path = target
        self.mark_saved(self._scene, text)
        old_recovery.unlink(missing_ok=True)
        self.recovery_path.unlink(missing_ok=True)
        self.version += 1
        return target

    def _text_of(self, scene: Scene) -> str:
        """The file's text for ``scene``: the saved text with only what changed written
        into it, comments and layout kept (filetext.py); bookmarks added alone appended as
        tables of their own (a shipped preset's copy made by the viewer's B)."""
        saved, n = self.saved, len(self.saved.bookmarks)
        if (
            replace(scene, bookmarks=saved.bookmarks) != saved
            or scene.bookmarks[:n] != saved.bookmarks
        ):
            return saved_text(self.saved_text, saved, scene)
        text = self.saved_text
        for k in range(n, len(scene.bookmarks)):
            want = replace(saved, bookmarks=scene.bookmarks[: k + 1])
            text = with_bookmark(text, scene.bookmarks[k], want)
        return text

    def add_bookmark(self, camera: Camera) -> tuple[str, Path]:
        """Append a bookmark of ``camera`` to the file (one undo step), its name and the file
        written. Other unsaved edits stay unsaved: the bookmark joins the file as it is on
        disk. A shipped preset's goes to its copy (``copy_target``), the document's file
        from then on. SceneError: the file cannot be read or written."""
        if self.template:
            name = f"view {len(self._scene.bookmarks) + 1}"
            marks = self._scene.bookmarks + [Bookmark(name, camera)]
            scene = apply_edit(self._scene, ("bookmarks",), marks)
            self.commit(scene, f"add bookmark {name!r}", written=True)
            return name, self.save(copy_target(self.path))
        on_disk = load_scene(self.path)
        name = f"view {len(on_disk.bookmarks) + 1}"
        bookmark = Bookmark(name, camera)
        written = replace(on_disk, bookmarks=on_disk.bookmarks + [bookmark])
        try:
            text = with_bookmark(read_file_text(self.path), bookmark, written)
            write_atomic(self.path, text)
        except OSError as e:
            raise SceneError("<file>", str(self.path), f"cannot save: {e.strerror}") from None
        scene = apply_edit(self._scene, ("bookmarks",), written.bookmarks)
        self.commit(scene, f"add bookmark {name!r}", written=True)
        self.mark_saved(written, text)
        return name, self.path

    def mark_saved(self, scene: Scene, text: str | None = None) -> None:
        """The file now holds ``scene`` (written here, or by the viewer's bookmark), as
        ``text`` (default: the scene written anew)."""
        self.saved, self.saved_text = scene, text if text is not None else scene_to_toml(scene)
        self.stamp = Stamp.of(self.path)

    # -------------------------------------------------------------------------- recovery
    @property
    def recovery_path(self) -> Path:
        """Beside the scene: ``NAME.toml.recovery`` (not a ``.toml``, so never a preset); a
        shipped preset's in ``recovery/`` of the user's data folder, never in the package."""
        name = self.path.name + RECOVERY_SUFFIX
        return user_folder() / "recovery" / name if self.template else self.path.with_name(name)

    def autosave(self, now: float) -> bool:
        """Call every event-loop turn: while dirty, rewrite the recovery file at most every
        AUTOSAVE_SECONDS (atomic); when clean, there is none. Returns True when it wrote; when
        it cannot write, ``autosave_error`` says why (and it tries again an interval later)."""
        if not self.dirty:
            if self._autosaved is not None:
                self.recovery_path.unlink(missing_ok=True)
                self._autosaved = None
            self._autosave_clock, self.autosave_error = None, ""
            return False
        if self._autosave_clock is None:
            self._autosave_clock = now  # first unsaved edit: start the interval
        if self._scene == self._autosaved or now - self._autosave_clock < AUTOSAVE_SECONDS:
            return False
        try:
            self.recovery_path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(self.recovery_path, scene_to_toml(self._scene))
        except OSError as e:  # a read-only folder: editing goes on, and the editor says so
            self._autosave_clock = now
            self.autosave_error = (
                f"autosave cannot write {self.recovery_path}: {e.strerror}; "
                "save your edits (Ctrl+S, or save as) to keep them"
            )
            return False
        self._autosaved, self._autosave_clock, self.autosave_error = self._scene, now, ""
        return True

    def recovery(self) -> Scene | None:
        """The autosaved scene, if a recovery file newer than the scene file holds one that
        differs from it (a crash left unsaved edits); None otherwise."""
        rec = Stamp.of(self.recovery_path)
        if rec is None or (self.stamp is not None and rec.mtime_ns < self.stamp.mtime_ns):
            return None
        try:
            scene = load_scene(self.recovery_path)
        except SceneError:
            return None
        return None if scene == self._scene else scene

    def restore_recovery(self) -> None:
        scene = self.recovery()
        if scene is not None:
            self.replace_scene(scene, "restore unsaved edits")

    def discard_recovery(self) -> None:
        self.recovery_path.unlink(missing_ok=True)
