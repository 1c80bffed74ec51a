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
    # its slider moves the plane along the normal by the drag's part along it: the slider
    # keeps its height above the plane, and the plane its normal
    pos = by(hs, h.path, "point")
    step = np.array([0.3, 0.0, 0.0])
    s = apply_edit(rock, pos.path, pos.value_at(rock, pos.position + step))
    m0, m1 = rock.krs.levels[h.level].mirror, s.krs.levels[h.level].mirror
    u = np.array(m0.normal)
    assert m1.normal == m0.normal
    assert math.isclose(u @ (pos.position + step) - m1.offset, u @ pos.position - m0.offset)
    assert math.isclose(m1.offset - m0.offset, u @ step) and abs(u @ step) > 0.01
    # the arrows fan out: every tip sits ARROW × the sphere's size from its plane's point
    # nearest the sphere's centre, so the twelve are as far apart as their normals
    for n in normals:
        m = rock.krs.levels[n.level].mirror
        foot = m.offset * np.array(m.normal)  # the plane's point nearest the centre (origin)
        tip = foot + 0.6 * 4.0 * np.array(m.normal)  # ARROW × 4 × the sphere's radius
        assert np.allclose(n.pivot, foot) and np.allclose(n.position, tip)


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


def turned_route(route_scene, i: int = 21, degrees: float = 36.0):
    """The tree with level i's normal turned about the axis n × z: its child crosses it."""
    n = np.array(route_scene.route.levels[i].normal)
    a = np.cross(n, [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    t = math.radians(degrees)
    u = n * math.cos(t) + np.cross(a, n) * math.sin(t)
    return apply_edit(route_scene, ("route", "levels", i, "normal"), tuple(u))


def test_the_clipped_part_is_the_branch_on_the_mirrors_positive_side(route_scene):
    """The spans found in closed form against 4001 points sampled along the branch, each
    classified by its side of the plane; the parts drawn are exactly the levels warned."""
    from krsview.editor.clipped import clipped_parts, positive_spans
    from krsview.scene.route import arc_points

    s = turned_route(route_scene)
    route = s.route
    said = route.warnings()  # the branch, and its sibling of the fork below, are cut
    assert len(said) == 2 and said[0].startswith(
        "levels[19] (L19): its mirror image in R19 at fork P20"
    )
    assert said[1].startswith(
        "levels[20] (L20): the branch crosses mirror R20 at fork P21, where it grows from"
    )
    # the names are the handles' own: each R and P the warnings say is the handle of the
    # field in parentheses, and each L is the outline's entry (they were levels[21].normal,
    # which the panel calls R20: one off [review])
    import re

    labels = {h.label: h.path for h in handles(s)}
    for text in said:
        for name, field in re.findall(r"(R\d+) \((levels\[\d+\]\.normal)\)", text):
            k = int(field[7 : field.index("]")])
            label = f"mirror normal {name} at P{k}"
            assert labels[label] == ("route", "levels", k, "normal"), text
        for name in re.findall(r"fork (P\d+)", text):
            assert labels[f"fork {name}"][-1] == "fork" and labels[f"fork {name}"][2] == int(
                name[1:]
            )
        k = int(text[7 : text.index("]")])
        assert outline(s)[k].startswith(text[text.index("(") + 1 : text.index(")")] + " ")
    m = route.mirror(21)
    samples = np.linspace(0.0, 1.0, 4001)
    g = arc_points(route.kernel(20), len(samples)) @ np.array(m.normal) - m.offset
    spans = positive_spans(route, 21)

    def within(spans):
        return np.array([any(a <= x <= b for a, b in spans) for x in samples])

    inside = within(spans)
    clear = np.abs(g) > 1e-9  # off the plane by more than rounding
    assert (inside[clear] == (g > 0)[clear]).all()
    assert inside.mean() > 0.5, "most of the turned branch lies across the mirror"
    parts = clipped_parts(route)
    assert {level for level, _ in parts} == {19, 20}
    for _, line in parts:
        assert (line @ np.array(m.normal) - m.offset >= -1e-9).all()
    # negative controls: the baked tree clips nothing; the other side of the same mirror is
    # the complement
    assert clipped_parts(route_scene.route) == []
    flipped = apply_edit(s, ("route", "levels", 21, "normal"), tuple(-np.array(m.normal)))
    assert (within(positive_spans(flipped.route, 21))[clear] == ~inside[clear]).all()


def test_a_turn_is_proportional_to_the_pointer_and_dragging_up_tilts_up():
    """trackball.turned: the angle is k × the drag's part perpendicular to the normal (never
    more than k × its length), the normal stays unit, an upward drag raises it; the tip-
    translate it replaces turns a short arrow far more for the same 3 pixels (the jump)."""
    from krsview.compile.camera import pixel_ray, project, view_of
    from krsview.editor.handles import Handle
    from krsview.editor.trackball import RADIANS_PER_PIXEL, turned

    rock = load_scene(resolve("rock"))
    v = view_of(rock.camera, 800, 500)
    rng = np.random.default_rng(7)
    for n in rng.normal(size=(40, 3)):
        n /= np.linalg.norm(n)
        for dx, dy in ((0.0, -3.0), (2.0, -1.0), (0.0, -0.5)):
            m = turned(n, v, dx, dy)
            d = dx * v.right - dy * v.up
            perp = d - n * (n @ d)
            angle = math.acos(np.clip(n @ m, -1, 1))
            assert math.isclose(angle, RADIANS_PER_PIXEL * np.linalg.norm(perp), rel_tol=1e-9)
            assert angle <= RADIANS_PER_PIXEL * math.hypot(dx, dy) * (1 + 1e-12)
            assert math.isclose(np.linalg.norm(m), 1.0, rel_tol=1e-14)
            if dx == 0:
                assert (m - n) @ v.up >= -1e-15
    # negative control: the tip dragged 3 px up in the screen plane (the old translate) turns
    # a short arrow pointing nearly at the eye by tens of degrees
    pivot = np.array(rock.camera.target)
    n = -v.forward + 0.05 * v.up
    n /= np.linalg.norm(n)
    tip = pivot + 0.15 * n
    x, y, z = project(v, tip)
    moved = v.origin + (z / (pixel_ray(v, x, y - 3) @ v.forward)) * pixel_ray(v, x, y - 3)
    h = Handle(("krs", "levels", 1, "mirror"), "normal", tip, 1, "", (), pivot=pivot)
    jumped = np.array(h.value_at(rock, moved).normal)
    assert math.degrees(math.acos(np.clip(n @ jumped, -1, 1))) > 10.0
    assert math.degrees(math.acos(np.clip(n @ turned(n, v, 0, -3), -1, 1))) <= 1.5 + 1e-9


def test_a_gizmo_move_snaps_to_the_absolute_grid_and_writes_no_float32_noise():
    from krsview.editor.gizmo import decimal_step, moved

    p = np.array([1.0, 0.1, -2.3])
    # snapping: 1.0 + 0.2125 = 1.2125 lands on 1.25 (grid 0.25), not 1.0 + 0.25 × k
    q = moved(p, np.array([0.2125, 0.0, 0.0]), 1e-4, 0.25)
    assert q[0] == 1.25 and q[1] == p[1] and q[2] == p[2]
    assert moved(p + [0.1, 0, 0], np.array([0.1125, 0.0, 0.0]), 1e-4, 0.25)[0] == 1.25
    # no snapping: the moved coordinate is a short decimal, the others bit-exact
    rel = np.float32(p - [0.5, 3.0, 9.0])  # camera-relative, as ImGuizmo holds it
    out = (rel + np.float32([0.0123456, 0.0, 0.0])).astype(np.float64)
    q = moved(p, out - rel.astype(np.float64), decimal_step(3e-4), None)
    assert q[1] == 0.1 and q[2] == -2.3 and repr(float(q[0])) == "1.0123"
    # negative control: the float32 position read back directly carries the noise
    noisy = out + [0.5, 3.0, 9.0]
    assert noisy[1] != 0.1 and abs(noisy[1] - 0.1) < 1e-6
    assert decimal_step(0.00731) == 0.001 and decimal_step(2.0) == 1.0


def test_only_the_selected_level_and_its_neighbours_show_their_arrows(route_scene):
    from krsview.editor.picking import visible

    rock = load_scene(resolve("rock"))
    hs = handles(rock)
    shown = visible(hs, None)  # the sphere's centre, and the empty levels' arrows
    assert [h.kind for h in shown] == ["point"] + ["normal"] * 12
    sel = next(h for h in hs if h.level == 5 and h.kind == "normal")
    near = visible(hs, sel)
    assert {h.level for h in near if h.path[-1] == "mirror" and h.kind == "point"} == {4, 5, 6}
    assert sum(h.kind == "normal" for h in near) == 12
    # a route: every fork, but control points and arrows only around the selection
    hs = handles(route_scene)
    assert {h.path[-1] for h in visible(hs, None)} == {"fork", "base"}
    sel = next(h for h in hs if h.level == 7)
    near = visible(hs, sel)
    assert {h.level for h in near if h.path[-1] in ("control", "normal")} == {6, 7, 8}
    assert len(near) < len(hs), "negative control: not everything shows"
