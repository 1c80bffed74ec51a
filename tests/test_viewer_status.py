"""What the viewer says about itself: the HUD's state of the image on screen (moving, refining
k/n, still), where F12 wrote its screenshot, and only the knobs that act on the setting."""

from __future__ import annotations

import os
import shutil
from dataclasses import replace

import numpy as np
import pytest
from imgui_bundle import imgui
from PIL import Image

from krsview import load
from krsview.scene.presets import resolve
from krsview.viewer.adaptive import Step
from krsview.viewer.hud import HUD_TITLE
from krsview.viewer.screenshots import pictures_folder, save_screenshot

SIZE = (640, 360)  # wide enough to see the image right of the HUD
HUD_RIGHT = 460  # pixels
RGB = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)


@pytest.fixture
def hud_viewer(display, tmp_path, monkeypatch, unfolded_hud):
    """A viewer with its HUD on; every line the HUD writes is kept in ``v.written``."""
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    drawn: list[str] = []
    text = imgui.text
    monkeypatch.setattr(imgui, "text", lambda s: (drawn.append(s), text(s))[1])
    v = Viewer(path, size=SIZE, hud=True)
    v.written = drawn
    yield v
    v.close()


def turn(v) -> tuple:
    """One event-loop turn: the state the HUD drew from, the lines it drew, the window."""
    v.written.clear()
    v.step(0.05)
    return v.frames.frame_state(), list(v.written), v.read_window()


def groups(seen: list[tuple]) -> list[list[tuple]]:
    """Consecutive turns showing the same image (the same FrameState object)."""
    out: list[list[tuple]] = []
    for turn_ in seen:
        if out and turn_[0] is out[-1][0][0]:
            out[-1].append(turn_)
        else:
            out.append([turn_])
    return out


def test_the_hud_shows_the_image_on_screen_moving_then_each_step_then_still(hud_viewer):
    v = hud_viewer
    v.set_render(shadow_block=1)  # the still image adds shadow rays per pixel: a step of its own
    v.frames.adaptive.target_fps = 60.0  # small moving frames; steps that take a few turns
    v.input.key("W", True)
    seen = [turn(v) for _ in range(4)]
    v.input.key("W", False)
    steps = v.frames.refinement.steps  # planned after the last moving frame
    n = len(steps)
    while seen[-1][0].state != "still":
        seen.append(turn(v))
        assert len(seen) < 400, "the view never became still"
    images = groups(seen)
    # four moving frames (the last one stays while the first step is traced), then each
    # step's image once it is done, the last one the still image
    assert [g[0][0].state for g in images[:4]] == ["moving"] * 4
    shown = [(g[0][0].state, g[0][0].step, g[0][0].size) for g in images[4:]]
    sizes = [v.frames.adaptive.size_at(step.scale) for step in steps]
    assert shown == [("refining", (k, n), sizes[k - 1]) for k in range(1, n)] + [
        ("still", (0, 0), SIZE)
    ]
    assert n >= 2 and steps[-2] == Step(1.0, 2, primary=True) and steps[-1] == Step(1.0, 1)
    # the HUD writes the state of the image on screen, for each state
    for s, drawn, _ in seen:
        assert drawn[0] == s.text() and drawn[1] == f"{s.timing()}; shaded view"
    moving = images[3][0][0]
    w, h = moving.size
    share = f"{w / SIZE[0]:.0%} of the window's width"
    assert w < SIZE[0] and images[3][0][1][0] == f"moving: {w}×{h} ({share})"
    first = images[4][0]
    w1, h1 = sizes[0]
    nxt = ", shadows next" if steps[0].primary else ""  # a fast machine plans no half step
    share = f"{w1 / SIZE[0]:.0%} of the window's width"
    assert first[1][0] == f"refining 1/{n}{nxt}: {w1}×{h1} ({share})"
    assert first[1][1].startswith("traced in ") and ", shadows per 2×2 px" in first[1][1]
    # the window-size primary image: lit by the blocks of the image before it, its own next
    primary, before = images[-2][0], images[-3][0]
    bw, bh = before[0].size
    assert primary[0].size == SIZE and primary[1][0].startswith(
        f"refining {n - 1}/{n}, shadows next"
    )
    assert primary[1][1].endswith(f", shadows per 2×2 px of the {bw}×{bh} image; shaded view")
    still, lines, _ = seen[-1]
    after = sum(g[0][0].seconds for g in images[4:])  # the refinement's images' tracing
    assert still.size == SIZE == v.frames.image[1] and lines[0] == (
        f"still (refined in {after:.2f} s): {SIZE[0]}×{SIZE[1]} (100% of the window's width)"
    )
    assert still.since_stop == pytest.approx(after) and still.since_stop > still.seconds
    assert "shadows per" not in lines[1]  # the still image's are per pixel
    # each image stays on screen, its very pixels (right of the HUD), until the next
    for g in images:
        assert all(np.array_equal(t[2][:, HUD_RIGHT:], g[0][2][:, HUD_RIGHT:]) for t in g)
    # negative control: the first step's image is not the moving frame's
    assert not np.array_equal(first[2][:, HUD_RIGHT:], images[3][-1][2][:, HUD_RIGHT:])
    a = v.frames.adaptive.moving_size()
    assert a != SIZE and f"{a[0]}×{a[1]}" not in lines[0]
    # the default [render] shadow_block: the still image shares its shadow rays too
    v.set_render(shadow_block=2)
    while not (v.frames.refined and seen[-1][0].state == "still" and seen[-1][0].shadows == 2):
        seen.append(turn(v))
        assert len(seen) < 800, "the view never became still"
    assert ", shadows per 2×2 px;" in seen[-1][1][1] and seen[-1][0].size == SIZE


def test_f12_writes_beside_the_scene_and_says_where(hud_viewer, capsys):
    from krsview.viewer.status import drawn_rect, meets

    v = hud_viewer
    turn(v)  # the HUD takes its height in its first frames (its knobs' part, then itself)
    v.input.key("F12", True)
    turn(v)
    v.input.key("F12", False)
    folder = v.path.parent / "tree.screenshots"
    (out,) = folder.iterdir()  # one PNG, no temporary file left
    assert out.suffix == ".png" and out.name.startswith("tree-")
    assert Image.open(out).size == SIZE
    assert v.status_line() == f"screenshot: {out}" and str(out) in capsys.readouterr().out
    _, drawn, _ = turn(v)
    assert f"screenshot: {out}" in drawn, "the status line is not drawn"
    # the path is too long for one line beside the HUD: the HUD ends above it, at the foot
    status, hud = (drawn_rect(n) for n in ("##status", HUD_TITLE))
    assert not meets(status, hud), "the status line covers the HUD"
    assert status[3] > SIZE[1] - 16 and status[2] > hud[2], (status, hud)
    v.clock += 10  # the status line goes after a few seconds; the HUD's message stays
    _, drawn, _ = turn(v)
    assert v.status_line() == "" and drawn.count(f"screenshot: {out}") == 0
    turn(v)  # the control: with nothing to say, the HUD reaches into the line's band again
    assert drawn_rect(HUD_TITLE)[3] > status[1]
    v.hud = False
    v.execute(v.input.commands())
    v.input.key("F12", True)
    turn(v)
    v.input.key("F12", False)
    _, drawn, _ = turn(v)
    assert [line for line in drawn if line.startswith("screenshot: ")] == [v.status_line()]


def test_an_error_is_the_status_line_in_red(hud_viewer, monkeypatch):
    """A scene file refused on reload: its error's first line is the status line at the
    window's foot, in red, while it stands, the HUD shown (whose own line at its end may be
    scrolled or folded out of sight) or hidden (F1); it used to show nowhere. What was said
    before it ("reloaded …") goes. A screenshot's path said after it takes the line for a
    while (the control: not red)."""
    import krsview.viewer.hudframe as hudframe

    v = hud_viewer
    text = v.path.read_text()
    v.edit(("render", "epsilon_scale"), 2.0)  # a HUD change: the file's contents replace it
    v.file.take()
    assert v.message == "reloaded tree.toml; the HUD's changes before it are one Ctrl+Z back"
    v.undo()
    assert v.scene.render.epsilon_scale == 2.0
    v.undo()
    v.file.take()
    assert v.message == "reloaded tree.toml", "control: nothing of the HUD's lost"
    v.path.write_text(text.replace("fov_y = 45", "fov_y = 60"))
    v.file.take()  # the file's camera changed: the view stays, and that is said
    assert v.message == "reloaded tree.toml; the view stays where it is (R: the file's camera)"
    assert v.scene.camera.fov_y == 60.0
    v.reset_view()  # R: the file's camera taken, and said no more
    assert v.message == "reloaded tree.toml"
    v.path.write_text(text.replace("branch_angle = 26.0", "branch_angle = 900.0"))
    v.file.take()
    assert "branch_angle" in v.error and v.message == ""
    assert v.status_line() == v.error.splitlines()[0] and v.status_is_error(v.status_line())
    v.say("screenshot: x.png")
    assert v.status_line() == "screenshot: x.png" and not v.status_is_error(v.status_line())
    v.clock += 10
    v.hud = False
    drawn = []
    real = hudframe.draw_status
    monkeypatch.setattr(
        hudframe,
        "draw_status",
        lambda status, error=False: (drawn.append((status, error)), real(status, error)),
    )
    turn(v)
    assert v.status_line() == v.error and (v.error, True) in drawn
    v.path.write_text(text)
    v.file.take()
    assert v.error == "" and v.status_line() == ""


def test_a_message_said_at_the_foot_is_not_also_in_the_hud(hud_viewer, monkeypatch):
    """A bookmark saved (B) was said twice, in the HUD and in the status line [a real-window
    review]: while the foot says it, the HUD does not; once the foot's line is gone the HUD
    keeps it (the control)."""
    v, wrapped = hud_viewer, []
    text_wrapped = imgui.text_wrapped
    monkeypatch.setattr(imgui, "text_wrapped", lambda s: (wrapped.append(s), text_wrapped(s))[1])
    turn(v)
    v.file.add_bookmark()
    turn(v)
    assert v.message.startswith("saved bookmark") and v.status_line() == v.message
    assert v.message not in wrapped and v.message in v.written
    v.clock += 10
    wrapped.clear()
    turn(v)
    assert v.status_line() == "" and v.message in wrapped


def test_an_error_said_after_a_message_takes_the_status_line_at_once(hud_viewer):
    """ "saved …" held the foot for its seconds while a refusal said after it waited unseen
    [a real-window review]: the newest takes the line. The controls: a message said after
    the error takes it in turn, and the same error set again does not take it back."""
    v = hud_viewer
    v.say("saved /tmp/x.toml")
    assert v.status_line() == "saved /tmp/x.toml"
    v.error = "save as: no folder /tmp/nowhere; save again to make it"
    assert v.status_line() == v.error and v.status_is_error(v.status_line())
    v.say("screenshot: x.png")
    assert v.status_line() == "screenshot: x.png"
    v.error = v.error  # the same error again (a field refused each frame): no change
    assert v.status_line() == "screenshot: x.png"


@pytest.mark.usefixtures("unfolded_hud")
def test_a_hud_reaching_the_foot_ends_above_the_status_line(display, tmp_path, monkeypatch):
    """A HUD tall enough to reach the window's foot ends above a status line too long for
    one line beside it (its knobs scroll in less height): neither covers the other. The
    control: with nothing to say, the same HUD reaches into the band the line takes. A short
    line goes beside the HUD, which keeps its height."""
    from krsview.viewer.status import drawn_rect, meets
    from krsview.viewer.window import Viewer

    from .test_editor import open_from_start

    open_from_start(monkeypatch, "accuracy and view")
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(520, 400), hud=True)
    try:
        for _ in range(3):
            v.step(0.05)
        alone = drawn_rect(HUD_TITLE)
        v.error = "a refusal long enough that no gap beside the HUD holds it on one line"
        for _ in range(3):
            v.step(0.05)
        status, hud = (drawn_rect(n) for n in ("##status", HUD_TITLE))
        assert not meets(status, hud), (status, hud)
        assert status[3] > 400 - 16 and hud[3] < status[1]  # the line at the foot, under it
        assert alone[3] > status[1], "control: the HUD alone does not reach the line's band"
        v.error = "no"  # fits on one line beside the HUD (56 px): the HUD keeps its height
        for _ in range(3):
            v.step(0.05)
        status, hud = (drawn_rect(n) for n in ("##status", HUD_TITLE))
        assert not meets(status, hud) and status[0] >= hud[2] and hud[3] > status[1]
    finally:
        v.close()


def test_in_the_editor_a_refusal_lies_between_the_hud_the_panel_and_the_timeline(display, tmp_path):
    """tree-growing at 800×500 with the HUD unfolded: a bake refused says why in a status
    line wrapped above the timeline, beside the panel, and the HUD ends above it; none of
    the four windows meets another (the line was drawn across the timeline and the panel).
    The control: before the refusal the HUD reaches into the band the line takes."""
    import glfw

    from krsview.editor.panels import PANEL_TITLE
    from krsview.editor.window import Editor
    from krsview.viewer.status import drawn_rect, meets

    from .test_editor import pump, xdo

    path = tmp_path / "tree-growing.toml"
    shutil.copy(resolve("tree-growing"), path)
    e = Editor(path, size=(800, 500))
    try:
        pump(e, 3)
        wx, wy = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", wx + 20, wy + 18)  # the HUD's arrow: it opens folded in the editor
        pump(e, 2)
        xdo("click", 1)
        pump(e, 2)
        xdo("mousemove", wx + 300, wy + 5)
        pump(e, 3)
        alone = drawn_rect(HUD_TITLE)
        assert alone[3] - alone[1] > 250, "the HUD did not unfold"
        e.bake()
        assert e.viewer.error.startswith("bake: "), e.viewer.error
        pump(e, 3)
        windows = {n: drawn_rect(n) for n in ("##status", HUD_TITLE, PANEL_TITLE, "##timeline")}
        for a in windows:
            for b in windows:
                assert a == b or not meets(windows[a], windows[b]), (a, b, windows)
        status, timeline = windows["##status"], windows["##timeline"]
        assert status[3] <= timeline[1] and status[1] >= windows[HUD_TITLE][3]
        assert alone[3] > status[1], "control: the HUD alone does not reach the line's band"
    finally:
        e.close()


def test_screenshot_goes_beside_a_writable_scene(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    scene = tmp_path / "scenes" / "fern.toml"
    scene.parent.mkdir()
    out = save_screenshot(RGB, scene, "20260101-000000")
    assert out == tmp_path / "scenes" / "fern.screenshots" / "fern-20260101-000000.png"
    assert np.array_equal(np.asarray(Image.open(out)), RGB)
    assert os.listdir(out.parent) == [out.name]  # written whole: no temporary file left
    assert not (tmp_path / "home").exists()  # negative control: the fallback is not used
    # two more in the same second: each a file of its own, none overwritten
    more = [save_screenshot(255 - RGB, scene, "20260101-000000") for _ in range(2)]
    assert [m.name for m in more] == ["fern-20260101-000000-2.png", "fern-20260101-000000-3.png"]
    assert np.array_equal(np.asarray(Image.open(out)), RGB)
    assert sorted(os.listdir(out.parent)) == sorted([out.name, *(m.name for m in more)])


def test_screenshot_of_a_read_only_scene_goes_to_the_pictures_folder(tmp_path, monkeypatch):
    home = tmp_path / "home"
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CONFIG_HOME", raising=False)
    scene = tmp_path / "installed" / "fern.toml"
    scene.parent.mkdir()
    (scene.parent / "fern.screenshots").write_text("")  # no folder can be made here, root or not
    scene.parent.chmod(0o555)
    try:
        out = save_screenshot(RGB, scene, "20260101-000000")
    finally:
        scene.parent.chmod(0o755)
    assert out == home / "Pictures" / "krsview" / "fern-20260101-000000.png"
    assert np.array_equal(np.asarray(Image.open(out)), RGB)


def test_screenshot_of_a_shipped_preset_goes_to_the_pictures_folder(tmp_path, monkeypatch):
    home = tmp_path / "home"
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CONFIG_HOME", raising=False)
    preset = resolve("tree")
    out = save_screenshot(RGB, preset, "20260101-000000")
    assert out == home / "Pictures" / "krsview" / "tree-20260101-000000.png"
    assert np.array_equal(np.asarray(Image.open(out)), RGB)
    assert not (preset.parent / "tree.screenshots").exists()  # the package's folder is left alone


@pytest.mark.skipif(not shutil.which("xdg-user-dir"), reason="xdg-user-dir is not installed")
def test_the_pictures_folder_is_the_users_xdg_one(tmp_path, monkeypatch):
    home = tmp_path / "home"
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CONFIG_HOME", raising=False)
    assert pictures_folder() == home / "Pictures" / "krsview"  # none set: xdg answers $HOME
    (home / ".config").mkdir(parents=True)
    (home / ".config" / "user-dirs.dirs").write_text('XDG_PICTURES_DIR="$HOME/Bilder"\n')
    assert pictures_folder() == home / "Bilder" / "krsview"


def test_a_screenshot_nowhere_writable_says_where_it_tried(tmp_path, monkeypatch):
    home = tmp_path / "home"
    home.write_text("")  # not a folder: nothing can be made under it
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.delenv("XDG_CONFIG_HOME", raising=False)
    scene = tmp_path / "fern.toml"
    (tmp_path / "fern.screenshots").write_text("")
    with pytest.raises(OSError, match=r"screenshot not written: .*fern\.screenshots: .*Pictures"):
        save_screenshot(RGB, scene, "20260101-000000")


def test_the_hud_offers_only_the_knobs_that_act_on_the_setting():
    from krsview.viewer.hud import knobs_shown

    render = load("tree").render
    tasks = {"shadow_tasks", "component_tasks"}
    fragment = set(knobs_shown(render))
    rounds = set(knobs_shown(replace(render, path="compute", steps=16)))
    lanes = set(knobs_shown(replace(render, path="compute", steps=0)))
    assert not fragment & (tasks | {"steps"}), "the compute path's knobs on the fragment path"
    assert rounds - fragment == tasks | {"steps"}, "the rounds' knobs are missing"
    assert lanes - fragment == {"steps"}, "persistent lanes trace no tasks"
    binary = set(knobs_shown(replace(render, tracer="binary")))
    assert {"xi_bonus", "xi_penalty"} <= binary and "relaxation" not in binary
    assert not {"xi_bonus", "xi_penalty"} & fragment


def test_a_coarse_image_draws_the_still_images_geometry_and_shading(renderer):
    """An image traced below the window's resolution draws the detail of the window's pixel
    (frames.Frames.detail, compile/camera.View.detail_height): ε, the level of detail, the
    textures' filter and the normals' smoothing. Its hits cover the view as the still
    image's do, within a fraction of a point, in the whole tree and inside the crown (zoom
    stops 2 and 6), at a quarter of the window's side; and its hits' mean colour is the
    still image's within 2 levels of 255. Negative controls: at its own pixel's detail every
    twig is a coarse pixel fatter (6 to 25 points more hits: crowns went solid while moving,
    then thinned at once when the camera stopped); with the window's ε alone (the last
    round's moving images) the hits agree but the bark's and leaves' texture is filtered
    away at the coarse pixel, and the whole tree is more than 8 levels brighter (a
    real-window review saw its crown darken by a fifth when the camera stopped)."""
    from dataclasses import replace

    from krsview import api
    from krsview.bench import zoom

    tree = api.fast_settings(api.load("tree"))
    stops = zoom.stops(tree, 12)
    window, size = (320, 180), (80, 45)

    def colour(f):
        return f.color[f.hit].mean(axis=0) * 255

    for scene in (tree, stops[2], stops[6]):
        still = renderer.render(scene, *window)
        coarse = renderer.render(scene, *size)
        moving = renderer.render(scene, *size, detail_height=window[1])
        assert abs(moving.hit.mean() - still.hit.mean()) < 0.005, scene.camera
        assert coarse.hit.mean() - still.hit.mean() > 0.01, scene.camera
        assert np.abs(colour(moving) - colour(still)).max() < 2.0, scene.camera
    render = replace(tree.render, epsilon_scale=tree.render.epsilon_scale * size[1] / window[1])
    eps_alone = renderer.render(replace(tree, render=render), *size)
    assert abs(eps_alone.hit.mean() - renderer.render(tree, *window).hit.mean()) < 0.005
    assert (colour(eps_alone) - colour(renderer.render(tree, *window))).min() > 8.0


def test_moving_and_refining_images_draw_the_windows_detail(hud_viewer, monkeypatch):
    """Every image the viewer traces below the window's size, moving or refining, draws the
    detail of the window's pixel; the still image its own."""
    import krsview.viewer.frames as frames

    v = hud_viewer
    made = []
    real = frames.PassImage

    def spy(renderer, targets, scene, size, *rest, detail_height=0):
        made.append((size, detail_height))
        return real(renderer, targets, scene, size, *rest, detail_height=detail_height)

    monkeypatch.setattr(frames, "PassImage", spy)
    v.input.key("W", True)
    for _ in range(4):
        turn(v)
    v.input.key("W", False)
    for _ in range(400):
        turn(v)
        if v.frames.refined:
            break
    full = v.frames.adaptive.full
    smaller = [(s, d) for s, d in made if s[1] < full[1]]
    assert smaller and any(s == full for s, _ in made), made
    assert all(d == full[1] for s, d in smaller), made
    assert all(d == 0 for s, d in made if s == full), made


def test_a_frame_that_compiled_is_not_counted_as_a_moving_frame(hud_viewer):
    """The first frame compiles the scene's shaders: the HUD's moving frames and the
    resolution's controller leave its time out."""
    v = hud_viewer
    compiles = v.renderer.programs.compiles
    scale = v.frames.adaptive.scale
    _, drawn, _ = turn(v)
    assert v.renderer.programs.compiles > compiles, "control: the first frame compiled"
    assert v.frames.frame_seconds == [] and v.frames.adaptive.scale == scale
    assert any(t.startswith("moving frames: none yet") for t in drawn)
    v.frames.dirty = True  # the view moved: the same programs draw again
    _, drawn, _ = turn(v)
    assert len(v.frames.frame_seconds) == 1 and v.frames.adaptive.history[-1] > 0
    assert any(t.startswith("moving frames: median ") for t in drawn)


def test_the_iterations_view_has_a_scale_and_a_legend(hud_viewer, monkeypatch):
    """The iterations view was white at the iteration cap (256 on tree), so a frame of 1–10
    iterations a pixel was nearly black, with no legend. White is now at the HUD's count
    (VIEW_WHITE at first), and the HUD draws the ramp with 0, N/2 and N under it; the
    control: the same image at the cap is darker."""
    from krsview.heatmap import VIEW_WHITE
    from krsview.viewer import commands as c

    v = hud_viewer
    header = imgui.collapsing_header  # the view's section open, as a person opens it
    monkeypatch.setattr(
        imgui,
        "collapsing_header",
        lambda label, *a: label == "accuracy and view" or header(label, *a),
    )
    v.execute([c.SetViewMode("iterations")])
    assert v.iteration_scale == VIEW_WHITE
    v.frames.dirty = True
    for _ in range(3):
        turn(v)
    v.execute([c.SetIterationScale(4)])
    _, drawn, bright = turn(v)
    legend = drawn[drawn.index("0") :][:3] if "0" in drawn else []
    assert legend == ["0", "2", "4"], "the legend's numbers"
    v.execute([c.SetIterationScale(v.scene.render.max_iterations)])
    _, _, dark = turn(v)
    view = np.s_[:, HUD_RIGHT:]
    assert bright[view].mean() > 2 * dark[view].mean() + 10


def test_the_hud_opens_any_scene_file_by_its_path(hud_viewer, monkeypatch, tmp_path):
    """The HUD listed the shipped presets and the last file of one's own: no other file
    could be opened. Its "open" field takes a path; Enter opens it (the control: a path
    that is no file says so and keeps the scene)."""
    from krsview.viewer import commands as c

    v = hud_viewer
    other = tmp_path / "mine" / "rock.toml"
    other.parent.mkdir()
    shutil.copy(resolve("rock"), other)
    header = imgui.collapsing_header
    monkeypatch.setattr(
        imgui,
        "collapsing_header",
        lambda label, *a: label == "scene, camera, output" or header(label, *a),
    )
    typed = [str(other)]
    monkeypatch.setattr(
        imgui, "input_text_with_hint", lambda label, hint, text, flags=0: (True, typed[0])
    )
    v.execute([c.SetIterationScale(8)])
    turn(v)
    assert v.path == other and v.scene.name == "rock" and v.file.open_text == str(other)
    from krsview.heatmap import VIEW_WHITE

    assert v.iteration_scale == VIEW_WHITE, "another scene: the iterations view's own scale"
    typed[0] = str(tmp_path / "none.toml")
    turn(v)
    assert v.path == other and "cannot read" in v.error
    v.execute([c.SetOpenText("")])


def test_a_flight_starts_at_the_scale_its_measured_cost_fits(hud_viewer, monkeypatch):
    """The first moving frame after the view came to rest is sized by the refinement's
    measured seconds per pixel (a review saw a first flight open with half a second of slow
    frames, the scale shrinking 0.7× a frame from half the window's side); the frames of a
    flight go on from the controller's scale (the control: no prediction between them)."""
    v = hud_viewer
    for _ in range(400):
        turn(v)
        if v.frames.refined:
            break
    asked: list[float] = []
    predict = v.frames.adaptive.predict
    monkeypatch.setattr(v.frames.adaptive, "predict", lambda c: (asked.append(c), predict(c))[1])
    v.frames.adaptive.scale = 1.0  # a scale far too large for the budget, as after a resize
    v.frames.adaptive.target_fps = 240.0  # a budget no window-size frame fits here
    v.input.key("W", True)
    turn(v)
    assert len(asked) == 1 and asked[0] == v.frames.moving_cost() > 0
    assert v.frames.shown.size[0] < v.frames.adaptive.full[0]
    turn(v)
    turn(v)
    v.input.key("W", False)
    assert len(asked) == 1, "a flight's later frames follow the controller"


def test_an_error_is_shown_once_its_further_lines_in_the_hud(hud_viewer, monkeypatch):
    """A refused reload's line was drawn twice, in the HUD and at the window's foot: the
    HUD now shows only the lines after the first (a shader's log), the status line the
    first. Control: a two-line error's second line is in the HUD."""
    v = hud_viewer
    wrapped: list[str] = []
    real = imgui.text_wrapped
    monkeypatch.setattr(imgui, "text_wrapped", lambda s: (wrapped.append(s), real(s))[1])
    v.path.write_text(v.path.read_text().replace("branch_angle = 26.0", "branch_angle = 900.0"))
    v.file.take()
    turn(v)
    assert v.status_line() == v.error and not any(v.error in s for s in wrapped)
    v.error = "first line\nsecond line"
    wrapped.clear()
    turn(v)
    assert "second line" in wrapped and not any("first line" in s for s in wrapped)


def test_undo_and_redo_say_what_they_undid_in_place_of_what_was_said_of_it(hud_viewer):
    """Ctrl+Z after a bookmark kept saying "bookmark … added" [a real-window review]: an undo
    or redo takes the message and the status line with the step's name. Control: a step
    that is not there says nothing and keeps what was said."""
    v = hud_viewer
    v.edit(("render", "epsilon_scale"), 2.0)
    v.message = "said of the edit"
    assert v.undo() and v.scene.render.epsilon_scale == 1.0
    assert v.message == "undid set render.epsilon_scale" == v.status_line()
    assert v.redo() and v.message == "redid set render.epsilon_scale" == v.status_line()
    v.message = "kept"
    assert not v.redo() and v.message == "kept"


@pytest.mark.usefixtures("unfolded_hud")
def test_the_huds_path_knob_shows_the_path_drawn_where_the_file_sets_none(
    display, tmp_path, monkeypatch
):
    """The file sets no path (None: the fragment path, which the view draws): the HUD's path
    knob shows "fragment", not a greyed "path: None" it could not change. Control: a file's
    own "compute" is shown as it is."""
    import krsview.viewer.hud as hud
    from krsview.viewer.window import Viewer

    from .test_editor import open_from_start

    open_from_start(monkeypatch, "accuracy and view")
    shown: dict[str, object] = {}
    widget = hud.field_widget

    def recording(label, value, meta, refused=None):
        shown[label] = value
        return widget(label, value, meta, refused)

    monkeypatch.setattr(hud, "field_widget", recording)
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=SIZE, hud=True)
    try:
        assert v.scene.render.path is None
        v.step(0.05)
        assert shown["path##render"] == "fragment"
        v.set_render(path="compute")
        v.step(0.05)
        assert shown["path##render"] == "compute"
    finally:
        v.close()


def test_a_narrow_window_opens_with_the_hud_folded(display, tmp_path):
    """At 640×400 the unfolded HUD (440 px wide) covered the trunk and most of the crown of
    the preset's view; a window narrower than two HUD widths opens it folded to its title
    bar (a click unfolds it). Control: a window 960 wide opens it unfolded, as before."""
    from krsview.viewer.status import drawn_rect
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    heights = {}
    for size in ((640, 400), (960, 400)):
        v = Viewer(path, size=size, hud=True)
        try:
            for _ in range(3):
                v.step(0.05)
            x0, y0, x1, y1 = drawn_rect(HUD_TITLE)
            heights[size[0]] = (y1 - y0) / imgui.get_frame_height()  # in lines
        finally:
            v.close()
    assert heights[640] < 1.5, heights  # its title bar
    assert heights[960] > 8, heights
