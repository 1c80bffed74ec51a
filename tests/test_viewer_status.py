"""What the viewer says about itself: the HUD's state of the image on screen (moving, refining
k/n rows, still) and where F12 wrote its screenshot."""

from __future__ import annotations

import os
import shutil

import numpy as np
import pytest
from imgui_bundle import imgui
from PIL import Image

from krsview.scene.presets import resolve
from krsview.viewer.screenshots import pictures_folder, save_screenshot

SIZE = (640, 360)  # wide enough to see the image right of the HUD
HUD_RIGHT = 460  # pixels
RGB = np.arange(4 * 6 * 3, dtype=np.uint8).reshape(4, 6, 3)


@pytest.fixture
def hud_viewer(display, tmp_path, monkeypatch):
    """A viewer with its HUD on; every line the HUD writes is kept in ``v.drawn``."""
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    drawn: list[str] = []
    text = imgui.text
    monkeypatch.setattr(imgui, "text", lambda s: (drawn.append(s), text(s))[1])
    v = Viewer(path, size=SIZE, hud=True)
    v.drawn = drawn
    yield v
    v.close()


def turn(v) -> tuple:
    """One event-loop turn: the state the HUD drew from, the lines it drew, the window."""
    v.drawn.clear()
    v.step(0.05)
    return v.frames.frame_state(), list(v.drawn), v.read_window()


def test_the_hud_shows_the_image_on_screen_moving_then_refining_then_still(hud_viewer):
    v = hud_viewer
    v.frames.adaptive.target_fps = 60.0  # the still image takes a few turns
    v.input.key("W", True)
    seen = [turn(v) for _ in range(4)]
    v.input.key("W", False)
    while seen[-1][0].state != "still":
        seen.append(turn(v))
        assert len(seen) < 400, "the view never became still"
    states = [s.state for s, _, _ in seen]
    k = states.index("refining")
    assert states == ["moving"] * k + ["refining"] * (len(states) - k - 1) + ["still"]
    assert k == 4 and len(states) - k - 1 >= 2, states  # moved 4 turns, refined in several
    # the HUD writes the state of the image on screen, for each state
    for s, drawn, _ in seen:
        assert drawn[0] == s.text() and drawn[1].startswith(f"traced in {s.seconds * 1e3:.1f} ms")
    moving, drawn, _ = seen[k - 1]
    w, h = moving.size
    assert moving.size == (w, h) != SIZE and w < SIZE[0]
    assert drawn[0] == f"moving: {w}×{h} ({w / SIZE[0]:.0%} of the window)"
    refining = [(s, d, window) for s, d, window in seen[k:-1]]
    rows = [s.rows for s, _, _ in refining]
    assert rows == sorted(rows) and rows[0][0] > 0 and rows[-1][0] < SIZE[1]
    assert {n for _, n in rows} == {SIZE[1]}
    assert refining[0][1][0] == f"refining {rows[0][0]}/{SIZE[1]} rows: {w}×{h} (" + (
        f"{w / SIZE[0]:.0%} of the window)"
    )
    # while refining, the window keeps the last moving frame: its size and its very pixels
    # (right of the HUD)
    assert all(s.size == (w, h) for s, _, _ in refining)
    right = [window[:, HUD_RIGHT:] for _, _, window in seen]
    assert all(np.array_equal(r, right[k - 1]) for r in right[k:-1])
    still, lines, _ = seen[-1]
    assert still.size == SIZE == v.frames.image[1] and still.rows == (0, 0)
    assert lines[0] == f"still: {SIZE[0]}×{SIZE[1]} (100% of the window)"
    assert not np.array_equal(right[-1], right[k - 1]), "the still image never reached the window"
    # negative control: the old first line's size, the adaptive (moving) one, is not the
    # still image's, nor is its text the refining one's
    a = v.frames.adaptive.moving_size()
    assert a != SIZE and f"{a[0]}×{a[1]}" not in lines[0] and lines[0] != refining[0][1][0]


def test_f12_writes_beside_the_scene_and_says_where(hud_viewer, capsys):
    v = hud_viewer
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
    v.clock += 10  # the status line goes after a few seconds; the HUD's message stays
    _, drawn, _ = turn(v)
    assert v.status_line() == "" and drawn.count(f"screenshot: {out}") == 0
    v.hud = False
    v.execute(v.input.commands())
    v.input.key("F12", True)
    turn(v)
    v.input.key("F12", False)
    _, drawn, _ = turn(v)
    assert [line for line in drawn if line.startswith("screenshot: ")] == [v.status_line()]


def test_screenshot_goes_beside_a_writable_scene(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    scene = tmp_path / "scenes" / "fern.toml"
    scene.parent.mkdir()
    out = save_screenshot(RGB, scene, "20260101-000000")
    assert out == tmp_path / "scenes" / "fern.screenshots" / "fern-20260101-000000.png"
    assert np.array_equal(np.asarray(Image.open(out)), RGB)
    assert os.listdir(out.parent) == [out.name]  # written whole: no temporary file left
    assert not (tmp_path / "home").exists()  # negative control: the fallback is not used


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
