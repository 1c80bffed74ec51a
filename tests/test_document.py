"""The editor's document: edits through one seam, undo/redo with drags merged by interaction,
atomic saves that keep the file's mode, owner and links, autosave and recovery, files changed
on disk never overwritten silently, and shipped presets kept as templates."""

from __future__ import annotations

import os
import shutil
import stat
import tempfile
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from krsview.document.document import (
    AUTOSAVE_SECONDS,
    ConflictError,
    Document,
    copy_target,
    not_here,
)
from krsview.scene import SceneError, load_scene, save_scene
from krsview.scene.edits import get_at, path_text
from krsview.scene.presets import PRESET_DIR, resolve


@pytest.fixture
def route_file(tmp_path):
    """The shipped tree, baked into a route, as a file of its own."""
    scene = load_scene(resolve("tree"))
    path = tmp_path / "tree.toml"
    save_scene(replace(scene, tree=None, route=scene.tree.route()), path)
    return path


FORK = ("route", "levels", 5, "fork")


def test_an_edit_is_validated_and_undoable(route_file):
    doc = Document(route_file)
    before = doc.scene
    doc.apply(FORK, [1.0, 5.0, 0.5])
    assert get_at(doc.scene, FORK) == (1.0, 5.0, 0.5) and doc.dirty and doc.title.startswith("*")
    assert doc.scene.geometry().levels[5].kernel.end == (1.0, 5.0, 0.5)
    with pytest.raises(SceneError, match=r"route\.levels\[5\]\.radius"):
        doc.apply(("route", "levels", 5, "radius"), -1.0)
    assert get_at(doc.scene, FORK) == (1.0, 5.0, 0.5), "a rejected edit changed the scene"
    assert doc.undo() and doc.scene == before and not doc.dirty
    assert doc.redo() and get_at(doc.scene, FORK) == (1.0, 5.0, 0.5)
    assert not doc.redo()


def test_one_drag_is_one_undo_step_and_two_drags_are_two(route_file):
    doc = Document(route_file)
    start = doc.scene
    for k in range(20):  # one gizmo drag: many small moves
        doc.apply(FORK, [0.5 + 0.01 * k, 4.0, 0.4], interaction=("drag", 1))
    after_first = doc.scene
    for k in range(5):
        doc.apply(FORK, [0.7, 4.0 + 0.01 * k, 0.4], interaction=("drag", 2))
    doc.apply(("render", "epsilon_scale"), 2.0)  # a plain panel edit: its own step
    assert len(doc.history.steps) == 3
    doc.undo()
    doc.undo()
    assert doc.scene == after_first
    doc.undo()
    assert doc.scene == start and not doc.history.can_undo


def test_a_step_keeps_the_callers_memo_and_undo_brings_it_back(route_file):
    """The editor keeps its selection with each step: undo brings back the selection the
    step was taken with (a drag's first, where its steps merged); redo the one it was undone
    with. Without a memo (the viewer) nothing is kept."""
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    assert doc.undo() and doc.restored is None
    selected = ["fork 5"]
    doc.memo = lambda: selected[0]
    for k in range(3):  # one drag, the selection moving along (the first one counts)
        doc.apply(FORK, [1.0 + k, 5.0, 0.5], interaction=("drag", 1))
        selected[0] = f"after {k}"
    doc.apply(("render", "epsilon_scale"), 2.0)
    selected[0] = "elsewhere"
    said = []
    for step in (doc.undo, doc.undo, doc.redo, doc.redo):
        assert step()
        selected[0] = doc.restored  # the editor selects what came back
        said.append(selected[0])
    assert said == ["after 2", "fork 5", "after 2", "elsewhere"]


def test_history_forgets_the_oldest_steps_beyond_its_limit(route_file, monkeypatch):
    monkeypatch.setattr("krsview.document.history.MAX_STEPS", 30)
    doc = Document(route_file)
    for k in range(40):
        doc.apply(("render", "max_iterations"), 100 + k)
    assert len(doc.history.steps) == 30
    while doc.undo():
        pass
    assert doc.scene.render.max_iterations == 109, "the oldest steps were not the ones dropped"


def test_save_is_atomic_and_clean_and_reopens_equal(route_file):
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.save()
    assert not doc.dirty and not doc.title.startswith("*")
    assert load_scene(route_file) == doc.scene
    assert [p.name for p in route_file.parent.iterdir()] == ["tree.toml"], "temporary files left"


def test_save_as_moves_the_document(route_file, tmp_path):
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    target = tmp_path / "copy.toml"
    doc.save(target)
    assert doc.path == target and load_scene(target) == doc.scene and not doc.dirty
    assert load_scene(route_file) != doc.scene, "save as wrote the old file"


def test_a_file_changed_on_disk_is_never_overwritten_silently(route_file):
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    other = replace(load_scene(route_file), name="edited elsewhere")
    save_scene(other, route_file)
    os.utime(route_file, ns=(doc.stamp.mtime_ns + 10**9,) * 2)
    assert doc.changed_on_disk()
    with pytest.raises(ConflictError, match="changed on disk"):
        doc.save()
    assert load_scene(route_file).name == "edited elsewhere"
    doc.save(overwrite=True)
    assert load_scene(route_file) == doc.scene


def test_touching_the_file_without_changing_it_is_no_conflict(route_file):
    doc = Document(route_file)
    os.utime(route_file, ns=(doc.stamp.mtime_ns + 10**9,) * 2)
    assert not doc.changed_on_disk()


def test_reload_takes_the_disk_version_and_is_undoable(route_file):
    doc = Document(route_file)
    before = doc.scene
    save_scene(replace(before, name="new"), route_file)
    doc.reload()
    assert doc.scene.name == "new" and not doc.dirty
    doc.undo()
    assert doc.scene == before and doc.dirty  # the old version is now an unsaved edit


def test_autosave_writes_a_recovery_file_while_dirty_and_removes_it_when_clean(route_file):
    doc = Document(route_file)
    assert not doc.autosave(0.0) and not doc.recovery_path.exists()
    doc.apply(FORK, [1.0, 5.0, 0.5])
    assert not doc.autosave(100.0), "wrote before an interval passed since the first edit"
    assert doc.autosave(100.0 + AUTOSAVE_SECONDS)
    assert load_scene(doc.recovery_path) == doc.scene
    assert not doc.autosave(200.0), "rewrote an unchanged scene"
    doc.save()
    doc.autosave(300.0)
    assert not doc.recovery_path.exists()


def test_a_newer_recovery_file_is_offered_and_restores_the_edit(route_file):
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.autosave(0.0)
    doc.autosave(AUTOSAVE_SECONDS)
    edited = doc.scene
    del doc  # the editor died without saving
    again = Document(route_file)
    assert again.recovery() == edited
    again.restore_recovery()
    assert again.scene == edited and again.dirty
    again.undo()
    assert again.scene == load_scene(route_file)
    # a recovery file older than the scene file (saved since) is not offered
    os.utime(route_file, ns=(again.recovery_path.stat().st_mtime_ns + 10**9,) * 2)
    assert Document(route_file).recovery() is None


# -------------------------------------------------------------------- random edit sequences
COORD = st.floats(-5.0, 5.0, allow_nan=False)
EDIT = st.one_of(
    st.tuples(st.just("fork"), st.integers(0, 22), st.lists(COORD, min_size=3, max_size=3)),
    st.tuples(st.just("control"), st.integers(0, 22), st.lists(COORD, min_size=3, max_size=3)),
    st.tuples(st.just("normal"), st.integers(1, 22), st.lists(COORD, min_size=3, max_size=3)),
    st.tuples(st.just("radius"), st.integers(0, 22), st.floats(-0.1, 0.5)),
)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(edits=st.lists(st.tuples(EDIT, st.sampled_from([None, 1, 2])), min_size=1, max_size=12))
def test_random_edits_undo_to_the_original_redo_to_the_final_and_round_trip(
    route_file, tmp_path_factory, edits
):
    doc = Document(route_file)
    original = doc.scene
    applied = 0
    for (name, level, value), interaction in edits:
        before = doc.scene
        try:
            doc.apply(("route", "levels", level, name), value, interaction=interaction)
            applied += 1
        except SceneError:
            assert doc.scene == before, "a rejected edit changed the scene"
    final = doc.scene
    while doc.undo():
        pass
    assert doc.scene == original
    while doc.redo():
        pass
    assert doc.scene == final
    if applied:  # a sequence of only rejected edits: nothing to save
        out = tmp_path_factory.mktemp("rt") / "saved.toml"
        doc.save(out)
        assert load_scene(out) == final and load_scene(out).geometry() == final.geometry()


def test_random_edit_sequences_do_apply_edits():
    """The property above is not vacuous: most of its edits are valid."""
    valid = 0
    scene = load_scene(resolve("tree"))
    doc_scene = replace(scene, tree=None, route=scene.tree.route())
    from krsview.scene.edits import apply_edit

    for k in range(20):
        try:
            apply_edit(doc_scene, ("route", "levels", k, "fork"), [0.1 * k, 3.0, 0.2])
            valid += 1
        except SceneError:
            pass
    assert valid >= 15


def test_edit_paths_print_like_scene_file_errors():
    assert path_text(("route", "levels", 3, "fork")) == "route.levels[3].fork"
    assert path_text(()) == "<scene>"


def test_an_unknown_path_is_a_clear_error(route_file):
    doc = Document(route_file)
    with pytest.raises(SceneError, match="not a field"):
        doc.apply(("route", "nonsense"), 1.0)
    with pytest.raises(SceneError, match="not a field"):
        doc.apply(("route", "levels", 99, "fork"), [0.0, 0.0, 0.0])


def test_a_read_only_folder_fails_the_save_clearly_and_keeps_the_edit(route_file, tmp_path):
    if os.geteuid() == 0:  # root may write anywhere: a folder that is a file
        (tmp_path / "a-file").write_text("")
        target = tmp_path / "a-file" / "x.toml"
    else:
        ro = tmp_path / "ro"
        ro.mkdir()
        ro.chmod(0o500)
        target = ro / "x.toml"
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    with pytest.raises(SceneError, match="cannot save"):
        doc.save(target)
    assert doc.dirty and doc.path == route_file
    shutil.rmtree(tmp_path / "ro", ignore_errors=True)
    new = tmp_path / "new-folder" / "x.toml"  # the control: a folder not there yet is made
    assert doc.save(new) == new and load_scene(new) == doc.scene


@pytest.mark.parametrize("depth", [1, 2])
def test_a_save_under_a_file_says_it_is_a_file(route_file, tmp_path, depth):
    """Right under a file the save said "File exists" (as if x.toml were there), deeper
    "Not a directory" [review]."""
    (tmp_path / "a-file").write_text("")
    target = tmp_path / "a-file" / ("sub/" * (depth - 1) + "x.toml")
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    with pytest.raises(SceneError) as e:
        doc.save(target)
    assert str(e.value).endswith(
        f"cannot save: {str(tmp_path / 'a-file')!r} is a file, not a folder"
    )
    assert doc.dirty and doc.path == route_file


# ------------------------------------------------------------------------------ file safety
@pytest.mark.parametrize("mode", [0o644, 0o664])
def test_saving_keeps_the_files_mode(route_file, mode):
    route_file.chmod(mode)
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.save()
    assert stat.S_IMODE(route_file.stat().st_mode) == mode
    assert load_scene(route_file) == doc.scene, "the contents were saved"


def test_negative_control_a_bare_temporary_file_has_mode_600(tmp_path):
    """What the save wrote before: mkstemp's 600, which the test above tells apart."""
    fd, name = tempfile.mkstemp(dir=tmp_path)
    os.close(fd)
    assert stat.S_IMODE(os.stat(name).st_mode) == 0o600


def test_a_new_file_gets_the_umasks_mode_and_a_link_stays_a_link(route_file, tmp_path):
    doc = Document(route_file)
    old = os.umask(0o002)
    try:
        doc.save(tmp_path / "new.toml")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "new.toml").stat().st_mode) == 0o664
    link = tmp_path / "link.toml"
    link.symlink_to(tmp_path / "new.toml")
    linked = Document(link)
    linked.apply(FORK, [2.0, 5.0, 0.5])
    linked.save()
    assert link.is_symlink() and load_scene(tmp_path / "new.toml") == linked.scene


def test_saving_keeps_the_owner_where_permitted(route_file):
    if os.geteuid() != 0:
        pytest.skip("only root may give a file to another user")
    os.chown(route_file, 12345, 23456)
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.save()
    st_ = route_file.stat()
    assert (st_.st_uid, st_.st_gid) == (12345, 23456)


def test_saving_syncs_the_folder_after_the_rename(route_file, monkeypatch):
    synced: list[bool] = []  # is each fsync'd descriptor a folder?
    real = os.fsync
    monkeypatch.setattr(
        os, "fsync", lambda fd: (synced.append(stat.S_ISDIR(os.fstat(fd).st_mode)), real(fd))
    )
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.save()
    assert synced == [False, True], "the file, then its folder"


@pytest.fixture
def data_home(tmp_path, monkeypatch):
    home = tmp_path / "data"
    monkeypatch.setenv("XDG_DATA_HOME", str(home))
    return home / "krsview"


def package_files() -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in PRESET_DIR.iterdir() if p.is_file()}


def test_a_shipped_preset_is_a_template_saved_only_as_a_copy(data_home, tmp_path, monkeypatch):
    before = package_files()
    doc = Document(resolve("tree"))
    assert doc.template
    doc.apply(("tree", "levels"), 12)
    with pytest.raises(SceneError, match="template that is never overwritten.*save a copy"):
        doc.save()
    with pytest.raises(SceneError, match="template"):
        doc.save(PRESET_DIR / "rock.toml")
    assert doc.autosave(0.0) is False and doc.autosave(AUTOSAVE_SECONDS)
    assert doc.recovery_path.parent == data_home / "recovery"
    assert package_files() == before, "something was written into the package"
    monkeypatch.chdir(tmp_path)
    target = copy_target(doc.path)
    assert target == tmp_path / "tree.toml"
    doc.save(target)
    assert not doc.template and load_scene(target).tree.levels == 12 and doc.save() == target


def test_a_presets_copy_goes_to_the_user_folder_when_the_working_one_is_taken(data_home, tmp_path):
    preset = resolve("tree")
    (tmp_path / "tree.toml").write_text("taken")
    assert copy_target(preset, tmp_path) == data_home / "tree.toml"
    data_home.mkdir(parents=True)
    (data_home / "tree.toml").write_text("taken too")
    assert copy_target(preset, tmp_path) == data_home / "tree-2.toml"
    assert copy_target(preset, PRESET_DIR) == data_home / "tree-2.toml", "never the package"
    free = tmp_path / "free"
    free.mkdir()
    assert copy_target(preset, free) == free / "tree.toml"
    # why, in words, for the copy dialog; nothing to say where it goes here (the control)
    assert not_here(preset, tmp_path) == f"{tmp_path / 'tree.toml'} exists"
    assert not_here(preset, PRESET_DIR) == f"{PRESET_DIR} holds krsview's own presets"
    assert not_here(preset, free) == ""


def test_an_autosave_that_cannot_write_says_so_and_recovers(route_file):
    doc = Document(route_file)
    doc.apply(FORK, [1.0, 5.0, 0.5])
    doc.recovery_path.mkdir()  # a folder where the file goes: no one may write it, root neither
    doc.autosave(0.0)
    assert not doc.autosave(AUTOSAVE_SECONDS)
    assert str(doc.recovery_path) in doc.autosave_error and "save" in doc.autosave_error
    doc.recovery_path.rmdir()  # negative control: once it can write, it does, and is quiet
    assert doc.autosave(2 * AUTOSAVE_SECONDS) and doc.autosave_error == ""


def test_a_shipped_presets_camera_path_goes_beside_its_copy(data_home, tmp_path, monkeypatch):
    from krsview.viewer.recording import path_file

    monkeypatch.chdir(tmp_path)
    assert path_file(resolve("tree")) == tmp_path / "tree.path.json"
    mine = tmp_path / "elsewhere" / "tree.toml"  # negative control: a file of one's own
    assert path_file(mine) == tmp_path / "elsewhere" / "tree.path.json"


def test_a_viewers_bookmark_is_appended_to_the_file_as_written(tmp_path):
    """The viewer's B appends the bookmark to the file's own text: its comments, its layout
    and numbers as the person wrote them (a light direction left unnormalised) stay, and
    the file reads back as before plus the bookmark, twice over. It used to write the whole
    scene anew: comments gone, every default written out, the direction normalised. A file
    that lists its bookmarks inline, where a table appended would be invalid TOML, is
    written anew (the control: appending there fails to parse)."""
    from krsview.scene import Camera, scene_from_toml

    path = tmp_path / "grove.toml"
    shutil.copy(resolve("grove"), path)
    text = path.read_text()
    assert "#" in text and "[0.5, 0.8, -0.35]" in text
    doc = Document(path)
    cams = [Camera((1.0, 2.0, 3.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), 45.0 + k) for k in (0, 1)]
    for k, cam in enumerate(cams):
        name, written = doc.add_bookmark(cam)
        assert written == path and name == f"view {k + 1}"
    now = path.read_text()
    assert now.startswith(text), "the file's own text was rewritten"
    again = load_scene(path)
    assert [b.camera for b in again.bookmarks] == cams
    assert replace(again, bookmarks=[]) == replace(load_scene(resolve("grove")), bookmarks=[])
    assert not doc.changed_on_disk() and not doc.dirty
    # inline bookmarks: a table appended would not parse, so the scene is written anew
    inline = tmp_path / "inline.toml"
    save_scene(replace(load_scene(resolve("rock")), bookmarks=[]), inline)
    cam = "{ position = [0.0, 9.0, 9.0], target = [0.0, 0.0, 0.0] }"
    rest = [ln for ln in inline.read_text().splitlines(True) if not ln.startswith("bookmarks")]
    inline.write_text(f'bookmarks = [{{ name = "a", camera = {cam} }}]\n' + "".join(rest))
    doc = Document(inline)
    with pytest.raises(SceneError):
        scene_from_toml(inline.read_text() + '\n[[bookmarks]]\nname = "b"\n')
    doc.add_bookmark(cams[0])
    assert [b.name for b in load_scene(inline).bookmarks] == ["a", "view 2"]
    # the shipped presets' empty ``bookmarks = []``: only that line goes (it used to write
    # every default out, a pre-pass and compute path among them)
    palm = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), palm)
    text = palm.read_text()
    assert "\nbookmarks = []\n" in text
    Document(palm).add_bookmark(cams[0])
    now = palm.read_text()
    assert now.startswith(text.replace("\nbookmarks = []\n", "\n")) and "[[bookmarks]]" in now
    assert load_scene(palm) == replace(
        load_scene(resolve("palm")), bookmarks=load_scene(palm).bookmarks
    )
    assert len(load_scene(palm).bookmarks) == 1


def test_a_viewers_bookmark_undone_and_redone_is_taken_out_of_the_file_and_written_again(
    tmp_path, monkeypatch
):
    """B writes the bookmark into the file at once, so its undo takes it out of the file (the
    file's own text back, byte for byte) and its redo writes it again, over what the file
    holds then: a bookmark another program added in between stays. Where the file cannot be
    written, the undo still happens and ``write_error`` says why, the file untouched.
    Negative control: the undo of an edit never written (a knob) leaves the file alone."""
    import errno
    import os

    from krsview.document import document
    from krsview.scene import Camera

    path = tmp_path / "grove.toml"
    shutil.copy(resolve("grove"), path)
    text = path.read_text()
    doc = Document(path)
    cam = Camera((1.0, 2.0, 3.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), 45.0)
    doc.apply(("render", "epsilon_scale"), 2.0)  # a knob's edit, never written
    doc.add_bookmark(cam)
    with_mark = path.read_text()
    doc.undo()
    assert path.read_text() == text and not doc.scene.bookmarks and not doc.write_error
    assert doc.dirty and not doc.changed_on_disk()  # the knob is still unsaved; no outside edit
    doc.undo()  # the knob: the file stays as it is
    assert path.read_text() == text and not doc.dirty
    doc.redo()
    doc.redo()
    assert path.read_text() == with_mark and not doc.changed_on_disk()
    # another program adds a bookmark of its own: the undo takes out only ours
    other = Camera((0.0, 9.0, 9.0), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0), 45.0)
    doc_b = Document(path)
    doc_b.add_bookmark(other)
    doc.undo()
    assert [b.camera for b in load_scene(path).bookmarks] == [other]
    # a file that cannot be written (a full disk, say): the scene steps back, the file
    # stays, and it is said
    doc.redo()
    before = path.read_text()

    def full(*_):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(document, "write_atomic", full)
    doc.undo()
    assert path.read_text() == before and not doc.scene.bookmarks
    assert doc.write_error == f"{path}: the file is as it was: No space left on device"


def test_a_shipped_presets_copy_made_by_a_bookmark_keeps_its_text(tmp_path, monkeypatch):
    """B on a shipped preset writes its copy as the preset's own text with the bookmark
    appended (it used to write every default out: a pre-pass, the fragment path, all the
    effect settings); a copy with other edits too keeps the preset's text."""
    from krsview.scene import Camera

    monkeypatch.chdir(tmp_path)
    cam = Camera((1.0, 2.0, 3.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0), 45.0)
    text = resolve("palm").read_text()
    doc = Document(resolve("palm"))
    name, copy = doc.add_bookmark(cam)
    assert copy == tmp_path / "palm.toml" and not doc.dirty
    now = copy.read_text()
    assert now.startswith(text.replace("\nbookmarks = []\n", "\n")) and name in now
    assert load_scene(copy).bookmarks[0].camera == cam
    other = Document(resolve("rock"))
    other.apply(("render", "epsilon_scale"), 2.0)
    _, written = other.add_bookmark(cam)
    back = load_scene(written)  # with other edits too, the preset's text is kept
    assert back.render.epsilon_scale == 2.0 and back.bookmarks[0].camera == cam
    assert "prepass_levels" not in written.read_text() and "prepass_levels" not in now


def test_a_save_writes_only_what_changed_into_the_persons_text(tmp_path):
    """Saving wrote the whole scene anew: comments gone, every default written out, a light
    direction never touched normalised (a one-value change on palm: a 156-line diff). Now
    the changed values are written into the file's own text; the file reads back as the
    scene saved. Levels inserted rewrite that list only; a field unset again goes."""
    import difflib

    def changed_lines(a: str, b: str) -> list[str]:
        return [
            line
            for line in difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="")
            if line[:1] in "+-" and line[:3] not in ("+++", "---")
        ]

    path = tmp_path / "tree.toml"
    text = "# my notes, kept\n" + resolve("tree").read_text()
    path.write_text(text)
    doc = Document(path)
    doc.apply(("render", "epsilon_scale"), 2.0)
    doc.apply(("camera", "fov_y"), 50.0)
    doc.save()
    now = path.read_text()
    assert changed_lines(text, now) == [
        "-fov_y = 45.0",
        "+fov_y = 50.0",
        "-epsilon_scale = 1.0",
        "+epsilon_scale = 2.0",
    ]
    assert load_scene(path) == doc.scene and "[0.5, 0.8, -0.35]" in now
    doc.apply(("render", "prepass"), 8)
    doc.save()
    assert changed_lines(now, path.read_text()) == ["+prepass = 8"]
    doc.undo()
    doc.save()
    assert path.read_text() == now, "unset again, the line goes"
    # a route's levels inserted: the list is written anew, the rest stays
    bent = tmp_path / "bent.toml"
    bent.write_text("# bent notes\n" + resolve("bent-tree").read_text())
    doc = Document(bent)
    from krsview.scene.restructure import split_level

    doc.commit(replace(doc.scene, route=split_level(doc.scene.route, 2, 0.5)), "insert")
    doc.save()
    assert bent.read_text().startswith("# bent notes\n") and load_scene(bent) == doc.scene


def test_a_shipped_presets_own_camera_path_replays_until_one_is_recorded(
    data_home, tmp_path, monkeypatch
):
    """grove-wind ships its camera path, yet F6 said there was none: the viewer looked only
    beside the copy a recording would make. It replays the shipped one (and says it
    replays); a recording saves beside the copy and is replayed from then on. Control: a
    shipped preset without a path of its own has none."""
    from krsview.scene.camera_path import Pose
    from krsview.viewer.camera import FlyCamera
    from krsview.viewer.recording import Recorder

    monkeypatch.chdir(tmp_path)
    r = Recorder(resolve("grove-wind"))
    assert r.path is not None and r.source == resolve("grove-wind").with_suffix(".path.json")
    r.replay(0.0)
    assert r.message.startswith("replaying grove-wind.path.json (")
    camera = FlyCamera.from_camera(load_scene(resolve("grove-wind")).camera)
    r.toggle()
    r.tick(0.0, camera)
    r.replay_start = None
    r.recording = [Pose(0.0, (1.0, 2.0, 3.0), 0.0, 0.0), Pose(1.0, (1.0, 2.0, 4.0), 0.0, 0.0)]
    r.toggle()
    assert r.source == tmp_path / "grove-wind.path.json" and r.source.exists()
    assert Recorder(resolve("grove-wind")).path.duration == 1.0
    assert Recorder(resolve("tree")).path is None
    copy = tmp_path / "mine" / "grove-wind.toml"  # a copy elsewhere: the shipped path too
    copy.parent.mkdir()
    shutil.copy(resolve("grove-wind"), copy)
    assert Recorder(copy).path is not None and Recorder(copy).source.parent == PRESET_DIR


def test_a_level_inserted_or_removed_changes_its_own_lines_alone(tmp_path):
    """A MöKRS level duplicated wrote the whole list of levels anew, every inline kernel
    turned into a table of its own (a 654-line diff on palm for one level). Now the level
    added or removed is the only change, written as its neighbours are (the kernel inline),
    and the file reads back as the scene saved. Control: a level changed in place changes
    its own lines, in place."""
    import difflib

    from krsview.editor.mokrs_levels import changed

    def diff(a: str, b: str) -> list[str]:
        lines = difflib.unified_diff(a.splitlines(), b.splitlines(), lineterm="", n=0)
        return [x for x in lines if x[:1] in "+-" and x[:3] not in ("+++", "---")]

    for name in ("palm", "tree-mokrs"):
        path = tmp_path / f"{name}.toml"
        shutil.copy(resolve(name), path)
        text = path.read_text()
        doc = Document(path)
        levels = doc.scene.mokrs.levels
        for op in ("duplicate", "insert", "remove"):
            doc.apply(("mokrs", "levels"), changed(levels, 5, op)[0])
            doc.save()
            lines = diff(text, path.read_text())
            assert load_scene(path) == doc.scene, (name, op)
            sign = "-" if op == "remove" else "+"
            assert lines and all(x.startswith(sign) for x in lines), (name, op, lines[:4])
            assert len(lines) < 25, (name, op, len(lines))
            if op == "duplicate":
                assert any(x.startswith("+kernel = {") for x in lines), (name, lines[:4])
            doc.undo()
            doc.save()
            assert path.read_text() == text, (name, op)
        doc.apply(("mokrs", "levels", 5, "reflect"), not levels[5].reflect)
        doc.save()
        assert len(diff(text, path.read_text())) == 2


def test_the_title_says_which_file_after_a_save_as_into_another_folder(
    route_file, tmp_path, monkeypatch
):
    """After a save as into another folder the title still said the name alone [review]."""
    monkeypatch.chdir(tmp_path)
    doc = Document(route_file)
    other = tmp_path / "elsewhere" / route_file.name
    doc.save(other)
    assert doc.title.startswith(f"elsewhere/{route_file.name} — ")
    monkeypatch.chdir(other.parent)  # control: from its own folder, the name alone
    assert doc.title.startswith(f"{route_file.name} — ")


@pytest.mark.parametrize("mark, ends", [("\ufeff", "\n"), ("", "\r\n"), ("\ufeff", "\r\n")])
def test_a_file_with_a_byte_order_mark_or_crlf_keeps_them_and_its_comments(tmp_path, mark, ends):
    """Windows' Notepad starts a file with a byte-order mark; many Windows editors end lines
    with CRLF. A save over such a file wrote the whole scene anew (a mark: every comment
    gone, every default spelled out) or turned every line end to LF (CRLF). The document's
    save, its bookmark and the API's save each keep the mark, the line ends and the
    comments; the control is the file's own text compared byte for byte."""
    import krsview

    plain = resolve("grove").read_text()
    assert plain.count("#") > 3
    for act in ("document", "bookmark", "api"):
        path = tmp_path / f"{act}.toml"
        path.write_bytes((mark + plain.replace("\n", ends)).encode())
        if act == "document":
            doc = Document(path)
            doc.apply(("render", "epsilon_scale"), 2.0)
            doc.save()
        elif act == "bookmark":
            cam = load_scene(path).camera
            Document(path).add_bookmark(replace(cam, fov_y=50.0))
        else:
            krsview.save(krsview.load(path).edit("render.epsilon_scale", 2.0), path)
        raw = path.read_bytes().decode()
        body = raw.removeprefix(mark)
        assert raw.startswith(mark) and body.startswith(plain.splitlines()[0]), act
        assert body.count("\n") == body.count(ends), f"{act}: mixed line ends"
        assert body.replace(ends, "\n").count("#") == plain.count("#"), act
        lines = body.replace(ends, "\n").splitlines()
        if act == "bookmark":  # appended: the file's text stays as it was above it
            assert body.replace(ends, "\n").startswith(plain.replace("\nbookmarks = []\n", "\n"))
        else:  # one line added to [render], not the scene written anew
            assert len(lines) <= len(plain.splitlines()) + 1, act
        again = load_scene(path)
        if act == "bookmark":
            assert again.bookmarks[-1].camera.fov_y == 50.0
        else:
            assert again.render.epsilon_scale == 2.0
