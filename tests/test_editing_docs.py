"""The shaping walk-through's saved files (docs/editing/, [issue 28]) are valid scene files and
differ from the shipped presets exactly as the walk-through says: the tree gained two levels
and lost one, is tapered and has a fork moved; the palm's leaflet steps shrink and curl more.
Each check is run on the preset itself too, which must fail it, so the docs cannot rot.
Last, what the walk-through found wrong in the window, driven by real pointer events."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from krsview.scene import Scene, load_scene, save_scene
from krsview.scene.presets import resolve

from .test_editor import open_from_start, pump, xdo
from .test_structure import outline_row

DOCS = Path(__file__).resolve().parents[1] / "docs" / "editing"
TAPER = 0.75  # the structure section's taper the walk-through applies


def baked(scene: Scene) -> Scene:
    """A grown tree as its route (what the editor's "bake into a route" makes)."""
    return replace(scene, tree=None, route=scene.tree.route()) if scene.tree else scene


def tree_changes(shaped: Scene, original: Scene) -> list[str]:
    """What the tree walk-through promises that ``shaped`` lacks (empty: all of it)."""
    levels, start = shaped.route.levels, baked(original).route.levels
    wrong = []
    if len(levels) != len(start) + 1:
        wrong.append(f"{len(levels)} levels, want {len(start)} + 2 inserted − 1 removed")
    by_hand = [lv for lv in levels if lv.grown is None]
    if len(by_hand) != 2:
        wrong.append(f"{len(by_hand)} levels made by hand, want the 2 inserted")
    kept = {lv.grown for lv in levels} - {None}
    if len(kept) != len(start) - 1:
        wrong.append(f"{len(start) - len(kept)} grown levels removed, want 1")
    radii = np.array([lv.radius for lv in levels])
    if not np.allclose(radii[:-1] / radii[1:], TAPER, rtol=1e-9):
        wrong.append(f"widths not tapered by {TAPER} per level")
    grown = {lv.grown: lv for lv in start}
    moved = [
        lv.grown
        for lv in levels
        if lv.grown is not None and np.abs(np.subtract(lv.fork, grown[lv.grown].fork)).max() > 0.1
    ]
    if not moved:
        wrong.append("no fork moved by more than 0.1")
    if shaped.route.base != baked(original).route.base:
        wrong.append("the foot moved")
    if shaped.description == original.description:
        wrong.append("the preset's description (22 forks)")
    return wrong


def palm_changes(shaped: Scene, original: Scene) -> list[str]:
    """What the palm walk-through promises that ``shaped`` lacks: the same levels and kernels,
    every leaflet level's scale below the preset's and its curl stronger, the rest unchanged."""
    a, b = shaped.mokrs.levels, original.mokrs.levels
    if len(a) != len(b):
        return [f"{len(a)} levels, want {len(b)}"]
    wrong = ["the preset's description"] if shaped.description == original.description else []
    for i, (new, old) in enumerate(zip(a, b, strict=True)):
        if (new.kernel, new.reflect) != (old.kernel, old.reflect):
            wrong.append(f"level {i}: its kernel or reflection changed")
        if [s.kind for s in new.transform] != [s.kind for s in old.transform]:
            wrong.append(f"level {i}: its steps' kinds changed")
            continue
        for s, t in zip(new.transform, old.transform, strict=True):
            if s.kind == "scale" and not s.factor < t.factor - 0.01:
                wrong.append(f"level {i}: scale {s.factor:g}, want below {t.factor:g}")
            if s.kind == "rotate" and not s.degrees < t.degrees - 1.0:
                wrong.append(f"level {i}: rotate {s.degrees:g}°, want a stronger curl")
            if s.kind == "translate" and s != t:
                wrong.append(f"level {i}: the translate step changed")
    return wrong


@pytest.mark.parametrize(
    ("name", "preset", "changes"),
    [("tree-reshaped", "tree", tree_changes), ("palm-reshaped", "palm", palm_changes)],
)
def test_saved_walkthrough_differs_as_described(name, preset, changes):
    original = load_scene(resolve(preset))
    shaped = load_scene(DOCS / f"{name}.toml")  # validated by the scene schema on loading
    assert changes(shaped, original) == []
    # negative control: the preset itself fails every promise it can fail
    assert changes(baked(original), original)
    assert (DOCS / f"{name}.png").stat().st_size <= 200_000


def test_each_promise_is_checked():
    """Undoing one change of a saved file makes exactly that check fail."""
    tree, palm = load_scene(resolve("tree")), load_scene(resolve("palm"))
    shaped = load_scene(DOCS / "tree-reshaped.toml")
    route = shaped.route
    flat = replace(route, levels=[replace(lv, radius=0.1) for lv in route.levels])
    assert tree_changes(replace(shaped, route=flat), tree) == [
        "widths not tapered by 0.75 per level"
    ]
    regrown = [
        replace(lv, grown=k) if lv.grown is None else lv for k, lv in enumerate(route.levels)
    ]
    wrong = tree_changes(replace(shaped, route=replace(route, levels=regrown)), tree)
    assert wrong[0] == "0 levels made by hand, want the 2 inserted"
    moved = replace(route, base=(0.0, 0.5, 0.0))
    assert tree_changes(replace(shaped, route=moved), tree) == ["the foot moved"]
    shaped = load_scene(DOCS / "palm-reshaped.toml")
    levels = list(shaped.mokrs.levels)
    levels[4] = palm.mokrs.levels[4]  # one leaflet level as shipped
    wrong = palm_changes(replace(shaped, mokrs=replace(shaped.mokrs, levels=levels)), palm)
    assert wrong == [
        "level 4: scale 0.93, want below 0.93",
        "level 4: rotate -2.5°, want a stronger curl",
    ]


def test_the_outline_menu_acts_on_the_entry_it_marks(display, tmp_path):
    """A right-click on an outline entry selects it, so the menu's "remove this fork" acts on
    the marked entry (it used to act on the right-clicked one while another stayed marked).
    Negative control: a left click on another entry moves the mark there."""
    from imgui_bundle import imgui

    from krsview.editor.window import Editor

    scene = load_scene(resolve("tree"))
    path = tmp_path / "route.toml"
    save_scene(baked(replace(scene, tree=replace(scene.tree, levels=8))), path)
    e = Editor(path, size=(640, 400))
    try:
        pump(e)
        n = len(e.scene.route.levels)
        for button, row, popups in ((1, 1, 0), (3, 3, 1)):  # the top row is the trunk
            xdo("mousemove", *map(round, outline_row(e, row)))
            pump(e, 2)
            xdo("click", button)
            pump(e, 3)
            assert imgui.get_current_context().open_popup_stack.size() == popups
            assert e.selected is not None and e.selected.level == n - 1 - row, (button, row)
    finally:
        e.close()


def test_the_description_is_typed_in_the_panel_as_one_undo_step(display, tmp_path, monkeypatch):
    """After a reshaping, the scene's description can be told (the shipped tree's counts its
    forks): typed into its panel field with real keys, Enter makes it the scene's, one undo
    step, and saved. Negative control: the shipped description before, and again after Ctrl+Z."""
    import glfw

    from krsview.editor import commands as ec
    from krsview.editor.window import Editor

    open_from_start(monkeypatch, "name and description")
    path, text = tmp_path / "palm.toml", "a palm leaf rolled in"
    shutil.copy(resolve("palm"), path)
    shipped = load_scene(path).description
    e = Editor(path, size=(640, 400))
    try:
        pump(e, 4)
        x0, y0, x1, y1 = e.viewer.interactions.rects[("description",)]
        wx, wy = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", round(wx + x0 + 20), round(wy + (y0 + y1) / 2))
        pump(e, 2)
        xdo("click", 1)
        pump(e, 2)
        assert e.scene.description == shipped
        xdo("key", "ctrl+a")
        xdo("type", text)
        pump(e, len(text) + 2)  # ImGui takes the typed characters one per frame
        assert e.scene.description == shipped, "taken before Enter"
        xdo("key", "Return")
        pump(e, 3)
        assert e.scene.description == text
        assert len(e.doc.history.labels()[0]) == 1, e.doc.history.labels()
        e.execute([ec.Save()])
        assert load_scene(path).description == text
        xdo("mousemove", round(wx + 100), round(wy + 300))  # the view: keys are the editor's
        pump(e, 2)
        xdo("key", "ctrl+z")
        pump(e, 3)
        assert e.scene.description == shipped
        # a click elsewhere takes the text too (it was dropped); Esc gives it up
        x0, y0, x1, y1 = e.viewer.interactions.rects[("name",)]
        for leave, kept in (("click", "rolled"), ("Escape", "rolled")):
            xdo("mousemove", round(wx + x0 + 20), round(wy + (y0 + y1) / 2))
            pump(e, 2)
            xdo("click", 1)
            pump(e, 2)
            xdo("key", "ctrl+a")
            xdo("type", "rolled" if leave == "click" else "not this")
            pump(e, 12)
            if leave == "click":
                xdo("mousemove", round(wx + 100), round(wy + 300))
                pump(e, 2)
                xdo("click", 1)
            else:
                xdo("key", "Escape")
            pump(e, 3)
            assert e.scene.name == kept, leave
    finally:
        e.close()


def test_the_dragging_section_waits_for_something_to_drag(display, tmp_path, monkeypatch):
    """A grown tree has no handles, so the panel shows no "dragging" section (snap, a fork
    carries its subtree) until it is baked; then it does (the negative control)."""
    from imgui_bundle import imgui

    from krsview.editor import commands as ec
    from krsview.editor.window import Editor

    drawn: list[str] = []
    header = imgui.collapsing_header
    monkeypatch.setattr(
        imgui, "collapsing_header", lambda label, *a: drawn.append(label) or header(label, *a)
    )
    scene = load_scene(resolve("tree"))
    path = tmp_path / "tree.toml"
    save_scene(replace(scene, tree=replace(scene.tree, levels=8)), path)
    e = Editor(path, size=(640, 400))
    try:
        pump(e)
        assert "material" in drawn and "dragging" not in drawn, drawn
        e.execute([ec.Bake()])
        drawn.clear()
        pump(e)
        assert "dragging" in drawn, drawn
    finally:
        e.close()
