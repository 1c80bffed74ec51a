"""A keyed fork moves its subtree, as a bone does (issue 28/29): the pose moves the finer
forks and control points by the keyed fork's offset from its rest value at every moment, a
drag of the keyed fork keys it and its subtree comes along, and a drag of an unkeyed fork
with its subtree takes the subtree's keyed parts along. The presets' playback is unchanged."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview import load
from krsview.editor.dragging import drag_edits
from krsview.editor.handles import handles
from krsview.editor.keys import key_now, keyed_edit, with_key
from krsview.scene import animation

FORK = ("route", "levels", 20, "fork")
FINER = ("route", "levels", 12, "fork")
MOVE = np.array([0.25, -0.1, 0.15])


@pytest.fixture(scope="module")
def bent():
    return load("bent-tree")


def keyed(scene, path, *keys):
    """``scene`` with a track on ``path``: keys (time, value)."""
    for t, v in keys:
        scene = scene.edit("animation", with_key(scene, path, t, tuple(v)))
    return scene


def apply(scene, edits):
    for path, value in edits:
        path, value = keyed_edit(scene, path, value, scene.animation.time if scene.animation else 0)
        scene = scene.edit(path, value)
    return scene


def offsets(scene, t):
    """Each level's fork as drawn at t less its rest value (levels 0..20)."""
    posed = scene.at(t).posed()
    return np.array(
        [np.subtract(posed.route.levels[j].fork, scene.route.levels[j].fork) for j in range(21)]
    )


def follows(scene, t) -> bool:
    """Whether every finer fork is drawn moved by the keyed fork's own move at t."""
    off = offsets(scene, t)
    return bool(np.allclose(off[:20], off[20], atol=1e-12)) and np.linalg.norm(off[20]) > 1e-3


def test_a_keyed_fork_drag_keys_it_and_its_subtree_follows_at_every_moment(bent):
    rest = np.array(bent.route.levels[20].fork)
    s = keyed(bent, FORK, (0.0, rest))  # K at 0 s: the rest value
    s = s.at(2.0)
    h = next(h for h in handles(s.posed()) if h.path == FORK)
    s = apply(s, drag_edits(s, h, rest + MOVE, carry=True, t=2.0))  # the drag at 2 s
    track = s.animation.tracks[0]
    assert [k.time for k in track.keys] == [0.0, 2.0] and s.route.levels[20].fork == tuple(rest)
    assert np.allclose(offsets(s, 2.0)[20], MOVE, atol=1e-12)
    assert follows(s, 2.0)  # the finer forks by the same delta at the keyed moment
    half = offsets(s, 1.0)  # half way: the smooth track's middle, the subtree with it
    assert np.allclose(half[20], MOVE / 2, atol=1e-12) and follows(s, 1.0)
    assert np.allclose(offsets(s, 0.0), 0.0), "at the first key the tree is at rest"
    control = s.at(2.0).posed().route.levels[20].control  # its own bend kept: half
    assert np.allclose(np.subtract(control, bent.route.levels[20].control), MOVE / 2)


def test_the_old_pose_moving_the_fork_alone_fails_the_same_check(bent, monkeypatch):
    """Negative control: the pose without bones (the fork alone) tears the subtree off."""
    rest = np.array(bent.route.levels[20].fork)
    s = keyed(bent, FORK, (0.0, rest), (2.0, rest + MOVE))
    assert follows(s, 2.0)
    monkeypatch.setattr(animation, "bone_offsets", lambda rest, values: {})
    assert not follows(s, 2.0)


def test_a_finer_key_holds_its_value_as_if_the_keyed_fork_were_at_rest(bent):
    rest = np.array(bent.route.levels[20].fork)
    s = keyed(bent, FORK, (0.0, rest), (2.0, rest + MOVE))
    drawn = np.array(s.at(2.0).posed().route.levels[12].fork)
    k = s.edit("animation", key_now(s, [FINER], 2.0))  # K on the finer fork at 2 s
    assert np.allclose(k.at(2.0).posed().route.levels[12].fork, drawn, atol=1e-12)
    assert np.allclose(k.animation.tracks[1].keys[0].value, drawn - MOVE, atol=1e-12)
    raw = k.edit("animation", with_key(s, FINER, 2.0, tuple(drawn)))  # the drawn value as key
    assert not np.allclose(raw.at(2.0).posed().route.levels[12].fork, drawn, atol=1e-3)
    target = drawn + np.array([0.0, 0.2, 0.0])  # a drag of the finer fork to target at 2 s
    dragged = apply(k.at(2.0), [(FINER, tuple(target))])
    assert np.allclose(dragged.at(2.0).posed().route.levels[12].fork, target, atol=1e-12)


@pytest.mark.parametrize("carry_tracks", [True, False])
def test_an_unkeyed_fork_dragged_with_its_subtree_takes_the_keyed_forks_along(bent, carry_tracks):
    """An unkeyed coarser fork (22) carried: the keyed finer fork (20) and its subtree move
    with it at every moment; negative control: the carry without moving the track."""
    rest = np.array(bent.route.levels[20].fork)
    s = keyed(bent, FORK, (0.0, rest), (2.0, rest + MOVE)).at(1.0)
    trunk = next(h for h in handles(s.posed()) if h.path == ("route", "levels", 22, "fork"))
    edits = drag_edits(s, trunk, trunk.position + np.array([0.0, 0.0, 0.3]), carry=True, t=1.0)
    assert len(edits) == 2 and edits[1][0] == ("animation",)
    moved = apply(s, edits if carry_tracks else edits[:1])
    for t in (0.0, 1.0, 2.0):
        was, now = s.at(t).posed().route, moved.at(t).posed().route
        shift = [np.subtract(now.levels[j].fork, was.levels[j].fork) for j in (12, 20, 21)]
        together = np.allclose(shift, [0.0, 0.0, 0.3], atol=1e-12)
        assert together == carry_tracks, (t, shift)


@pytest.mark.parametrize("name", ["palm-curl", "tree-growing", "tree-sway"])
def test_the_presets_play_as_before(name, monkeypatch):
    """The moving presets key no fork: their poses are those without bones, at five moments
    over the loop (the comparison is shown to see a fork track: the last assertion)."""
    s = load(name)
    times = np.linspace(0.0, s.duration, 5)
    now = [s.at(t).posed() for t in times]
    with monkeypatch.context() as m:
        m.setattr(animation, "bone_offsets", lambda rest, values: {})
        before = [s.at(t).posed() for t in times]
        assert now == before
        tree = load("bent-tree")
        fork = np.array(tree.route.levels[20].fork)
        k = keyed(tree, FORK, (0.0, fork), (1.0, fork + MOVE)).at(1.0)
        without = replace(k).posed()
    assert k.posed() != without
