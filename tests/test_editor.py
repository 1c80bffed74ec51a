"""The editor in a real window under Xvfb, driven by real X pointer and key events (xdotool):
select by clicking, drag the gizmo and a normal's arrow tip, undo/redo/save by keyboard, and
compare the saved file's headless render with the window. Also: killed mid-edit, the
recovery is offered; closing or a disk change with unsaved edits asks first."""

from __future__ import annotations

import math
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from krsview.editor.commands import Bake
from krsview.scene import load_scene
from krsview.scene.presets import resolve
from krsview.viewer.commands import Edit, SetPrepass

from .conftest import headless_render

SIZE = (800, 500)
LEVEL = 19  # a fork near the top of the shipped tree, clear of the panels


@pytest.fixture
def editor(display, tmp_path):
    from krsview.editor.window import Editor

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    e = Editor(path, size=SIZE)
    yield e
    e.close()


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
    v = e.window_view()
    depth = float((old - v.origin) @ v.forward)
    expected = 40 * 2 * v.tan_half * depth / v.height * v.right  # the screen-plane move
    assert np.linalg.norm(new - old - expected) < 0.1 * np.linalg.norm(expected), (
        new - old,
        expected,
    )
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
    # the window (HUD and overlays hidden) against a headless render of the saved file
    e.viewer.hud = False
    e.viewer.frames.dirty = True
    settle(e)
    shot = e.viewer.read_window()
    same_prepass = ("--prepass", str(e.viewer.prepass))  # the window's pre-pass tile
    ref = headless_render(load_scene(e.path), tmp_path / "saved", SIZE, *same_prepass)
    close = np.abs(shot.astype(int) - ref.astype(int)).max(-1) <= 2
    assert close.mean() >= 0.99, f"window and headless render agree on {close.mean():.2%}"
    # negative control: the unedited tree differs where the fork moved
    before = headless_render(load_scene(resolve("tree")), tmp_path / "before", SIZE, *same_prepass)
    same = np.abs(shot.astype(int) - before.astype(int)).max(-1) <= 2
    assert same.mean() < 0.97, f"the edit changed only {1 - same.mean():.2%} of the pixels"
    from PIL import Image

    Image.fromarray(shot).save(tmp_path / "edited-window.png")


def test_overlay_is_composited_by_traced_depth(editor):
    """Overlay fragments behind the traced surface are hidden (drawn at HIDDEN_ALPHA, here
    set to 0 to see them vanish, then to 1 as the negative control)."""
    import glfw

    e = editor
    e.execute([Bake()])
    e.select_level(LEVEL)
    e.viewer.hud = False
    settle(e)
    plain = e.viewer.read_window().astype(int)
    e.viewer.hud = True

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
        assert e.recovered is not None
        pump(e)  # the modal is drawn (panels run)
        e.restore()
        assert e.scene.route.levels[5].radius == 0.123 and e.doc.dirty
        assert e.recovered is None
    finally:
        e.close()


def test_closing_with_unsaved_edits_asks_and_cancel_keeps_the_window(editor):
    import glfw

    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    glfw.set_window_should_close(e.viewer.window, True)
    assert not e.should_close() and e.asking == ("close", None)
    pump(e)
    e.answer_cancel()
    assert not e.should_close() and e.doc.dirty
    glfw.set_window_should_close(e.viewer.window, True)
    e.should_close()
    e.answer_discard()
    assert e.should_close()
    assert load_scene(e.path).render.epsilon_scale == 1.0, "discard wrote the file"


def test_a_disk_change_with_unsaved_edits_is_a_conflict_never_overwritten(editor):
    from dataclasses import replace

    from krsview.scene import save_scene

    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    other = replace(load_scene(e.path), name="changed elsewhere")
    time.sleep(0.05)
    save_scene(other, e.path)
    os.utime(e.path, ns=(e.doc.stamp.mtime_ns + 10**9,) * 2)
    time.sleep(0.6)
    pump(e)
    assert e.conflict and e.scene.render.epsilon_scale == 2.0
    assert not e.save() and "changed on disk" in e.viewer.error
    assert load_scene(e.path).name == "changed elsewhere"
    e.take_file()
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
    e.save_as(str(tmp_path / "x.png"))
    assert "ends in .toml" in e.viewer.error or "ending in .toml" in e.viewer.error
    e.save_as(str(tmp_path / "copy.toml"))
    assert e.path == tmp_path / "copy.toml" and load_scene(tmp_path / "copy.toml") == e.scene


def test_opening_another_scene_with_unsaved_edits_asks_first(editor):
    e = editor
    assert e.edit(("render", "epsilon_scale"), 2.0)
    e.doc.autosave(0.0)
    e.doc.autosave(10.0)
    recovery = e.doc.recovery_path
    assert recovery.exists()
    e.open_preset(resolve("sierpinski"))
    assert e.asking == ("open", resolve("sierpinski")) and e.scene.name == "tree"
    pump(e)  # the question is drawn as a modal
    e.answer_discard()
    assert e.scene.name == "sierpinski" and e.asking is None and not e.doc.dirty
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
    depth = e.viewer.geometry.depth
    click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected.level == depth - 1
    e.viewer.set_levels(6)
    settle(e)
    e.select(None)
    click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected is not None and e.selected.level == depth - 1


def test_the_hud_prepass_knob_is_an_edit_saved_with_the_scene_and_undone_by_ctrl_z(editor):
    """The HUD's pre-pass knob goes through the document in the editor too: the title says
    unsaved, Ctrl+Z (a real key) takes it back, and Ctrl+S writes it to the file."""
    e = editor
    pump(e)
    assert load_scene(e.path).render.prepass == 0
    e.execute([SetPrepass(8)])
    pump(e)
    assert e.scene.render.prepass == 8 == e.viewer.prepass and e._title.startswith(
        "krsview edit — *"
    )
    xdo("key", "ctrl+z")
    pump(e)
    assert e.scene.render.prepass == 0 and not e.doc.dirty and "*" not in e._title
    xdo("key", "ctrl+shift+z")
    xdo("key", "ctrl+s")
    pump(e)
    assert load_scene(e.path).render.prepass == 8 and not e.doc.dirty
