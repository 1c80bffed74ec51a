"""The editor's file part alone (editor/file_actions.py), without a window: it is given a
stand-in for the viewer (a document, a camera, the message lines, and the viewer's real file
part, viewer/files.py) and the editor's edit as a function. Each answer is checked against
the file on disk, read back independently; the window tests (test_editor.py) drive the
same part through the editor."""

from __future__ import annotations

import os
import shutil
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from krsview.document.document import Document
from krsview.editor import commands as ec
from krsview.editor.file_actions import FILE_HANDLERS, FileActions
from krsview.editor.handlers import EDITOR_HANDLERS
from krsview.editor.saving import autosave
from krsview.gpu.program import SHADER_DIR
from krsview.scene import SceneError, load_scene, save_scene
from krsview.scene.presets import resolve
from krsview.viewer import commands as vc
from krsview.viewer.camera import FlyCamera
from krsview.viewer.files import ViewerFile


class Window:
    """What the file part reads and calls of the viewer, with no window behind it."""

    def __init__(self, path: Path):
        self.doc = Document(path)
        self.camera = FlyCamera.from_camera(self.doc.scene.camera)
        self.message = self.error = ""
        self.hud = False
        self.said: list[str] = []  # the status line's texts
        self.opened_count = 0
        self.file = ViewerFile(self, SHADER_DIR)

    def sync(self) -> None:
        pass  # nothing drawn

    def say(self, text: str) -> None:
        self.said.append(text)

    def opened(self) -> None:
        self.opened_count += 1


def part(path: Path) -> tuple[FileActions, Window, list[str]]:
    """The file part over a stand-in window; the editor's ``opened`` calls are listed."""
    w, told = Window(path), []

    def edit(at: tuple, value, label: str | None = None) -> bool:
        try:
            w.doc.apply(at, value, label=label)
        except SceneError as e:
            w.error = str(e)
            return False
        return True

    return FileActions(w, edit, lambda: told.append("opened")), w, told


@pytest.fixture
def tree(tmp_path) -> Path:
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    return path


def change_on_disk(path: Path, doc: Document, name: str) -> None:
    save_scene(replace(load_scene(path), name=name), path)
    os.utime(path, ns=(doc.stamp.mtime_ns + 10**9,) * 2)  # a later stamp, however fast


def test_a_disk_change_is_taken_unless_there_are_unsaved_edits(tree):
    f, w, _ = part(tree)
    change_on_disk(tree, w.doc, "first")
    f.reload_scene()  # negative control: no edits, so the file's contents are taken
    assert not f.conflict and w.doc.scene.name == "first" and "reloaded" in w.message
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    assert w.doc.dirty
    change_on_disk(tree, w.doc, "second")
    f.reload_scene()
    assert f.conflict and w.doc.scene.name == "first", "unsaved edits were overwritten"
    assert not f.save() and "changed on disk" in w.error
    assert load_scene(tree).name == "second" and load_scene(tree).render.epsilon_scale == 1.0
    f.take_file()
    assert not f.conflict and w.doc.scene.name == "second" and not w.doc.dirty


def test_keeping_mine_in_a_conflict_lets_the_next_save_overwrite(tree):
    """ "keep mine" used to be followed by a save refused again and again: nothing ever
    saved over the file. Now it does, once; a later change on disk asks again. A file
    deleted or spoilt on disk cannot be taken: the conflict says so, and keeping mine
    writes it anew."""
    f, w, _ = part(tree)
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    change_on_disk(tree, w.doc, "theirs")
    f.reload_scene()
    assert f.conflict and not f.unreadable
    assert not f.save(), "control: a save is refused before the answer"
    f.keep_mine()
    assert "Ctrl+S overwrites tree.toml" in w.said[-1]
    assert f.save() and load_scene(tree).render.epsilon_scale == 2.0
    assert load_scene(tree).name == "tree" and not f.kept
    w.doc.apply(("render", "epsilon_scale"), 3.0)
    change_on_disk(tree, w.doc, "again")
    assert not f.save() and f.conflict, "kept once is not kept for ever"
    tree.unlink()
    f.reload_scene()
    assert f.conflict and "cannot read" in f.unreadable
    f.keep_mine()
    assert f.save() and load_scene(tree).render.epsilon_scale == 3.0
    w.doc.apply(("render", "epsilon_scale"), 4.0)
    tree.write_text("fov_y = banana\n")
    f.reload_scene()
    assert f.conflict and "not valid TOML" in f.unreadable


def test_closing_asks_only_with_unsaved_edits_and_discard_writes_nothing(tree):
    f, w, _ = part(tree)
    assert f.may_close() and f.asking is None, "a clean scene closes at once"
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    assert not f.may_close() and f.asking == ("close", None) and w.hud
    f.answer_cancel()
    assert f.asking is None and not f.quit
    f.may_close()
    f.answer_discard()
    assert f.quit and load_scene(tree).render.epsilon_scale == 1.0


def test_opening_another_scene_with_edits_asks_then_tells_the_editor(tree):
    f, w, told = part(tree)
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    f.open_preset(resolve("sierpinski"))
    assert f.asking == ("open", resolve("sierpinski")) and w.doc.scene.name == "tree" and not told
    f.answer_discard()
    assert w.doc.scene.name == "sierpinski" and told == ["opened"] and w.opened_count == 1
    assert w.file.watcher.scene_file == resolve("sierpinski"), "the new file is not watched"


def test_a_bookmark_is_an_edit_saved_with_the_scene_not_written_at_once(tree):
    f, w, _ = part(tree)
    before = len(load_scene(tree).bookmarks)
    f.add_bookmark()
    assert w.doc.dirty and len(w.doc.scene.bookmarks) == before + 1 and "added" in w.message
    assert w.said == [w.message], "said at the window's foot too: the HUD is folded away"
    assert len(load_scene(tree).bookmarks) == before, "the editor's bookmark skipped the save"
    assert w.doc.history.labels()[0] == [f"add bookmark 'view {before + 1}'"]  # undo says it
    # the viewer's own bookmark (negative control) is appended to the file on disk at once
    w.file.add_bookmark()
    assert len(load_scene(tree).bookmarks) == before + 1
    assert w.message.startswith("saved bookmark") and w.said[-1] == w.message  # said too
    assert w.doc.history.labels()[0][-1] == f"add bookmark 'view {before + 1}'"


def test_a_shipped_preset_asks_for_its_copy_then_saves_and_follows_it(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    f, w, _ = part(resolve("tree"))
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    assert f.may_close() is False
    assert f.save() is False and f.asking is None, "the copy dialog takes over the question"
    assert f.copy_to.text == str(tmp_path / "tree.toml") and f.copy_to.then == ("close", None)
    assert not (tmp_path / "tree.toml").exists(), "saved before the copy was named"
    f.copy_to = replace(f.copy_to, text=str(tmp_path / "mine.toml"))
    f.save_copy()
    assert f.copy_to is None and f.quit, "the question that asked was not answered"
    assert load_scene(tmp_path / "mine.toml").render.epsilon_scale == 2.0
    assert w.file.watcher.scene_file == tmp_path / "mine.toml" and f.save_as_text.endswith(
        "mine.toml"
    )


def test_a_presets_copy_proposed_in_the_data_folder_says_why(tmp_path, monkeypatch):
    """./tree.toml taken: the dialog proposes the user's data folder and says why; with the
    working folder free (the control) it proposes ./tree.toml and says nothing."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    f, _, _ = part(resolve("tree"))
    f.ask_save_as()
    assert f.copy_to.text == str(tmp_path / "tree.toml") and f.copy_to.why == ""
    (tmp_path / "tree.toml").write_text("taken")
    f.ask_save_as()
    assert f.copy_to.text == str(tmp_path / "data" / "krsview" / "tree.toml")
    assert f.copy_to.why == f"{tmp_path / 'tree.toml'} exists"
    assert f.save() is False and f.copy_to.why, "Ctrl+S's dialog says it too"


def test_the_editors_handlers_reach_the_file_part(tree, tmp_path):
    """Commands the editor takes go to its ``file``: save as under the typed name, and a
    bookmark as an edit (the viewer's handler would write the file)."""
    f, w, _ = part(tree)
    editor = SimpleNamespace(file=f)
    target = tmp_path / "other.toml"
    for command in (ec.SetSaveAsText(str(target)), ec.SaveAs(), vc.AddBookmark()):
        EDITOR_HANDLERS[type(command)](editor, command)
    assert load_scene(target) == load_scene(tree) and w.doc.path == target
    assert w.doc.dirty and len(load_scene(target).bookmarks) == len(w.doc.scene.bookmarks) - 1


def test_an_autosave_that_cannot_write_is_said_once_in_the_status_line(tree):
    from krsview.document.document import AUTOSAVE_SECONDS

    f, w, _ = part(tree)
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    autosave(f, 0.0)  # the interval starts
    autosave(f, AUTOSAVE_SECONDS + 1)
    assert w.said == [] and w.doc.recovery_path.exists(), "a working autosave said something"
    w.doc.recovery_path.unlink()
    w.doc.recovery_path.mkdir()  # no one may write there, root neither
    w.doc.apply(("render", "epsilon_scale"), 3.0)
    for k in (2, 3):
        autosave(f, k * (AUTOSAVE_SECONDS + 1))
    assert w.said == [w.error] and "autosave cannot write" in w.error


def test_save_as_replaces_another_file_only_when_asked_twice(tree, tmp_path):
    """Save-as over another scene file replaced it without a word (a review lost a tree
    that way): the first save says it exists, the same name again replaces it, and a
    changed name asks anew. The controls: a new name, and the document's own file, save
    at once."""
    other = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), other)
    f, w, _ = part(tree)
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    assert not f.save_as(str(other)) and "palm.toml exists; save again to replace it" in w.error
    assert load_scene(other).name == "palm" and f.replace_asked(str(other))
    assert f.save_as(str(tmp_path / "new.toml"))  # a new name: saved at once
    assert load_scene(tmp_path / "new.toml").render.epsilon_scale == 2.0
    assert not f.replace_asked(str(other)), "another save in between asks again"
    assert not f.save_as(str(other)) and load_scene(other).name == "palm"
    assert f.save_as(str(other)) and load_scene(other).name == "tree"
    w.doc.apply(("render", "epsilon_scale"), 3.0)
    assert f.save_as(str(other)), "the document's own file now: saved at once"
    assert load_scene(other).render.epsilon_scale == 3.0


def test_save_as_makes_a_missing_folder_only_when_asked_twice(tree, tmp_path, monkeypatch):
    """Save-as into a folder that does not exist made it, and every folder above it, without
    a word: a typo in a folder's name left folders behind [a real-window review]. The first
    save says the folder is missing and writes nothing; the same name again makes it. The
    controls: an existing folder saves at once, and so does the user's data folder, where a
    shipped preset's copy may go."""
    f, w, _ = part(tree)
    w.doc.apply(("render", "epsilon_scale"), 2.0)
    typo = tmp_path / "scnees" / "deep" / "x.toml"
    assert not f.save_as(str(typo)) and "no folder" in w.error and "save again" in w.error
    assert not (tmp_path / "scnees").exists()
    assert f.save_as(str(typo)) and load_scene(typo).render.epsilon_scale == 2.0
    assert f.save_as(str(tmp_path / "here.toml"))  # control: an existing folder
    data = tmp_path / "data"
    monkeypatch.setenv("XDG_DATA_HOME", str(data))
    assert f.save_as(str(data / "krsview" / "tree.toml")), "the data folder: made at once"
    assert not f.save_as(str(tmp_path / "other" / "y.toml")), "a new folder asks anew"


def test_a_save_as_refusal_goes_with_the_name_it_was_said_of(tree, tmp_path):
    """ "save as: no folder …" stood at the window's foot after the person had typed another
    name [a real-window review]: a refusal of a save-as name goes when the field's text
    changes. The controls: the same text keeps it, and another error stays."""
    f, w, _ = part(tree)
    missing = str(tmp_path / "nowhere" / "x.toml")
    FILE_HANDLERS[ec.SetSaveAsText](f, ec.SetSaveAsText(missing))
    assert not f.save_as(missing) and w.error.startswith("save as: no folder")
    FILE_HANDLERS[ec.SetSaveAsText](f, ec.SetSaveAsText(missing))
    assert w.error.startswith("save as: no folder"), "the same name: it stays"
    FILE_HANDLERS[ec.SetSaveAsText](f, ec.SetSaveAsText(missing[:-5]))
    assert w.error == "" and f.save_as_text == missing[:-5]
    w.error = "bookmark not saved: the disk is full"
    FILE_HANDLERS[ec.SetSaveAsText](f, ec.SetSaveAsText(missing))
    assert w.error == "bookmark not saved: the disk is full", "not the name's: it stays"


def test_the_save_as_dialog_says_its_own_refusal_and_opens_again_without_it(tree, tmp_path):
    """A save as refused under a file, then Esc: Ctrl+Shift+S opened the dialog with the old
    refusal still in it [review]. The dialog says its own, until the name changes."""
    f, w, _ = part(tree)
    (tmp_path / "afile").write_text("")
    f.ask_save_as()
    FILE_HANDLERS[ec.SetCopyText](f, ec.SetCopyText(str(tmp_path / "afile" / "x.toml")))
    f.save_copy()
    assert f.copy_to is not None and "is a file" in f.copy_to.said  # it stays, saying why
    FILE_HANDLERS[ec.SetCopyText](f, ec.SetCopyText(str(tmp_path / "afile" / "y.toml")))
    assert f.copy_to.said == ""  # another name: not said of it yet
    f.save_copy()
    FILE_HANDLERS[ec.CancelCopy](f, ec.CancelCopy())
    f.ask_save_as()
    assert f.copy_to.said == "" and "is a file" in w.error  # control: the error still stands
