"""The editor's document: edits through one seam, undo/redo with drags merged by interaction,
atomic saves, autosave and recovery, and files changed on disk never overwritten silently."""

from __future__ import annotations

import os
import shutil
from dataclasses import replace

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from krsview.document.document import AUTOSAVE_SECONDS, ConflictError, Document
from krsview.scene import SceneError, load_scene, save_scene
from krsview.scene.edits import get_at, path_text
from krsview.scene.presets import resolve


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
    if os.geteuid() == 0:
        target = tmp_path / "no-such-dir" / "x.toml"  # root may write anywhere: a missing folder
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
