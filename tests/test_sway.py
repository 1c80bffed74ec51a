"""Low-index sway (issue 29, [KRS17 §10]): the coarsest fork mirrors turn about their forks,
bounded so that no child branch crosses its mirror, by the rule of what Alg. 1 clips."""

from __future__ import annotations

import math
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from krsview import load
from krsview.editor.clipped import clipped_parts
from krsview.scene import SceneError
from krsview.scene.edits import validated
from krsview.scene.sway import Sway, swayed, turned

PRESETS = Path(__file__).resolve().parent.parent / "presets"


def swaying(**sway) -> object:
    return load("tree").edit("animation", {"sway": sway})


def angle(u, v) -> float:
    return math.degrees(math.acos(min(1.0, abs(float(np.dot(u, v))))))


def test_each_swayed_mirror_turns_by_its_own_sine_about_its_fork():
    """The turn of the k-th mirror from the trunk is A |sin(2π f t + k φ)|, computed here from
    the parameters; the mirror still passes through its fork; finer mirrors stay."""
    s = swaying(levels=3, amplitude=3.0, frequency=0.5, phase_step=100.0)
    rest = s.tree.route()
    n = len(rest.levels)
    for t in (0.0, 0.3, 1.1):
        posed = s.at(t).posed().route
        for k in range(3):
            i = n - 1 - k
            want = 3.0 * abs(math.sin(2 * math.pi * 0.5 * t + math.radians(100.0 * k)))
            assert angle(posed.levels[i].normal, rest.levels[i].normal) == pytest.approx(
                want, abs=1e-6
            )
            m = posed.mirror(i)
            assert float(np.dot(m.normal, rest.levels[i].fork)) == pytest.approx(m.offset)
        assert posed.levels[: n - 3] == rest.levels[: n - 3]
        assert posed.levels[n - 3].fork == rest.levels[n - 3].fork  # branches do not move


def test_the_phases_are_deterministic_and_differ_by_level():
    a, b = (load(PRESETS / "tree-sway.toml").at(0.7).posed().route for _ in range(2))
    assert a == b
    s = load(PRESETS / "tree-sway.toml")
    rest = s.tree.route()
    n = len(rest.levels)
    turns = [angle(a.levels[n - 1 - k].normal, rest.levels[n - 1 - k].normal) for k in range(3)]
    assert len({round(x, 6) for x in turns}) == 3


def crossing_levels(route) -> set[int]:
    """The levels whose mirror Alg. 1 clips a branch across: the editor's red parts."""
    return {level + 1 for level, _ in clipped_parts(route)}


def test_an_accepted_sway_clips_nothing_at_any_time_of_a_period():
    """Brute force over a dense grid of one period with the editor's rule of what Alg. 1
    clips (editor/clipped.py), independent of the sampling bound the check uses."""
    s = load(PRESETS / "tree-sway.toml")
    period = 1.0 / s.animation.sway.frequency
    assert not crossing_levels(s.tree.route())
    for t in np.linspace(0.0, period, 400):
        assert not crossing_levels(s.at(float(t)).posed().route), t


def test_a_large_amplitude_is_refused_naming_the_level_and_time():
    """Negative control: an amplitude that swings a mirror across its child branch. The
    error names the sway level, the route level and a time at which the editor's rule
    (independent of the check's sampling) finds that level clipped."""
    with pytest.raises(SceneError) as e:
        swaying(levels=2, amplitude=30.0)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("animation.sway.amplitude = 30.0: at t = ")
    m = re.search(r"t = ([0-9.e+-]+) s the mirror of route\.levels\[(\d+)\] \(sway level (\d)", msg)
    t, i, k = float(m[1]), int(m[2]), int(m[3])
    rest = load("tree").tree.route()
    assert i == len(rest.levels) - 1 - k
    sway = Sway(levels=2, amplitude=30.0)
    normal = tuple(float(c) for c in turned(rest, i, sway.angle(k, t)))
    levels = list(rest.levels)
    levels[i] = replace(levels[i], normal=normal)
    assert i in crossing_levels(replace(rest, levels=levels))
    assert not crossing_levels(rest)
    with pytest.raises(SceneError, match=rf"route\.levels\[{i}\]"):  # the frame refuses it too
        swayed(rest, sway, t, "animation.sway")


def test_sway_needs_a_tree_and_enough_forks():
    with pytest.raises(SceneError, match=r"^animation\.sway = <sway>: sway turns the fork"):
        load("palm").edit("animation", {"sway": {}})
    with pytest.raises(SceneError, match=r"^animation\.sway\.levels = 8: this tree has 3 fork"):
        load("tree").edit("tree.levels", 3).edit("animation", {"sway": {"levels": 8}})
    load("tree").edit("tree.levels", 3).edit("animation", {"sway": {"levels": 3}})


def test_a_route_moved_by_a_track_into_the_sway_is_refused_at_that_frame():
    """The load check holds the rest route; a track that swings the trunk's child across
    the trunk's fork mirror makes the sway's turned mirror cut it: that frame names the
    level and the time, and an earlier frame draws."""
    r = load("tree").tree.route()
    n = len(r.levels)
    base = validated(replace(load("tree"), tree=None, route=r))
    child, fork = np.array(r.levels[n - 2].fork), np.array(r.levels[n - 1].fork)
    u = np.array(r.levels[n - 1].normal)
    across = child - 2.2 * float((child - fork) @ u) * u  # beyond its mirror image
    moving = base.edit(
        "animation",
        {
            "sway": {"levels": 1, "amplitude": 2.0},
            "tracks": [
                {
                    "path": f"route.levels[{n - 2}].fork",
                    "keys": [[0.0, list(child)], [4.0, list(across)]],
                }
            ],
        },
    )
    moving.at(0.0).posed()
    with pytest.raises(
        SceneError, match=rf"at t = 4 s the mirror of route\.levels\[{n - 1}\] \(sway level 0"
    ):
        moving.at(4.0).posed()
