"""The editor in a real window under Xvfb, driven by real X pointer and key events (xdotool):
select by clicking, drag the gizmo and a normal's arrow tip, undo/redo/save by keyboard, and
compare the saved file's headless render with the window. Also: killed mid-edit, the
recovery is offered; closing or a disk change with unsaved edits asks first; the rock's twelve
normals picked and turned by small drags; a refused value kept in its field with its message;
the gizmo's axes, snapping and float64 values; the clipped part in red; nothing cut off at
640×360 and 1280×720, the scene framed beside the panel."""

from __future__ import annotations

import math
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np
import pytest

from krsview.editor.commands import Bake
from krsview.scene import load_scene
from krsview.scene.presets import resolve
from krsview.viewer.commands import Edit, SetPrepass

from .conftest import headless_render

SIZE = (800, 500)
LEVEL = 19  # a fork near the top of the shipped tree, clear of the panels
ROCK_SIZE = (640, 400)  # small: the rock's test draws some 200 frames


def editor_on_a_copy(tmp_path, preset: str, size: tuple[int, int]):
    """An editor on a copy of a shipped preset in ``tmp_path``, closed afterwards."""
    from krsview.editor.window import Editor

    path = tmp_path / f"{preset}.toml"
    shutil.copy(resolve(preset), path)
    e = Editor(path, size=size)
    yield e
    e.close()


@pytest.fixture
def editor(display, tmp_path):
    yield from editor_on_a_copy(tmp_path, "tree", SIZE)


def pump(e, turns: int = 3) -> None:
    """Event-loop turns as `run` makes them: deliver the X events, then step."""
    import glfw

    for _ in range(turns):
        glfw.poll_events()
        e.step(0.02)


def settle(e, limit: int = 400) -> None:
    for _ in range(limit):
        pump(e, 1)
        if e.viewer.frames.refined:
            return
    raise AssertionError("the view never refined")


def xdo(*args) -> None:
    assert shutil.which("xdotool"), "xdotool is needed for real X events (`make deps` installs it)"
    subprocess.run(["xdotool", *map(str, args)], check=True, timeout=10)


def screen_of(e, world) -> tuple[float, float]:
    import glfw

    from krsview.compile.camera import project

    x, y, z = project(e.window_view(), np.asarray(world))
    assert z > 0
    wx, wy = glfw.get_window_pos(e.viewer.window)
    return wx + x, wy + y


def drag(e, start, offset, steps: int = 8) -> None:
    x, y = start
    xdo("mousemove", round(x), round(y))
    pump(e, 2)
    xdo("mousedown", 1)
    pump(e, 2)
    for k in range(1, steps + 1):
        xdo("mousemove", round(x + offset[0] * k / steps), round(y + offset[1] * k / steps))
        pump(e, 1)
    xdo("mouseup", 1)
    pump(e, 2)


def click(e, at) -> None:
    xdo("mousemove", round(at[0]), round(at[1]))
    pump(e, 2)
    xdo("click", 1)
    pump(e, 3)


def assert_moved_right(e, old, new, pixels: float) -> None:
    """``new`` is ``old`` moved ``pixels`` to the right in the plane through it that faces
    the camera (as a drag of the gizmo's centre moves it), within 10 %."""
    v = e.window_view()
    depth = float((np.asarray(old) - v.origin) @ v.forward)
    expected = pixels * 2 * v.tan_half * depth / v.height * v.right
    moved = np.asarray(new) - np.asarray(old)
    assert np.linalg.norm(moved - expected) < 0.1 * np.linalg.norm(expected), (moved, expected)


def handle(e, path):
    return next(h for h in e.handles if h.path == path)


def test_drag_a_fork_and_turn_a_normal_undo_redo_save_and_render_headless(editor, tmp_path):
    e = editor
    settle(e)
    e.execute([Bake()])
    settle(e)
    compiles = e.viewer.renderer.programs.compiles
    fork_path = ("route", "levels", LEVEL, "fork")
    # select by clicking the handle, then drag the gizmo's centre 40 px to the right
    h = handle(e, fork_path)
    click(e, screen_of(e, h.position))
    assert e.selected is not None and e.selected.path == fork_path
    old = np.array(h.position)
    drag(e, screen_of(e, old), (40, 0))
    new = np.array(e.scene.route.levels[LEVEL].fork)
    assert_moved_right(e, old, new, 40)
    assert len(e.doc.history.steps) == 2, "the drag was not one undo step (bake + drag)"
    # the mirror normal of that fork, by its arrow tip: 30 px up
    normal_path = ("route", "levels", LEVEL, "normal")
    tip = handle(e, normal_path)
    click(e, screen_of(e, tip.position))
    assert e.selected.path == normal_path
    n0 = np.array(e.scene.route.levels[LEVEL].normal)
    drag(e, screen_of(e, tip.position), (0, -30))
    n1 = np.array(e.scene.route.levels[LEVEL].normal)
    turned = math.degrees(math.acos(np.clip(n0 @ n1, -1, 1)))
    assert turned > 5.0 and math.isclose(np.linalg.norm(n1), 1.0, rel_tol=1e-12), turned
    assert e.viewer.renderer.programs.compiles == compiles, "a drag recompiled the shader"
    # keyboard undo / redo in the window
    xdo("key", "ctrl+z")
    pump(e)
    assert np.allclose(e.scene.route.levels[LEVEL].normal, n0)
    xdo("key", "ctrl+shift+z")
    pump(e)
    assert np.allclose(e.scene.route.levels[LEVEL].normal, n1)
    assert e._title.startswith("krsview edit — *")
    xdo("key", "ctrl+s")
    pump(e)
    saved = load_scene(e.path)
    assert saved == e.scene and not e.doc.dirty and "*" not in e._title
    assert saved.route.levels[LEVEL].fork == tuple(new)
    # picking the tree itself: a trunk pixel away from the handles selects the trunk level
    click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected is not None and e.selected.level == len(saved.route.levels) - 1
    # the window (HUD and overlays hidden, the status line's "saved …" gone) against a
    # headless render of the saved file
    e.viewer.hud = False
    e.viewer.clock += 60
    e.viewer.frames.dirty = True
    settle(e)
    shot = e.viewer.read_window()
    same_prepass = ("--prepass", str(e.viewer.prepass))  # the window's pre-pass tile
    seen = e.viewer.camera.to_camera()  # framed in the part the panel leaves
    ref = headless_render(
        replace(load_scene(e.path), camera=seen), tmp_path / "saved", SIZE, *same_prepass
    )
    close = np.abs(shot.astype(int) - ref.astype(int)).max(-1) <= 2
    assert close.mean() >= 0.99, f"window and headless render agree on {close.mean():.2%}"
    # negative control: the unedited tree differs where the fork moved
    before = headless_render(
        replace(load_scene(resolve("tree")), camera=seen), tmp_path / "before", SIZE, *same_prepass
    )
    same = np.abs(shot.astype(int) - before.astype(int)).max(-1) <= 2
    assert same.mean() < 0.97, f"the edit changed only {1 - same.mean():.2%} of the pixels"
    from PIL import Image

    Image.fromarray(shot).save(tmp_path / "edited-window.png")


def test_a_press_on_a_fork_drags_it_without_selecting_it_first(editor):
    """Press on a fork nobody selected and drag: it is selected at the press and follows the
    pointer in the plane facing the camera, as the gizmo's centre moves it, in one undo step,
    and the camera stays; a press that slips a click's 4 px only selects it, and on the
    selected handle (the gizmo's centre) moves nothing; a flick let go before a turn saw its
    press lands too.
    Negative control: the same drag pressed 30 px beside the fork, off every handle, moves
    nothing and selects nothing."""
    from krsview.editor.picking import under

    e = editor
    settle(e)
    e.execute([Bake()])
    e.select(None)
    settle(e)
    path = ("route", "levels", LEVEL, "fork")
    old = np.array(handle(e, path).position)
    camera, steps = e.viewer.camera.to_camera(), len(e.doc.history.steps)
    beside = screen_of(e, old)
    beside = (beside[0], beside[1] - 30)
    import glfw

    wx, wy = glfw.get_window_pos(e.viewer.window)
    assert under(e.shown(), e.window_view(), beside[0] - wx, beside[1] - wy) is None
    drag(e, beside, (40, 0))
    assert e.selected is None and np.array_equal(e.scene.route.levels[LEVEL].fork, old)
    assert len(e.doc.history.steps) == steps
    drag(e, screen_of(e, old), (40, 0))
    assert e.selected is not None and e.selected.path == path
    new = np.array(e.scene.route.levels[LEVEL].fork)
    assert_moved_right(e, old, new, 40)
    assert len(e.doc.history.steps) == steps + 1, e.doc.history.labels()
    assert e.doc.history.labels()[0][-1] == f"drag {e.selected.label}"  # the undo tooltip
    assert e.viewer.camera.to_camera() == camera
    e.viewer.undo()
    assert np.array_equal(e.scene.route.levels[LEVEL].fork, old)
    # a click that slips 3 px selects the fork without nudging it (a click's CLICK_PIXELS)
    e.select(None)
    pump(e, 2)
    drag(e, screen_of(e, old), (3, 0), steps=3)
    assert e.selected is not None and e.selected.path == path
    assert np.array_equal(e.scene.route.levels[LEVEL].fork, old)
    assert e.doc.history.index == steps and e.doc.history.can_redo  # no step pushed
    # and now selected, a slip of a click's whole 4 px on its point (the gizmo) neither
    pump(e, 2)
    drag(e, screen_of(e, old), (4, 0), steps=4)
    assert np.array_equal(e.scene.route.levels[LEVEL].fork, old)
    assert e.doc.history.index == steps and e.doc.history.can_redo
    # a flick: pressed, dragged and let go before a turn saw the press still lands
    e.select(None)
    pump(e, 2)
    x, y = screen_of(e, old)
    xdo("mousemove", round(x), round(y))
    pump(e, 2)
    xdo("mousedown", 1)
    xdo("mousemove", round(x + 20), round(y))
    xdo("mousemove", round(x + 40), round(y))
    xdo("mouseup", 1)
    pump(e, 3)
    assert e.selected is not None and e.selected.path == path
    assert_moved_right(e, old, e.scene.route.levels[LEVEL].fork, 40)
    assert e.doc.history.index == steps + 1 and not e.doc.history.can_redo


def test_a_press_on_a_normals_tip_turns_it_without_selecting_it_first(editor):
    """With its fork selected (so its arrow is shown), press on the tip of the mirror normal
    and drag 30 px up: the normal is selected at the press and turned by its trackball, in
    one undo step named after it; a press that slips a click's 4 px only selects it. Before,
    a press there did nothing. Negative control: the same drag pressed 30 px beside the tip,
    off every handle, turns nothing and leaves the fork selected."""
    import glfw

    from krsview.editor.picking import under

    e = editor
    settle(e)
    e.execute([Bake()])
    fork = handle(e, ("route", "levels", LEVEL, "fork"))
    e.select(fork)
    settle(e)
    path = ("route", "levels", LEVEL, "normal")
    n0 = np.array(e.scene.route.levels[LEVEL].normal)
    tip = screen_of(e, handle(e, path).position)
    beside = (tip[0] + 30, tip[1])
    wx, wy = glfw.get_window_pos(e.viewer.window)
    assert under(e.shown(), e.window_view(), beside[0] - wx, beside[1] - wy) is None
    index = e.doc.history.index
    drag(e, beside, (0, -30))
    assert e.selected.same(fork) and e.doc.history.index == index
    drag(e, tip, (3, 0), steps=3)  # a click that slips: selects it, turns nothing
    assert e.selected is not None and e.selected.path == path
    assert np.array_equal(e.scene.route.levels[LEVEL].normal, n0)
    assert e.doc.history.index == index
    e.select(fork)
    pump(e, 2)
    drag(e, tip, (0, -30))
    assert e.selected is not None and e.selected.path == path
    n1 = np.array(e.scene.route.levels[LEVEL].normal)
    turned = math.degrees(math.acos(np.clip(n0 @ n1, -1, 1)))
    assert turned > 5.0 and math.isclose(np.linalg.norm(n1), 1.0, rel_tol=1e-12), turned
    assert e.doc.history.index == index + 1
    assert e.doc.history.labels()[0][-1] == f"drag {e.selected.label}"


def test_a_hover_label_reaching_under_the_panel_is_hidden_there(editor, monkeypatch):
    """A fork's hover label is drawn with the view, under ImGui's windows: with the camera
    flown so that the panel's edge crosses the label, the label's part under the panel
    (which lets some of the view through) changes the panel's pixels by under 0.3 of what
    its part in the view changes there, measured against the same frame drawn without any
    label (16 against 66 levels on average; written over the panel, as it was, 121). A
    handle grabbed beside the panel wrote its name over the panel's text."""
    from imgui_bundle import imgui

    import krsview.editor.drawing as drawing
    from krsview.compile.camera import project

    e = editor
    settle(e)
    e.execute([Bake()])
    e.select(None)

    h = handle(e, ("route", "levels", LEVEL, "fork"))
    size = imgui.calc_text_size(h.label)
    edge = imgui.internal.find_window_by_name("edit").pos.x
    cam = e.viewer.camera

    def at() -> tuple[float, float]:
        px, py, _ = project(e.window_view(), np.asarray(h.position))
        return px, py

    for _ in range(4):  # the camera flown sideways: the panel's edge across the label
        px, _ = at()
        cam.fly(np.array([1.0, 0.0, 0.0]), 0.01)
        slope = (at()[0] - px) / 0.01
        cam.fly(np.array([1.0, 0.0, 0.0]), (edge - size.x / 2 - 10 - at()[0]) / slope)
    e.viewer.frames.dirty = True
    settle(e)
    px, py = at()
    edge = round(edge)
    x0, x1 = round(px + 10), round(px + 10 + size.x)
    assert x0 + 8 < edge < x1 - 8, (x0, edge, x1)
    xdo("mousemove", *map(round, window_xy(e, px, py)))
    pump(e, 3)
    rows = slice(round(py - 20), round(py - 20 + size.y))
    labelled = e.viewer.read_window()[rows].astype(int)
    with monkeypatch.context() as m:
        m.setattr(drawing, "hover_label", lambda shown, view: None)
        pump(e, 1)
        bare = e.viewer.read_window()[rows].astype(int)
    change = np.abs(labelled - bare).max(axis=(0, 2))
    in_view, under_panel = change[x0 : edge - 2].mean(), change[edge + 2 : x1].mean()
    assert in_view > 40, "control: no label in the view"
    assert under_panel < 0.3 * in_view, (under_panel, in_view)


def test_overlay_is_composited_by_traced_depth(editor):
    """Overlay fragments behind the traced surface are hidden (drawn at HIDDEN_ALPHA, here
    set to 0 to see them vanish, then to 1 as the negative control)."""
    import glfw

    e = editor
    e.execute([Bake()])
    e.select_level(LEVEL)
    settle(e)
    draw, e.overlay.draw = e.overlay.draw, lambda *a, **k: None  # the image without it
    pump(e, 2)
    plain = e.viewer.read_window().astype(int)
    e.overlay.draw = draw

    def overlay_change(hidden_alpha: float, world) -> float:
        e.overlay.prog["u_hidden_alpha"].value = hidden_alpha
        pump(e, 2)
        shot = e.viewer.read_window().astype(int)
        wx, wy = glfw.get_window_pos(e.viewer.window)
        x, y = screen_of(e, world)
        px, py = round(x - wx), round(y - wy)
        return float(
            np.abs(
                shot[py - 1 : py + 2, px - 1 : px + 2] - plain[py - 1 : py + 2, px - 1 : px + 2]
            ).max()
        )

    inside = e.scene.route.levels[-1].control  # on the trunk's axis: behind its surface
    tip = handle(e, ("route", "levels", LEVEL, "normal")).position  # in the open
    assert overlay_change(0.0, tip) > 80, "a visible handle is not drawn"
    assert overlay_change(0.0, inside) == 0, "a handle behind the trunk shows through"
    assert overlay_change(1.0, inside) > 80, "negative control: unhidden, it must show"


RECOVERY_SCRIPT = """
import os, signal, sys, time
from pathlib import Path
from krsview.editor.window import Editor
e = Editor(Path(sys.argv[1]), size=(320, 200))
e.bake()
e.edit(("route", "levels", 5, "radius"), 0.123, ("gizmo", 1))
end = time.monotonic() + 30                 # autosave writes within AUTOSAVE_SECONDS
while not e.doc.recovery_path.exists() and time.monotonic() < end:
    e.step(0.05)
    time.sleep(0.05)
os.kill(os.getpid(), signal.SIGKILL)
"""


def test_killed_mid_edit_the_reopened_editor_offers_the_recovery(display, tmp_path):
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    r = subprocess.run(
        [sys.executable, "-c", RECOVERY_SCRIPT, str(path)],
        timeout=180,
        capture_output=True,
        text=True,
    )
    assert r.returncode == -signal.SIGKILL, r.stderr
    assert load_scene(path).tree is not None, "the killed editor saved the scene"
    assert path.with_name(path.name + ".recovery").exists(), "no autosave before the kill"
    from krsview.editor.window import Editor

    e = Editor(path, size=(320, 200))
    try:
        assert e.file.recovered is not None
        pump(e)  # the modal is drawn (panels run)
        e.file.restore()
        assert e.scene.route.levels[5].radius == 0.123 and e.doc.dirty
        assert e.file.recovered is None
    finally:
        e.close()


def test_closing_with_unsaved_edits_asks_and_cancel_keeps_the_window(editor):
    import glfw

    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    assert not e.should_close()  # negative control: nothing asked to close yet
    e.execute([e.viewer.input.keymap["ctrl+Q"]])  # Ctrl+Q, as the close button
    assert not e.should_close() and e.file.asking == ("close", None)
    pump(e)
    e.file.answer_cancel()
    assert not e.should_close() and e.doc.dirty
    glfw.set_window_should_close(e.viewer.window, True)
    e.should_close()
    e.file.answer_discard()
    assert e.should_close()
    assert load_scene(e.path).render.epsilon_scale == 1.0, "discard wrote the file"


def test_the_unsaved_edits_question_is_answered_by_clicking_its_button(editor):
    """The question drawn in the real window; its first answer, "save", clicked with the
    mouse, saves the edits and closes (editor/modals.py's answers)."""
    import glfw
    from imgui_bundle import imgui

    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    glfw.set_window_should_close(e.viewer.window, True)
    assert not e.should_close() and e.file.asking == ("close", None)
    pump(e)
    w = imgui.internal.find_window_by_name("unsaved changes")
    pad, frame = imgui.get_style().window_padding, imgui.get_style().frame_padding
    x = w.pos.x + pad.x + 4
    y = w.pos.y + w.size.y - pad.y - frame.y - imgui.get_font_size() / 2
    pump(e)  # negative control: drawn again, not clicked, nothing answered
    assert not e.should_close() and load_scene(e.path).render.epsilon_scale == 1.0
    click(e, window_xy(e, x, y))
    assert e.file.asking is None and e.should_close()
    assert load_scene(e.path).render.epsilon_scale == 2.0 and not e.doc.dirty


def test_a_disk_change_with_unsaved_edits_is_a_conflict_never_overwritten(editor):
    from krsview.scene import save_scene

    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    other = replace(load_scene(e.path), name="changed elsewhere")
    time.sleep(0.05)
    save_scene(other, e.path)
    os.utime(e.path, ns=(e.doc.stamp.mtime_ns + 10**9,) * 2)
    time.sleep(0.6)
    pump(e)
    assert e.file.conflict and e.scene.render.epsilon_scale == 2.0
    assert not e.file.save() and "changed on disk" in e.viewer.error
    assert load_scene(e.path).name == "changed elsewhere"
    e.file.take_file()
    assert e.scene.name == "changed elsewhere" and not e.doc.dirty
    e.viewer.undo()
    assert e.scene.render.epsilon_scale == 2.0, "the edits were lost on reload"


def test_a_bad_panel_value_keeps_the_last_valid_scene(editor):
    e = editor
    e.execute([Bake()])
    before = e.scene
    e.execute([Edit(("route", "levels", 3, "normal"), (0.0, 0.0, 0.0))])
    assert e.scene == before and "route.levels[3].normal" in e.viewer.error
    e.execute([Edit(("route", "levels", 3, "radius"), float("nan"))])
    assert e.scene == before and "NaN" in e.viewer.error
    pump(e)  # the error shows; nothing breaks


def test_save_as_a_bad_name_is_a_clear_error(editor, tmp_path):
    e = editor
    e.file.save_as(str(tmp_path / "x.png"))
    assert "ends in .toml" in e.viewer.error or "ending in .toml" in e.viewer.error
    e.file.save_as(str(tmp_path / "copy.toml"))
    assert e.path == tmp_path / "copy.toml" and load_scene(tmp_path / "copy.toml") == e.scene


def test_opening_another_scene_with_unsaved_edits_asks_first(editor):
    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    e.doc.autosave(0.0)
    e.doc.autosave(10.0)
    recovery = e.doc.recovery_path
    assert recovery.exists()
    e.file.open_preset(resolve("sierpinski"))
    assert e.file.asking == ("open", resolve("sierpinski")) and e.scene.name == "tree"
    pump(e)  # the question is drawn as a modal
    e.file.answer_discard()
    assert e.scene.name == "sierpinski" and e.file.asking is None and not e.doc.dirty
    assert not recovery.exists(), "discarded edits left a recovery file to be offered later"


@pytest.mark.parametrize("preset, entries", [("rock", 13), ("grove", 8), ("palm", 60)])
def test_the_editor_opens_every_kind_of_scene(display, tmp_path, preset, entries):
    """A KRS shows its levels, a compound its components, a MöKRS its levels; the panels
    draw without an error."""
    from krsview.editor.handles import outline
    from krsview.editor.window import Editor

    path = tmp_path / f"{preset}.toml"
    shutil.copy(resolve(preset), path)
    e = Editor(path, size=(400, 300))
    try:
        pump(e, 3)
        assert len(outline(e.scene)) == entries and not e.viewer.error
        if entries:
            e.select_level(entries - 1)
            pump(e, 2)
            assert e.selected is not None and not e.viewer.error
    finally:
        e.close()


def test_a_panel_drag_is_one_undo_step_and_a_second_drag_another(editor):
    """Drag the selected branch's radius field in the panel with the real pointer."""
    e = editor
    e.execute([Bake()])
    e.select_level(LEVEL)
    pump(e, 3)
    path = ("route", "levels", LEVEL, "radius")
    x0, y0, x1, y1 = e.viewer.interactions.rects[path]
    r0, steps0 = e.scene.route.levels[LEVEL].radius, len(e.doc.history.steps)
    import glfw

    wx, wy = glfw.get_window_pos(e.viewer.window)
    drag(e, (wx + (x0 + x1) / 2, wy + (y0 + y1) / 2), (40, 0))
    r1 = e.scene.route.levels[LEVEL].radius
    assert r1 > r0 and len(e.doc.history.steps) == steps0 + 1, (r0, r1, e.doc.history.labels())
    drag(e, (wx + (x0 + x1) / 2, wy + (y0 + y1) / 2), (-20, 0))
    assert e.scene.route.levels[LEVEL].radius < r1 and len(e.doc.history.steps) == steps0 + 2
    e.viewer.undo()
    assert e.scene.route.levels[LEVEL].radius == r1
    e.viewer.undo()
    assert e.scene.route.levels[LEVEL].radius == r0


def test_picking_the_geometry_with_fewer_levels_drawn_selects_the_right_level(editor):
    """The levels slider keeps the coarsest levels: a picked kernel slot is offset by the
    finest levels cut away (the trunk stays the trunk)."""
    e = editor
    e.execute([Bake()])
    settle(e)
    depth = e.viewer.drawn.geometry.depth
    click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected.level == depth - 1
    e.viewer.drawn.set_levels(6)
    settle(e)
    e.select(None)
    click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected is not None and e.selected.level == depth - 1


def test_the_hud_prepass_knob_is_an_edit_saved_with_the_scene_and_undone_by_ctrl_z(editor):
    """The HUD's pre-pass knob goes through the document in the editor too: the title says
    unsaved, Ctrl+Z (a real key) takes it back, and Ctrl+S writes it to the file."""
    e = editor
    pump(e)
    assert load_scene(e.path).render.prepass is None
    e.execute([SetPrepass(8)])
    pump(e)
    assert e.scene.render.prepass == 8 == e.viewer.prepass and e._title.startswith(
        "krsview edit — *"
    )
    xdo("key", "ctrl+z")
    pump(e)
    assert e.scene.render.prepass is None and not e.doc.dirty and "*" not in e._title
    xdo("key", "ctrl+shift+z")
    xdo("key", "ctrl+s")
    pump(e)
    assert load_scene(e.path).render.prepass == 8 and not e.doc.dirty


def scroll_to(e, path, margin: float, dx: float) -> tuple:
    """Scroll the panel (wheel over it, at ``dx`` into the field) until the field of ``path``
    is ``margin`` pixels above the window's foot; its rectangle."""
    import glfw

    height = glfw.get_window_size(e.viewer.window)[1]
    for _ in range(10):
        x0, y0, x1, y1 = e.viewer.interactions.rects[path]
        if y1 < height - margin:
            break
        xdo("mousemove", *map(round, window_xy(e, x0 + dx, height - 30)))  # not the outline
        xdo("click", 5)
        pump(e, 2)
    return e.viewer.interactions.rects[path]


def open_from_start(monkeypatch, section: str) -> None:
    """Make the panel's folding ``section`` open from the start (a test's first frame)."""
    from imgui_bundle import imgui

    header = imgui.collapsing_header
    monkeypatch.setattr(
        imgui,
        "collapsing_header",
        lambda label, *a: (
            header(label, imgui.TreeNodeFlags_.default_open)
            if label == section
            else header(label, *a)
        ),
    )


def type_at(e, at, *text: str) -> None:
    """Ctrl+click the field at window point ``at``, type ``text`` (xdotool's arguments: "--"
    lets a value start with a minus) and press Return."""
    xdo("mousemove", *map(round, at))
    pump(e, 2)
    xdo("keydown", "ctrl")
    xdo("click", 1)
    xdo("keyup", "ctrl")
    pump(e, 2)
    xdo("type", *text)
    pump(e, sum(map(len, text)) + 2)  # ImGui takes the typed characters one per frame
    xdo("key", "Return")
    pump(e, 3)


def window_xy(e, x, y) -> tuple[float, float]:
    """Screen point of window point (x, y)."""
    import glfw

    wx, wy = glfw.get_window_pos(e.viewer.window)
    return wx + x, wy + y


def angle(a, b) -> float:
    return math.degrees(math.acos(np.clip(np.dot(a, b), -1.0, 1.0)))


@pytest.fixture
def rock_editor(display, tmp_path):
    yield from editor_on_a_copy(tmp_path, "rock", ROCK_SIZE)


def test_the_rocks_twelve_normals_are_each_picked_and_turned_by_small_drags(rock_editor):
    """Each of the rock's twelve mirror arrows is selected by a click at its projected tip,
    then turned by a 3-pixel drag up (real pointer events; the first arrow by three in a
    row): each a small turn of about 1.5° (k × 3 px at most), raising the normal on screen,
    and one undo step. Negative controls: no label away from the tips; the same drag started
    30 px beside a tip turns nothing (and tests/test_handles.py: the tip-translate it
    replaces jumps)."""
    from krsview.editor.trackball import RADIANS_PER_PIXEL

    e = rock_editor
    pump(e, 3)
    tips = [h for h in e.shown() if h.kind == "normal"]
    assert len(tips) == 12

    def label_pixels(h) -> int:
        """White text where the hover label of ``h`` goes (right of and above its tip)."""
        from krsview.compile.camera import project

        pump(e, 2)
        shot = e.viewer.read_window().astype(int)
        x, y, _ = project(e.window_view(), h.position)
        box = shot[round(y) - 20 : round(y) - 4, round(x) + 10 : round(x) + 90]
        return int((box.min(-1) > 245).sum())

    xdo("mousemove", *map(round, window_xy(e, 5, ROCK_SIZE[1] - 5)))
    assert label_pixels(tips[4]) == 0
    xdo("mousemove", *map(round, screen_of(e, tips[4].position)))
    assert label_pixels(tips[4]) > 30, "no hover label naming the arrow"
    most = math.degrees(RADIANS_PER_PIXEL) * 3
    for h in tips:
        click(e, screen_of(e, h.position))
        assert e.selected is not None and e.selected.same(h), (h.label, e.selected)
        n = np.array(e.scene.krs.levels[h.level].mirror.normal)
        up = e.window_view().up
        for _ in range(3 if h is tips[0] else 1):
            drag(e, screen_of(e, e.selected.position), (0, -3), steps=3)
            m = np.array(e.scene.krs.levels[h.level].mirror.normal)
            assert 0.2 * most < angle(n, m) <= most * 1.001, (h.label, angle(n, m))
            assert (m - n) @ up > 0, f"{h.label}: dragging up lowered the normal"
            n = m
        if h is tips[0]:
            x, y = screen_of(e, e.selected.position)
            drag(e, (x + 30, y), (0, -3), steps=3)
            assert np.array_equal(e.scene.krs.levels[h.level].mirror.normal, n), "turned off it"
    assert len(e.doc.history.steps) == 3 + 11, "each drag is one undo step"


def test_a_zero_normal_typed_stays_red_in_its_field_with_the_message_under_it(editor):
    """Type 0 into the three components of a normal (ctrl+click, keys): the last one makes
    the zero vector, which is refused. The field keeps (0, 0, 0) on red with the message under
    it, the scene keeps its last valid normal, nothing goes to the HUD; a valid value clears
    it, Esc cancels it, and so does selecting another level (it used to come back red when
    the level was selected again) (negative control: no red before)."""
    e = editor
    e.execute([Bake()])
    e.select_level(LEVEL)
    pump(e, 3)
    path = ("route", "levels", LEVEL, "normal")

    def red_below() -> int:
        """Red message pixels in the two lines under the field, and red field background."""
        x0, y0, x1, y1 = e.viewer.interactions.rects[path]  # warnings come and go above it
        part = (x1 - x0 - 50) / 3  # three components, then the label (about 50 px)
        shot = e.viewer.read_window().astype(int)
        r, g, b = (shot[round(y1) : round(y1) + 34, round(x0) : round(x1), k] for k in range(3))
        text = (r > 180) & (g < 140) & (b < 130) & (r - g > 80)
        field = shot[round(y0) + 2 : round(y1) - 2, round(x0) + 2 : round(x0 + part) - 2]
        frame = (np.abs(field - [140, 20, 15]) < 40).all(-1)
        return int(text.sum()) + int(frame.sum())

    def type_into(k: int, text: str) -> None:
        x0, y0, x1, y1 = scroll_to(e, path, 60, 0)
        part = (x1 - x0 - 50) / 3
        type_at(e, window_xy(e, x0 + (k + 0.5) * part, (y0 + y1) / 2), text)

    assert red_below() == 0
    for k in range(3):
        type_into(k, "0")
    last = e.scene.route.levels[LEVEL].normal
    assert abs(last[2]) == 1.0, "two zeros typed: the normal is ±z"
    assert path in e.viewer.interactions.refused, (e.viewer.error, e.doc.history.labels())
    refused = e.viewer.interactions.refused[path]
    assert refused.value == (0.0, 0.0, 0.0) and "must not be the zero vector" in refused.message
    assert e.viewer.error == "", "the message went to the HUD"
    pump(e, 2)
    assert red_below() > 40, "no red field and message under it"
    type_into(2, "0.5")
    assert path not in e.viewer.interactions.refused and red_below() == 0
    type_into(2, "0")
    assert path in e.viewer.interactions.refused
    xdo("key", "Escape")
    pump(e, 3)
    assert path not in e.viewer.interactions.refused and red_below() == 0
    assert e.scene.route.levels[LEVEL].normal == last
    type_into(2, "0")  # refused again, then another level selected: the value is stale
    pump(e, 2)
    assert path in e.viewer.interactions.refused, "control: gone by itself"
    e.select_level(LEVEL - 1)
    pump(e, 2)
    assert not e.viewer.interactions.refused
    e.select_level(LEVEL)
    pump(e, 3)
    assert red_below() == 0 and e.scene.route.levels[LEVEL].normal == last


def test_the_gizmo_axes_point_the_way_the_world_axes_do(editor, monkeypatch):
    """The translate gizmo on a fork: its red and green arrows (X, Y) run along the screen
    directions of the world's +x and +y there. Negative control: ImGuizmo's axis flip (what
    the editor had) turns the tree's Y arrow down."""
    from imgui_bundle import imguizmo

    from krsview.compile.camera import project
    from krsview.editor.gizmo import Gizmo

    e = editor
    e.execute([Bake()])
    h = handle(e, ("route", "levels", LEVEL, "fork"))
    e.select(h)
    xdo("mousemove", *map(round, window_xy(e, 5, SIZE[1] - 5)))

    def arrows() -> dict[str, float]:
        pump(e, 3)
        shot = e.viewer.read_window().astype(int)
        v = e.window_view()
        x, y, _ = project(v, h.position)
        rows, cols = np.mgrid[0 : shot.shape[0], 0 : shot.shape[1]]
        near = np.hypot(cols - x, rows - y) < 120
        out = {}
        for name, k, axis in (("x", 0, [1, 0, 0]), ("y", 1, [0, 1, 0])):
            others = [c for c in range(3) if c != k]
            mask = near & (shot[..., k] > 150) & (shot[..., others].max(-1) < 60)
            assert mask.sum() > 20, f"no {name} arrow"
            d = np.array([cols[mask].mean() - x, rows[mask].mean() - y])
            tx, ty, _ = project(v, h.position + 0.1 * np.array(axis))
            want = np.array([tx - x, ty - y])
            out[name] = float(d @ want / np.linalg.norm(d) / np.linalg.norm(want))
        return out

    assert min(arrows().values()) > 0.9
    flip = imguizmo.im_guizmo.begin_frame
    monkeypatch.setattr(
        Gizmo,
        "begin_frame",
        staticmethod(lambda: (flip(), imguizmo.im_guizmo.allow_axis_flip(True))),
    )
    assert arrows()["y"] < 0, "negative control: the flipped Y arrow points down"


def x_arrow(e, h) -> tuple[tuple[float, float], np.ndarray]:
    """The selected handle ``h``'s gizmo, as drawn: a screen point on its red X arrow (4/5
    of the way out) and the arrow's unit direction on screen."""
    from krsview.compile.camera import project

    shot = e.viewer.read_window().astype(int)
    x, y, _ = project(e.window_view(), h.position)
    rows, cols = np.mgrid[0 : shot.shape[0], 0 : shot.shape[1]]
    red = (np.hypot(cols - x, rows - y) < 120) & (shot[..., 0] > 150) & (shot[..., 1:].max(-1) < 60)
    far = np.argmax(np.hypot(cols[red] - x, rows[red] - y))
    step = np.array([cols[red][far] - x, rows[red][far] - y])
    grab = window_xy(e, x + 0.8 * step[0], y + 0.8 * step[1])
    return grab, step / np.linalg.norm(step)


def selected_fork(e):
    """The tree baked, fork LEVEL selected (its gizmo shown) and the pointer parked in a
    corner: its handle and position."""
    e.execute([Bake()])
    h = handle(e, ("route", "levels", LEVEL, "fork"))
    e.select(h)
    xdo("mousemove", *map(round, window_xy(e, 5, SIZE[1] - 5)))
    pump(e, 3)
    return h, e.scene.route.levels[LEVEL].fork


def flick(start, offset) -> None:
    """Press at ``start``, move by ``offset`` in two moves and let go, all before the
    editor's next turn (a quick drag on a slow frame)."""
    x, y = start
    xdo("mousemove", round(x), round(y))
    xdo("mousedown", 1)
    xdo("mousemove", round(x + offset[0] / 2), round(y + offset[1] / 2))
    xdo("mousemove", round(x + offset[0]), round(y + offset[1]))
    xdo("mouseup", 1)


def test_a_flick_on_the_gizmo_lands_where_a_slow_drag_does(editor):
    """The fork's X arrow pressed, dragged 40 px and let go before the editor's next turn
    (one event poll): the fork lands where the same drag made slowly, a turn per move, puts
    it (within 5 % of the way), in one undo step. ImGui used to read the last motion and the
    release in one frame, and ImGuizmo ended the drag before moving it
    (platform.Platform.hand). Negative control: the same flick pressed 30 px beside the
    arrow, off the gizmo, moves nothing."""
    e = editor
    h, old = selected_fork(e)
    grab, step = x_arrow(e, h)
    drag(e, grab, tuple(40 * step))
    slow = e.scene.route.levels[LEVEL].fork
    assert slow[0] != old[0] and slow[1:] == old[1:]
    e.viewer.undo()
    pump(e, 3)
    assert e.scene.route.levels[LEVEL].fork == old
    steps = e.doc.history.index
    xdo("mousemove", *map(round, grab))
    pump(e, 3)
    flick(grab, tuple(40 * step))
    pump(e, 4)
    fast = e.scene.route.levels[LEVEL].fork
    assert fast[1:] == old[1:] and abs(fast[0] - slow[0]) < 0.05 * abs(slow[0] - old[0]), (
        old,
        slow,
        fast,
    )  # ImGuizmo scales its steps by the handle's depth as it moves: a path of 2 or 8 moves
    assert e.doc.history.index == steps + 1 and not e.doc.history.can_redo
    e.viewer.undo()
    pump(e, 3)
    beside = (grab[0] - 30 * step[1], grab[1] + 30 * step[0])  # the view's: it orbits
    flick(beside, tuple(40 * step))
    pump(e, 4)
    assert e.scene.route.levels[LEVEL].fork == old and e.doc.history.index == steps


def test_a_shift_drag_lands_on_the_absolute_grid_and_saves_no_float32_noise(editor):
    """Drag the fork's X arrow with Shift held: x lands on the 0.05 grid (not start + k ×
    0.05), y and z keep their float64 values bit for bit, and so does the saved file."""
    e = editor
    h, old = selected_fork(e)
    assert abs(old[0] / 0.05 - round(old[0] / 0.05)) > 0.01, "the start is off the grid"
    v = e.window_view()
    grab, step = x_arrow(e, h)
    xdo("keydown", "shift")
    drag(e, grab, tuple(40 * step))
    xdo("keyup", "shift")
    new = e.scene.route.levels[LEVEL].fork
    assert (
        new[0] != old[0]
        and round(new[0] / 0.05) * 0.05 == new[0]
        or (repr(new[0]) == repr(round(round(new[0] / 0.05) * 0.05, 3)))
    ), new
    assert new[1] == old[1] and new[2] == old[2]
    xdo("key", "ctrl+s")
    pump(e)
    assert load_scene(e.path).route.levels[LEVEL].fork == new
    # negative control: the position read back through ImGuizmo's float32 matrix is noisy
    noisy = np.float64(np.float32(old[1] - v.origin[1])) + v.origin[1]
    assert noisy != old[1]


def test_the_clipped_part_of_a_warned_branch_is_drawn_red_in_the_view(editor):
    """Turn the mirror at fork 21 by 36° (its child branch 20 crosses it): the panel names
    the level and the view draws the part Alg. 1 clips in red where it projects. Negative
    control: the same pixels before the turn are not red."""
    from krsview.compile.camera import project
    from krsview.editor.clipped import clipped_parts

    e = editor
    e.execute([Bake()])
    settle(e)

    def red_at(points) -> float:
        pump(e, 3)
        shot = e.viewer.read_window().astype(int)
        v = e.window_view()
        hits = []
        for p in points:
            x, y, z = project(v, p)
            px = shot[round(y) - 1 : round(y) + 2, round(x) - 1 : round(x) + 2]
            hits.append(((px[..., 0] > 200) & (px[..., 1:].max(-1) < 80)).any())
        return float(np.mean(hits))

    n = np.array(e.scene.route.levels[21].normal)
    a = np.cross(n, [0.0, 0.0, 1.0])
    a /= np.linalg.norm(a)
    t = math.radians(36.0)
    turned = n * math.cos(t) + np.cross(a, n) * math.sin(t)
    before = e.scene
    assert e.edit(("route", "levels", 21, "normal"), tuple(turned))
    settle(e)
    parts = clipped_parts(e.scene.route)  # the turned branch, and the sibling below it
    assert [level for level, _ in parts] == [19, 20]
    assert [entry for entry, _ in e.warnings] == [19, 20]
    assert e.warnings[1][1].startswith("route.levels[20] (L20): the branch crosses")
    points = parts[1][1][::4]
    assert red_at(points) > 0.8
    e.doc.commit(before, "back")
    e.viewer.sync()
    settle(e)
    assert red_at(points) < 0.1, "negative control: red before the turn"


@pytest.mark.parametrize("size", [(640, 360), (1280, 720)])
def test_nothing_is_cut_off_and_the_scene_is_framed_beside_the_panel(display, tmp_path, size):
    """The edit panel and the unsaved-changes dialog lie inside the window (the panel
    scrolls what it cannot show), and the scene camera's target is in the middle of the part
    the panel leaves, docked right or left."""
    from imgui_bundle import imgui

    from krsview.compile.camera import project
    from krsview.editor.commands import PlacePanel
    from krsview.editor.window import Editor

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    e = Editor(path, size=size)
    try:
        e.execute([Bake()])
        e.select_level(LEVEL)
        assert e.edit(("render", "epsilon_scale"), 2.0)
        pump(e, 4)

        def inside(name: str) -> None:
            w = imgui.internal.find_window_by_name(name)
            assert w is not None, name
            x, y, width, height = w.pos.x, w.pos.y, w.size.x, w.size.y
            assert x >= 0 and y >= 0 and x + width <= size[0] and y + height <= size[1], name
            assert w.content_size.x <= width, f"{name} is cut off on the right"
            if w.content_size.y > height:
                assert w.scroll_max.y > 0, f"{name} hides what it cannot show"

        # the panel's edge dragged 80 px into the view widens it (where it is already half
        # the window, 60 px the other way narrows it), still docked right
        x, _, width, _ = e.layout.panel(size)
        grow = 80.0 if 0.5 * size[0] - width >= 80 else -60.0
        drag(e, window_xy(e, x + 1, size[1] / 2), (-grow, 0))
        now = e.layout.clamped(size[0])
        assert abs(now - (width + grow)) <= 2, (now, width, grow)
        w = imgui.internal.find_window_by_name("edit")
        assert abs(w.pos.x + w.size.x - (size[0] - 8)) <= 1
        inside("edit")
        e.file.asking = ("close", None)
        pump(e, 3)
        inside("unsaved changes")
        e.file.answer_cancel()
        for side in ("left", "right"):  # each a new side: framed again
            e.execute([PlacePanel(side, e.layout.width)])
            pump(e, 2)
            x0, x1 = e.layout.free(size)
            x, _, _ = project(e.window_view(), np.array(e.scene.camera.target))
            assert abs(x - (x0 + x1) / 2) < 2, (side, x, x0, x1)
            # negative control: the scene camera, unframed, has it in the window's middle
            assert abs(size[0] / 2 - (x0 + x1) / 2) > 50
    finally:
        e.close()


def test_a_mokrs_steps_hint_is_one_line_that_neither_wraps_nor_widens_the_panel(display, tmp_path):
    """Selecting a step wrapped its drag hint to two lines and moved every row below it
    between two clicks [review]: the hint is one line, cut at the panel's edge."""
    from imgui_bundle import imgui

    from krsview.editor.mokrs_panel import HINTS
    from krsview.editor.window import Editor

    path = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), path)
    e = Editor(path, size=(640, 360))
    try:
        for role in ("point", "factor"):
            e.select(next(h for h in e.handles if getattr(h, "role", "") == role))
            pump(e, 3)
            w = imgui.internal.find_window_by_name("edit")
            assert w.content_size.x <= w.size.x, f"{role}: the panel is widened"
        # control: the one line it was, the name and the hint, is wider than the panel
        said = f"{e.selected.label}: {HINTS['factor']}"
        assert imgui.calc_text_size(said).x > w.size.x - 2 * imgui.get_style().window_padding.x
    finally:
        e.close()
