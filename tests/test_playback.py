"""The viewer's clock (issue 29): playing advances the moment shown by wall time × speed round
the loop; paused, nothing moves."""

import shutil

import pytest

from krsview.scene.presets import resolve
from krsview.viewer.playback import SPEED_RANGE, Playback, Posing


def test_playing_advances_by_wall_time_times_speed_round_the_loop():
    p = Playback(time=9.0, duration=10.0, playing=True, speed=2.0)
    assert p.advance(0.25) and p.time == pytest.approx(9.5)
    assert p.advance(0.5) and p.time == pytest.approx(0.5)  # 10.5 wraps to 0.5
    p.playing = False  # the negative control: paused, the clock stands
    assert not p.advance(1.0) and p.time == pytest.approx(0.5)


@pytest.mark.parametrize("t, shown", [(-3.0, 0.0), (4.0, 4.0), (99.0, 10.0)])
def test_seek_stays_in_the_loop(t, shown):
    p = Playback(duration=10.0)
    p.seek(t)
    assert p.time == shown


def test_speed_stays_in_the_sliders_range():
    p = Playback()
    p.set_speed(100.0)
    assert p.speed == SPEED_RANGE[1]
    p.set_speed(0.0)
    assert p.speed == SPEED_RANGE[0]
    p.set_speed(1.5)
    assert p.speed == 1.5


def test_a_moment_asked_twice_is_posed_once(monkeypatch):
    """A turn asks the pose for the geometry and again for the image: the second is the
    first pose (palm-curl posed every moment twice, 9 ms each); a new moment or a new scene
    (an edit) poses anew."""
    import krsview
    from krsview.scene import scene as scene_module

    scene, posed = krsview.load("palm-curl"), []
    real = scene_module.pose
    monkeypatch.setattr(scene_module, "pose", lambda s: posed.append(s.time) or real(s))
    p = Posing()
    first = p.pose(scene, 1.5)
    assert p.pose(scene, 1.5) is first and posed == [1.5]
    assert p.pose(scene, 1.75) is not first and posed == [1.5, 1.75]  # controls
    edited = scene.edit("name", "edited")
    assert p.pose(edited, 1.75).name == "edited" and posed == [1.5, 1.75, 1.75]
    expected = krsview.load("palm-curl").at(1.5).posed()
    assert p.pose(scene, 1.5) == expected


def press(v, key: str) -> None:
    v.input.key(key, True)
    v.step(0.0)
    v.input.key(key, False)


def test_space_plays_the_sway_in_a_window_and_the_paused_frame_is_render_at_that_time(
    display, tmp_path
):
    """A real window (Xvfb): Space plays, time advances by wall time and each turn draws the
    tree anew (time counts as motion); paused, the image refines to what
    `krsview render --time T` draws (another process, no window)."""
    import shutil
    from dataclasses import replace

    import numpy as np

    from krsview.scene import load_scene
    from krsview.scene.presets import resolve
    from krsview.viewer.window import Viewer

    from .conftest import headless_render

    path = tmp_path / "tree-sway.toml"
    shutil.copy(resolve("tree-sway"), path)
    v = Viewer(path, size=(160, 120), hud=False)
    try:
        for _ in range(400):
            v.step(0.02)
            if v.frames.refined:
                break
        assert v.is_idle() and v.drawn.playback.time == 0.0
        rest = v.read_window()
        press(v, "Space")
        assert v.drawn.playback.playing
        changed, last = 0, rest
        for _ in range(6):
            v.step(0.25)
            now = v.read_window()
            changed += int(np.abs(now.astype(int) - last).max() > 40)
            last = now
            assert not v.is_idle(), "a playing scene let the loop wait for events"
        assert v.drawn.playback.time == pytest.approx(1.5)
        assert changed >= 5, f"the tree moved in {changed} of 6 turns"
        press(v, "Space")
        assert not v.drawn.playback.playing
        for _ in range(400):
            v.step(0.02)
            if v.frames.refined:
                break
        t = v.drawn.playback.time
        shot = v.read_window().astype(int)
        scene = replace(load_scene(path), camera=v.camera.to_camera())
        ref = headless_render(scene, tmp_path / "at", (160, 120), "--time", str(t)).astype(int)
        close = np.abs(shot - ref).max(-1) <= 2
        assert close.mean() >= 0.99, f"window and render --time agree on {close.mean():.2%}"
        # negative control: the rest pose is another picture
        assert (np.abs(rest - ref).max(-1) <= 2).mean() < close.mean() - 0.005
    finally:
        v.close()


def test_space_on_a_scene_that_does_not_move_says_so(display, tmp_path):
    import shutil

    from krsview.scene.presets import resolve
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(64, 48), hud=False)
    try:
        press(v, "Space")
        assert not v.drawn.playback.playing and "nothing in this scene moves" in v.message
    finally:
        v.close()


def test_a_moment_that_cannot_be_posed_shows_why_and_keeps_the_last_pose(display, tmp_path):
    """A track whose blend breaks its field's rule between two valid keys (a mirror normal
    turned through zero, at 1 s): scrubbing there shows the one-line error and draws the last
    pose; scrubbing on poses again and clears it. No traceback, no NaN image."""
    import numpy as np

    from krsview import load
    from krsview.scene import save_scene
    from krsview.viewer.commands import SetTime
    from krsview.viewer.window import Viewer

    s = load("tree").with_geometry(load("tree").tree.route().krs())
    s = s.edit("krs.levels[20].mirror.normal", [1.0, 0.0, 0.0])
    track = {"path": "krs.levels[20].mirror.normal", "keys": [[0, [1, 0, 0]], [2, [-1, 0, 0]]]}
    s = s.edit("animation", {"tracks": [dict(track, interpolation="linear")]})
    path = tmp_path / "flip.toml"
    save_scene(s, path)
    v = Viewer(path, size=(64, 48), hud=False)
    try:
        v.execute([SetTime(0.5)])
        v.step(0.02)
        assert not v.error
        before = v.read_window()
        v.execute([SetTime(1.0)])
        v.step(0.02)
        assert "animation.tracks[0]" in v.error and "\n" not in v.error
        assert np.isfinite(v.read_window()).all() and v.read_window().any()
        assert v.view_scene().krs == s.at(0.5).posed().krs  # the last pose, still drawn
        v.execute([SetTime(1.6)])
        v.step(0.02)
        assert not v.error, "posing again did not clear the error"
        assert (v.read_window() != before).any()
    finally:
        v.close()


def test_a_keyed_camera_is_followed_while_playing_and_flown_when_paused(display, tmp_path):
    """tree-growing keys the camera (it steps back as the tree grows): playing puts the view
    where the track does; paused, W flies from there, and R goes back to the keyed camera
    of the moment shown (it went to the file's camera, the first moment's close-up)."""
    import shutil

    import numpy as np

    from krsview.scene import load_scene
    from krsview.scene.presets import resolve
    from krsview.viewer.window import Viewer

    path = tmp_path / "grow.toml"
    shutil.copy(resolve("tree-growing"), path)
    v = Viewer(path, size=(64, 48), hud=False)
    try:
        press(v, "Space")
        for _ in range(8):
            v.step(0.5)
        t = v.drawn.playback.time
        keyed = load_scene(path).at(t).posed().camera.position
        assert np.allclose(v.camera.position, keyed, atol=1e-9)
        assert not np.allclose(keyed, load_scene(path).camera.position, atol=0.1)  # it moved
        press(v, "Space")
        v.input.key("W", True)
        for _ in range(4):
            v.step(0.1)
        v.input.key("W", False)
        assert np.linalg.norm(v.camera.position - np.array(keyed)) > 0.05, "paused, W did not fly"
        press(v, "R")  # the keyed camera at this moment, not the file's first one
        v.step(0.01)
        assert np.allclose(v.camera.position, keyed, atol=1e-9), "R took the first moment's"
    finally:
        v.close()


def test_playing_past_the_last_key_redraws_nothing_and_the_image_refines(display, tmp_path):
    """tree-growing's keys end at 7.5 s: played on from 8 s nothing changes, so no turn asks
    for a new image and the view refines to still; between keys every turn asks for one
    (the control)."""
    from krsview.scene import load_scene, save_scene
    from krsview.scene.presets import resolve
    from krsview.viewer.window import Viewer

    s = load_scene(resolve("tree-growing"))
    path = tmp_path / "grow.toml"
    save_scene(s.at(8.0).edit("animation.duration", 20.0), path)
    v = Viewer(path, size=(64, 48), hud=False)
    try:
        press(v, "Space")
        asked = 0
        for _ in range(20):
            v.move(0.05)  # the clock advances here; a new image is asked for by `dirty`
            asked += v.frames.dirty
            v.step(0.0)
        assert v.drawn.playback.playing and asked == 0, f"{asked} new images past the last key"
        assert v.frames.refined
        v.drawn.set_time(3.0)  # the control: between keys each turn asks
        v.step(0.0)
        asked = 0
        for _ in range(5):
            v.move(0.05)
            asked += v.frames.dirty
            v.step(0.0)
        assert asked == 5
    finally:
        v.close()


def test_nan_typed_for_the_time_or_the_speed_is_ignored():
    """A NaN froze the clock at a time of NaN (the HUD's slider let it through); ∞ is the
    end of the range, as any value past it."""
    p = Playback(time=2.0, duration=10.0, speed=1.5)
    p.seek(float("nan"))
    p.set_speed(float("nan"))
    assert (p.time, p.speed) == (2.0, 1.5)
    p.seek(float("inf"))
    p.set_speed(float("inf"))
    assert (p.time, p.speed) == (10.0, SPEED_RANGE[1])  # control: a number past the end


@pytest.mark.usefixtures("unfolded_hud")
def test_a_speed_typed_into_the_hud_is_that_speed_and_stays_in_range(display, tmp_path):
    """Ctrl+click the HUD's speed slider and type, with real X events: 2 plays ×2 (the typed
    value was the slider's exponent, ×4), 1e9 is taken to the top of the range (2**1e9
    overflowed and closed the window, losing an editor's unsaved edits), nan leaves the
    speed as it was. Control: the speed before typing is 1."""
    import glfw

    from krsview.viewer.window import Viewer

    from .test_editor import pump, type_at

    path = tmp_path / "tree-sway.toml"
    shutil.copy(resolve("tree-sway"), path)
    v = Viewer(path, size=(640, 480), hud=True)
    try:
        pump(v, 3)
        assert v.drawn.playback.speed == 1.0
        wx, wy = glfw.get_window_pos(v.window)

        def typed(text: str) -> float:
            x0, y0, x1, y1 = v.interactions.rects[("playback", "speed")]
            type_at(v, (wx + (x0 + x1) / 2, wy + (y0 + y1) / 2), text)
            return v.drawn.playback.speed

        assert typed("2") == pytest.approx(2.0)
        assert typed("1e9") == SPEED_RANGE[1]
        assert typed("0.5") == pytest.approx(0.5)
        assert typed("nan") == pytest.approx(0.5)
        assert not glfw.window_should_close(v.window)
    finally:
        v.close()


@pytest.mark.usefixtures("unfolded_hud")
def test_numbers_typed_into_the_huds_whole_number_fields_are_taken_or_refused(
    display, tmp_path, monkeypatch
):
    """Real X events into the HUD's 'accuracy and view' section. The levels slider: -1 closed
    the window (an IndexError cutting the tree); now it is taken at the slider's end, 1. The
    iteration cap (a whole-number field): 2.5 was read as 2 and 1e30 as 1, without a word;
    now both stay red in the field with the schema's reason, and the cap is unchanged.
    Control: a whole number typed is taken."""
    import glfw

    from krsview.viewer.window import Viewer

    from .test_editor import open_from_start, pump, type_at

    open_from_start(monkeypatch, "accuracy and view")
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(640, 720), hud=True)
    try:
        pump(v, 3)
        wx, wy = glfw.get_window_pos(v.window)

        def centre(key):
            x0, y0, x1, y1 = v.interactions.rects[key]
            return wx + (x0 + x1) / 2, wy + (y0 + y1) / 2

        type_at(v, centre(("view", "levels")), "--", "-1")
        assert not glfw.window_should_close(v.window) and v.drawn.levels == 1
        cap = v.scene.render.max_iterations
        for text, said in (("2.5", "expected a whole number"), ("1e30", "allowed: 1 ≤ value")):
            type_at(v, centre(("render", "max_iterations")), text)
            assert v.scene.render.max_iterations == cap, text
            refused = v.interactions.refused[("render", "max_iterations")]
            assert said in refused.message, refused.message
        type_at(v, centre(("render", "max_iterations")), "300")  # control
        assert v.scene.render.max_iterations == 300, v.interactions.refused
        assert ("render", "max_iterations") not in v.interactions.refused
    finally:
        v.close()
