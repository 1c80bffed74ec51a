"""Keyframes in the editor (issue 29): K keys the selected value at the moment shown, a drag
of a keyed value sets its key (auto-key), keys move in time between their neighbours and go
with a right-click; in a real window, a fork keyed at two moments plays between them, its
subtree with it, and the keys are saved."""

from __future__ import annotations

import numpy as np
import pytest

from krsview import load
from krsview.editor.keys import (
    KEY_SNAP,
    key_now,
    keyed_edit,
    keys_together,
    linked_paths,
    moved_keys,
    strip_words,
    track_index,
    with_key,
    without_keys,
)
from krsview.scene.scene import scene_from_toml, scene_to_toml

FORK = ("route", "levels", 20, "fork")


@pytest.fixture(scope="module")
def bent():
    return load("bent-tree")


def test_a_key_makes_a_track_and_a_key_at_the_same_moment_replaces_it(bent):
    a = with_key(bent, FORK, 2.0, (0.0, 1.0, 0.0))
    assert [(tr.path, [k.time for k in tr.keys]) for tr in a.tracks] == [
        ("route.levels[20].fork", [2.0])
    ]
    s = bent.edit("animation", a)  # validated like a file's
    b = with_key(s, FORK, 2.0 + KEY_SNAP / 2, (0.0, 1.1, 0.0))
    assert len(b.tracks[0].keys) == 1 and b.tracks[0].keys[0].value == (0.0, 1.1, 0.0)
    c = with_key(s, FORK, 0.5, (0.0, 0.9, 0.0))  # before it: sorted in front
    assert [k.time for k in c.tracks[0].keys] == [0.5, 2.0]
    assert with_key(s, FORK, 14.0, (0.0, 1.0, 0.0)).duration == 14.0  # the loop reaches it
    noisy = with_key(s, FORK, 1.7000000000000006, (0.0, 1.0, 0.0))  # a time after playing
    assert [k.time for k in noisy.tracks[0].keys] == [1.7, 2.0], "saved with its float noise"
    saved = scene_from_toml(scene_to_toml(bent.edit("animation", c)))
    assert saved.animation.tracks == c.tracks


def test_k_holds_the_value_drawn_then_and_a_drag_of_a_keyed_value_sets_its_key(bent):
    rest = bent.route.levels[20].fork
    moved = tuple(x + 0.1 for x in rest)
    s = bent.edit("animation", with_key(bent, FORK, 0.0, rest))
    s = s.edit("animation", with_key(s, FORK, 2.0, moved))
    middle = key_now(s, [FORK], 1.0).tracks[0].keys[1]
    assert middle.time == 1.0
    assert np.allclose(middle.value, (np.array(rest) + moved) / 2, atol=1e-12)  # smooth: the middle
    assert not np.allclose(middle.value, rest), "K took the rest value, not the one drawn"
    path, value = keyed_edit(s, FORK, (0.0, 0.0, 0.0), 2.0)
    assert path == ("animation",) and value.tracks[0].keys[-1].value == (0.0, 0.0, 0.0)
    other = ("route", "levels", 19, "fork")  # not keyed: the drag edits the value itself
    assert keyed_edit(s, other, (0.0, 0.0, 0.0), 2.0) == (other, (0.0, 0.0, 0.0))


def test_a_key_dragged_in_time_stays_between_its_neighbours_and_right_click_deletes(bent):
    s = bent
    for t in (1.0, 2.0, 3.0):
        s = s.edit("animation", with_key(s, FORK, t, (0.0, t, 0.0)))
    times = [k.time for k in moved_keys(s, [(0, 1)], 2.5).tracks[0].keys]
    assert times == [1.0, 2.5, 3.0]
    assert moved_keys(s, [(0, 1)], 2.4995515695).tracks[0].keys[1].time == 2.5  # to the ms
    times = [k.time for k in moved_keys(s, [(0, 1)], 9.0).tracks[0].keys]
    assert times[1] < times[2] == 3.0, "a key passed its neighbour"
    assert [k.time for k in without_keys(s, [(0, 0)]).tracks[0].keys] == [2.0, 3.0]
    one = bent.edit("animation", with_key(bent, FORK, 1.0, (0.0, 1.0, 0.0)))
    assert without_keys(one, [(0, 0)]).tracks == [], "a track without keys stayed"


CURL = ("mokrs", "levels", 58, "transform", 1, "degrees")  # palm-curl: tracked in 30 levels


def test_k_and_the_strips_key_edits_act_on_the_linked_levels_as_a_drag_does():
    """palm-curl's curl, step edits going to linked levels: K keys the curl of all 30 linked
    levels, and a key dragged in time or deleted on the strip takes the keys at its moment
    in the other 29 tracks along, so the levels stay alike. Negative control: with step
    edits on one level only, each acts on level 58's track alone."""
    s = load("palm-curl")
    paths = linked_paths(s, CURL, carry=True)
    tracks = [track_index(s, p) for p in paths]
    assert len(paths) == 30 and paths[0] == CURL and None not in tracks
    # what the strip says it keys (with nothing selected it said "… and -1 linked levels")
    assert strip_words(paths) == "mokrs.levels[58].transform[1].degrees and 29 linked levels"
    assert strip_words([CURL]) == "mokrs.levels[58].transform[1].degrees"
    assert strip_words([]) == "select a handle to key it"
    assert strip_words([], grown=True) == "click a growth field to key it"
    assert linked_paths(s, CURL, carry=False) == [CURL]
    assert linked_paths(s, FORK, carry=True) == [FORK]  # not a MöKRS step: alone

    def times(a, i):
        return [k.time for k in a.tracks[i].keys]

    before = times(s.animation, tracks[0])
    keyed = key_now(s, paths, 1.0)
    assert all(times(keyed, i) == sorted([*before, 1.0]) for i in tracks)
    alone = key_now(s, [CURL], 1.0)
    assert [1.0 in times(alone, i) for i in tracks].count(True) == 1

    s = s.edit("animation", keyed)
    j = times(s.animation, tracks[0]).index(1.0)
    together = keys_together(s, tracks, tracks[0], j)
    assert len(together) == 30 and together[0] == (tracks[0], j)
    moved = moved_keys(s, together, 1.5)
    assert all(1.5 in times(moved, i) and 1.0 not in times(moved, i) for i in tracks)
    one = moved_keys(s, together[:1], 1.5)
    assert [1.0 in times(one, i) for i in tracks].count(True) == 29  # the others stayed
    gone = without_keys(s, together)
    assert all(times(gone, i) == before for i in tracks)
    assert len(gone.tracks) == len(s.animation.tracks)


def test_in_a_window_k_and_a_drag_key_a_fork_that_then_plays_and_is_saved(display, tmp_path):
    import shutil

    from krsview.editor.window import Editor
    from krsview.scene import load_scene
    from krsview.scene.presets import resolve
    from krsview.viewer.commands import Edit, SetTime

    from .test_editor import click, drag, handle, pump, screen_of, settle, xdo

    path = tmp_path / "bent.toml"
    shutil.copy(resolve("bent-tree"), path)
    e = Editor(path, size=(800, 500))
    try:
        settle(e)
        h = handle(e, FORK)
        rest = np.array(h.position)
        finer = ("route", "levels", 19, "fork")
        finer_rest = np.array(handle(e, finer).position)
        click(e, screen_of(e, h.position))
        assert e.selected is not None and e.selected.path == FORK
        xdo("key", "k")  # a key at 0 s, holding the fork where it is
        pump(e, 3)
        e.execute([SetTime(2.0)])
        pump(e, 2)
        drag(e, screen_of(e, rest), (60, 0))
        track = e.scene.animation.tracks[0]
        assert track.path == "route.levels[20].fork" and [k.time for k in track.keys] == [0, 2.0]
        assert e.scene.route.levels[20].fork == tuple(rest), "the drag moved the rest value"
        keyed = np.array(track.keys[1].value)
        assert np.linalg.norm(keyed - rest) > 0.05
        assert np.allclose(handle(e, FORK).position, keyed), "the handle is not where drawn"
        follows = handle(e, finer).position - finer_rest  # its subtree came along (a bone)
        assert np.allclose(follows, keyed - rest, atol=1e-9), "the crown tore from the fork"
        assert e.scene.route.levels[19].fork == tuple(finer_rest), "the finer rest moved"
        e.execute([SetTime(1.0)])
        pump(e, 2)
        between = handle(e, FORK).position  # the fork drawn half way: between its keys
        assert 0.3 < np.linalg.norm(between - rest) / np.linalg.norm(keyed - rest) < 0.7
        e.execute([Edit(FORK, (0.1, 2.0, 0.3))])  # a value typed into the keyed field
        track = e.scene.animation.tracks[0]
        assert [k.time for k in track.keys] == [0, 1.0, 2.0] and track.keys[1].value[1] == 2.0
        assert e.scene.route.levels[20].fork == tuple(rest), "typing moved the rest value"
        xdo("key", "ctrl+s")
        pump(e, 3)
        saved = load_scene(path)
        assert saved.animation.tracks == e.scene.animation.tracks and not e.doc.dirty
        assert len(e.doc.history.steps) == 3, "K, the drag and the typing: one step each"
    finally:
        e.close()


def test_a_keyed_value_out_of_range_is_refused_at_its_field(display, tmp_path):
    """tree-growing keys tree.levels. Typing 0 there keys it at the moment shown; the key is
    refused, and the refusal was said of `animation.tracks[0].keys[0]`, at the panel's foot,
    while the field snapped back. Now it is said of the field typed in, and kept there (red,
    with the field's range). Control: a value in range is keyed, and nothing stays red."""
    from .test_editor import editor_on_a_copy

    for e in editor_on_a_copy(tmp_path, "tree-growing", (640, 400)):
        v, field = e.viewer, ("tree", "levels")
        for _ in range(3):  # the panel drawn, its growth section open: the field shown
            e.step(0.02)
        before = e.scene.animation
        assert not e.edit(field, 0)
        assert e.scene.animation == before
        refused = v.interactions.refused[field]
        assert refused.value == 0
        assert refused.message.startswith("tree.levels = 0: allowed: 1 ≤ value ≤ 63")
        assert e.edit(field, 12)  # control
        assert e.scene.animation != before and field not in v.interactions.refused
