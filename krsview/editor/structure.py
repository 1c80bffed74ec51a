"""The editor's structure tools [KRS17 §9.2]: insert, remove and duplicate a route's levels
(keys, the outline's right-click menu and the panel's "structure" section), taper, scale the
widths or the tree, move its foot, and grow a baked tree again from its growth parameters.

Each operation is a pure function of the route (``scene/restructure.py``,
``scene/regrow.py``); here its result is validated by the scene's schema and committed as one
undo step. A refused operation changes nothing and says why in one line, in the section and
in the status. Re-growing that would lose hand edits lists them and asks first."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, fields, replace
from typing import Any, Protocol

from imgui_bundle import imgui

from ..document.document import Document
from ..scene import Route, Scene, SceneError
from ..scene.edits import validated
from ..scene.growth import Growth
from ..scene.regrow import rebake
from ..scene.restructure import (
    duplicate_level,
    merge_level,
    move_base,
    scale_tree,
    scale_widths,
    split_level,
    taper,
)
from ..scene.schema import Vec3, from_dict, to_dict
from ..viewer.commands import Command
from ..viewer.widgets import Interactions, field_widget
from ..viewer.window import Viewer
from . import commands as ec
from .handles import Handle

RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)
MAX_LISTED = 12  # lost edits listed in the re-grow dialog; the rest are counted

# Insert / Delete / Ctrl+D act on the selected level (the viewer's keys are letters, F-keys
# and Ctrl+Z/Y; Ctrl+D is free: D alone flies).
STRUCTURE_KEYS: dict[str, Command] = {
    "Insert": ec.InsertLevel(),
    "Delete": ec.RemoveLevel(),
    "ctrl+D": ec.DuplicateLevel(),
}


@dataclass
class StructureTools:
    """The structure section's values and its last word."""

    split_at: float = 0.5  # where along the branch a fork is inserted
    taper: float = 0.75  # child / parent radius
    widths: float = 1.25  # × every radius
    scale: float = 1.25  # × the whole tree, about its foot
    base: Vec3 | None = None  # where "move the foot" puts it (None: where it is)
    message: str = ""
    refused: bool = False
    pending: tuple[Route, list[str], str] | None = None  # a re-grow waiting for a yes


class Structured(Protocol):
    """What the structure tools read and call of the editor."""

    viewer: Viewer
    selected: Handle | None
    structure: StructureTools

    @property
    def doc(self) -> Document: ...
    @property
    def scene(self) -> Scene: ...
    def select_level(self, level: int) -> None: ...


# ----------------------------------------------------------------------------- applying
def _say(e: Structured, text: str, refused: bool) -> None:
    t = e.structure
    t.message, t.refused = text, refused
    if refused:
        e.viewer.error = text
    else:
        e.viewer.error, e.viewer.message = "", text


def commit_route(
    e: Structured, make: Callable[[Route], Route], label: str, interaction: Any = None
) -> bool:
    """Replace the route by ``make(route)``, validated, as one undo step; a SceneError
    (from the operation or the schema) changes nothing and is said."""
    if e.scene.route is None:
        _say(e, f"{label}: structure edits need a route; bake the tree first", True)
        return False
    try:
        scene = validated(replace(e.scene, route=make(e.scene.route)))
    except SceneError as err:
        _say(e, f"{label} refused: {err}", True)
        return False
    e.doc.commit(scene, label, interaction)
    e.viewer.sync()
    warned = scene.route.warnings()
    _say(e, label + (f" ({len(warned)} warnings)" if warned else ""), False)
    return True


def _level(e: Structured, level: int | None, what: str) -> int | None:
    if level is not None:
        return level
    if e.selected is None or e.scene.route is None:
        _say(e, f"{what}: select a level first (click it in the outline or the view)", True)
        return None
    return e.selected.level


def insert(e: Structured, level: int | None) -> None:
    i = _level(e, level, "insert a fork")
    s = e.structure.split_at
    if i is not None and commit_route(
        e, lambda r: split_level(r, i, s), f"insert a fork in L{i} at {s:.2f}"
    ):
        e.select_level(i + 1)


def remove(e: Structured, level: int | None) -> None:
    i = _level(e, level, "remove a fork")
    if i is not None and commit_route(e, lambda r: merge_level(r, i), f"remove the fork of L{i}"):
        e.select_level(min(i, len(e.scene.route.levels) - 1))


def duplicate(e: Structured, level: int | None) -> None:
    i = _level(e, level, "duplicate a level")
    if i is not None and commit_route(e, lambda r: duplicate_level(r, i), f"duplicate L{i}"):
        e.select_level(i)


def whole_tree(e: Structured, op: str) -> None:
    t = e.structure
    ops = {
        "taper": (lambda r: taper(r, t.taper), f"taper by {t.taper:.3g} per level"),
        "widths": (lambda r: scale_widths(r, t.widths), f"widths x {t.widths:.3g}"),
        "scale": (lambda r: scale_tree(r, t.scale), f"tree x {t.scale:.3g}"),
        "base": (lambda r: move_base(r, t.base or r.base), f"move the foot to {t.base}"),
    }
    commit_route(e, *ops[op])


def set_growth(e: Structured, name: str, value: Any, interaction: Any) -> None:
    """Grow again with one parameter changed; ask first when hand edits would be lost."""
    route = e.scene.route
    label = f"grow again with {name} = {value}"
    try:
        growth = from_dict(Growth, {**to_dict(route.growth), name: value}, "route.growth")
        new, lost = rebake(route, growth)
    except SceneError as err:
        _say(e, f"{label} refused: {err}", True)
        return
    _regrown(e, new, lost, label, interaction)


def regrow(e: Structured) -> None:
    try:
        new, lost = rebake(e.scene.route, e.scene.route.growth)
    except SceneError as err:
        _say(e, f"grow again refused: {err}", True)
        return
    _regrown(e, new, lost, "grow again from the growth parameters", None)


def _regrown(e: Structured, new: Route, lost: list[str], label: str, interaction: Any) -> None:
    if lost:
        e.structure.pending = (new, lost, label)
    else:
        commit_route(e, lambda r: new, label, interaction)


def confirm_regrow(e: Structured) -> None:
    pending, e.structure.pending = e.structure.pending, None
    if pending is not None:
        new, lost, label = pending
        commit_route(e, lambda r: new, f"{label} (losing {len(lost)} hand edits)")


STRUCTURE_HANDLERS: dict[type[Command], Callable[[Any, Any], None]] = {
    ec.InsertLevel: lambda e, c: insert(e, c.level),
    ec.RemoveLevel: lambda e, c: remove(e, c.level),
    ec.DuplicateLevel: lambda e, c: duplicate(e, c.level),
    ec.WholeTree: lambda e, c: whole_tree(e, c.op),
    ec.SetToolValue: lambda e, c: setattr(e.structure, c.name, c.value),
    ec.SetGrowth: lambda e, c: set_growth(e, c.name, c.value, c.interaction),
    ec.Regrow: lambda e, c: regrow(e),
    ec.ConfirmRegrow: lambda e, c: confirm_regrow(e),
    ec.CancelRegrow: lambda e, c: setattr(e.structure, "pending", None),
}


# ------------------------------------------------------------------------------ drawing
def outline_menu(k: int) -> list[Command]:
    """The right-click menu of outline entry k (call right after its selectable)."""
    out: list[Command] = []
    if imgui.begin_popup_context_item(f"structure##{k}"):
        for text, keys, command in (
            ("insert a fork", "Insert", ec.InsertLevel(k)),
            ("remove this fork", "Delete", ec.RemoveLevel(k)),
            ("duplicate", "Ctrl+D", ec.DuplicateLevel(k)),
        ):
            if imgui.menu_item(text, keys, False)[0]:
                out.append(command)
        imgui.end_popup()
    return out


def structure_section(e: Structured, interactions: Interactions) -> list[Command]:
    """The panel's "structure" section (a route only), and the re-grow dialog."""
    out: list[Command] = []
    route, t = e.scene.route, e.structure
    if route is None or not imgui.collapsing_header("structure", imgui.TreeNodeFlags_.default_open):
        return out
    imgui.push_text_wrap_pos(0.0)
    imgui.text_disabled(
        ("on the selected level" if e.selected is not None else "select a level first")
        + "; or right-click an outline entry"
    )
    imgui.pop_text_wrap_pos()
    imgui.set_next_item_width(120)
    changed, s = imgui.slider_float("split at##structure", t.split_at, 0.05, 0.95, "%.2f")
    if changed:
        out.append(ec.SetToolValue("split_at", s))
    for k, (text, command) in enumerate(
        (
            ("insert (Ins)", ec.InsertLevel()),
            ("remove (Del)", ec.RemoveLevel()),
            ("duplicate (Ctrl+D)", ec.DuplicateLevel()),
        )
    ):
        if k:
            imgui.same_line()
        if imgui.button(text):
            out.append(command)
    imgui.separator_text("whole tree")
    for name, op, lo, hi, button in (
        ("taper", "taper", 0.05, 1.0, "taper"),
        ("widths", "widths", 0.1, 10.0, "scale widths"),
        ("scale", "scale", 0.1, 10.0, "scale tree"),
    ):
        imgui.set_next_item_width(120)
        changed, v = imgui.slider_float(f"##{name}", getattr(t, name), lo, hi, "%.3g")
        if changed:
            out.append(ec.SetToolValue(name, v))
        imgui.same_line()
        if imgui.button(button):
            out.append(ec.WholeTree(op))
    imgui.set_next_item_width(180)
    changed, b = imgui.drag_float3("##base", list(t.base or route.base), 0.01, 0.0, 0.0, "%.3g")
    if changed:
        out.append(ec.SetToolValue("base", tuple(float(c) for c in b)))
    imgui.same_line()
    if imgui.button("move foot"):
        out.append(ec.WholeTree("base"))
    if t.message:
        (imgui.text_colored(RED, t.message) if t.refused else imgui.text_wrapped(t.message))
    if route.growth is not None:
        _growth(route.growth, out, interactions)
    _regrow_dialog(t, out)
    return out


def _growth(growth: Growth, out: list[Command], interactions: Interactions) -> None:
    if not imgui.tree_node("growth (edits kept where they can be)"):
        return
    for f in fields(Growth):
        value = getattr(growth, f.name)
        if value is None or isinstance(value, list):
            continue
        changed, new = field_widget(f"{f.name}##growth", value, dict(f.metadata))
        key = interactions.key(("route", "growth", f.name))
        if changed:
            out.append(ec.SetGrowth(f.name, new, key))
    if imgui.button("grow again"):
        out.append(ec.Regrow())
    imgui.tree_pop()


def _regrow_dialog(t: StructureTools, out: list[Command]) -> None:
    if t.pending is not None and not imgui.is_popup_open("grow again?"):
        imgui.open_popup("grow again?")
    if not imgui.begin_popup_modal("grow again?", None, imgui.WindowFlags_.always_auto_resize)[0]:
        return
    lost = t.pending[1] if t.pending else []
    imgui.text("Growing the tree again loses these edits made by hand:")
    for line in lost[:MAX_LISTED]:
        imgui.bullet_text(line)
    if len(lost) > MAX_LISTED:
        imgui.text(f"... and {len(lost) - MAX_LISTED} more")
    if imgui.button("grow again, losing them"):
        out.append(ec.ConfirmRegrow())
        imgui.close_current_popup()
    imgui.same_line()
    if imgui.button("cancel (keep the tree)"):
        out.append(ec.CancelRegrow())
        imgui.close_current_popup()
    imgui.end_popup()
