"""Editor handles: every handle edits the field it is tied to, as the geometry says it should
(a fork drag moves the branch end, a normal tip turns the mirror about its fork, a KRS mirror
stays on its pivot, a compound component moves as a whole)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from krsview.editor.handles import handles, outline, polyline
from krsview.editor.trackball import snap_direction
from krsview.scene import SceneError, load_scene
from krsview.scene.edits import apply_edit
from krsview.scene.presets import resolve


@pytest.fixture(scope="module")
def route_scene():
    s = load_scene(resolve("tree"))
    return replace(s, tree=None, route=s.tree.route())


def by(hs, path, kind=None):
    return next(h for h in hs if h.path == path and (kind is None or h.kind == kind))


def test_a_route_has_a_fork_and_control_per_level_and_a_normal_above_level_0(route_scene):
    hs = handles(route_scene)
    n = len(route_scene.route.levels)
    assert sum(h.path[-1] == "fork" for h in hs) == n
    assert sum(h.path[-1] == "control" for h in hs) == n
    assert sum(h.kind == "normal" for h in hs) == n - 1
    assert len(outline(route_scene)) == n
    line = polyline(route_scene)
    assert np.allclose(line[0], route_scene.route.base) and np.allclose(
        line[-1], route_scene.route.levels[0].fork
    )


def test_dragging_a_fork_alone_moves_the_branch_end_and_the_childs_start(route_scene):
    h = by(handles(route_scene), ("route", "levels", 7, "fork"))
    p = h.position + np.array([0.1, -0.05, 0.2])
    s = apply_edit(route_scene, *h.edit_to(route_scene, p, carry=False))
    krs = s.geometry()
    assert np.allclose(krs.levels[7].kernel.end, p) and np.allclose(krs.levels[6].kernel.start, p)
    assert krs.levels[5] == route_scene.geometry().levels[5]
    m = krs.levels[7].mirror  # the fork's mirror follows the fork
    assert abs(np.array(m.normal) @ p - m.offset) < 1e-12


def test_a_dragged_fork_carries_its_subtree_rigidly(route_scene):
    """Every finer kernel moves by the drag, every finer mirror keeps its normal and passes
    through its moved fork: the subtree is the same geometry, translated (checked on the
    expanded KRS with the reference distance), and the crown stays attached."""
    from krsview.compile.krs import compile_krs
    from krsview.reference.krs import distance
    from krsview.scene import KRS

    i = 20
    h = by(handles(route_scene), ("route", "levels", i, "fork"))
    delta = np.array([-0.6, 0.1, 0.3])
    s = apply_edit(route_scene, *h.edit_to(route_scene, h.position + delta))
    assert np.allclose(s.route.levels[i].fork, h.position + delta)
    sub0 = KRS(route_scene.geometry().levels[:i])
    sub1 = KRS(s.geometry().levels[:i])
    pts = np.random.default_rng(5).normal(np.array(h.position), 1.0, (2000, 3))
    d0 = distance(compile_krs(sub0, (0.5,) * 3), pts)
    d1 = distance(compile_krs(sub1, (0.5,) * 3), pts + delta)
    np.testing.assert_allclose(d1, d0, atol=1e-9)
    assert s.route.warnings() == [], "carrying the subtree made a branch cross its mirror"
    # negative control: moving the fork alone detaches the crown (Alg. 1 clips it)
    alone = apply_edit(route_scene, *h.edit_to(route_scene, h.position + delta, carry=False))
    assert alone.route.warnings()


def test_dragging_the_trunk_foot_moves_the_whole_tree(route_scene):
    h = by(handles(route_scene), ("route", "base"))
    delta = np.array([1.0, 0.0, -2.0])
    s = apply_edit(route_scene, *h.edit_to(route_scene, h.position + delta))
    for k0, k1 in zip(route_scene.geometry().kernels, s.geometry().kernels):
        assert np.allclose(np.subtract(k1.start, k0.start), delta)
        assert np.allclose(np.subtract(k1.end, k0.end), delta)


def test_dragging_a_normal_tip_turns_the_mirror_about_its_fork(route_scene):
    h = by(handles(route_scene), ("route", "levels", 7, "normal"))
    fork = np.array(route_scene.route.levels[7].fork)
    target = fork + np.array([0.0, 0.3, 0.0])
    s = apply_edit(route_scene, h.path, h.value_at(route_scene, target))
    assert np.allclose(s.route.levels[7].normal, [0.0, 1.0, 0.0])
    # the tip onto the fork is a zero normal: a clear error, not a NaN mirror
    with pytest.raises(SceneError, match="must not be the zero vector"):
        apply_edit(route_scene, h.path, h.value_at(route_scene, fork))


def test_the_rocks_twelve_mirrors_have_handles_that_keep_each_plane_on_its_pivot():
    rock = load_scene(resolve("rock"))
    hs = handles(rock)
    normals = [h for h in hs if h.kind == "normal"]
    assert len(normals) == rock.krs.n == 12
    h = normals[3]
    tilt = h.position - h.pivot + np.array([0.0, 0.2, 0.1])
    s = apply_edit(rock, h.path, h.value_at(rock, h.pivot + tilt))
    m = s.krs.levels[h.level].mirror
    assert np.allclose(m.normal, tilt / np.linalg.norm(tilt))
    assert abs(np.array(m.normal) @ h.pivot - m.offset) < 1e-12
    # its position handle slides the plane along the normal through the dragged point
    pos = by(hs, h.path, "point")
    p = pos.position + np.array([0.3, 0.0, 0.0])
    s = apply_edit(rock, pos.path, pos.value_at(rock, p))
    m0, m1 = rock.krs.levels[h.level].mirror, s.krs.levels[h.level].mirror
    assert m1.normal == m0.normal and math.isclose(m1.offset, np.array(m0.normal) @ p)


def test_a_compound_component_handle_moves_the_whole_component():
    grove = load_scene(resolve("grove"))
    hs = handles(grove)
    assert len(hs) == len(grove.compound) == len(outline(grove))
    h = hs[2]
    delta = np.array([0.5, 0.0, -0.25])
    s = apply_edit(grove, h.path, h.value_at(grove, h.position + delta))
    before, after = grove.geometry().parts[2], s.geometry().parts[2]
    for k0, k1 in zip(before.kernels, after.kernels):
        if hasattr(k0, "start"):
            assert np.allclose(np.subtract(k1.start, k0.start), delta)
    assert s.geometry().parts[1] == grove.geometry().parts[1]


def test_snapped_directions_lie_on_the_angle_grid():
    rng = np.random.default_rng(3)
    for d in rng.normal(size=(50, 3)):
        s = snap_direction(d, 5.0)
        assert math.isclose(np.linalg.norm(s), np.linalg.norm(d), rel_tol=1e-12)
        theta = math.degrees(math.acos(s[1] / np.linalg.norm(s)))
        assert abs(theta / 5.0 - round(theta / 5.0)) < 1e-9
        assert math.degrees(math.acos(np.clip(s @ d / (d @ d), -1, 1))) < 5.0
