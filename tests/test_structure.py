"""Structure edits of a route (scene/restructure.py) and growing a baked route again
(scene/regrow.py), checked with the reference distance of the kernels and of the whole KRS,
not with the construction itself; and the editor's glue (editor/structure.py): one undo step
each, a refusal changes nothing and says why, re-growing asks before losing hand edits."""

from __future__ import annotations

import time
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from krsview.compile.krs import compile_krs
from krsview.document.document import Document
from krsview.editor import commands as ec
from krsview.editor.structure import STRUCTURE_HANDLERS, StructureTools
from krsview.reference.krs import distance
from krsview.scene import KRS, Level, SceneError, load_scene, save_scene, scene_from_toml
from krsview.scene.edits import validated
from krsview.scene.presets import resolve
from krsview.scene.regrow import frame, grow, rebake
from krsview.scene.restructure import (
    duplicate_level,
    free_normal,
    merge_level,
    move_base,
    scale_tree,
    scale_widths,
    split_level,
    tangent_at,
    taper,
)
from krsview.scene.route import centre_at
from krsview.viewer.widgets import Interactions

ALBEDO = (0.5, 0.5, 0.5)
LINE = np.linspace(0.0, 1.0, 41)


@pytest.fixture(scope="module")
def scene():
    """The shipped tree with 8 forks (fast), bent as shipped."""
    s = load_scene(resolve("tree"))
    return replace(s, tree=replace(s.tree, levels=8))


@pytest.fixture(scope="module")
def route(scene):
    return scene.tree.route()


def kernel_d(k, pts) -> np.ndarray:
    return distance(compile_krs(KRS([Level(k)]), ALBEDO), np.asarray(pts, dtype=float))


def krs_d(route, pts) -> np.ndarray:
    return distance(compile_krs(route.krs(), ALBEDO), np.asarray(pts, dtype=float))


def route_points(route) -> np.ndarray:
    """Points along every branch of the route itself (the identity instances)."""
    return np.concatenate([centre_at(route.kernel(i), LINE) for i in range(len(route.levels))])


# ---------------------------------------------------------------------------- insert
@pytest.mark.parametrize("i,s", [(0, 0.5), (3, 0.3), (8, 0.7)])
def test_the_split_halves_trace_the_old_branch(route, i, s):
    old = route.kernel(i)
    new = split_level(route, i, s)
    upper, lower = new.kernel(i), new.kernel(i + 1)
    assert new.levels[i + 1].fork == upper.start == lower.end
    # every point of each half lies on the old branch's centre line, and the old line is
    # covered by the two halves: measured by the reference kernel distance (−radius on it)
    tol = 1e-9
    for half in (upper, lower):
        np.testing.assert_allclose(kernel_d(old, centre_at(half, LINE)), -old.radius, atol=tol)
    on_old = centre_at(old, LINE)
    both = np.minimum(kernel_d(upper, on_old), kernel_d(lower, on_old))
    np.testing.assert_allclose(both, -old.radius, atol=tol)
    # the fork lies at fraction s of the arc length: the halves' lengths are s : 1 − s
    lengths = [
        np.linalg.norm(np.diff(centre_at(k, LINE), axis=0), axis=1).sum() for k in (lower, upper)
    ]
    assert lengths[0] / sum(lengths) == pytest.approx(s, abs=1e-3)


def test_negative_control_a_split_that_drops_the_control_points_moves_the_curve(route):
    i = 3
    old, new = route.kernel(i), split_level(route, i, 0.5)
    lv = new.levels[i]
    naive_start = np.array(new.levels[i + 1].fork)
    naive = replace(new.kernel(i), control=tuple((naive_start + np.array(lv.fork)) / 2))
    off = kernel_d(old, centre_at(naive, LINE)) + old.radius
    assert off.max() > 1e-3, "the bent branch should leave the old curve when straightened"


def test_the_new_forks_mirror_passes_through_it_and_keeps_its_branch_unclipped(route):
    for i in range(len(route.levels)):
        new = split_level(route, i, 0.4)
        u, q = np.array(new.levels[i + 1].normal), np.array(new.levels[i + 1].fork)
        t = tangent_at(route.kernel(i), 0.4)
        assert abs(np.linalg.norm(u) - 1) < 1e-12
        assert -np.sin(np.radians(45.01)) <= u @ t <= 1e-9, "tilted back by at most 45°"
        assert new.krs().levels[i + 1].mirror.offset == pytest.approx(u @ q, abs=1e-12)
        assert new.warnings() == route.warnings() == []


def test_free_normal_prefers_the_hint_among_equally_good_planes():
    t = np.array([0.0, 1.0, 0.0])
    line = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])  # on the tangent: every plane is good
    assert free_normal(np.zeros(3), t, line, line, (0.0, 0.0, 1.0)) == pytest.approx((0, 0, 1))
    assert free_normal(np.zeros(3), t, line, line, (1.0, 0.0, 0.0)) == pytest.approx((1, 0, 0))


@pytest.fixture(scope="module")
def old_surface(route):
    """Points on the surface of the tree before any edit (|reference distance| < 0.02)."""
    pts = np.random.default_rng(0).uniform((-4, 0, -4), (4, 8, 4), (120_000, 3))
    return pts[np.abs(krs_d(route, pts)) < SURFACE]


SURFACE = 0.02


def test_the_tree_keeps_its_old_geometry_after_an_insert(route, old_surface):
    """The reference distance of the whole KRS after an insert: along the old route (the
    identity instances) it is what it was, and on the old tree's surface it stays on the
    surface (the new mirror adds its image of the crown and folds away almost nothing)."""
    pts = route_points(route)
    before = krs_d(route, pts)
    assert len(old_surface) > 200
    for i in (2, 5, 8):
        new = split_level(route, i, 0.5)
        np.testing.assert_allclose(krs_d(new, pts), before, atol=1e-9)
        kept = (krs_d(new, old_surface) < SURFACE).mean()
        assert kept >= 0.98, (i, kept)
    # negative control: the mirror in the plane of the branch (no tilt, the old neighbour's
    # normal made ⟂ the branch) folds away a large part of the crown
    new = split_level(route, 5, 0.5)
    t = tangent_at(route.kernel(5), 0.5)
    n = np.array(route.levels[5].normal)
    flat = (n - (n @ t) * t) / np.linalg.norm(n - (n @ t) * t)
    lv = new.levels[6]
    flat_route = replace(
        new, levels=[*new.levels[:6], replace(lv, normal=tuple(flat)), *new.levels[7:]]
    )
    assert (krs_d(flat_route, old_surface) < SURFACE).mean() < 0.9


# ----------------------------------------------------------------- remove, duplicate
@pytest.mark.parametrize("i", [0, 1, 4, 8])
@pytest.mark.parametrize("s", [0.2, 0.5, 0.9])
def test_remove_after_insert_is_the_identity(route, i, s):
    back = merge_level(split_level(route, i, s), i + 1)
    assert len(back.levels) == len(route.levels)
    for a, b in zip(back.levels, route.levels):
        assert (a.radius, a.color, a.normal, a.grown) == (b.radius, b.color, b.normal, b.grown)
        np.testing.assert_allclose(a.fork, b.fork, atol=1e-12)
        np.testing.assert_allclose(a.control, b.control, atol=1e-12)


def test_removing_a_fork_merges_two_branches_through_it(route):
    i = 4
    merged = merge_level(route, i)
    k = merged.kernel(i - 1)
    assert len(merged.levels) == len(route.levels) - 1
    assert k.start == route.starts()[i] and k.end == route.levels[i - 1].fork
    assert kernel_d(k, [route.levels[i].fork])[0] == pytest.approx(-k.radius, abs=1e-9)
    twigless = merge_level(route, 0)
    assert twigless.levels[0].normal is None and twigless.levels[0].fork == route.levels[1].fork
    with pytest.raises(SceneError, match="at least one level"):
        merge_level(replace(route, levels=route.levels[-1:]), 0)


@pytest.mark.parametrize("i", [0, 3, 8])
def test_a_duplicate_repeats_the_branch_at_its_tip_and_carries_the_finer_levels(route, i):
    dup = duplicate_level(route, i)
    v = np.subtract(route.levels[i].fork, route.starts()[i])
    assert len(dup.levels) == len(route.levels) + 1
    np.testing.assert_allclose(np.subtract(dup.levels[i].fork, dup.levels[i + 1].fork), v)
    for j in range(i):  # the finer levels, moved along
        np.testing.assert_allclose(np.subtract(dup.levels[j].fork, route.levels[j].fork), v)
    assert dup.levels[i + 1].fork == route.levels[i].fork and dup.levels[i].grown is None
    assert dup.warnings() == []
    pts = centre_at(route.kernel(i), LINE) + v  # the copy lies where the branch, moved, is
    np.testing.assert_allclose(kernel_d(dup.kernel(i), pts), -route.levels[i].radius, atol=1e-9)


# --------------------------------------------------------------------------- whole tree
def test_taper_sets_each_radius_to_the_ratio_times_its_parents(route):
    t = taper(route, 0.6)
    r = [lv.radius for lv in t.levels]
    np.testing.assert_allclose(np.array(r[:-1]) / np.array(r[1:]), 0.6, rtol=1e-12)
    assert r[-1] == route.levels[-1].radius
    with pytest.raises(SceneError, match="taper"):
        taper(route, 1.5)


def test_scaling_the_tree_scales_its_distance_and_moving_it_moves_it(route):
    pts = np.random.default_rng(3).normal((0, 3, 0), 2.0, (300, 3))
    base = np.array(route.base)
    d = krs_d(route, pts)
    big = scale_tree(route, 1.7)
    np.testing.assert_allclose(krs_d(big, base + 1.7 * (pts - base)), 1.7 * d, atol=1e-9)
    moved = move_base(route, (1.0, -2.0, 0.5))
    np.testing.assert_allclose(krs_d(moved, pts + (1.0, -2.0, 0.5)), d, atol=1e-9)
    wide = scale_widths(route, 2.0)
    assert [lv.radius for lv in wide.levels] == [2.0 * lv.radius for lv in route.levels]
    assert not np.allclose(krs_d(wide, pts), d), "negative control: wider branches differ"
    with pytest.raises(SceneError, match="factor > 0"):
        scale_tree(route, 0.0)


def test_scaling_a_forest_moves_its_mirrors_with_it():
    s = load_scene(resolve("forest"))
    r = replace(s.tree, levels=6).route()
    pts = np.random.default_rng(4).normal((0, 2, 0), 4.0, (200, 3))
    base = np.array(r.base)
    np.testing.assert_allclose(
        krs_d(scale_tree(r, 0.5), base + 0.5 * (pts - base)), 0.5 * krs_d(r, pts), atol=1e-9
    )


# ------------------------------------------------------------------------------ re-grow
def test_a_baked_route_keeps_its_growth_and_depths_through_a_file(scene, tmp_path):
    baked = replace(scene, tree=None, route=scene.tree.route())
    save_scene(baked, tmp_path / "b.toml")
    again = load_scene(tmp_path / "b.toml")
    assert again == baked and again.route.growth.levels == 8
    assert [lv.grown for lv in again.route.levels] == list(range(8, -1, -1))
    text = (tmp_path / "b.toml").read_text()
    bad = text.replace("grown = 3", "grown = 9", 1)
    with pytest.raises(SceneError, match=r"route\.levels\[5\]\.grown.*0\.\.8"):
        scene_from_toml(bad)
    with pytest.raises(SceneError, match="does not have"):
        validated(replace(baked, route=replace(baked.route, growth=None)))


def test_growing_again_unchanged_is_the_identity_and_new_growth_is_the_new_bake(route):
    same, lost = rebake(route, route.growth)
    assert same == route and lost == []
    g = replace(route.growth, branch_angle=40.0, levels=6)
    assert rebake(route, g) == (grow(g), [])


def test_hand_edits_survive_a_change_of_the_growth_parameters(route):
    k = 5  # bend level 5's branch and thicken level 2
    lv = route.levels[k]
    edited = replace(
        route,
        levels=[
            *route.levels[:2],
            replace(route.levels[2], radius=route.levels[2].radius * 1.5),
            *route.levels[3:k],
            replace(lv, control=tuple(np.add(lv.control, (0.1, 0.0, 0.05)))),
            *route.levels[k + 1 :],
        ],
    )
    g = replace(route.growth, branch_angle=40.0)
    new, lost = rebake(edited, g)
    fresh = grow(g)
    assert lost == []
    assert new.levels[2].radius == pytest.approx(fresh.levels[2].radius * 1.5, rel=1e-12)

    # the control's offset from the bake, in the branch's frame and length, is the same
    def offset(r, b, j):
        L = np.linalg.norm(np.subtract(b.levels[j].fork, b.starts()[j]))
        return frame(b, j).T @ (np.subtract(r.levels[j].control, b.levels[j].control)) / L

    np.testing.assert_allclose(offset(new, fresh, k), offset(edited, route, k), atol=1e-12)
    untouched = [j for j in range(len(route.levels)) if j not in (2, k)]
    for j in untouched:  # the rest is the new bake (forks move only below edited ones)
        assert new.levels[j].radius == fresh.levels[j].radius
    assert new.levels[-1] == fresh.levels[-1]
    assert offset(new, fresh, 4).any() == 0 and np.abs(offset(edited, route, 4)).max() == 0


def test_growing_again_lists_what_it_cannot_keep(route):
    inserted = split_level(route, 3, 0.5)
    _, lost = rebake(inserted, route.growth)
    assert any("levels[4] (L4): a fork made by hand" in line for line in lost)
    _, lost = rebake(merge_level(route, 3), route.growth)
    assert any("depth 5 was removed by hand" in line for line in lost)
    moved = replace(route, levels=[replace(route.levels[0], radius=0.5), *route.levels[1:]])
    _, lost = rebake(moved, replace(route.growth, levels=5))
    assert any("levels[0] (L0): its edits are dropped" in line for line in lost)
    _, nothing = rebake(route, replace(route.growth, levels=5))  # unedited: nothing to lose
    assert nothing == []


# -------------------------------------------------------------------------- editor glue
class FakeEditor:
    """What editor/structure.py reads and calls of the editor, without a window."""

    def __init__(self, path):
        self.said: list[str] = []
        self.viewer = SimpleNamespace(
            doc=None,
            sync=lambda: None,
            error="",
            message="",
            interactions=Interactions(),
            say=self.said.append,
        )
        self.viewer.doc = Document(path)
        self.selected = SimpleNamespace(level=3)
        self.structure = StructureTools()
        self.chosen: list[int] = []

    @property
    def doc(self):
        return self.viewer.doc

    @property
    def scene(self):
        return self.doc.scene

    def select_level(self, level):
        self.chosen.append(level)

    def run(self, command):
        STRUCTURE_HANDLERS[type(command)](self, command)


@pytest.fixture
def editor(scene, tmp_path):
    path = tmp_path / "tree.toml"
    save_scene(replace(scene, tree=None, route=scene.tree.route()), path)
    return FakeEditor(path)


def test_each_operation_is_one_undo_step(editor):
    start = editor.scene
    for command in (
        ec.InsertLevel(),
        ec.RemoveLevel(2),
        ec.DuplicateLevel(),
        ec.WholeTree("taper"),
    ):
        before = editor.scene
        editor.run(command)
        assert editor.scene != before and editor.viewer.error == "", command
        editor.doc.undo()
        assert editor.scene == before
        editor.doc.redo()
    assert len(editor.doc.history.steps) == 4 and editor.chosen == [4, 2, 3]
    assert editor.said[0].startswith("insert a fork in L3"), "said at the window's foot too"
    while editor.doc.undo():
        pass
    assert editor.scene == start


def test_a_refused_operation_changes_nothing_and_says_why(scene, tmp_path):
    path = tmp_path / "full.toml"  # 63 forks: 64 levels, as many as the shaders hold
    save_scene(replace(scene, tree=None, route=replace(scene.tree, levels=63).route()), path)
    editor = FakeEditor(path)
    before = editor.scene
    editor.run(ec.InsertLevel(10))
    assert editor.scene == before and editor.doc.history.steps == []
    assert "refused" in editor.structure.message and "≤ 64" in editor.structure.message
    assert editor.viewer.error == editor.structure.message and "\n" not in editor.viewer.error
    editor.run(ec.RemoveLevel(10))  # negative control: the same editor does take an edit
    assert len(editor.scene.route.levels) == 63 and editor.viewer.error == ""
    editor.selected = None
    editor.run(ec.RemoveLevel())
    assert "select a level first" in editor.viewer.error


def test_growing_again_asks_before_losing_hand_edits(editor):
    editor.run(ec.InsertLevel(3))
    inserted = editor.scene
    editor.run(ec.SetGrowth("branch_angle", 40.0, ("drag", 1)))
    assert editor.scene == inserted, "nothing lands before the answer"
    at, new, lost, _ = editor.structure.pending
    assert at == ("route",)
    assert any("made by hand" in line for line in lost)
    editor.run(ec.CancelRegrow())
    assert editor.structure.pending is None and editor.scene == inserted
    editor.run(ec.SetGrowth("branch_angle", 40.0, ("drag", 1)))
    editor.run(ec.ConfirmRegrow())
    assert editor.scene.route == new and editor.scene.route.growth.branch_angle == 40.0
    editor.doc.undo()
    assert editor.scene == inserted
    editor.run(ec.SetGrowth("branch_angle", 200.0, None))
    assert "branch_angle" in editor.viewer.error and editor.scene == inserted
    # drawn in the panel, the field keeps the refused value and says why under it
    from krsview.editor.structure import growth_field

    field = growth_field("branch_angle")
    editor.viewer.interactions.refusal(field)
    editor.run(ec.SetGrowth("branch_angle", 200.0, None))
    refused = editor.viewer.interactions.refused[field]
    assert refused.value == 200.0 and "branch_angle" in refused.message
    assert editor.viewer.error == "" and editor.scene == inserted


# ---------------------------------------------------------------------- in a real window
WINDOW = (640, 400)


def xdo(*args) -> None:
    import shutil
    import subprocess

    assert shutil.which("xdotool"), "xdotool is needed for real X key events"
    subprocess.run(["xdotool", *map(str, args)], check=True, timeout=10)


def pump(e, turns: int = 4) -> None:
    import glfw

    for _ in range(turns):
        glfw.poll_events()
        e.step(0.02)


@pytest.fixture
def window_editor(display, scene, tmp_path):
    import glfw

    from krsview.editor.window import Editor

    path = tmp_path / "tree.toml"
    save_scene(replace(scene, tree=None, route=scene.tree.route()), path)
    e = Editor(path, size=WINDOW)
    x, y = glfw.get_window_pos(e.viewer.window)
    xdo("mousemove", x + 100, y + WINDOW[1] - 60)  # over the view, off the panels
    pump(e)
    yield e
    e.close()


def test_insert_delete_and_ctrl_d_keys_edit_the_selected_level(window_editor):
    e = window_editor
    n = len(e.scene.route.levels)
    xdo("key", "Insert")  # nothing selected: refused, nothing changes
    pump(e)
    assert len(e.scene.route.levels) == n and "select a level first" in e.viewer.error
    e.select_level(3)
    for key, change in (("Insert", 1), ("Delete", -1), ("ctrl+d", 1)):
        before = len(e.scene.route.levels)
        xdo("key", key)
        pump(e)
        assert len(e.scene.route.levels) == before + change, key
    assert len(e.doc.history.steps) == 3
    xdo("key", "ctrl+z")
    pump(e)
    assert len(e.scene.route.levels) == n


TALL = (800, 900)  # the structure section's buttons inside the window, a level selected


def test_the_level_buttons_are_greyed_with_no_level_selected(display, scene, tmp_path, monkeypatch):
    """With nothing selected the structure section's insert / remove / duplicate had nothing
    to act on, yet looked ready; a click said why far below them, cut off at the panel's
    foot [a real-window review]. They are greyed, and a click (real X events) does nothing;
    the control: with a level selected, the same click removes it."""
    import glfw
    from imgui_bundle import imgui

    from krsview.editor.window import Editor

    rects = {}
    button = imgui.button

    def recorded(label, *a):
        pressed = button(label, *a)
        rects[label] = (imgui.get_item_rect_min(), imgui.get_item_rect_max())
        return pressed

    monkeypatch.setattr(imgui, "button", recorded)
    path = tmp_path / "tree.toml"
    save_scene(replace(scene, tree=None, route=scene.tree.route()), path)
    e = Editor(path, size=TALL)
    pump(e, 2)

    def click_remove() -> None:
        lo, hi = rects["remove (Del)"]
        assert hi.y < TALL[1], "the button is out of the window"
        x, y = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", round(x + (lo.x + hi.x) / 2), round(y + (lo.y + hi.y) / 2))
        pump(e, 2)
        xdo("click", 1)
        pump(e, 3)

    try:
        n = len(e.scene.route.levels)
        click_remove()
        assert len(e.scene.route.levels) == n and e.viewer.error == "", e.viewer.error
        e.select_level(3)
        pump(e, 2)
        click_remove()
        assert len(e.scene.route.levels) == n - 1, "control: the click removed nothing"
    finally:
        e.close()


def test_the_grow_again_question_lists_the_edits_it_would_lose(window_editor):
    """After an insert, growing the tree again asks first, in a dialog listing the hand
    edits lost (drawing it closed the editor: it listed the new route instead). Cancel keeps
    the tree; the control: the question was up."""
    from imgui_bundle import imgui

    e = window_editor
    e.select_level(3)
    xdo("key", "Insert")
    pump(e)
    inserted = e.scene
    listed, said = [], []
    bullet, text_ = imgui.bullet_text, imgui.text
    imgui.bullet_text = lambda text: (listed.append(text), bullet(text))[1]
    imgui.text = lambda text: (said.append(text), text_(text))[1]
    try:
        e.execute([ec.Regrow()])
        pump(e, 3)
    finally:
        imgui.bullet_text, imgui.text = bullet, text_
    assert e.structure.pending is not None
    assert listed and all(line in e.structure.pending.lost for line in listed)
    assert "Grow again from the growth parameters?" in said  # what is applied, said first
    xdo("key", "Escape")  # cancels, as in the other dialogs (it took a click)
    pump(e, 2)
    assert e.scene == inserted and e.structure.pending is None


def test_undo_and_redo_bring_the_selection_back(window_editor):
    """Ctrl+Z after an insert selects what was selected before it (it used to keep the
    selection's level number, now another branch); Ctrl+Shift+Z what was selected when it
    was undone."""
    e = window_editor

    def chosen():
        return (e.selected.path, e.selected.kind) if e.selected else None

    e.select_level(3)
    before = chosen()
    xdo("key", "Insert")
    pump(e)
    inserted = chosen()
    assert inserted != before, "control: the insert selects its new level"
    e.select_level(1)
    looked = chosen()
    xdo("key", "ctrl+z")
    pump(e)
    assert chosen() == before
    xdo("key", "ctrl+shift+z")
    pump(e)
    assert chosen() == looked
    e.select(None)
    xdo("key", "ctrl+z")
    pump(e)
    assert chosen() == before


def test_the_panels_words_go_once_stale_and_a_level_is_selected_by_its_own_handle(
    window_editor,
):
    """The structure section's message and the panel's error line stay while the scene and
    the selection are those they were said of, and go with an undo, another selection or a
    save (they used to stay: 'select a level first' with a level selected, 'insert a fork'
    after its undo or a save). Selecting the trunk by its outline entry selects its fork (the
    panel shows the trunk's fields), not the trunk foot, which is the whole route's; so does
    Delete of the level below it. The trunk foot's growth parameters are text there, not
    fields that set them without growing the tree again. The control: each word is there
    until then."""
    e = window_editor
    n = len(e.scene.route.levels)
    xdo("key", "Insert")
    pump(e)
    assert "select a level first" in e.viewer.error and e.structure.refused
    pump(e, 3)
    assert "select a level first" in e.viewer.error, "control: gone by itself"
    e.select_level(n - 1)  # the trunk
    pump(e)
    assert e.viewer.error == "" and e.structure.message == ""
    assert e.selected.owner == ("route", "levels", n - 1), e.selected.label
    xdo("key", "Insert")
    pump(e, 3)
    assert e.structure.message.startswith("insert a fork in L")
    xdo("key", "ctrl+z")
    pump(e, 2)
    assert e.structure.message == "" and len(e.scene.route.levels) == n
    e.select_level(n - 2)
    xdo("key", "Delete")
    pump(e)
    assert len(e.scene.route.levels) == n - 1 and e.structure.message.startswith("remove")
    assert e.selected.owner == ("route", "levels", n - 2), e.selected.label
    pump(e, 2)
    assert e.structure.message.startswith("remove"), "control: gone by itself"
    xdo("key", "ctrl+s")  # saved: the last edit's word is history, the foot says "saved"
    pump(e, 2)
    assert not e.doc.dirty and e.structure.message == "" and "saved" in e.viewer.message
    # the trunk foot shows the route's fields, but not the growth parameters as fields: set
    # there, they would not grow the tree again (the structure section's growth node does)
    e.select(next(h for h in e.handles if h.path == ("route", "base")))
    e.viewer.interactions.rects.clear()
    pump(e, 2)
    assert ("route", "base") in e.viewer.interactions.rects
    assert not [k for k in e.viewer.interactions.rects if k[:2] == ("route", "growth")]


def test_saving_a_shipped_preset_asks_for_a_copy_and_never_writes_the_package(
    display, tmp_path, monkeypatch
):
    from krsview.document.document import copy_target
    from krsview.editor.window import Editor
    from krsview.scene.presets import PRESET_DIR

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    before = {p.name: p.stat().st_mtime_ns for p in PRESET_DIR.iterdir()}
    e = Editor(resolve("tree"), size=WINDOW)
    try:
        e.execute([ec.Bake()])
        assert e.file.save() is False and e.file.copy_to.text == str(tmp_path / "tree.toml")
        assert copy_target(e.path) == tmp_path / "tree.toml"
        pump(e)  # the dialog is drawn
        e.execute([ec.SetCopyText(str(tmp_path / "mine.toml")), ec.SaveCopy()])
        assert e.file.copy_to is None and e.path == tmp_path / "mine.toml" and not e.doc.dirty
        assert load_scene(tmp_path / "mine.toml").route is not None
        e.execute([ec.InsertLevel(2)])
        assert e.file.save() is True, "the copy is an ordinary file: Ctrl+S saves it"
    finally:
        e.close()
    assert {p.name: p.stat().st_mtime_ns for p in PRESET_DIR.iterdir()} == before


def test_an_autosave_that_cannot_write_is_said_in_the_status_line(window_editor):
    from krsview.document.document import AUTOSAVE_SECONDS

    e = window_editor
    e.execute([ec.WholeTree("widths")])
    e.doc.recovery_path.mkdir()  # no one may write there, root neither
    pump(e, 1)  # the interval starts
    time.sleep(AUTOSAVE_SECONDS + 0.1)
    pump(e, 1)
    assert "autosave cannot write" in e.viewer.status_line()
    assert e.viewer.error == e.doc.autosave_error


def test_a_viewer_bookmark_of_a_shipped_preset_goes_to_its_copy(display, tmp_path, monkeypatch):
    from krsview.scene.presets import PRESET_DIR
    from krsview.viewer.window import Viewer

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    before = {p.name: p.read_bytes() for p in PRESET_DIR.iterdir() if p.is_file()}
    v = Viewer(resolve("sierpinski"), size=WINDOW, hud=False)
    try:
        v.file.add_bookmark()
        assert v.path == tmp_path / "sierpinski.toml" and not v.doc.dirty, v.error
        assert (
            len(load_scene(v.path).bookmarks)
            == len(load_scene(resolve("sierpinski")).bookmarks) + 1
        )
        v.file.add_bookmark()  # the copy is an ordinary file now: the next one goes there too
        assert (
            len(load_scene(v.path).bookmarks)
            == len(load_scene(resolve("sierpinski")).bookmarks) + 2
        )
    finally:
        v.close()
    assert {p.name: p.read_bytes() for p in PRESET_DIR.iterdir() if p.is_file()} == before


def test_closing_a_shipped_preset_with_edits_saves_the_copy_then_closes(
    display, tmp_path, monkeypatch
):
    import glfw

    from krsview.editor.window import Editor

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    e = Editor(resolve("sierpinski"), size=WINDOW)
    try:
        e.edit(("render", "epsilon_scale"), 2.0)
        glfw.set_window_should_close(e.viewer.window, True)
        assert not e.should_close() and e.file.asking == ("close", None)
        pump(e)
        e.execute([ec.AnswerSave()])
        pump(e)
        assert e.file.asking is None and e.file.copy_to.then == ("close", None)
        assert not e.should_close(), "nothing saved yet: the window stays"
        e.execute([ec.SaveCopy()])
        assert e.should_close() and e.path == tmp_path / "sierpinski.toml"
        assert load_scene(e.path).render.epsilon_scale == 2.0
    finally:
        e.close()


# ------------------------------------------------------------------ a compound's components
@pytest.fixture
def compound_editor(scene, tmp_path):
    """A compound of the 8-fork tree grown (component 0), the same tree as a route, turned,
    scaled and moved (1), and the rock's explicit KRS (2); nothing selected."""
    from krsview.scene.compound import Component

    rock = load_scene(resolve("rock")).krs
    parts = [
        Component(tree=scene.tree),
        Component(route=scene.tree.route(), position=(3.0, 0.0, 1.0), angle=40.0, scale=0.7),
        Component(krs=rock, position=(-3.0, 0.0, 0.0)),
    ]
    path = tmp_path / "compound.toml"
    save_scene(replace(scene, tree=None, compound=parts), path)
    e = FakeEditor(path)
    e.selected = None
    return e


def placed(scene, k: int) -> KRS:
    return scene.compound[k].placed()


def picked(k: int) -> SimpleNamespace:
    """Component k picked as a whole (its entry in the outline), not a handle of its route."""
    return SimpleNamespace(level=k, path=("compound", k))


def test_structure_tools_act_on_the_selected_components_route(compound_editor):
    """Component 1 (a route): insert at the section's level adds a level to it alone (the
    compiled world-space KRS one level deeper, the others as they were), one undo step;
    remove by the Delete key's command takes it out again; scale widths scales its world
    radii alone. Negative controls: nothing selected, a grown component and an explicit KRS
    are refused, each with its reason, and nothing changes."""
    e = compound_editor
    start = e.scene
    for selected, why in (
        (None, "select a component first"),
        (0, "component 0 is grown from ratios: bake it"),
        (2, "component 2 is an explicit KRS"),
    ):
        e.selected = None if selected is None else picked(selected)
        e.run(ec.InsertLevel())
        assert why in e.viewer.error and e.structure.refused, (selected, e.viewer.error)
        assert e.scene is start and not e.doc.history.steps
    e.selected = picked(1)
    e.structure.level = 3
    e.run(ec.InsertLevel())
    assert not e.structure.refused, e.structure.message
    after = e.scene
    assert len(after.compound[1].route.levels) == len(start.compound[1].route.levels) + 1
    assert placed(after, 1).depth == placed(start, 1).depth + 1
    assert [placed(after, k) for k in (0, 2)] == [placed(start, k) for k in (0, 2)]
    assert e.structure.level == 4 and e.chosen == [], "the new fork, not component 4"
    assert e.doc.history.labels()[0] == ["insert a fork in L3 at 0.50 (component 1)"]
    e.run(ec.RemoveLevel())  # the key's command: the section's level (the new fork)
    forks = lambda s: [lv.fork for lv in s.compound[1].route.levels]  # noqa: E731
    assert forks(e.scene) == forks(start)
    e.structure.widths = 1.5
    e.run(ec.WholeTree("widths"))
    world = lambda s: [k.radius for k in placed(s, 1).kernels if hasattr(k, "radius")]  # noqa: E731
    np.testing.assert_allclose(world(e.scene), 1.5 * np.array(world(start)), rtol=1e-12)
    assert [placed(e.scene, k) for k in (0, 2)] == [placed(start, k) for k in (0, 2)]
    assert len(e.doc.history.steps) == 3


def test_a_grown_component_is_baked_in_place_then_its_route_grows_again(compound_editor):
    """Baking component 0 gives it a route that draws the same surface (reference distance
    of the world-space KRS at points around it, before and after); then growing again with
    a new branch angle acts on that component's route (its growth changed, the others not).
    Negative control: the route component's growth is untouched."""
    from krsview.editor.structure import baked

    e = compound_editor
    start = e.scene
    scene, label, _ = baked(start, 0)
    assert scene.compound[0].tree is None and scene.compound[0].route is not None
    assert scene.compound[1:] == start.compound[1:] and "component 0" in label
    rng = np.random.default_rng(1)
    pts = rng.uniform([-1.5, 0.0, -1.5], [1.5, 3.5, 1.5], (400, 3))
    np.testing.assert_allclose(
        distance(compile_krs(placed(scene, 0), ALBEDO), pts),
        distance(compile_krs(placed(start, 0), ALBEDO), pts),
        atol=1e-9,
    )
    e.doc.commit(scene, label)
    e.selected = SimpleNamespace(level=0)
    e.run(ec.SetGrowth("branch_angle", 40.0, None))
    assert not e.structure.refused and e.structure.pending is None, e.structure.message
    assert e.scene.compound[0].route.growth.branch_angle == 40.0
    assert e.scene.compound[1].route.growth == start.compound[1].route.growth
    assert placed(e.scene, 0) != placed(scene, 0)


def test_in_a_window_a_clicked_component_takes_the_insert_key_once_baked(display, compound_editor):
    """A compound in a real window: click component 0's handle, press Insert: refused (a
    grown tree), said in the section and nothing changes; baked (the section's button's
    command), Insert adds a fork to that component's route alone, one undo step; Ctrl+Z
    takes it back."""
    import glfw

    from krsview.compile.camera import project
    from krsview.editor.window import Editor

    e = Editor(compound_editor.doc.path, size=WINDOW)
    try:
        pump(e)
        h = next(h for h in e.handles if h.level == 0)
        x, y, _ = project(e.window_view(), h.position)
        wx, wy = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", round(wx + x), round(wy + y))
        pump(e, 2)
        xdo("click", 1)
        pump(e)
        assert e.selected is not None and e.selected.level == 0, e.selected
        start = e.scene
        xdo("key", "Insert")
        pump(e)
        assert "component 0 is grown from ratios" in e.structure.message
        assert e.structure.refused and e.scene is start
        e.execute([ec.Bake(0)])
        baked = e.scene
        n = len(baked.compound[0].route.levels)
        e.execute([ec.SetToolValue("level", 4)])
        xdo("key", "Insert")
        pump(e)
        assert len(e.scene.compound[0].route.levels) == n + 1, e.structure.message
        assert e.scene.compound[1:] == start.compound[1:]
        xdo("key", "ctrl+z")
        pump(e)
        assert e.scene == baked
    finally:
        e.close()


def outline_row(e, row: int) -> tuple[float, float]:
    """Screen point of the outline's entry ``row`` (0: the top one)."""
    import glfw
    from imgui_bundle import imgui

    child = next(
        w for w in imgui.get_current_context().windows if w.name.startswith("edit/outline")
    )
    wx, wy = glfw.get_window_pos(e.viewer.window)
    y = child.pos.y + 4 + imgui.get_text_line_height_with_spacing() * (row + 0.5)
    return wx + child.pos.x + 40, wy + y


def test_a_compounds_outline_entries_have_no_level_menu(display, scene, tmp_path, compound_editor):
    """A right-click on a compound's outline entry (a component, not a level) opens no
    insert/remove menu (its level would be a component's number); the entry still selects
    by a left click. Negative control: on a route, the same right-click opens the menu."""
    from imgui_bundle import imgui

    from krsview.editor.window import Editor

    def right_click(e, row: int) -> int:
        xdo("mousemove", *map(round, outline_row(e, row)))
        pump(e, 2)
        xdo("click", 1)
        pump(e, 2)
        xdo("click", 3)
        pump(e, 3)
        return imgui.get_current_context().open_popup_stack.size()

    route = tmp_path / "route.toml"
    save_scene(replace(scene, tree=None, route=scene.tree.route()), route)
    for path, menus, level in ((route, 1, len(scene.tree.route().levels) - 3), (None, 0, 0)):
        e = Editor(path or compound_editor.doc.path, size=WINDOW)
        try:
            pump(e)
            assert right_click(e, 2) == menus, path
            assert e.selected is not None and e.selected.level == level, "no selection"
        finally:
            e.close()


def test_the_growth_section_says_when_the_forks_differ_from_the_growth(route):
    """After forks inserted or removed by hand the growth section said levels 22 beside a
    route of 24 forks, with nothing to tell them apart [review]."""
    from krsview.editor.structure_panel import forks_note

    assert forks_note(route) == ""  # as baked: the forks are the growth's
    grown = route.growth.levels
    more = split_level(route, 5)
    assert forks_note(more) == f"the route has {grown + 1} forks now; grow again makes {grown}"
    assert forks_note(merge_level(more, 5)) == ""  # control: back to the grown count


def test_baking_a_tree_whose_tracks_move_its_growth_is_refused_and_says_which(display, tmp_path):
    """tree-growing's tracks move tree.levels, tree.trunk_length …: a route has none of them,
    and baking it closed the editor with a traceback [a real-window review]. It is refused,
    the tracks named, the scene as it was; the control: tree-sway (a sway, no growth track)
    bakes."""
    import shutil

    from krsview.editor.window import Editor

    for name, refused in (("tree-growing", True), ("tree-sway", False)):
        path = tmp_path / f"{name}.toml"
        shutil.copy(resolve(name), path)
        e = Editor(path, size=WINDOW)
        try:
            before = e.scene
            e.execute([ec.Bake()])
            pump(e, 2)
            if refused:
                assert e.scene == before and not e.doc.dirty
                assert e.viewer.error.startswith("bake: animation.tracks = ")
                assert "tree.levels" in e.viewer.error and "tree.trunk_length" in e.viewer.error
                assert "camera.position" not in e.viewer.error, "a camera track is kept"
            else:
                assert e.scene.route is not None and e.viewer.error == ""
        finally:
            e.close()


def test_in_a_compound_the_selection_follows_the_inserted_fork(display, compound_editor):
    """A fork of component 1's route selected, Insert: the selection moves to the new fork
    with the section's level, so Delete removes the fork selected. It stayed at the old
    index while the section's level moved on, and Delete removed another fork [a
    real-window review]. The control: the fork first selected."""
    from krsview.editor.window import Editor

    e = Editor(compound_editor.doc.path, size=WINDOW)
    try:
        pump(e)
        fork = ("compound", 1, "route", "levels", 3, "fork")
        e.select(next(h for h in e.handles if h.path == fork))
        assert e.structure.level == 3
        start = e.scene
        e.execute([ec.InsertLevel()])
        pump(e)
        assert e.structure.level == 4 and e.selected.path[:6] == (*fork[:4], 4, "fork")
        e.execute([ec.RemoveLevel()])
        pump(e)
        forks = [[lv.fork for lv in s.compound[1].route.levels] for s in (e.scene, start)]
        assert forks[0] == forks[1], "Delete removed another fork than the inserted one"
    finally:
        e.close()


def keyed(scene, tracks: dict[str, list]):
    """``scene`` with ``tracks`` (path → keys [[t, value], …]) and its moment at 1 s."""
    from krsview import load_dict
    from krsview.scene.schema import to_dict

    tracks = [{"path": p, "keys": k} for p, k in tracks.items()]
    return load_dict(to_dict(scene) | {"animation": {"time": 1.0, "tracks": tracks}})


def test_the_tracks_follow_their_levels_through_insert_remove_and_duplicate(scene, tmp_path):
    """A key keeps moving the level it was set on: insert and duplicate move the coarser
    levels' tracks one up, remove drops the removed fork's track and says so, duplicate
    copies the level's track to the copy and moves the keyed positions of the levels it
    carries along the branch with them. Before, the tracks stayed at their indices and
    drove other forks (tree-sway baked: Delete on a keyed fork). Controls: a track on the
    camera, and on a finer level an insert does not move, stay as they were."""
    route = scene.tree.route()
    fork3, control1 = route.levels[3].fork, route.levels[1].control
    normal5 = route.levels[5].normal
    tracks = {
        "route.levels[3].fork": [[0, list(fork3)], [2, [fork3[0] + 0.2, *fork3[1:]]]],
        "route.levels[1].control": [
            [0, list(control1)],
            [2, [control1[0], control1[1] + 0.1, control1[2]]],
        ],
        "route.levels[5].normal": [[0, list(normal5)], [2, [0.3, 0.9, 0.3]]],
        "camera.position": [[0, list(scene.camera.position)], [2, [0.0, 3.0, 12.0]]],
    }
    path = tmp_path / "keyed.toml"
    save_scene(keyed(replace(scene, tree=None, route=route), tracks), path)

    def posed(e, i, name):
        return np.array(getattr(e.scene.posed().route.levels[i], name))

    editor = FakeEditor(path)
    normal_before = posed(editor, 5, "normal")
    editor.run(ec.InsertLevel(3))
    paths = [t.path for t in editor.scene.animation.tracks]
    assert paths == [
        "route.levels[3].fork",
        "route.levels[1].control",
        "route.levels[6].normal",
        "camera.position",
    ]
    assert np.allclose(posed(editor, 6, "normal"), normal_before)  # the same branch turns
    assert "went with it" not in editor.said[-1]
    editor.doc.undo()

    editor.run(ec.RemoveLevel(3))
    paths = [t.path for t in editor.scene.animation.tracks]
    assert paths == ["route.levels[1].control", "route.levels[4].normal", "camera.position"]
    assert np.allclose(posed(editor, 4, "normal"), normal_before)
    assert "its 1 track went with it (route.levels[3].fork)" in editor.said[-1]
    editor.doc.undo()

    editor.run(ec.DuplicateLevel(3))
    v = np.subtract(route.levels[3].fork, route.starts()[3])
    got = {t.path: np.array([k.value for k in t.keys]) for t in editor.scene.animation.tracks}
    assert sorted(got) == sorted(
        [
            "route.levels[4].fork",
            "route.levels[3].fork",
            "route.levels[1].control",
            "route.levels[6].normal",
            "camera.position",
        ]
    )
    keys = {p: np.array([v for _, v in k]) for p, k in tracks.items()}
    assert np.allclose(got["route.levels[4].fork"], keys["route.levels[3].fork"])  # the original
    assert np.allclose(got["route.levels[3].fork"], keys["route.levels[3].fork"] + v)  # its copy
    assert np.allclose(got["route.levels[1].control"], keys["route.levels[1].control"] + v)
    assert np.allclose(got["route.levels[6].normal"], keys["route.levels[5].normal"])
    assert np.allclose(got["camera.position"], keys["camera.position"])
    assert len(editor.doc.history.steps) == 1  # one undo step each
