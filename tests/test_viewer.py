"""The real viewer window under Xvfb, driven through its input layer."""

from __future__ import annotations

import shutil
import time
from dataclasses import replace

import numpy as np
import pytest

from krsview.scene import load_scene, save_scene
from krsview.scene.presets import resolve
from krsview.scene.render import VIEW_PREPASS
from krsview.viewer.commands import (
    NextBookmark,
    Redo,
    Replay,
    ResetView,
    SetPrepass,
    ToggleOrbit,
    ToggleRecording,
    Undo,
)
from krsview.viewer.window import STATUS_SECONDS

from .conftest import headless_render

SIZE = (160, 120)


@pytest.fixture
def viewer(display, tmp_path):
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=SIZE, hud=False)
    yield v
    v.close()


def settle(v, limit: int = 400) -> None:
    for _ in range(limit):
        v.step(0.02)
        if v.frames.refined:
            return
    raise AssertionError("the view never refined to full resolution")


def hold(v, key: str, steps: int, dt: float = 0.05) -> None:
    """Hold ``key`` for ``steps`` event-loop turns, then release it."""
    v.input.key(key, True)
    for _ in range(steps):
        v.step(dt)
    v.input.key(key, False)


def test_flying_and_looking_then_screenshot_matches_headless_render(viewer, tmp_path):
    v = viewer
    settle(v)
    start = v.read_window()
    p0 = v.camera.position.copy()
    hold(v, "W", 5, 0.1)
    v.input.button("right", True)
    v.input.move_cursor(0, 0)
    v.input.move_cursor(25, -10)
    v.step(0.05)
    v.input.button("right", False)
    settle(v)
    assert np.linalg.norm(v.camera.position - p0) > 0.1, "W did not move the camera"
    shot = v.read_window()
    assert np.abs(shot.astype(int) - start).max() > 50, "the view did not change"
    ref = headless_render(v.view_scene().with_geometry(v.drawn.krs), tmp_path / "headless", SIZE)
    close = np.abs(shot.astype(int) - ref.astype(int)).max(-1) <= 2
    assert close.mean() >= 0.99, f"window and headless render agree on {close.mean():.2%}"


def test_adaptive_resolution_drops_when_slow_and_restores_when_still(viewer):
    v = viewer
    v.frames.adaptive.target_fps = 2000.0  # a budget no llvmpipe frame meets
    scales = []
    for _ in range(8):
        v.input.key("D", True)
        v.step(0.05)
        scales.append(v.frames.adaptive.scale)
    v.input.key("D", False)
    assert scales[-1] < scales[0] and v.frames.adaptive.moving_size()[0] < SIZE[0] / 3
    settle(v)
    assert v.frames.image[1] == SIZE, "the still image is not back at full resolution"


def test_orbit_keeps_distance_to_the_picked_point(viewer):
    v = viewer
    settle(v)
    v.execute([ToggleOrbit()])
    pivot = v.nav.orbit_pivot
    r0 = np.linalg.norm(v.camera.position - pivot)
    v.input.button("left", True)
    v.input.move_cursor(0, 0)
    v.input.move_cursor(80, 0)
    v.step(0.05)
    v.input.button("left", False)
    assert np.isclose(np.linalg.norm(v.camera.position - pivot), r0, rtol=1e-9)
    assert np.allclose(v.camera.forward(), (pivot - v.camera.position) / r0, atol=1e-9)


def test_bookmark_is_saved_in_the_preset_and_reset_restores(viewer):
    v = viewer
    assert not v.scene.bookmarks
    at = v.camera.to_camera()
    v.execute([NextBookmark()])  # none yet: said how to add one, the view unmoved
    assert v.status_line() == "no bookmarks yet: B adds the view as one"
    assert v.camera.to_camera() == at
    hold(v, "A", 1, 0.2)
    moved = v.camera.to_camera()
    hold(v, "B", 1, 0.01)
    saved = load_scene(v.path)
    assert saved.bookmarks and saved.bookmarks[-1].camera == moved
    v.execute([ResetView()])
    assert v.camera.to_camera().position == saved.camera.position
    v.execute([NextBookmark()])
    assert np.allclose(v.camera.position, moved.position)
    # B wrote the bookmark to the file, so Ctrl+Z takes it out of the file too, and Ctrl+Shift+Z
    # writes it again; the viewer's own write is no outside edit (no reload said). It used to
    # leave the file holding the bookmark the view no longer had.
    with_mark = v.path.read_text()
    v.execute([Undo()])
    assert not v.scene.bookmarks and not load_scene(v.path).bookmarks
    assert v.status_line() == f"undid add bookmark 'view 1' in {v.path.name}"
    v.step(0.6)
    assert "reloaded" not in v.message and not v.error
    v.execute([Redo()])
    assert v.path.read_text() == with_mark and v.scene.bookmarks == load_scene(v.path).bookmarks


def test_hot_reload_applies_edits_and_keeps_the_last_good_scene(viewer):
    v = viewer
    settle(v)
    scene = load_scene(v.path)
    save_scene(replace(scene, material=replace(scene.material, background=(1.0, 0.0, 0.0))), v.path)
    time.sleep(0.6)
    for _ in range(3):
        v.step(0.3)
    assert v.scene.material.background == (1.0, 0.0, 0.0) and not v.error
    v.path.write_text(v.path.read_text().replace("levels = 22", "levels = -4"))
    time.sleep(0.6)
    for _ in range(3):
        v.step(0.3)
    assert "tree.levels = -4" in v.error
    assert v.scene.material.background == (1.0, 0.0, 0.0)  # last good scene kept
    assert v.frames.image is not None
    # changed back to the contents last read, twice over: the refusal goes each time (it
    # stayed, since the file no longer differed from the scene shown)
    good = v.path.read_text().replace("levels = -4", "levels = 22")
    for _ in range(2):
        v.path.write_text(good.replace("levels = 22", "levels = -4"))
        time.sleep(0.6)
        for _ in range(3):
            v.step(0.3)
        assert "tree.levels = -4" in v.error
        v.path.write_text(good)
        time.sleep(0.6)
        for _ in range(3):
            v.step(0.3)
        assert v.error == "" and "as it was" in v.message


def test_shader_edit_reloads_and_a_broken_shader_keeps_the_last_good_image(display, tmp_path):
    from krsview.gpu.program import SHADER_DIR
    from krsview.viewer.window import Viewer

    shaders = tmp_path / "shaders"
    shutil.copytree(SHADER_DIR, shaders)
    v = Viewer(resolve("sierpinski"), size=SIZE, hud=False, shader_dir=shaders)
    try:
        settle(v)
        shade = shaders / "shade.glsl"
        shade.write_text(
            shade.read_text().replace(
                "vec3 color = albedo * light;", "vec3 color = vec3(1.0, 0.0, 1.0);"
            )
        )
        time.sleep(0.6)
        v.step(0.01)
        settle(v)
        magenta = v.read_window()
        assert (
            not v.error and (np.abs(magenta.astype(int) - (255, 0, 255)).max(-1) < 3).mean() > 0.1
        )
        lines = shade.read_text().splitlines()
        k = next(i for i, line in enumerate(lines) if "vec3(1.0, 0.0, 1.0)" in line)
        lines[k] = lines[k].replace(";", " +;")
        shade.write_text("\n".join(lines) + "\n")
        time.sleep(0.6)
        v.step(0.01)
        settle(v)
        assert f"shade.glsl:{k + 1}" in v.error, v.error
        assert v.status_line() == v.error.splitlines()[0]  # the HUD hidden: at the foot
        top = SIZE[1] // 2  # above the status line, the last good image stays
        assert np.array_equal(v.read_window()[:top], magenta[:top]), "the last good image was lost"
    finally:
        v.close()


def test_record_and_replay_a_camera_path(viewer):
    v = viewer
    v.execute([ToggleRecording()])
    hold(v, "E", 5)
    v.execute([ToggleRecording()])
    end = v.camera.position.copy()
    v.execute([ResetView()])
    v.execute([Replay()])
    for _ in range(20):
        v.step(0.05)
    assert v.file.recorder.replay_start is None and np.allclose(v.camera.position, end)


def test_camera_path_is_saved_beside_the_preset_and_loaded_again(viewer):
    v = viewer
    v.execute([ToggleRecording()])
    hold(v, "W", 4)
    v.execute([ToggleRecording()])
    end, recorded = v.camera.position.copy(), len(v.file.recorder.path.poses)
    assert v.file.recorder.file.exists() and v.file.recorder.file.name == "tree.path.json"
    v.file.recorder.path = None
    v.file.open(v.path)  # as a new session would: the path comes from the file
    assert len(v.file.recorder.path.poses) == recorded > 0
    v.execute([Replay()])
    for _ in range(20):
        v.step(0.05)
    assert np.allclose(v.camera.position, end)
    v.file.recorder.file.write_text('{"poses": [{"t": 0, "position": [1, "x"]}]}')
    v.file.open(v.path)
    assert v.file.recorder.path is None and "tree.path.json: poses[0]" in v.error


def test_tracer_switch_compiles_one_new_variant_then_hits_the_cache(viewer):
    """The HUD's tracer choice goes through Viewer.set_render: a new define set compiles once
    (its tracing program, its pre-pass and its free tiles' pass (gpu/renderer.py), the tree's
    blocks listed and their shadow rays, the hits' depth, the sky's and the shading with those,
    and its outline pixels': gpu/passes.py; the still image shares them, [render]
    shadow_block); switching back, and moving accuracy knobs, compile nothing."""
    v = viewer
    settle(v)
    programs = v.renderer.programs
    before = programs.compiles
    sphere_image = v.read_window()
    v.set_render(tracer="binary")
    settle(v)
    assert v.prepass and programs.compiles == before + 9
    assert any(("KRS_TRACER_BINARY", None) in key[2] for key in programs._programs)
    binary_image = v.read_window()
    assert np.abs(binary_image.astype(int) - sphere_image).max() > 0  # a different tracer ran
    v.set_render(tracer="sphere")
    settle(v)
    v.set_render(epsilon_scale=2.0, max_iterations=100, xi_bonus=3.0)
    settle(v)
    assert programs.compiles == before + 9


def test_precision_knob_switches_to_the_double_variant_in_the_window(viewer):
    """render.precision from the HUD: a double variant compiles, the window shows the same
    picture as float32 at the preset's view (to rounding), and no error appears. A shadow
    ray per pixel in both: the double variant traces no other (gpu/passes.py)."""
    v = viewer
    v.set_render(shadow_block=1)
    settle(v)
    single = v.read_window()
    v.set_render(precision="double")
    settle(v)
    assert any(("KRS_DOUBLE", None) in key[2] for key in v.renderer.programs._programs)
    double = v.read_window()
    assert not v.error and v.scene.render.precision == "double"
    assert (np.abs(double.astype(int) - single).max(-1) > 2).mean() < 0.01
    v.set_render(precision="float", shadow_block=2)
    settle(v)


def test_mokrs_presets_fly_in_the_viewer(viewer):
    v = viewer
    for name in ("palm", "shell", "inversion"):
        v.file.open(resolve(name))
        assert v.error == "" and v.scene.mokrs is not None
        settle(v)
        img = v.read_window()
        background = np.round(np.array(v.scene.material.background) ** (1 / 2.2) * 255)
        assert (np.abs(img - background).max(-1) > 8).mean() > 0.02, f"{name}: nothing drawn"
        d = v.nearest_distance()
        assert 0 < d < 1e6, f"{name}: free radius {d}"
        v.set_render(tracer="sphere")
        assert v.scene.render.tracer == "binary" and "binary tracing" in v.error
        v.error = ""
        hold(v, "W", 3)
        settle(v)
        assert np.isfinite(v.camera.position).all()


def test_preset_picker_and_levels_slider(viewer):
    v = viewer
    settle(v)
    full = v.read_window()
    v.drawn.set_levels(6)
    assert len(v.drawn.krs.levels) == 6 and v.drawn.krs.kernels[-1] == v.drawn.geometry.kernels[-1]
    settle(v)
    assert (np.abs(v.read_window().astype(int) - full).max(-1) > 30).mean() > 0.01  # fewer twigs
    v.drawn.set_levels(len(v.drawn.geometry.levels))
    assert v.drawn.krs is v.drawn.geometry
    v.file.open(resolve("sierpinski"))
    assert v.scene.name == "sierpinski" and v.path == resolve("sierpinski") and not v.error
    assert v.camera.to_camera().position == v.scene.camera.position
    settle(v)
    v.file.open(v.path.with_name("missing.toml"))
    assert "cannot read" in v.error and v.scene.name == "sierpinski"  # kept the last good one


def test_effect_toggles_compile_once_then_hit_the_cache(viewer):
    """The HUD's effect checkboxes go through Viewer.set_effect: a new effect set compiles one
    variant with its define (with shadows: the tracing, its pre-pass and its free tiles'
    pass, the blocks listed and their shadow rays, the hits' depth, the sky's and the shading
    with them and its outline pixels', gpu/passes.py); switching back and forth again
    compiles nothing."""
    v = viewer
    v.file.open(resolve("sierpinski"))
    settle(v)
    programs = v.renderer.programs
    before = programs.compiles
    plain = v.read_window()
    v.set_effect("shadows", True)
    settle(v)
    assert programs.compiles == before + 9
    assert any(("KRS_SHADOWS", None) in key[2] for key in programs._programs)
    assert np.abs(v.read_window().astype(int) - plain).max() > 0
    v.set_effect("soft_shadows", True)  # replaces the hard shadows: they exclude each other
    assert v.scene.effects == ["soft_shadows"]
    settle(v)
    v.set_effect("soft_shadows", False)
    settle(v)
    v.set_effect("shadows", True)
    settle(v)
    assert programs.compiles == before + 18
    v.file.open(resolve("palm"))
    v.set_effect("twist", True)
    assert "twist" not in v.scene.effects and "MöKRS" in v.error


def test_compound_preset_flies_and_the_levels_slider_cuts_every_component(viewer):
    v = viewer
    v.file.open(resolve("grove"))
    assert v.error == "" and len(v.drawn.geometry.parts) == 8
    settle(v)
    full = v.read_window()
    background = np.round(np.array(v.scene.material.background) ** (1 / 2.2) * 255)
    assert (np.abs(full - background).max(-1) > 8).mean() > 0.02, "nothing drawn"
    v.drawn.set_levels(4)
    assert [p.depth for p in v.drawn.krs.parts] == [4] * 7 + [1]
    settle(v)
    assert (np.abs(v.read_window().astype(int) - full).max(-1) > 30).mean() > 0.01
    assert 0 < v.nearest_distance() < 1e3
    hold(v, "W", 3)
    settle(v)
    assert np.isfinite(v.camera.position).all()


def test_measured_accuracy_panel_finds_the_setting_and_the_best_within_budget(
    viewer, tmp_path, monkeypatch
):
    """A constructed report: the panel knows which row the view draws, and its button puts
    the view on the most accurate row that fits the frame budget (scaled by pixels). The
    bench draws its rows with the file's pre-pass (none for tree) but its pre-pass rows, so
    the viewer's own pre-pass makes the view the pre-pass row's, and a row applied draws
    with the row's pre-pass."""
    from krsview.viewer import hud, measured
    from krsview.viewer.measured import apply_row, best_within, load_measured, matches

    (tmp_path / "tree").mkdir()
    (tmp_path / "tree" / "accuracy.csv").write_text(
        "knob,value,width,height,ms,mask_error\n"
        "scene,as saved,100,100,50,0.02\nepsilon_scale,0.5,100,100,80,0.01\n"
        "epsilon_scale,4,100,100,20,0.09\nlevels,12,100,100,10,0.2\n"
        "tracer,binary 2/0.3,100,100,90,0.015\nprecision,double,100,100,70,0.019\n"
        "walk_restart,on,100,100,55,0.02\nprepass,4,100,100,40,0.021\n"
    )
    monkeypatch.setattr(measured, "REPORT_DIRS", (tmp_path,))
    rows = load_measured("tree")
    v = viewer

    def drawn(prepass=None) -> list[str]:
        """The rows the view draws, as the panel asks (the view's own pre-pass)."""
        tile = v.prepass if prepass is None else prepass
        args = v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth, tile
        return [r["value"] for r in rows if matches(r, *args)]

    assert v.scene.render.prepass is None and v.prepass == VIEW_PREPASS == 4
    assert drawn() == ["4"]  # the viewer's pre-pass: not the scene as the bench drew it
    assert drawn(prepass=0) == ["as saved"]  # control: the bench's own pre-pass, none
    v.execute(apply_row(rows[7], v.doc.saved))
    assert v.prepass == 4 and drawn() == ["4"]
    v.execute(apply_row(rows[0], v.doc.saved))
    assert v.prepass == 0 and drawn() == ["as saved"]  # the row as measured: no pre-pass
    assert best_within(rows, 60.0, 100 * 100)["value"] == "as saved"
    assert best_within(rows, 100.0, 100 * 100)["value"] == "0.5"
    assert best_within(rows, 200.0, 400 * 400)["value"] == "12"  # 16× the pixels
    assert best_within(rows, 1.0, 100 * 100) is None
    v.execute(apply_row(rows[1], v.doc.saved))
    assert v.scene.render.epsilon_scale == 0.5
    assert [
        r["value"]
        for r in rows
        if matches(r, v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth)
    ] == ["0.5"]
    v.execute(apply_row(rows[4], v.doc.saved))
    assert v.scene.render.tracer == "binary" and matches(
        rows[4], v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth
    )
    v.execute(apply_row(rows[5], v.doc.saved))
    assert v.scene.render.precision == "double" and v.scene.render.tracer == "sphere"
    assert [
        r["value"]
        for r in rows
        if matches(r, v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth)
    ] == ["double"]
    v.execute(apply_row(rows[6], v.doc.saved))
    assert v.scene.render.walk_restart == "on" and v.scene.render.precision == "float"
    assert [
        r["value"]
        for r in rows
        if matches(r, v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth)
    ] == ["on"]
    v.execute(apply_row(rows[3], v.doc.saved))
    assert v.drawn.levels == 12 and v.prepass == 0
    assert replace(v.scene.render, prepass=None) == v.doc.saved.render
    # the panel itself draws inside an ImGui frame and returns commands, not changes
    v._measured = (v.path.stem, rows)  # as read for this file name
    v.platform.new_frame()
    from imgui_bundle import imgui

    imgui.begin("test")
    commands: list = []
    hud._measured(v, commands)
    imgui.end()
    v.platform.render()
    assert commands == [] and v.drawn.levels == 12
    # the suggestion is for the moving frames' size when the view came to rest: steady
    # while flying, where every frame changes that size
    settle(v)
    rest = v.frames.rest_size
    assert rest == v.frames.adaptive.moving_size()
    asked = []
    monkeypatch.setattr(hud, "best_within", lambda rows, ms, px: asked.append(px))
    for scale in (0.2, 0.3):  # two moving frames of other sizes
        v.frames.adaptive.scale = scale
        v.frames.dirty = True
        v.step(0.02)
        assert v.frames.rest_size == rest != v.frames.adaptive.moving_size()
        v.platform.new_frame()
        imgui.begin("test")
        hud._measured(v, [])
        imgui.end()
        v.platform.render()
    assert asked == [rest[0] * rest[1]] * 2
    (tmp_path / "tree" / "accuracy.csv").write_text("knob,value,ms\nscene,x,notanumber\n")
    assert load_measured("tree") is None


def test_the_viewer_draws_with_the_prepass_and_its_knob_is_an_undoable_edit(viewer):
    """The viewer flies with the pre-pass (tile VIEW_PREPASS) where the file has none; the
    HUD's knob sets the scene's render.prepass through the document (validated by the
    schema's range, one undo step), and the view then draws with it. Off or on, the window
    shows the same tree (pixels change only on outlines, where grazing rays may flip)."""
    v = viewer
    settle(v)
    assert v.scene.render.prepass is None, "the shipped tree gives no pre-pass of its own"
    assert v.prepass == VIEW_PREPASS and v.view_scene().render.prepass == VIEW_PREPASS
    with_prepass = v.read_window().astype(int)
    steps = len(v.doc.history.steps)
    v.execute([SetPrepass(65)])  # beyond the schema's range: refused, nothing changes
    assert "render.prepass = 65" in v.error and "≤ 64" in v.error
    assert v.prepass == VIEW_PREPASS and len(v.doc.history.steps) == steps
    v.execute([SetPrepass(8)])
    assert v.scene.render.prepass == 8 and v.view_scene().render.prepass == 8 and v.doc.dirty
    assert len(v.doc.history.steps) == steps + 1 and not v.error
    v.execute([Undo()])  # back to the file's: none given, so the view's own
    assert v.scene.render.prepass is None and v.view_scene().render.prepass == VIEW_PREPASS
    assert not v.doc.dirty
    v.execute([Redo()])
    assert v.view_scene().render.prepass == 8
    v.execute([SetPrepass(0)])  # off, as a file's 0 says
    assert v.scene.render.prepass == 0 and v.view_scene().render.prepass == 0
    settle(v)
    # the status line still says "redid …" at the window's foot (drawn whenever a turn
    # comes after the redo's: on a loaded machine settle takes more): a turn after it goes
    v.step(STATUS_SECONDS)
    assert v.status_line() == ""
    changed = (np.abs(v.read_window().astype(int) - with_prepass).max(-1) > 40).mean()
    assert 0 < changed < 0.02


def test_the_compute_path_draws_the_same_window(viewer):
    """The HUD's path knob: the compute path (rays traced in rounds, shaded in a deferred
    pass) shows the window the fragment path shows, pixel for pixel, while the adaptive
    resolution and the refinement tiles draw it (a shadow ray per pixel: the compute path
    traces no other)."""
    v = viewer
    v.set_render(shadow_block=1)
    settle(v)
    fragment = v.read_window()
    v.set_render(path="compute", steps=4)
    settle(v)
    assert v.view_scene().render.path == "compute"
    assert np.array_equal(v.read_window(), fragment)
    v.set_render(path="fragment", shadow_block=2)


def test_moving_frames_light_like_the_still_image(viewer, tmp_path):
    """While the view moves, frames keep the tree's soft shadows, their rays traced per 2 × 2
    pixels (gpu/passes.py): over the hit pixels, a moving frame at half the window's side has
    the mean colour of the still image's render at its size (shadow rays per pixel) to 2/255
    per channel, and a frame without the shadows (what moving frames drew before) does not.
    `--moving-effects` traces them per pixel: the moving frame at the window's size is then
    the still image itself. (The still image here has a shadow ray per pixel,
    ``shadow_block = 1``; with the default 2 it is the window-size image with 2 × 2 blocks.)"""
    from krsview.gpu.renderer import read_buffers

    v = viewer
    v.set_render(shadow_block=2)
    settle(v)
    assert v.frames.frame_state().state == "still" and v.frames.frame_state().shadows == 2
    v.set_render(shadow_block=1)
    a = v.frames.adaptive
    a.target_fps, a.scale = 0.5, 0.5  # every frame fits the budget: the scale only grows
    a.predict = lambda seconds_per_pixel: None  # from 0.5, not the scale that fits 2 s

    def buffers():
        fbo, size = v.frames.image
        return read_buffers(fbo, *size)

    hold(v, "W", 1)
    assert v.frames.image[1] == (80, 60) and v.frames.frame_state().state == "moving"
    assert v.frames.frame_state().shadows == 2
    moving = buffers()
    settle(v)
    still = buffers()
    assert still.color.shape[:2] == (SIZE[1], SIZE[0]) and v.frames.frame_state().shadows == 1
    plain = replace(v.view_scene(), effects=[e for e in v.scene.effects if e != "soft_shadows"])

    def at_80x60(scene):  # with the window's detail, as the moving frame (frames.detail)
        return v.renderer.render(scene, 80, 60, v.drawn.krs, detail_height=SIZE[1]).color

    def lit(color, hit):
        return color[hit].mean(0)

    target = lit(at_80x60(v.view_scene()), moving.hit)
    assert np.abs(lit(moving.color, moving.hit) - target).max() < 2 / 255
    assert np.abs(lit(at_80x60(plain), moving.hit) - target).max() > 8 / 255
    v.set_moving_effects(True)
    a.scale = 1.0
    hold(v, "S", 1)
    assert v.frames.frame_state().state == "still" and v.frames.refined  # no step to follow
    full = headless_render(v.view_scene().with_geometry(v.drawn.krs), tmp_path / "full", SIZE)
    close = np.abs(v.read_window().astype(int) - full.astype(int)).max(-1) <= 2
    assert close.mean() >= 0.99


def test_drop_down_lists_are_opaque(viewer):
    """A HUD combo's open list hides the fields under it: ImGui's default popup background
    (alpha 0.94, the negative control) let their text show through its entries."""
    from imgui_bundle import imgui

    bg = imgui.get_style().color_(imgui.Col_.popup_bg.value)
    assert bg.w == 1.0
    imgui.style_colors_dark()  # ImGui's own default
    assert imgui.get_style().color_(imgui.Col_.popup_bg.value).w < 1.0


def test_the_title_bar_names_the_scene_the_hud_opened(viewer, monkeypatch):
    """Another preset chosen in the HUD: the title bar names it (it kept the first scene's
    name). Control: nothing is set before."""
    import glfw

    from krsview.viewer.commands import OpenPreset

    titles: list[str] = []
    monkeypatch.setattr(glfw, "set_window_title", lambda window, title: titles.append(title))
    viewer.step(0.02)
    assert titles == []
    viewer.execute([OpenPreset(resolve("palm"))])
    assert titles == ["krsview — palm"] and viewer.scene.name == "palm"


def test_f6_without_a_path_says_how_to_record_one_and_a_new_scene_starts_unsaid(viewer):
    """F6 with no camera path recorded says how to record one (it did nothing); what was
    said of one scene ('replay finished', a bookmark's file) is gone when another opens."""
    from krsview.viewer.commands import OpenPreset, Replay

    v = viewer
    assert v.file.recorder.path is None
    v.execute([Replay()])
    v.step(0.02)
    assert "F5 records one" in v.message and v.file.recorder.replay_start is None
    v.execute([OpenPreset(resolve("rock"))])
    assert v.message == "" and v.scene.name == "rock"


def test_the_hud_names_a_scene_file_of_ones_own_as_its_file(display, tmp_path, monkeypatch):
    """The HUD's preset list shows a shipped preset by its name and a file of one's own as
    that file (it showed a blank entry, or a preset's name for a copy called tree.toml), and
    with another preset open it still offers that file back."""
    from imgui_bundle import imgui

    from krsview.viewer.commands import OpenPreset
    from krsview.viewer.window import Viewer

    from .test_editor import open_from_start

    open_from_start(monkeypatch, "scene, camera, output")
    previews: list[str] = []
    begin = imgui.begin_combo

    def spy(label, preview, *a):
        previews.append(preview)
        return begin(label, preview, *a)

    monkeypatch.setattr(imgui, "begin_combo", spy)
    shutil.copy(resolve("tree"), tmp_path / "tree.toml")
    for path, name in (
        (resolve("tree"), "tree"),
        (tmp_path / "tree.toml", "tree.toml (your file)"),
    ):
        v = Viewer(path, size=SIZE, hud=True)
        try:
            previews.clear()
            v.step(0.02)
            v.step(0.02)
            assert name in previews, previews
            if name.endswith("(your file)"):  # another preset opened: the list leads back
                v.execute([OpenPreset(resolve("palm"))])
                assert v.file.mine == path and v.scene.name == "palm"
                v.execute([OpenPreset(v.file.mine)])
                assert v.path == path and v.scene.name == "tree"
        finally:
            v.close()


def test_f6_said_at_the_foot_while_the_hud_is_hidden(viewer):
    """The HUD hidden (the viewer fixture's), F6 without a path says so at the window's foot
    too (it said it only in the hidden HUD)."""
    from krsview.viewer.commands import Replay

    v = viewer
    assert not v.hud and v.status_line() == ""
    v.execute([Replay()])
    v.step(0.02)
    assert "F5 records one" in v.status_line()
