"""The edit panel and the HUD in real windows under Xvfb, with real pointer and key events:
folding the panel gives the view the whole width (the scene stays in the middle of what is
free); a route level's ``grown`` is text, not a field; a shipped preset's save-as field
starts at its copy, never in the package; a value the viewer's HUD refuses stays in its
field with the message under it, as the editor's panel keeps its own."""

from __future__ import annotations

import shutil
from contextlib import contextmanager

import numpy as np
import pytest

from krsview.editor.commands import Bake, SaveAs
from krsview.editor.layout import MARGIN, Layout
from krsview.scene import load_scene
from krsview.scene.presets import PRESET_DIR, resolve
from krsview.viewer.hud import HUD_RIGHT

from .test_editor import LEVEL, click, open_from_start, pump, scroll_to, window_xy, xdo
from .test_editor import type_at as type_into

SIZE = (640, 400)


@pytest.fixture
def tree_editor(display, tmp_path):
    from krsview.editor.window import Editor

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    e = Editor(path, size=SIZE)
    e.execute([Bake()])
    yield e
    e.close()


def target_column(e) -> float:
    from krsview.compile.camera import project

    x, _, _ = project(e.window_view(), np.array(e.scene.camera.target))
    return x


def test_folding_the_panel_gives_the_view_the_whole_width_and_unfolding_takes_it_back(
    tree_editor,
):
    """A click on the panel's fold arrow: the scene's target moves to the middle of the
    window, and back to the middle of the part left of the panel on unfolding. Negative
    control: unfolded, it is well off the window's middle."""
    from imgui_bundle import imgui

    e = tree_editor
    pump(e, 3)
    x0, x1 = e.layout.free(SIZE)
    assert abs(target_column(e) - (x0 + x1) / 2) < 2
    assert abs(target_column(e) - SIZE[0] / 2) > 50, "negative control: already centred"
    w = imgui.internal.find_window_by_name("edit")
    arrow = window_xy(e, w.pos.x + 10, w.pos.y + imgui.get_frame_height() / 2)
    for folded, middle in ((True, SIZE[0] / 2), (False, (x0 + x1) / 2)):
        xdo("mousemove", *map(round, arrow))
        pump(e, 2)
        xdo("click", 1)
        pump(e, 3)
        assert e.layout.folded is folded
        assert imgui.internal.find_window_by_name("edit").collapsed is folded
        assert abs(target_column(e) - middle) < 2, (folded, target_column(e), middle)


def test_f1_gives_the_view_the_whole_width_and_takes_it_back(tree_editor):
    """F1 (a real key) hides the panel with the HUD: the scene's target moves to the middle
    of the window, as when the panel folds, and back beside the panel when F1 shows it again
    (it stayed in the middle of a part no longer covered [a real-window review]). The
    control: with the panel shown it is well off the window's middle."""
    e = tree_editor
    pump(e, 3)
    x0, x1 = e.layout.free(SIZE)
    assert abs(target_column(e) - SIZE[0] / 2) > 50, "control: already centred"
    for hud, middle in ((False, SIZE[0] / 2), (True, (x0 + x1) / 2)):
        xdo("key", "F1")
        pump(e, 3)
        assert e.viewer.hud is hud
        assert abs(target_column(e) - middle) < 2, (hud, target_column(e), middle)


def test_a_levels_grown_depth_is_text_that_clicks_and_typing_do_not_change(tree_editor):
    """The selected level's ``grown`` (bookkeeping for growing again) is a line of text:
    ctrl+click on it and typing a number changes nothing and refuses nothing (a field took
    the typing and refused the depth). Negative control: the same on the radius field just
    above edits the radius (one undo step)."""
    e = tree_editor
    e.select_level(LEVEL)
    pump(e, 3)
    level = ("route", "levels", LEVEL)
    grown = e.scene.route.levels[LEVEL].grown
    assert grown is not None

    def type_at(field: str, text: str) -> None:
        x0, y0, _, y1 = scroll_to(e, (*level, field), 40, 5)
        type_into(e, window_xy(e, x0 + 20, (y0 + y1) / 2), text)

    steps = len(e.doc.history.steps)
    type_at("grown", "7")  # a depth another level has: a field would refuse it, and say so
    assert e.scene.route.levels[LEVEL].grown == grown
    assert len(e.doc.history.steps) == steps
    assert e.viewer.error == "" and (*level, "grown") not in e.viewer.interactions.refused
    type_at("radius", "0.125")
    assert e.scene.route.levels[LEVEL].radius == 0.125, "negative control: a field edits"
    assert len(e.doc.history.steps) == steps + 1


def test_a_shipped_presets_save_as_field_starts_at_its_copy(display, tmp_path, monkeypatch):
    """Opened from the package, the save-as field holds ./tree.toml in the working folder
    and "save as" writes there, the package untouched. Negative control: a user's own file
    starts with its own path."""
    from krsview.editor.window import Editor

    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    before = {p.name: p.stat().st_mtime_ns for p in PRESET_DIR.iterdir()}
    e = Editor(resolve("tree"), size=SIZE)
    try:
        assert e.file.save_as_text == str(tmp_path / "tree.toml")
        e.execute([Bake()])
        pump(e)
        e.execute([SaveAs()])
        assert e.path == tmp_path / "tree.toml" and load_scene(e.path).route is not None
    finally:
        e.close()
    assert {p.name: p.stat().st_mtime_ns for p in PRESET_DIR.iterdir()} == before
    mine = tmp_path / "mine.toml"
    shutil.copy(resolve("tree"), mine)
    e = Editor(mine, size=SIZE)
    try:
        assert e.file.save_as_text == str(mine)
    finally:
        e.close()


def test_a_save_as_path_longer_than_its_field_is_whole_on_hover(tree_editor, monkeypatch):
    """The save-as field shows a long path's start only, so the file's name is cut off; the
    pointer over it shows the whole path (real X events). The control: a short path, whole
    in the field, gets no tooltip."""
    from imgui_bundle import imgui

    from krsview.editor.commands import SetSaveAsText

    e, field = tree_editor, {}
    box = imgui.input_text

    def recorded(label, *a):
        out = box(label, *a)
        if label == "##saveas":
            field["rect"] = (imgui.get_item_rect_min(), imgui.get_item_rect_max())
        return out

    monkeypatch.setattr(imgui, "input_text", recorded)

    def tips() -> list[str]:
        return [
            w.name
            for w in imgui.get_current_context().windows
            if w.name.startswith("##Tooltip") and w.active
        ]

    for text, tip in (("short.toml", False), ("/a/" + "long_folder/" * 8 + "mine.toml", True)):
        e.execute([SetSaveAsText(text)])
        pump(e)
        lo, hi = field["rect"]
        xdo("mousemove", *map(round, window_xy(e, (lo.x + hi.x) / 2, (lo.y + hi.y) / 2)))
        pump(e, 3)
        assert bool(tips()) == tip, (text, tips())
        xdo("mousemove", *map(round, window_xy(e, 20, 390)))  # off the field: the tip goes
        pump(e, 2)


def test_a_value_the_viewers_hud_refuses_stays_in_its_field_with_its_message(
    display, tmp_path, monkeypatch
):
    """In the viewer (no editor), type 0 into the HUD's max_iterations (allowed 1..10000):
    the field keeps 0 on red with the message under it, the scene keeps 256, the HUD's error
    line stays empty; a valid value clears it, Esc cancels a refused one. Negative control:
    no red there before."""
    import glfw

    from krsview.viewer.window import Viewer

    open_from_start(monkeypatch, "accuracy and view")
    monkeypatch.setattr("krsview.viewer.hud.FOLDED_BELOW", 0.0)  # unfolded at 640 wide
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(640, 720))
    field = ("render", "max_iterations")

    def turn(n: int = 3) -> None:
        for _ in range(n):
            glfw.poll_events()
            v.step(0.02)

    def red_below() -> int:
        x0, y0, x1, y1 = v.interactions.rects[field]
        shot = v.read_window().astype(int)
        r, g, b = (shot[round(y1) : round(y1) + 34, round(x0) : round(x1), k] for k in range(3))
        text = (r > 180) & (g < 140) & (b < 130) & (r - g > 80)
        box = shot[round(y0) + 2 : round(y1) - 2, round(x0) + 2 : round(x1) - 60]
        return int(text.sum()) + int((np.abs(box - [140, 20, 15]) < 40).all(-1).sum())

    def type_in(text: str) -> None:
        x0, y0, x1, y1 = v.interactions.rects[field]
        wx, wy = glfw.get_window_pos(v.window)
        xdo("mousemove", round(wx + x0 + 30), round(wy + (y0 + y1) / 2))
        turn(2)
        xdo("keydown", "ctrl")
        xdo("click", 1)
        xdo("keyup", "ctrl")
        turn(2)
        xdo("key", "ctrl+a")
        xdo("type", text)
        turn(len(text) + 2)  # ImGui takes the typed characters one per frame
        xdo("key", "Return")
        turn(3)

    try:
        turn(4)
        assert field in v.interactions.rects, "the section is not open"
        assert red_below() == 0
        type_in("0")
        refused = v.interactions.refused.get(field)
        assert refused is not None and refused.value == 0, v.error
        assert "max_iterations" in refused.message and v.error == ""
        assert v.scene.render.max_iterations == 256
        turn(2)
        assert red_below() > 40, "no red field and message under it"
        type_in("300")
        assert v.scene.render.max_iterations == 300 and field not in v.interactions.refused
        assert red_below() == 0
        type_in("0")
        assert field in v.interactions.refused
        xdo("key", "Escape")
        turn(3)
        assert field not in v.interactions.refused and red_below() == 0
        assert v.scene.render.max_iterations == 300
    finally:
        v.close()


@contextmanager
def hud_open(monkeypatch, tmp_path, section="accuracy and view"):
    """A 640×720 viewer on a copy of tree, its HUD's ``section`` open from the start, and a
    function that makes event-loop turns; closed afterwards."""
    import glfw

    from krsview.viewer.window import Viewer

    open_from_start(monkeypatch, section)
    monkeypatch.setattr("krsview.viewer.hud.FOLDED_BELOW", 0.0)  # unfolded at 640 wide
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(640, 720))

    def turn(n: int = 3) -> None:
        for _ in range(n):
            glfw.poll_events()
            v.step(0.02)

    try:
        yield v, turn
    finally:
        v.close()


def hover(v, turn, field: tuple, dx: float | None = None) -> None:
    """The pointer onto a HUD ``field``, ``dx`` pixels into it (None: its middle), for two
    turns after the HUD's first four."""
    import glfw

    turn(4)
    x0, y0, x1, y1 = v.interactions.rects[field]
    wx, wy = glfw.get_window_pos(v.window)
    x = x0 + dx if dx is not None else (x0 + x1) / 2
    xdo("mousemove", round(wx + x), round(wy + (y0 + y1) / 2))
    turn(2)


def test_a_flight_key_let_go_while_a_field_has_the_keyboard_stops_the_flight(
    display, tmp_path, monkeypatch
):
    """Hold W, ctrl+click into a HUD field (ImGui takes the keyboard), let W go: the viewer
    lets it go too. It used to miss the release and fly on until W was pressed again.
    Control: W is held before, and the field has the keyboard when it is let go."""
    from imgui_bundle import imgui

    with hud_open(monkeypatch, tmp_path) as (v, turn):
        hover(v, turn, ("render", "max_iterations"), 30)
        xdo("keydown", "w")
        turn(2)
        assert "W" in v.input.held
        xdo("keydown", "ctrl")
        xdo("click", 1)
        xdo("keyup", "ctrl")
        turn(3)
        assert imgui.get_io().want_capture_keyboard, "control: the field has no keyboard"
        xdo("keyup", "w")
        turn(2)
        assert "W" not in v.input.held
        xdo("key", "Escape")
        turn(2)


def test_a_long_tooltip_wraps_inside_a_small_window(display, tmp_path, monkeypatch):
    """Hover the HUD's culling field in a window 640 px wide: its tooltip (a long help text and
    its range) wraps at TIP_EMS font sizes and lies inside the window; ImGui's own tooltip is
    one line, which ran off the window's right edge (the control: that line is wider than
    the window)."""
    from dataclasses import fields

    from imgui_bundle import imgui

    from krsview.scene.render import Render
    from krsview.viewer.widgets import TIP_EMS, tooltip_text

    with hud_open(monkeypatch, tmp_path) as (v, turn):
        hover(v, turn, ("render", "culling"), 10)
        turn(2)
        meta = next(dict(f.metadata) for f in fields(Render) if f.name == "culling")
        line = imgui.calc_text_size(tooltip_text(meta, str)).x
        assert line > 640, "control: the help fits on one line anyway"
        tip = next(
            w
            for w in imgui.get_current_context().windows
            if w.name.startswith("##Tooltip") and w.active
        )
        assert tip.pos.x >= 0 and tip.pos.x + tip.size.x <= 640, (tip.pos.x, tip.size.x)
        assert (
            tip.size.x
            <= TIP_EMS * imgui.get_font_size() + 2 * imgui.get_style().window_padding.x + 1
        )


def test_the_hud_scrolls_under_its_numbers_which_stay_in_sight(display, tmp_path, monkeypatch):
    """The HUD with its knobs open is taller than a 640×720 window: the wheel over it (real X
    events) scrolls its knobs, and the lines that say what the image on screen is (moving,
    refining k/n, still) stay at its top. The whole HUD scrolled, and they went with it (the
    control: the wheel did scroll something)."""
    import glfw
    from imgui_bundle import imgui

    from krsview.viewer.hud import HUD_BODY, HUD_TITLE

    with hud_open(monkeypatch, tmp_path) as (v, turn):
        turn(4)
        wx, wy = glfw.get_window_pos(v.window)
        xdo("mousemove", wx + 200, wy + 600)
        turn(2)
        for _ in range(4):
            xdo("click", 5)
            turn(2)
        hud = imgui.internal.find_window_by_name(HUD_TITLE)
        parts = [w for w in imgui.get_current_context().windows if w.name.startswith(HUD_TITLE)]
        assert max(w.scroll.y for w in parts) > 0, "control: the wheel scrolled nothing"
        assert hud.scroll.y == 0, "the numbers scrolled away"
        assert any(HUD_BODY in w.name and w.scroll.y > 0 for w in parts)
        assert hud.pos.y + hud.size.y <= 720, "the HUD runs off the window"


def test_escape_closes_an_open_drop_down_list_and_keeps_its_value(display, tmp_path, monkeypatch):
    """A click on the HUD's tracer combo opens its list; Esc closes it, the tracer as it was
    (ImGui's keyboard navigation, which would close it, is off). Negative control: the list
    is open before the key, and another key (J, which the viewer ignores)
    leaves it open."""
    from imgui_bundle import imgui

    def is_open() -> bool:
        return imgui.is_popup_open("", imgui.PopupFlags_.any_popup)

    with hud_open(monkeypatch, tmp_path) as (v, turn):
        hover(v, turn, ("render", "tracer"))
        xdo("click", 1)
        turn(3)
        assert is_open(), "the click opened no list"
        xdo("key", "j")
        turn(3)
        assert is_open(), "negative control: another key closed it"
        xdo("key", "Escape")
        turn(3)
        assert not is_open(), "Esc left the list open"
        assert v.scene.render.tracer == "sphere"


@pytest.mark.parametrize("side", ["left", "right"])
def test_the_panel_starts_below_the_hud_where_they_would_overlap(side):
    """The viewer's HUD bar sits at the top left, HUD_RIGHT wide: a panel docked left, or
    docked right in a window too narrow for both side by side (640×360), starts below it;
    docked right in a wide window (the negative control) it starts at the top."""
    bar = 20.0
    layout = Layout(side=side)
    x, y, width, _ = layout.panel((640, 360), bar, HUD_RIGHT)
    assert y == MARGIN + bar + MARGIN and x < HUD_RIGHT
    x, y, width, _ = layout.panel((1280, 720), bar, HUD_RIGHT)
    overlaps = x < HUD_RIGHT + MARGIN
    assert overlaps == (side == "left") and y == (MARGIN + bar + MARGIN if overlaps else MARGIN)


def test_the_hud_opened_in_the_editor_moves_off_the_panel_docked_left(display, tmp_path):
    """Docked left, the panel sits under the collapsed HUD's title bar; the HUD opened by a
    click on its arrow (real X events) moves beside the panel instead of covering it. The
    control: where it opened, at its own place, it covered the panel."""
    from imgui_bundle import imgui

    from krsview.editor.commands import PlacePanel
    from krsview.editor.panels import PANEL_TITLE
    from krsview.editor.window import Editor
    from krsview.viewer.hud import HUD_AT, HUD_TITLE
    from krsview.viewer.status import meets, window_rect

    mine = tmp_path / "mine.toml"
    shutil.copy(resolve("tree"), mine)
    e = Editor(mine, size=(1100, 620))
    try:
        pump(e)
        e.execute([PlacePanel("left", 340.0)])
        pump(e, 3)
        hud, panel = (imgui.internal.find_window_by_name(n) for n in (HUD_TITLE, PANEL_TITLE))
        assert hud.collapsed and not meets(window_rect(hud), window_rect(panel))
        bar = imgui.get_frame_height()
        click(e, window_xy(e, HUD_AT + bar / 2, HUD_AT + bar / 2))  # the arrow
        pump(e, 3)
        hud = imgui.internal.find_window_by_name(HUD_TITLE)
        assert not hud.collapsed, "the click opened nothing"
        assert not meets(window_rect(hud), window_rect(panel)), "the HUD covers the panel"
        opened = (HUD_AT, HUD_AT, HUD_AT + hud.size.x, HUD_AT + hud.size.y)
        assert meets(opened, window_rect(panel)), "control: opened in place, it covered it"
    finally:
        e.close()


def test_the_growth_parameters_labels_fit_in_the_panel(tree_editor, monkeypatch):
    """The structure section's growth fields leave room for their labels: each field and
    its name end inside the panel (branch_angle's name was cut off at its edge)."""
    from dataclasses import fields

    from imgui_bundle import imgui

    from krsview.scene.growth import Growth

    e = tree_editor
    node = imgui.tree_node

    def opened(label: str) -> bool:
        if label.startswith("growth"):
            imgui.set_next_item_open(True, imgui.Cond_.once)
        return node(label)

    monkeypatch.setattr(imgui, "tree_node", opened)
    pump(e, 3)
    w = imgui.internal.find_window_by_name("edit")
    right = w.pos.x + w.size.x - w.scrollbar_sizes.x
    shown = [
        f.name for f in fields(Growth) if ("route", "growth", f.name) in e.viewer.interactions.rects
    ]
    assert "branch_angle" in shown, shown
    for name in shown:  # a widget's rectangle holds its label
        x0, y0, x1, y1 = e.viewer.interactions.rects[("route", "growth", name)]
        assert x1 <= right + 0.5, (name, x1, right)


def test_ctrl_shift_s_asks_the_name_and_enter_saves_there(display, tmp_path):
    """Ctrl+Shift+S saved at once under whatever the panel's field held (its own file at
    first: a plain save). Now a dialog asks, its field focused: typed name, Enter, saved
    there; Esc cancels, writing nothing (the control)."""
    import glfw

    from krsview.editor.window import Editor

    mine = tmp_path / "mine.toml"
    shutil.copy(resolve("tree"), mine)
    e = Editor(mine, size=SIZE)
    try:
        x, y = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", x + SIZE[0] - 40, y + SIZE[1] - 40)
        pump(e)
        e.edit(("render", "epsilon_scale"), 2.0)
        xdo("key", "ctrl+shift+s")
        pump(e, 3)
        assert e.file.copy_to is not None and e.file.copy_to.text == str(mine)
        xdo("key", "Escape")
        pump(e, 3)
        assert e.file.copy_to is None and e.doc.dirty and sorted(tmp_path.iterdir()) == [mine]
        xdo("key", "ctrl+shift+s")
        pump(e, 3)
        other = tmp_path / "other.toml"
        xdo("key", "ctrl+a")
        xdo("type", str(other))
        pump(e, 2 * len(str(other)))  # ImGui takes the typed characters one per frame
        xdo("key", "Return")
        pump(e, 3)
        assert e.file.copy_to is None and e.path == other and not e.doc.dirty
        assert load_scene(other).render.epsilon_scale == 2.0
        assert load_scene(mine).render.epsilon_scale == 1.0
    finally:
        e.close()


def test_the_status_line_is_not_drawn_under_the_panel_docked_left(display, tmp_path):
    """Docked left, the panel reaches the window's foot: the status line (a bookmark's
    words) goes beside it. It went under it: the editor's gizmo draws over the whole window
    in a window of its own, so no gap was found (the control: that window is there)."""
    from imgui_bundle import imgui

    from krsview.editor.commands import PlacePanel
    from krsview.editor.window import Editor
    from krsview.viewer.commands import AddBookmark

    mine = tmp_path / "mine.toml"
    shutil.copy(resolve("tree"), mine)
    e = Editor(mine, size=(900, 500))
    try:
        pump(e)
        e.execute([PlacePanel("left", 320.0), AddBookmark()])
        pump(e, 3)
        status, panel = (imgui.internal.find_window_by_name(n) for n in ("##status", "edit"))
        assert panel.pos.x < 10 and panel.pos.y + panel.size.y > status.pos.y
        assert status.pos.x >= panel.pos.x + panel.size.x, "under the panel"
        wide = [w for w in imgui.get_current_context().windows if w.size.x >= 890]
        assert wide, "control: a window as wide as the editor's (the gizmo's)"
    finally:
        e.close()


def test_a_warning_or_an_error_appearing_moves_no_field(tree_editor, monkeypatch):
    """A warning appearing after an edit pushed the fields below it down by four lines, and
    a review's next Ctrl+click set another field; an error at the panel's top did the same.
    Warnings now keep one line (folded, counted), errors come last (and in the status line):
    every field stays where it was. Control: the warnings' line is there, and says them."""
    from imgui_bundle import imgui

    e = tree_editor
    e.selected = next(h for h in e.handles if h.path[-1] == "fork" and h.path[2] == 16)
    pump(e, 3)
    before = dict(e.viewer.interactions.rects)
    said = [(15, "route.levels[15]: the branch crosses the mirror"), (3, "another")]
    monkeypatch.setattr(type(e), "warnings", property(lambda self: said))
    e.viewer.error = "a refusal\nof two lines"
    lines: list[str] = []
    node = imgui.tree_node
    monkeypatch.setattr(
        imgui, "tree_node", lambda label, *a: (lines.append(label), node(label, *a))[1]
    )
    pump(e, 2)
    after = e.viewer.interactions.rects
    assert before and set(before) == set(after)
    assert all(abs(after[k][1] - before[k][1]) < 0.5 for k in before), "a field moved"
    assert any(s.startswith("2 warnings: branches Alg. 1 cuts") for s in lines)


def test_own_color_gives_a_level_the_albedo_it_is_drawn_in_and_takes_it_back(tree_editor):
    """The "own color" box of a level, clicked: a level with its own colour goes to the
    material's albedo (None); clicked again, it gets a colour of its own, that albedo, so
    its pixels do not change (it started at the default grey, and the level changed colour
    when ticked [review]). Negative control: its own bark colour, before, shows."""
    e = tree_editor
    e.select_level(LEVEL)
    pump(e, 3)
    path = ("route", "levels", LEVEL, "color")
    bark = e.scene.route.levels[LEVEL].color
    assert bark is not None and bark != e.scene.material.albedo

    def image():
        return e.viewer.renderer.render(e.scene, 96, 54).color

    def click_box() -> None:
        x0, y0, _, y1 = scroll_to(e, (*path, "own"), 40, 5)
        click(e, window_xy(e, x0 + 6, (y0 + y1) / 2))

    before = image()
    click_box()
    assert e.scene.route.levels[LEVEL].color is None
    albedo = image()
    assert not np.array_equal(albedo, before), "negative control: the bark colour shows"
    click_box()
    assert e.scene.route.levels[LEVEL].color == tuple(e.scene.material.albedo)
    assert np.array_equal(image(), albedo)  # ticked: nothing changes until it is set
    assert len(e.doc.history.steps) == 3  # the bake and one undo step per click


def test_the_opened_hud_ends_above_the_editors_timeline(display, tmp_path, monkeypatch):
    """In an 800×500 editor on a moving scene the timeline strip spans the foot of the view;
    the HUD opened by a click on its arrow (real X events), its accuracy section unfolded,
    ends above the strip and scrolls the rest, so the strip's play button and time bar stay
    in sight. It reached down over them. Control: with no room kept at the foot, the same
    HUD covers the strip."""
    from imgui_bundle import imgui

    from krsview.editor import drawing
    from krsview.editor.window import Editor
    from krsview.viewer.hud import HUD_AT, HUD_TITLE
    from krsview.viewer.status import meets, window_rect

    open_from_start(monkeypatch, "accuracy and view")
    mine = tmp_path / "curl.toml"
    shutil.copy(resolve("tree-growing"), mine)
    e = Editor(mine, size=(800, 500))

    def rects():
        hud, strip = (imgui.internal.find_window_by_name(n) for n in (HUD_TITLE, "##timeline"))
        assert not hud.collapsed, "the click opened nothing"
        return window_rect(hud), window_rect(strip)

    try:
        pump(e)
        bar = imgui.get_frame_height()
        click(e, window_xy(e, HUD_AT + bar / 2, HUD_AT + bar / 2))  # the arrow
        pump(e, 4)
        hud, strip = rects()
        assert not meets(hud, strip) and hud[3] <= strip[1] - HUD_AT
        monkeypatch.setattr(drawing, "STRIP_ROOM", 0.0)
        pump(e, 4)
        hud, strip = rects()
        assert meets(hud, strip), "control: the HUD is short enough anyway"
    finally:
        e.close()
