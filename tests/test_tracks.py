"""Keyframe tracks (issue 29): [[animation.tracks]] validated at load by the edits' rule,
evaluated at the scene's time by Scene.posed(), and drawn that way by both renderers."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from krsview import load
from krsview.bench.metrics import gpu_reference_agreement, tolerance_failures
from krsview.reference import render_reference
from krsview.scene import SceneError
from krsview.scene.animation import Key, Track
from krsview.scene.edits import replace_at, revalidated, validated
from krsview.scene.scene import scene_from_toml, scene_to_toml

from .conftest import check_against_reference, per_pixel

PRESETS = Path(__file__).resolve().parent.parent / "presets"


def tracked(base: str, tracks: list[dict], **animation) -> object:
    """Preset ``base`` with these tracks (a dict per track, as the file's table)."""
    return load(base).edit("animation", {"tracks": tracks, **animation})


def radius(scene, t: float) -> float:
    return scene.at(t).posed().tree.trunk_radius


def test_linear_and_smooth_pass_through_the_keys_and_interpolate_between():
    keys = [[1.0, 0.1], [2.0, 0.3], [4.0, 0.2]]
    lin = tracked("tree", [{"path": "tree.trunk_radius", "keys": keys, "interpolation": "linear"}])
    smooth = tracked("tree", [{"path": "tree.trunk_radius", "keys": keys}])
    for t, v in keys:
        assert radius(lin, t) == pytest.approx(v) and radius(smooth, t) == pytest.approx(v)
    assert radius(lin, 0.0) == radius(lin, 1.0) and radius(lin, 9.0) == pytest.approx(0.2)
    assert radius(lin, 1.5) == pytest.approx(0.2) and radius(lin, 3.0) == pytest.approx(0.25)
    # smooth: the cubic Hermite, by hand on the middle segment; the key at 2 s is a peak, so
    # its slope is 0 (Catmull–Rom's would be (0.2 − 0.1) / 3), the last key's 0 (the end)
    s = 0.5
    hand = (2 * s**3 - 3 * s**2 + 1) * 0.3 + (-2 * s**3 + 3 * s**2) * 0.2
    assert radius(smooth, 3.0) == pytest.approx(hand)
    # on a rise, Catmull–Rom's slope where it is within 3× each segment's slope
    rise = [[0.0, 0.1], [1.0, 0.2], [3.0, 0.5]]
    smooth = tracked("tree", [{"path": "tree.trunk_radius", "keys": rise}])
    m = (0.5 - 0.1) / 3.0 * 2.0  # × the segment's 2 s; 3× the slopes: 0.3 and 0.45 per s
    hand = (2 * s**3 - 3 * s**2 + 1) * 0.2 + (s**3 - 2 * s**2 + s) * m
    hand += (-2 * s**3 + 3 * s**2) * 0.5
    assert radius(smooth, 2.0) == pytest.approx(hand)


def catmull_rom(keys: list, t: float) -> float:
    """The unlimited curve, by hand: cubic Hermite with Catmull–Rom slopes, 0 at the ends."""
    times, v = [k[0] for k in keys], [k[1] for k in keys]
    j = max(i for i in range(len(times) - 1) if times[i] <= t)
    h, s = times[j + 1] - times[j], (t - times[j]) / (times[j + 1] - times[j])

    def m(i):
        inner = 0 < i < len(times) - 1
        return (v[i + 1] - v[i - 1]) / (times[i + 1] - times[i - 1]) * h if inner else 0.0

    return (
        (2 * s**3 - 3 * s**2 + 1) * v[j]
        + (s**3 - 2 * s**2 + s) * m(j)
        + (-2 * s**3 + 3 * s**2) * v[j + 1]
        + (s**3 - s**2) * m(j + 1)
    )


def test_smooth_never_leaves_the_range_of_the_keys_around_it():
    """Keys 40, 0, 88 of a branch angle (allowed 0..89): Catmull–Rom dips below 0 before
    the middle key (the control, by hand), so a moment `krsview check` never posed could
    not be drawn. The limited curve stays within [0, 40] there, and every moment poses."""
    from krsview import check

    keys = [[0.0, 40.0], [3.75, 0.0], [7.5, 88.0]]
    ts = np.linspace(0.0, 3.75, 301)
    assert min(catmull_rom(keys, t) for t in ts) < -1e-3  # the control: it overshoots
    s = tracked("tree", [{"path": "tree.branch_angle", "keys": keys}])
    angles = [s.at(t).posed().tree.branch_angle for t in ts]
    assert min(angles) >= 0.0 and max(angles) <= 40.0
    assert not check(s).warnings


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(0.0, 1.0), min_size=2, max_size=6),
    st.lists(st.floats(0.05, 3.0), min_size=5, max_size=5),
)
def test_smooth_stays_between_each_pair_of_keys(values, gaps):
    """Random keys at random spacings: the value between two keys lies between theirs."""
    times = np.concatenate([[0.0], np.cumsum(gaps[: len(values) - 1])])
    track = Track("tree.trunk_radius", [Key(float(t), v) for t, v in zip(times, values)])
    for j in range(len(values) - 1):
        lo, hi = sorted(values[j : j + 2])
        for t in np.linspace(times[j], times[j + 1], 17):
            got = track.value_at(float(t), False, False)
            assert lo - 1e-12 <= got <= hi + 1e-12, (t, got, lo, hi)


def slope(scene, t: float, side: float, h: float = 1e-5) -> float:
    return (radius(scene, t + side * h) - radius(scene, t)) / (side * h)


def test_smooth_is_c1_at_the_keys_and_linear_is_not():
    """Negative control: linear's slope jumps at a key, smooth's does not; smooth eases in
    and out of the first and last key (slope 0, so holding before and after is C¹ too)."""
    keys = [[1.0, 0.1], [2.0, 0.3], [4.0, 0.2]]
    lin = tracked("tree", [{"path": "tree.trunk_radius", "keys": keys, "interpolation": "linear"}])
    smooth = tracked("tree", [{"path": "tree.trunk_radius", "keys": keys}])
    assert abs(slope(lin, 2.0, -1) - slope(lin, 2.0, 1)) > 0.2
    assert slope(smooth, 2.0, -1) == pytest.approx(slope(smooth, 2.0, 1), abs=1e-3)
    for t in (1.0, 4.0):
        assert abs(slope(smooth, t, -1)) < 1e-3 and abs(slope(smooth, t, 1)) < 1e-3
    assert abs(slope(lin, 1.0, 1)) > 0.1


def test_whole_numbers_step_and_vectors_move_per_component():
    s = tracked(
        "tree",
        [
            {"path": "tree.levels", "keys": [[0.0, 4], [2.0, 9]], "interpolation": "linear"},
            {"path": "camera.position", "keys": [[0.0, [0, 2, -9]], [2.0, [2, 4, -5]]]},
        ],
    )
    assert [s.at(t).posed().tree.levels for t in (0.0, 1.99, 2.0, 5.0)] == [4, 4, 9, 9]
    cam = s.at(1.0).posed().camera.position  # halfway, smooth: each component halfway
    assert cam == pytest.approx((1.0, 3.0, -7.0))


def test_a_unit_normal_is_interpolated_and_normalised():
    """nlerp: the per-component blend, normalised (computed here independently)."""
    r = load("tree").tree.route()
    a, b = (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    scene = load("tree").with_geometry(r.krs())  # a [krs]: its mirrors' normals require unit
    scene = scene.edit("krs.levels[20].mirror.normal", list(a))
    s = scene.edit(
        "animation",
        {
            "tracks": [
                {
                    "path": "krs.levels[20].mirror.normal",
                    "keys": [[0, list(a)], [1, list(b)]],
                    "interpolation": "linear",
                }
            ]
        },
    )
    got = np.array(s.at(0.25).posed().krs.levels[20].mirror.normal)
    want = 0.75 * np.array(a) + 0.25 * np.array(b)
    assert got == pytest.approx(want / np.linalg.norm(want))
    assert abs(np.linalg.norm(got) - 1.0) < 1e-12 and np.linalg.norm(want) < 0.8


def test_posing_keeps_time_drops_tracks_and_posing_twice_is_posing_once():
    s = tracked("tree", [{"path": "tree.bend", "keys": [[0.0, 0.0], [2.0, 0.3]]}])
    p = s.at(1.0).posed()
    assert p.time == 1.0 and p.animation.tracks == [] and not p.animated
    assert p.posed() is p and p.tree.bend == pytest.approx(0.15)
    assert s.at(1.0).tree.bend == load("tree").tree.bend  # at(t): rest values, time moved
    assert s.animated and not load("tree").animated


def test_duration_defaults_to_the_last_key_and_a_file_keeps_it_following():
    s = tracked("tree", [{"path": "tree.bend", "keys": [[0.0, 0.0], [6.5, 0.3]]}])
    assert s.animation.duration == 6.5 and load("tree").at(1.0).animation.duration == 10.0
    text = scene_to_toml(s)
    assert "duration" not in text and "tree.bend" in text
    longer = text.replace("[6.5, 0.3]", "[8.0, 0.3]")
    assert scene_from_toml(longer).animation.duration == 8.0
    given = s.edit("animation.duration", 3.0)  # negative control: a duration given is kept
    assert "duration = 3.0" in scene_to_toml(given)
    assert scene_from_toml(scene_to_toml(given)).animation.duration == 3.0


@pytest.mark.parametrize(
    "track, where, rule",
    [
        (
            {"path": "tree.trunk_radius", "keys": [[0, 0.1], [1, -0.2]]},
            r"animation\.tracks\[1\]\.keys\[1\]",
            r"tree\.trunk_radius: allowed: 0 < value",
        ),
        (
            {"path": "tree.levels", "keys": [[0, 3], [1, 99]]},
            r"animation\.tracks\[1\]\.keys\[1\]",
            r"tree\.levels: allowed: 1 ≤ value ≤ 63",
        ),
        (
            {"path": "tree.trunk_radius", "keys": [[1, 0.1], [1, 0.2]]},
            r"animation\.tracks\[1\]\.keys\[1\]",
            "times must ascend",
        ),
        (
            {"path": "tree.trunk_radius", "keys": [[0, 0.1], [1, [1, 2, 3]]]},
            r"animation\.tracks\[1\]\.keys\[1\]",
            "same kind of value",
        ),
        (
            {"path": "tree.no_such", "keys": [[0, 0.1]]},
            r"animation\.tracks\[1\]\.path",
            "no such value",
        ),
        (
            {"path": "route.base", "keys": [[0, [0, 0, 0]]]},
            r"animation\.tracks\[1\]\.path",
            "no such value",
        ),
        (
            {"path": "tree..bend", "keys": [[0, 1.0]]},
            r"animation\.tracks\[1\]\.path = 'tree\.\.bend'",
            "expected field names and list indices",
        ),
        (
            {"path": "animation.time", "keys": [[0, 1.0]]},
            r"animation\.tracks\[1\]\.path",
            "time itself",
        ),
        ({"path": "lights", "keys": [[0, 1.0]]}, r"animation\.tracks\[1\]\.path", "one value"),
        (
            {"path": "tree.bend", "keys": [[0, {"a": 1}]]},
            r"animation\.tracks\[1\]\.keys\[0\]\[1\]",
            "a number, true/false",
        ),
        (
            {"path": "tree.bend", "keys": [[-1, 0.1]]},
            r"animation\.tracks\[1\]\.keys\[0\]\[0\]",
            "a time in seconds",
        ),
        (
            {"path": "tree.bend", "keys": [[k, 0.1] for k in range(257)]},
            r"animation\.tracks\[1\]\.keys",
            "1..256 keys",
        ),
        (
            {"path": "tree.bend", "keys": [[0, 0.1]], "interpolation": "cubic"},
            r"animation\.tracks\[1\]\.interpolation",
            "'linear', 'smooth'",
        ),
    ],
)
def test_a_bad_track_is_a_one_line_error_naming_the_key_and_the_rule(track, where, rule):
    good = {"path": "tree.bend", "keys": [[0, 0.1]]}
    tracked("tree", [good, good])  # negative control: good tracks load
    with pytest.raises(SceneError) as e:
        tracked("tree", [good, track])
    msg = str(e.value)
    assert "\n" not in msg and re.search(where, msg) and re.search(rule, msg), msg


def test_a_value_between_keys_that_breaks_its_rule_is_refused_at_that_frame():
    """Two valid keys whose blend is not: a mirror normal turned through zero. The frame at
    the midpoint names the track and the time; a frame before it draws."""
    s = load("tree").with_geometry(load("tree").tree.route().krs())
    s = s.edit("krs.levels[20].mirror.normal", [1.0, 0.0, 0.0])
    s = s.edit(
        "animation",
        {
            "tracks": [
                {
                    "path": "krs.levels[20].mirror.normal",
                    "keys": [[0, [1, 0, 0]], [2, [-1, 0, 0]]],
                    "interpolation": "linear",
                }
            ]
        },
    )
    s.at(0.5).posed()
    with pytest.raises(SceneError) as e:
        s.at(1.0).posed()
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("animation.tracks[0] at t = 1 s")
    assert "krs.levels[20].mirror.normal" in msg


def test_tracks_move_a_route_and_a_mokrs_transform_step():
    r = tracked("bent-tree", [{"path": "route.levels[5].fork", "keys": [[0, [0, 1, 0]]]}])
    assert r.at(3.0).posed().route.levels[5].fork == (0.0, 1.0, 0.0)
    palm = load(PRESETS / "palm-curl.toml")
    deg = [palm.at(t).posed().mokrs.levels[10].transform[1].degrees for t in (0.0, 1.0, 2.0)]
    assert deg[0] == -2.5 and deg[2] == -7.0 and -7.0 < deg[1] < -2.5
    assert palm.mokrs.levels[10].transform[1].degrees == -2.5  # the rest scene is unchanged


@pytest.mark.parametrize(
    "path, value",
    [
        (("mokrs", "levels", 12, "transform", 1, "degrees"), -5.0),
        (("mokrs", "levels", 12, "transform", 0, "factor"), 1e-9),  # out of range
        (("mokrs", "levels", 3, "reflect"), True),
        (("camera", "position"), [0.0, 0.0, 0.0]),
        (("mokrs", "levels", 12, "kernel", "radius"), -1.0),
        (("mokrs", "levels", 12, "kernel"), {"type": "sphere", "radius": 0.1}),
        (("render", "tracer"), "sphere"),  # the scene's rule: a MöKRS needs binary
        (("lights", 0, "direction"), [0.0, 2.0, 0.0]),  # normalised
    ],
)
def test_revalidating_what_changed_is_the_whole_validation(path, value):
    """An edit validates only the tables it changed and the rules around them: the same
    scene, or the same error, as validating the whole scene as a file (the independent
    reference)."""
    palm = load("palm")
    changed = replace_at(palm, path, value)
    try:
        want = validated(changed)
    except SceneError as e:
        with pytest.raises(SceneError) as got:
            revalidated(changed, [path])
        assert str(got.value) == str(e)
        return
    got = revalidated(changed, [path])
    assert scene_to_toml(got) == scene_to_toml(want) and got == want


@pytest.mark.parametrize(
    "name, times", [("tree-growing", (0.5, 3.0, 6.0)), ("tree-sway", (0.3, 0.9, 1.7))]
)
def test_gpu_draws_what_the_reference_draws_at_three_times(renderer, name, times):
    """Both renderers pose the scene at its time (tracks; sway). Negative control: the GPU's
    image at one time against the reference's at another fails the comparison (it moves)."""
    s = load(PRESETS / f"{name}.toml")
    s = per_pixel(replace(s, render=replace(s.render, lod=0.0)))
    w, h = 64, 48
    refs = {}
    for t in times:
        scene = s.at(t)
        refs[t] = render_reference(scene, w, h)
        assert refs[t].hit.mean() > 0.01
        check_against_reference(f"{name}-t{t:g}", renderer.render(scene, w, h), refs[t])
    wrong = gpu_reference_agreement(renderer.render(s.at(times[0]), w, h), refs[times[-1]])
    assert tolerance_failures(wrong)
