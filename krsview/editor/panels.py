"""The editor's ImGui panels. A panel reads the editor's state and returns commands; it never
writes the editor or the scene itself (the editor applies the commands through the document),
so the arrows run one way: editor window → panels."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path
from typing import Any, Protocol

from imgui_bundle import imgui

from ..document.document import Document
from ..scene import Scene
from ..scene.edits import get_at
from ..viewer.commands import Command, Edit, Redo, Undo
from ..viewer.widgets import Interactions, field_widget
from ..viewer.window import Viewer
from . import commands as ec
from .gizmo import Snap
from .handles import Handle, outline
from .mokrs_panel import mokrs_section

GEOMETRY_TABLES = ("krs", "route")  # a component's own geometry: too big for a panel
YELLOW = imgui.ImVec4(1.0, 0.85, 0.3, 1.0)
RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)


class Edited(Protocol):
    """What the panels read of the editor (they write nothing: they return commands)."""

    viewer: Viewer
    selected: Handle | None
    warnings: list[str]
    snap: Snap
    carry: bool
    save_as_text: str
    conflict: bool
    scroll_outline: bool
    asking: tuple[str, Path | None] | None
    recovered: Scene | None

    @property
    def doc(self) -> Document: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def handles(self) -> list[Handle]: ...


def edit_panel(e: Edited, interactions: Interactions) -> list[Command]:
    out: list[Command] = []
    imgui.set_next_window_pos(
        imgui.ImVec2(e.viewer.frames.adaptive.full[0] - 348, 8), imgui.Cond_.first_use_ever
    )
    imgui.set_next_window_size(
        imgui.ImVec2(340, e.viewer.frames.adaptive.full[1] - 16), imgui.Cond_.first_use_ever
    )
    imgui.set_next_window_bg_alpha(0.8)
    imgui.begin("edit")
    _file(e, out)
    scene = e.scene
    if scene.tree is not None:
        imgui.text_wrapped(
            "This tree is grown from ratios. Bake it into a route to drag its "
            "forks, control points and mirror normals [KRS17 §9.2]."
        )
        if imgui.button("bake into a route"):
            out.append(ec.Bake())
    elif scene.mokrs is not None:
        mokrs_section(e, out, interactions, _fields)
    else:
        for w in e.warnings:
            imgui.push_style_color(imgui.Col_.text, YELLOW)
            imgui.text_wrapped("route." + w)
            imgui.pop_style_color()
        _outline(e, out)
        if imgui.collapsing_header("selection", imgui.TreeNodeFlags_.default_open):
            _selection(e, out, interactions)
    if imgui.collapsing_header("material"):
        _fields(scene.material, ("material",), out, interactions)
    if imgui.collapsing_header("effect settings"):
        imgui.text_disabled(
            "effects: " + (", ".join(scene.effects) or "none") + " (switched in the krsview window)"
        )
        _fields(scene.effect_settings, ("effect_settings",), out, interactions)
    if imgui.collapsing_header("dragging", imgui.TreeNodeFlags_.default_open):
        if scene.route is not None:  # only a route's forks carry anything
            changed, on = imgui.checkbox("a fork carries its subtree", e.carry)
            if changed:
                out.append(ec.SetCarry(on))
            if imgui.is_item_hovered():
                imgui.set_tooltip(
                    "on: the finer forks, control points and mirrors move with a "
                    "dragged fork, so the crown stays attached; off: only the fork"
                )
        changed, on = imgui.checkbox("snap (or hold Shift while dragging)", e.snap.on)
        if changed:
            out.append(ec.SetSnap(on))
        imgui.text(f"grid {e.snap.grid:g} units, angle {e.snap.angle:g}°")
    imgui.end()
    _modals(e, out)
    return out


def _file(e: Edited, out: list) -> None:
    doc = e.doc
    imgui.text(("* unsaved: " if doc.dirty else "saved: ") + str(doc.path.name))
    if imgui.button("save (Ctrl+S)"):
        out.append(ec.Save())
    imgui.same_line()
    imgui.set_next_item_width(150)
    changed, text = imgui.input_text("##saveas", e.save_as_text)
    if changed:
        out.append(ec.SetSaveAsText(text))
    imgui.same_line()
    if imgui.button("save as"):
        out.append(ec.SaveAs())
    done, undone = doc.history.labels()
    imgui.begin_disabled(not done)
    if imgui.button("undo (Ctrl+Z)"):
        out.append(Undo())
    imgui.end_disabled()
    if done and imgui.is_item_hovered(imgui.HoveredFlags_.allow_when_disabled):
        imgui.set_tooltip("undo: " + done[-1])
    imgui.same_line()
    imgui.begin_disabled(not undone)
    if imgui.button("redo (Ctrl+Shift+Z)"):
        out.append(Redo())
    imgui.end_disabled()
    if undone and imgui.is_item_hovered(imgui.HoveredFlags_.allow_when_disabled):
        imgui.set_tooltip("redo: " + undone[0])
    if e.conflict:
        imgui.text_colored(RED, f"{doc.path.name} changed on disk, and you have unsaved edits.")
        if imgui.button("take the file (your edits stay undoable)"):
            out.append(ec.TakeFile())
        imgui.same_line()
        if imgui.button("keep mine"):
            out.append(ec.KeepMine())


def _outline(e: Edited, out: list) -> None:
    entries = outline(e.scene)
    imgui.text("outline (click an entry, a handle or the geometry)")
    if imgui.begin_child("outline", imgui.ImVec2(-1, 120), imgui.ChildFlags_.borders):
        for k in range(len(entries) - 1, -1, -1):  # trunk first, as it grows
            selected = e.selected is not None and e.selected.level == k
            clicked, _ = imgui.selectable(f"{entries[k]}##{k}", selected)
            if clicked:
                out.append(ec.SelectLevel(k))
            if selected and e.scroll_outline:
                imgui.set_scroll_here_y()
                out.append(ec.OutlineScrolled())
    imgui.end_child()


def _selection(e: Edited, out: list, interactions: Interactions) -> None:
    h = e.selected
    if h is None:
        imgui.text_disabled("nothing selected")
        return
    same_level = [k for k in e.handles if k.level == h.level]
    for k, other in enumerate(same_level):
        if imgui.radio_button(f"{other.label}##h{k}", other.same(h)):
            out.append(ec.Select(other))
        if k % 2 == 0 and k + 1 < len(same_level):
            imgui.same_line()
    _fields(get_at(e.scene, h.owner), h.owner, out, interactions)


def _fields(obj: Any, at: tuple, out: list, interactions: Interactions) -> None:
    """A widget per field of the dataclass ``obj`` at ``at``; nested tables recurse."""
    for f in fields(obj):
        value = getattr(obj, f.name)
        path = (*at, f.name)
        if value is None or isinstance(value, list) or f.name in GEOMETRY_TABLES:
            continue
        if hasattr(value, "__dataclass_fields__"):
            imgui.separator_text(
                f"{f.name}" + (f" ({value.kind})" if hasattr(value, "kind") else "")
            )
            _fields(value, path, out, interactions)
            continue
        changed, new = field_widget(
            f"{f.name}##{'.'.join(map(str, path))}", value, dict(f.metadata)
        )
        key = interactions.key(path)
        if changed:
            out.append(Edit(path, new, key))


def _modals(e: Edited, out: list) -> None:
    if e.asking is not None and not imgui.is_popup_open("unsaved changes"):
        imgui.open_popup("unsaved changes")
    if imgui.begin_popup_modal("unsaved changes", None, imgui.WindowFlags_.always_auto_resize)[0]:
        what = "closing" if e.asking == ("close", None) else "opening another scene"
        imgui.text(f"{e.doc.path.name} has unsaved edits. Save them before {what}?")
        for label, command in (
            ("save", ec.AnswerSave()),
            ("discard", ec.AnswerDiscard()),
            ("cancel", ec.AnswerCancel()),
        ):
            if imgui.button(label):
                out.append(command)
                imgui.close_current_popup()
            imgui.same_line()
        imgui.end_popup()
    if e.recovered is not None and not imgui.is_popup_open("recover"):
        imgui.open_popup("recover")
    if imgui.begin_popup_modal("recover", None, imgui.WindowFlags_.always_auto_resize)[0]:
        imgui.text(
            f"{e.doc.recovery_path.name} holds unsaved edits from a session that "
            "did not end cleanly."
        )
        if imgui.button("restore them"):
            out.append(ec.Restore())
            imgui.close_current_popup()
        imgui.same_line()
        if imgui.button("discard them"):
            out.append(ec.DiscardRecovery())
            imgui.close_current_popup()
        imgui.end_popup()
