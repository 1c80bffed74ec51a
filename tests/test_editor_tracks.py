"""The panels under keyframe tracks (issue 28/29), in a real window: the MöKRS section shows
the values drawn at the moment shown (as the KRS panel and the handles do), a tracked field
is marked (yellow on a key, green between keys), and a value typed into it keys it at that
moment, in every linked level a track moves."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from krsview.editor import panels
from krsview.editor.keys import BETWEEN, DIAMOND, KEY, MARK_BETWEEN, MARK_ON_KEY, ON_KEY
from krsview.editor.mokrs_panel import LEVELS
from krsview.scene.edits import get_at
from krsview.scene.presets import resolve

from .test_editor import pump, scroll_to, settle, type_at, window_xy, xdo

CURL = (*LEVELS, 58, "transform", 1, "degrees")  # palm-curl's track: -2.5° at 0, 4 s; -7° at 2 s
FACTOR = (*LEVELS, 58, "transform", 0, "factor")  # no track


def recorded_fields(monkeypatch) -> dict[str, object]:
    """The values the panels' fields show, recorded by path ("tree.levels") as drawn."""
    shown: dict[str, object] = {}
    widget = panels.field_widget

    def recording(label, value, meta, refused=None):
        shown[label.split("##", 1)[1]] = value
        return widget(label, value, meta, refused)

    monkeypatch.setattr(panels, "field_widget", recording)
    return shown


@pytest.fixture
def palm(display, tmp_path, monkeypatch):
    """palm-curl in an editor, with the values its panel's fields show recorded by path."""
    from krsview.editor.window import Editor

    shown = recorded_fields(monkeypatch)
    path = tmp_path / "palm-curl.toml"
    shutil.copy(resolve("palm-curl"), path)
    e = Editor(path, size=(800, 500))
    e.shown_values = shown
    yield e
    e.close()


def pointer_away(e) -> None:
    """The pointer off the 800×500 window: nothing in it is drawn hovered."""
    xdo("mousemove", *(round(v) for v in window_xy(e, 900, 600)))
    pump(e, 3)


def frame_colour(e, path, colour) -> int:
    """Pixels of the field at ``path`` (its left half: the frame) in ``colour`` (an ImVec4).
    The pointer goes off the window first: one left over a field (by this test or an earlier
    one in the same X server) draws that field in ImGui's hovered colour, not its frame."""
    pointer_away(e)
    x0, y0, x1, y1 = e.viewer.interactions.rects[path]
    shot = e.viewer.read_window().astype(int)
    field = shot[round(y0) + 2 : round(y1) - 2, round(x0) + 2 : round((x0 + x1) / 2)]
    rgb = np.array([colour.x, colour.y, colour.z]) * 255
    return int((np.abs(field - rgb) < 14).all(-1).sum())


def on_bar(e, t: float) -> tuple[int, int]:
    """The screen point of moment ``t`` on the timeline strip's bar, as last drawn."""
    x, y, width = e.timeline.bar
    return tuple(map(round, window_xy(e, x + width * t / e.scene.animation.duration, y)))


def drag_on_bar(e, t0: float, t1: float) -> None:
    """Press on the strip's bar at ``t0`` and drag to ``t1`` in five steps, as a hand does."""
    xdo("mousemove", *on_bar(e, t0))
    pump(e, 3)
    xdo("mousedown", 1)
    pump(e, 2)
    for k in range(1, 6):
        xdo("mousemove", *on_bar(e, t0 + (t1 - t0) * k / 5))
        pump(e, 2)
    xdo("mouseup", 1)
    pump(e, 3)


def diamond_pixels(e, path, mark) -> int:
    """Pixels of the key's diamond (``mark``: ON_KEY filled, BETWEEN hollow) right of the
    field at ``path`` and its label, as drawn in the window."""
    x0, y0, x1, y1 = e.viewer.interactions.rects[path]
    colour = MARK_ON_KEY if mark is ON_KEY else MARK_BETWEEN
    rgb = np.array([colour & 0xFF, (colour >> 8) & 0xFF, (colour >> 16) & 0xFF])
    shot = e.viewer.read_window().astype(int)
    band = shot[round(y0) : round(y1), round(x1) : round(x1) + 2 * round(DIAMOND) + 4]
    return int((np.abs(band - rgb) < 40).all(-1).sum())


def test_the_mokrs_panel_shows_the_pose_marks_tracks_and_a_typed_value_keys_them(palm):
    from krsview.viewer.commands import SetTime

    e = palm
    settle(e)
    e.select(next(h for h in e.handles if h.path == CURL))
    key = ".".join(map(str, CURL))
    rest = get_at(e.scene, CURL)
    for t, mark in ((1.0, BETWEEN), (2.0, ON_KEY)):
        e.execute([SetTime(t)])
        pump(e, 3)
        scroll_to(e, CURL, 60, 0)
        pump(e, 3)
        posed = get_at(e.scene.at(t).posed(), CURL)
        assert e.shown_values[key] == posed != rest, (t, e.shown_values[key], posed, rest)
        assert frame_colour(e, CURL, mark) > 50, f"the tracked field is not marked at {t} s"
        other = BETWEEN if mark is ON_KEY else ON_KEY
        assert frame_colour(e, CURL, other) == 0
        assert frame_colour(e, FACTOR, mark) == 0, "an untracked field is marked"
        whole = 32 if mark is ON_KEY else 16  # filled or hollow (whole: 40 and 20 pixels)
        assert diamond_pixels(e, CURL, mark) >= whole, f"the diamond at {t} s is cut off"
        assert diamond_pixels(e, FACTOR, mark) == 0
    e.execute([SetTime(1.0)])
    pump(e, 3)
    x0, y0, x1, y1 = scroll_to(e, CURL, 60, 0)
    type_at(e, window_xy(e, (x0 + x1) / 2 - 40, (y0 + y1) / 2), "--", "-6")
    a = e.scene.animation
    curls = [tr for tr in a.tracks if tr.path.endswith("transform[1].degrees")]
    assert len(curls) == 30 and all([k.time for k in tr.keys] == [0, 1, 2, 4] for tr in curls)
    assert all(tr.keys[1].value == -6.0 for tr in curls), "a linked track was not keyed"
    assert get_at(e.scene, CURL) == rest, "typing moved the rest value"
    assert get_at(e.scene.at(1.0).posed(), CURL) == -6.0
    assert get_at(e.scene, (*LEVELS, 57, "transform")) == get_at(
        e.doc.history.steps[0].before, (*LEVELS, 57, "transform")
    )
    assert len(e.doc.history.steps) == 1, "the typed value was not one undo step"
    # what Ctrl+Z will say: the field typed into, keyed (not "set animation")
    assert e.doc.history.labels()[0] == ["key mokrs.levels[58].transform[1].degrees at 1.00 s"]
    assert frame_colour(e, CURL, ON_KEY) > 50, "the new key is not marked"


def test_k_and_the_strips_key_edits_reach_every_linked_curl_in_a_window(palm):
    """palm-curl in a window, step edits going to linked levels: K at 1 s keys all 30 curls;
    a right-click on that key on the strip deletes it from all 30, and a drag of the key at
    2 s to 3 s moves all 30. Controls: each is one undo step; with step edits on one level
    only, K keys level 58 alone."""
    from krsview.viewer.commands import SetTime

    e = palm
    settle(e)
    e.select(next(h for h in e.handles if h.path == CURL))
    curls = [i for i, tr in enumerate(e.scene.animation.tracks) if tr.path.endswith("[1].degrees")]

    def times() -> set[tuple[float, ...]]:
        return {tuple(k.time for k in e.scene.animation.tracks[i].keys) for i in curls}

    assert len(curls) == 30 and times() == {(0, 2, 4)}
    e.execute([SetTime(1.0)])
    pump(e, 3)
    xdo("key", "k")
    pump(e, 3)
    assert times() == {(0, 1, 2, 4)}, "K did not key every linked curl"
    said = e.viewer.message  # in the status line too: the HUD starts folded
    assert said.startswith("key at 1.00 s") and e.viewer.status_line() == said

    xdo("mousemove", *on_bar(e, 1.0))
    pump(e, 3)
    xdo("click", 3)
    pump(e, 3)
    assert times() == {(0, 2, 4)}, "the right-click deleted the key of one curl only"
    assert e.viewer.message == "", "what was said of the key deleted stayed"
    drag_on_bar(e, 2.0, 3.0)
    moved = times()
    assert len(moved) == 1 and abs(next(iter(moved))[1] - 3.0) < 0.05, moved
    assert len(e.doc.history.steps) == 3, "K, the delete and the drag: one step each"
    curl = "mokrs.levels[58].transform[1].degrees"
    assert e.doc.history.labels()[0] == [
        "key at 1.00 s for L58 step 1 rotate -4.75 deg and 29 linked levels",
        f"delete the key at 1.00 s of {curl} and 29 linked keys",
        f"move the key at 2.00 s of {curl} and 29 linked keys in time",
    ]  # what an undo says it undid
    e.carry = False
    xdo("key", "k")
    pump(e, 3)
    assert len(times()) == 2, "with step edits on one level, K keyed more than level 58"


def test_the_krs_panel_marks_a_keyed_fork(display, tmp_path):
    """A route's keyed fork: its field framed green between keys, yellow on one; its
    neighbour's (no track) neither."""
    from krsview.editor.keys import with_key
    from krsview.editor.window import Editor
    from krsview.viewer.commands import SetTime

    path = tmp_path / "bent.toml"
    shutil.copy(resolve("bent-tree"), path)
    e = Editor(path, size=(800, 500))
    try:
        fork = ("route", "levels", 20, "fork")
        rest = np.array(e.scene.route.levels[20].fork)
        s = e.scene
        for t, v in ((0.0, rest), (2.0, rest + 0.1)):
            s = s.edit("animation", with_key(s, fork, t, tuple(v)))
        e.doc.commit(s, "keys")
        e.viewer.sync()
        e.select(next(h for h in e.handles if h.path == fork))
        for t, mark in ((1.0, BETWEEN), (2.0, ON_KEY)):
            e.execute([SetTime(t)])
            pump(e, 3)
            scroll_to(e, fork, 60, 0)
            pump(e, 3)
            assert frame_colour(e, fork, mark) > 50, t
            assert frame_colour(e, ("route", "levels", 20, "control"), mark) == 0
    finally:
        e.close()


def test_a_linked_dial_drag_on_palm_curl_keys_every_curl_at_the_moment():
    """The curl's dial dragged at 1 s (carry on): one edit of the animation, a key at 1 s in
    each of the 30 linked tracks, the rest values kept. Negative control: carry off keys
    level 58 alone."""
    from krsview import load
    from krsview.editor.dragging import drag_edits
    from krsview.editor.handles import handles

    s = load("palm-curl").at(1.0)
    h = next(h for h in handles(s.posed()) if h.path == CURL)
    a, r, turn = np.asarray(h.axis), h.position - h.pivot, np.radians(5.0)  # 5° on the ring
    p = (
        h.pivot
        + r * np.cos(turn)
        + np.cross(a, r) * np.sin(turn)
        + a * (a @ r) * (1 - np.cos(turn))
    )
    edits = drag_edits(s, h, p, carry=True, t=1.0)
    assert [path for path, _ in edits] == [("animation",)]
    keyed = [tr for tr in edits[0][1].tracks if any(k.time == 1.0 for k in tr.keys)]
    assert len(keyed) == 30 and len({tr.keys[1].value for tr in keyed}) == 1
    drawn = get_at(s.posed(), CURL)
    assert 4.0 < abs(keyed[0].keys[1].value - drawn) < 6.0, (keyed[0].keys[1].value, drawn)
    alone = drag_edits(s, h, p, carry=False, t=1.0)
    assert [path for path, _ in alone] == [CURL]  # keyed by Editor.edit: this level only


def test_a_grown_trees_growth_fields_show_the_moment_and_a_typed_value_keys_it(
    display, tmp_path, monkeypatch
):
    """tree-growing's tracks move its growth parameters, which no handle holds: the panel's
    growth section shows them as grown at the moment shown, the tracked ones marked, and a
    value typed into a tracked one keys it at that moment (one undo step, the rest value
    kept). They could be edited only in a text editor. Negative control: an untracked field
    (radius_ratio) typed sets the value itself, no track made."""
    from krsview.editor.window import Editor
    from krsview.scene import load_scene
    from krsview.viewer.commands import SetTime

    shown = recorded_fields(monkeypatch)
    path = tmp_path / "growing.toml"
    shutil.copy(resolve("tree-growing"), path)
    e = Editor(path, size=(800, 500))
    ratio, radius = ("tree", "length_ratio"), ("tree", "radius_ratio")
    try:
        e.execute([SetTime(3.0)])
        pump(e, 4)
        posed = e.scene.at(3.0).posed().tree
        assert shown["tree.length_ratio"] == posed.length_ratio != e.scene.tree.length_ratio
        assert shown["tree.levels"] == posed.levels == 12
        assert frame_colour(e, ratio, BETWEEN) > 50 and frame_colour(e, radius, BETWEEN) == 0
        x0, y0, x1, y1 = e.viewer.interactions.rects[ratio]
        type_at(e, window_xy(e, (x0 + x1) / 2, (y0 + y1) / 2), "0.7")
        track = next(tr for tr in e.scene.animation.tracks if tr.path == "tree.length_ratio")
        assert [(k.time, k.value) for k in track.keys] == [(0.0, 0.62), (3.0, 0.7), (7.5, 0.76)]
        assert e.scene.tree.length_ratio == load_scene(path).tree.length_ratio  # rest kept
        assert e.doc.history.labels()[0] == ["key tree.length_ratio at 3.00 s"]
        x0, y0, x1, y1 = e.viewer.interactions.rects[radius]
        type_at(e, window_xy(e, (x0 + x1) / 2, (y0 + y1) / 2), "0.7")
        assert e.scene.tree.radius_ratio == 0.7
        assert not any(tr.path == "tree.radius_ratio" for tr in e.scene.animation.tracks)
    finally:
        e.close()


def strip_keys(e, times) -> list[int]:
    """Pixels of a key's diamond on the timeline strip's bar at each of ``times``, as drawn
    in the window (the pointer off the window first: a key under it is drawn hot)."""
    pointer_away(e)
    x, y, width = e.timeline.bar
    rgb = np.array([KEY & 0xFF, (KEY >> 8) & 0xFF, (KEY >> 16) & 0xFF])
    shot = e.viewer.read_window().astype(int)
    band = (np.abs(shot[round(y - DIAMOND) : round(y + DIAMOND) + 1] - rgb) < 40).all(-1)
    columns = [round(x + width * t / e.scene.animation.duration) for t in times]
    return [int(band[:, c - round(DIAMOND) : c + round(DIAMOND) + 1].sum()) for c in columns]


def test_a_growth_field_clicked_puts_its_keys_on_the_strip_where_k_keys_and_drags_move_them(
    display, tmp_path
):
    """tree-growing has no handles, so its growth tracks' keys never reached the timeline
    strip (it said to type a value): a click into a growth field puts the field on the strip,
    which draws its keys; K keys it at the moment shown; a key dragged along the strip moves
    and a right-click deletes it, each one undo step. Controls: before the click the strip
    draws no key and K keys nothing (it says what to do); the click itself changes nothing;
    the diamonds are found at the keys' moments and not between them."""
    from krsview.editor.window import Editor
    from krsview.viewer.commands import SetTime

    path = tmp_path / "growing.toml"
    shutil.copy(resolve("tree-growing"), path)
    e = Editor(path, size=(800, 500))
    ratio = ("tree", "length_ratio")

    def keys() -> list[float]:
        track = next(tr for tr in e.scene.animation.tracks if tr.path == "tree.length_ratio")
        return [k.time for k in track.keys]

    try:
        e.execute([SetTime(3.0)])
        pump(e, 4)
        before = e.scene
        assert keys() == [0.0, 7.5] and strip_keys(e, (0.0, 7.5)) == [0, 0]
        xdo("key", "k")
        pump(e, 3)
        assert e.scene == before and e.viewer.message == "click a growth field to key it (K)"
        x0, y0, x1, y1 = e.viewer.interactions.rects[ratio]
        xdo("mousemove", *map(round, window_xy(e, (x0 + x1) / 2, (y0 + y1) / 2)))
        pump(e, 2)
        xdo("click", 1)
        pump(e, 3)
        assert e.scene == before, "a click into the field changed the scene"
        assert e.timeline.field == ratio
        at_keys, between = strip_keys(e, (0.0, 7.5)), strip_keys(e, (1.5, 4.5))
        assert min(at_keys) > 20 and between == [0, 0], (at_keys, between)
        xdo("key", "k")
        pump(e, 3)
        drawn = e.scene.at(3.0).posed().tree.length_ratio
        assert keys() == [0.0, 3.0, 7.5]
        track = next(tr for tr in e.scene.animation.tracks if tr.path == "tree.length_ratio")
        assert track.keys[1].value == pytest.approx(drawn)
        assert e.viewer.message == "key at 3.00 s for tree.length_ratio"
        drag_on_bar(e, 3.0, 4.0)
        assert keys() == [0.0, 4.0, 7.5], keys()
        xdo("mousemove", *on_bar(e, 4.0))
        pump(e, 3)
        xdo("click", 3)
        pump(e, 3)
        assert keys() == [0.0, 7.5]
        assert e.doc.history.labels()[0] == [
            "key at 3.00 s for tree.length_ratio",
            "move the key at 3.00 s of tree.length_ratio in time",
            "delete the key at 4.00 s of tree.length_ratio",
        ]
    finally:
        e.close()


def test_an_infinity_typed_into_a_keyed_step_is_refused_as_the_fields_own(palm):
    """palm-curl's curl is keyed in 30 linked levels. An infinity or NaN typed into it was
    refused as `…degrees = inf: animation.tracks[29].keys[1][1] = inf: a key's value is a
    number, …`, blaming a key the person never saw for not being a number. It is refused
    with the field's own rule, at the field, as the same value typed into a field without a
    track (the control: FACTOR's). A value in range is keyed (the second control)."""
    from krsview.editor.keys import linked_edits
    from krsview.scene.edits import path_text

    e, v = palm, palm.viewer
    settle(e)
    e.select(next(h for h in e.handles if h.path == CURL))
    pump(e, 3)
    scroll_to(e, CURL, 60, 0)  # the fields drawn: a refusal stays at them
    pump(e, 3)
    for bad in (float("inf"), float("nan")):
        before = e.scene
        for path, value in linked_edits(e.scene, CURL, bad, 1.0):
            assert not e.edit(path, value, field=(CURL, bad))
        assert e.scene == before
        said = v.interactions.refused[CURL].message
        assert said.startswith(f"{path_text(CURL)} = {bad}: NaN and infinity"), said
        assert "tracks" not in said
    e.edit(FACTOR, float("inf"), field=(FACTOR, float("inf")))
    plain = v.interactions.refused[FACTOR].message
    assert "NaN and infinity are not allowed" in plain and "tracks" not in plain
    for path, value in linked_edits(e.scene, CURL, -3.0, 1.0):
        assert e.edit(path, value, field=(CURL, -3.0))
    assert CURL not in v.interactions.refused
