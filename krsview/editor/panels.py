"""The editor's ImGui panels. A panel reads the editor's state and returns commands; it never
writes the editor or the scene itself (the editor applies the commands through the document),
so the arrows run one way: editor window → panels."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields
from functools import partial
from typing import Any, Protocol

from imgui_bundle import imgui

from ..document.document import Document
from ..messages import counted
from ..scene import Scene
from ..scene.edits import get_at
from ..scene.render import Material
from ..viewer.commands import Command, Edit, Redo, Undo
from ..viewer.hud import HUD_RIGHT
from ..viewer.widgets import Interactions, field_widget, red_text, tooltip
from ..viewer.window import Viewer
from . import commands as ec
from .file_actions import FileActions
from .gizmo import Snap
from .handles import Handle, outline
from .keys import MARK_ROOM, key_marks, marked
from .layout import MIN_WIDTH, Layout
from .modals import answer_buttons, begin_modal
from .mokrs_panel import mokrs_section
from .saving import copy_dialog
from .structure_panel import outline_menu, structure_section

GEOMETRY_TABLES = ("krs", "route")  # a component's own geometry: too big for a panel
YELLOW = imgui.ImVec4(1.0, 0.85, 0.3, 1.0)
PANEL_TITLE = "edit"
WARNINGS_OPEN = 0  # warnings are folded under one line that counts them (it never moves)


class Edited(Protocol):
    """What the panels read of the editor (they write nothing: they return commands)."""

    viewer: Viewer
    selected: Handle | None
    warnings: list[tuple[int, str]]
    snap: Snap
    carry: bool
    file: FileActions  # save as, a conflict, the unsaved-edits and recovery questions
    scroll_outline: bool
    layout: Layout

    @property
    def doc(self) -> Document: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def handles(self) -> list[Handle]: ...
    def handled_scene(self) -> Scene: ...


def edit_panel(e: Edited, interactions: Interactions) -> list[Command]:
    out: list[Command] = []
    interactions.inline.clear()  # the fields drawn this frame show their own errors
    size = imgui.get_io().display_size
    x, y, width, height = e.layout.panel((size.x, size.y), imgui.get_frame_height(), HUD_RIGHT)
    imgui.set_next_window_pos(imgui.ImVec2(x, y), imgui.Cond_.always)
    imgui.set_next_window_size(imgui.ImVec2(width, height), imgui.Cond_.always)
    imgui.set_next_window_bg_alpha(0.8)
    imgui.begin(PANEL_TITLE)  # scrolls when taller than the window; folds by its arrow
    folded = imgui.is_window_collapsed()
    if folded != e.layout.folded:
        out.append(ec.FoldPanel(folded))
    if not folded:
        _dock(e, out, width)
    _file(e, out)
    scene = e.scene
    shown = e.handled_scene()  # as drawn at the moment shown (tracks), its tracked fields marked
    marks = key_marks(scene, e.viewer.drawn.playback.time)
    fields_of = partial(_fields, marks=marks, albedo=scene.material.albedo)
    if scene.tree is not None:
        imgui.text_wrapped(
            "This tree is grown from ratios. Bake it into a route to drag its "
            "forks, control points and mirror normals [KRS17 §9.2]."
        )
        if imgui.button("bake into a route"):
            out.append(ec.Bake())
        if imgui.collapsing_header("growth", imgui.TreeNodeFlags_.default_open):
            # as grown at the moment shown; a value a track moves is keyed there (tree-growing)
            fields_of(shown.tree, ("tree",), out, interactions)
    elif scene.mokrs is not None:
        mokrs_section(e, out, interactions, fields_of)
    else:
        _warnings(e, out)
        _outline(e, out)
        if imgui.collapsing_header("selection", imgui.TreeNodeFlags_.default_open):
            _selection(e, out, interactions, fields_of)
        out += structure_section(e, interactions)
    if imgui.collapsing_header("name and description"):
        _about(scene, out, interactions)
    if imgui.collapsing_header("material"):
        fields_of(shown.material, ("material",), out, interactions)
    if imgui.collapsing_header("effect settings"):
        imgui.push_text_wrap_pos(0.0)  # wrapped: a narrow panel cut the list off
        imgui.text_disabled(
            "effects: " + (", ".join(scene.effects) or "none") + " (switched in the HUD, F1)"
        )
        imgui.pop_text_wrap_pos()
        fields_of(shown.effect_settings, ("effect_settings",), out, interactions)
    if scene.tree is None and imgui.collapsing_header(  # a grown tree has nothing to drag
        "dragging", imgui.TreeNodeFlags_.default_open
    ):
        if scene.route is not None or any(c.route for c in scene.compound):  # a route's forks
            changed, on = imgui.checkbox("a fork carries its subtree", e.carry)
            if changed:
                out.append(ec.SetCarry(on))
            if imgui.is_item_hovered():
                tooltip(
                    "on: the finer forks, control points and mirrors move with a "
                    "dragged fork, so the crown stays attached; off: only the fork. "
                    "A keyed fork always takes its subtree along, as a bone does"
                )
        changed, on = imgui.checkbox("snap (or hold Shift while dragging)", e.snap.on)
        if changed:
            out.append(ec.SetSnap(on))
        imgui.text(f"grid {e.snap.grid:g} units, angle {e.snap.angle:g}°")
    # last: a message appearing above the fields moved them under the pointer (a review's
    # next Ctrl+click set another field); its first line is the status line's too
    red_text(e.viewer.error)
    imgui.end()
    _modals(e, out)
    out += copy_dialog(e.file)
    return out


def _dock(e: Edited, out: list, width: float) -> None:
    """The panel's side, and its width as the person drags its edge."""
    now = imgui.get_window_width()
    if abs(now - width) >= 1.0:
        out.append(ec.PlacePanel(e.layout.side, max(now, MIN_WIDTH)))
    other = "left" if e.layout.side == "right" else "right"
    if imgui.small_button(f"dock {other}"):
        out.append(ec.PlacePanel(other, e.layout.width))
    if imgui.is_item_hovered():
        tooltip("drag the panel's edge to resize it; its title bar's arrow folds it")


def _about(scene: Scene, out: list, interactions: Interactions) -> None:
    """The scene's name and one-line description, to be told after a reshaping (the shipped
    tree's says how many forks it has). Enter, or leaving the field, takes the typed text,
    as one undo step (the view is not redrawn at every key; a click elsewhere used to drop
    it); Esc gives it up."""
    for name in ("name", "description"):
        imgui.set_next_item_width(-imgui.calc_text_size("description").x - 8)
        entered, text = imgui.input_text(
            f"{name}##scene", getattr(scene, name), imgui.InputTextFlags_.enter_returns_true
        )
        left = imgui.is_item_deactivated_after_edit()
        key = interactions.key((name,))
        if imgui.is_item_hovered():
            tooltip("Enter or a click elsewhere takes the text; Esc gives it up")
        if (entered or left) and text != getattr(scene, name):
            out.append(Edit((name,), text, key))


def _warnings(e: Edited, out: list) -> None:
    """Each warning names its level (in a compound, its component's route's); a click
    selects that level or component (the view shows the clipped part in red)."""
    what = "component" if e.scene.compound else "level"
    said = e.warnings
    if not said:  # the line is kept: a warning appearing moves no field under the pointer
        imgui.text_disabled("no warnings: Alg. 1 cuts no branch")
        return
    if len(said) > WARNINGS_OPEN:  # folded: eight of four lines each pushed the outline away
        imgui.push_style_color(imgui.Col_.text, YELLOW)
        count = counted(len(said), "warning")
        shown = imgui.tree_node(f"{count}: branches Alg. 1 cuts (red in the view)###warnings")
        imgui.pop_style_color()
        if not shown:
            return
    for k, (entry, text) in enumerate(said):
        imgui.push_style_color(imgui.Col_.text, YELLOW)
        imgui.text_wrapped(text)
        imgui.pop_style_color()
        name = f"component {entry}" if what == "component" else f"L{entry}"
        if imgui.small_button(f"select {name}##warn{k}"):
            out.append(ec.SelectLevel(entry))
    if len(said) > WARNINGS_OPEN:
        imgui.tree_pop()


def _file(e: Edited, out: list) -> None:
    doc = e.doc
    imgui.text(("* unsaved edits: " if doc.dirty else "as on disk: ") + str(doc.path.name))
    if imgui.is_item_hovered():
        tooltip(str(doc.path.resolve()))
    if imgui.button("save (Ctrl+S)"):
        out.append(ec.Save())
    imgui.same_line()
    asked = e.file.replace_asked(e.file.save_as_text)  # the field names another file: again
    if imgui.button("replace it###save as" if asked else "save as"):
        out.append(ec.SaveAs())
    imgui.same_line()
    imgui.set_next_item_width(-1)  # the rest of the line, however wide the panel
    enter = imgui.InputTextFlags_.enter_returns_true
    done, text = imgui.input_text("##saveas", e.file.save_as_text, enter)
    inside = imgui.get_item_rect_size().x - 2 * imgui.get_style().frame_padding.x
    if imgui.is_item_hovered() and imgui.calc_text_size(text).x > inside:
        tooltip(text)  # the field shows a long path's start only: the name is at its end
    if text != e.file.save_as_text:
        out.append(ec.SetSaveAsText(text))
    if done:  # Enter saves under the name typed, as the button does
        out.append(ec.SaveAs())
    done, undone = doc.history.labels()
    imgui.begin_disabled(not done)
    if imgui.button("undo (Ctrl+Z)"):
        out.append(Undo())
    imgui.end_disabled()
    if done and imgui.is_item_hovered(imgui.HoveredFlags_.allow_when_disabled):
        tooltip("undo: " + done[-1])
    imgui.same_line()
    imgui.begin_disabled(not undone)
    if imgui.button("redo (Ctrl+Shift+Z)"):
        out.append(Redo())
    imgui.end_disabled()
    if undone and imgui.is_item_hovered(imgui.HoveredFlags_.allow_when_disabled):
        tooltip("redo: " + undone[0])
    if e.file.conflict:
        if e.file.unreadable:  # nothing to take: a file deleted, or no scene any more
            red_text(f"{doc.path.name} changed on disk and cannot be read: {e.file.unreadable}")
        else:
            red_text(f"{doc.path.name} changed on disk, and you have unsaved edits.")
            if imgui.button("take the file"):
                out.append(ec.TakeFile())
            if imgui.is_item_hovered():
                tooltip("load the file's contents; your edits stay undoable")
            imgui.same_line()
        if imgui.button("keep mine"):
            out.append(ec.KeepMine())
        if imgui.is_item_hovered():
            tooltip("keep your edits: the next save (Ctrl+S) writes the file anew with them")


def _outline(e: Edited, out: list) -> None:
    entries = outline(e.scene)
    imgui.text_wrapped("outline (click an entry, a handle or the geometry)")
    tall = min(120.0, 0.3 * imgui.get_io().display_size.y)
    if imgui.begin_child("outline", imgui.ImVec2(-1, tall), imgui.ChildFlags_.borders):
        for k in range(len(entries) - 1, -1, -1):  # trunk first, as it grows
            selected = e.selected is not None and e.selected.level == k
            clicked, _ = imgui.selectable(f"{entries[k]}##{k}", selected)
            if clicked:
                out.append(ec.SelectLevel(k))
            if e.scene.route is not None:  # entries are levels (a compound's: components)
                out += outline_menu(k, entries[k])
            if selected and e.scroll_outline:
                imgui.set_scroll_here_y()
                out.append(ec.OutlineScrolled())
    imgui.end_child()


def _selection(e: Edited, out: list, interactions: Interactions, fields_of: Callable) -> None:
    h = e.selected
    if h is None:
        imgui.text_disabled("nothing selected")
        return
    same_level = [k for k in e.handles if k.owner == h.owner]  # a compound's: its level
    for k, other in enumerate(same_level):
        if imgui.radio_button(f"{other.label}##h{k}", other.same(h)):
            out.append(ec.Select(other))
        if k % 2 == 0 and k + 1 < len(same_level):
            imgui.same_line()
    fields_of(get_at(e.handled_scene(), h.owner), h.owner, out, interactions)  # as drawn


def _fields(
    obj: Any,
    at: tuple,
    out: list,
    interactions: Interactions,
    marks: dict | None = None,
    albedo: tuple = Material().albedo,
) -> None:
    """A widget per field of the dataclass ``obj`` at ``at``; nested tables recurse; the
    fields the program keeps (BOOKKEEPING) as a line of text; a field a track moves marked
    (``marks``: keys.key_marks). The widgets leave room for the longest label (a narrow
    panel cut labels off: shadow_softness) and a key's diamond after it, tracked or not, so
    that a first key moves no field (the panel's edge cut the diamond off)."""
    longest = max((imgui.calc_text_size(f.name).x for f in fields(obj)), default=0.0)
    imgui.push_item_width(-longest - imgui.get_style().item_inner_spacing.x - MARK_ROOM)
    for f in fields(obj):
        _field(obj, f, at, out, interactions, marks, albedo)
    imgui.pop_item_width()


def _field(
    obj: Any, f: Any, at: tuple, out: list, interactions: Interactions, marks, albedo: tuple
) -> None:
    """Field ``f`` of ``obj`` (see :func:`_fields`)."""
    value = getattr(obj, f.name)
    path = (*at, f.name)
    if f.name in BOOKKEEPING:
        _bookkeeping(f.name, value, path, interactions)
    elif (
        f.name == "color"
        and f.default is None
        and not _own_color(value, path, out, albedo, interactions)
    ):
        return  # drawn in the material's albedo: no colour field
    elif value is None or isinstance(value, list) or f.name in GEOMETRY_TABLES:
        return
    elif f.name == "growth":  # set there, the tree grows again (structure_panel.py)
        imgui.text_disabled("growth parameters: under structure, growth")
    elif hasattr(value, "__dataclass_fields__"):
        imgui.separator_text(f"{f.name}" + (f" ({value.kind})" if hasattr(value, "kind") else ""))
        _fields(value, path, out, interactions, marks, albedo)
    else:
        refused = interactions.refusal(path)
        tracked = (marks or {}).get(path)
        with marked(tracked):
            changed, new = field_widget(
                f"{f.name}##{'.'.join(map(str, path))}", value, dict(f.metadata), refused
            )
        if imgui.is_item_activated() and (tracked is not None or path[0] == "tree"):
            out.append(ec.ShowKeys(path))  # its keys on the strip (a grown tree: no handles)
        key = interactions.key(path)
        if changed:
            out.append(Edit(path, new, key))


def _own_color(
    value: Any, path: tuple, out: list, albedo: tuple, interactions: Interactions
) -> bool:
    """A colour that may be left to the material's ``albedo`` (none): a box that gives it
    one of its own, starting at that albedo (so nothing changes until it is set), or takes
    it back; whether it has one (its field follows). The box's place: ``(*path, "own")``."""
    changed, own = imgui.checkbox(f"own color##{'.'.join(map(str, path))}", value is not None)
    interactions.place((*path, "own"))
    if imgui.is_item_hovered():
        tooltip("ticked: its own colour, below; not: drawn in the material's albedo")
    if changed:
        out.append(Edit(path, tuple(albedo) if own else None))
    return value is not None


def _bookkeeping(name: str, value: Any, path: tuple, interactions: Interactions) -> None:
    """A field the program writes, shown as text: the person reads it, never edits it (its
    place is kept in ``interactions.rects`` like a widget's, for tests and automation)."""
    text, tip = BOOKKEEPING[name](value)
    imgui.text_disabled(text)
    interactions.place(path)
    if imgui.is_item_hovered():
        tooltip(tip)


def _grown(depth: int | None) -> tuple[str, str]:
    """A route level's ``grown``: which level of the growth parameters it was baked as."""
    if depth is None:
        return "made by hand", "not baked from growth parameters: growing again drops it"
    return f"grown at depth {depth}", (
        f"baked from depth {depth} (0: the trunk) of the growth parameters: growing the "
        "tree again puts this level's edits back on the level grown there"
    )


# Fields the program keeps for itself: (text, tooltip) of the value, shown instead of a widget.
BOOKKEEPING: dict[str, Callable[[Any], tuple[str, str]]] = {"grown": _grown}


def _modals(e: Edited, out: list) -> None:
    if e.file.asking is not None and not imgui.is_popup_open("unsaved changes"):
        imgui.open_popup("unsaved changes")
    if begin_modal("unsaved changes"):
        what = "closing" if e.file.asking == ("close", None) else "opening another scene"
        imgui.text_wrapped(f"{e.doc.path.name} has unsaved edits. Save them before {what}?")
        red_text(e.viewer.error)  # a save that failed says why here, where one looks
        answers = [("save", ec.AnswerSave()), ("discard", ec.AnswerDiscard())]
        answer_buttons([*answers, ("cancel (Esc)", ec.AnswerCancel())], out)
        if imgui.is_key_pressed(imgui.Key.escape):
            out.append(ec.AnswerCancel())
            imgui.close_current_popup()
        imgui.end_popup()
    if e.file.recovered is not None and not imgui.is_popup_open("recover"):
        imgui.open_popup("recover")
    if begin_modal("recover"):
        imgui.text_wrapped(
            f"{e.doc.recovery_path.name} holds unsaved edits from a session that "
            "did not end cleanly."
        )
        answer_buttons(
            [("restore them", ec.Restore()), ("discard them", ec.DiscardRecovery())], out
        )
        imgui.end_popup()
