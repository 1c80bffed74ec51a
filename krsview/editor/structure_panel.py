"""The structure tools' panel parts [KRS17 §9.2]: the outline's right-click menu, the
"structure" section (insert, remove, duplicate; taper, widths, scale, the foot; a compound
component's level; the growth parameters) and the re-grow dialog. They return commands, which
structure.py's handlers apply."""

from __future__ import annotations

from dataclasses import fields

from imgui_bundle import imgui

from ..scene import Route
from ..scene.edits import get_at
from ..scene.growth import Growth
from ..viewer.commands import Command
from ..viewer.widgets import Interactions, as_typed, field_widget, red_text, tooltip
from . import commands as ec
from .handles import route_outline
from .modals import answer_buttons, entry_menu
from .structure import Structured, StructureTools, component, growth_field, target

MAX_LISTED = 12  # lost edits listed in the re-grow dialog; the rest are counted
TIPS = {  # the structure tools' values (ctrl+click a slider to type one)
    "split_at": "where along the selected branch Insert puts the new fork: 0 its start, 1 its end",
    "taper": "each branch's radius set to this × its parent's, from the trunk up",
    "widths": "every branch's radius × this",
    "scale": "the whole tree × this, about its foot (the route's base stays put)",
    "base": "where the tree's foot goes: the whole tree moves with it",
}


def outline_menu(k: int, name: str) -> list[Command]:
    """The right-click menu of outline entry k, titled by its ``name`` (call right after its
    selectable): the structure keys' operations on that level."""
    items = (
        ("insert a fork", "Insert", lambda: [ec.InsertLevel(k)]),
        ("remove this fork", "Delete", lambda: [ec.RemoveLevel(k)]),
        ("duplicate", "Ctrl+D", lambda: [ec.DuplicateLevel(k)]),
    )
    return entry_menu(f"structure##{k}", k, name, items)


def structure_section(e: Structured, interactions: Interactions) -> list[Command]:
    """The panel's "structure" section (a route only), and the re-grow dialog."""
    out: list[Command] = []
    t = e.structure
    at, why = target(e)
    if (at is None and not e.scene.compound) or not imgui.collapsing_header(
        "structure", imgui.TreeNodeFlags_.default_open
    ):
        return out
    imgui.push_text_wrap_pos(0.0)
    if at is None:  # a compound's component without a route
        imgui.text_disabled(why)
        k = component(e)
        tree = k is not None and e.scene.compound[k].tree is not None
        if tree and imgui.button(f"bake component {k} into a route"):
            out.append(ec.Bake(k))
        imgui.pop_text_wrap_pos()
        return out
    route = get_at(e.scene, at)
    if at == ("route",):
        imgui.text_disabled(
            ("on the selected level" if e.selected is not None else "select a level first")
            + "; or right-click an outline entry"
        )
    else:
        _component_level(t, route, out)
    imgui.pop_text_wrap_pos()
    imgui.set_next_item_width(120)
    changed, s = imgui.slider_float("split at##structure", t.split_at, 0.05, 0.95, "%.2f")
    if changed:
        out.append(ec.SetToolValue("split_at", as_typed(s, t.split_at)))
    if imgui.is_item_hovered():
        tooltip(TIPS["split_at"])
    unselected = at == ("route",) and e.selected is None  # no level to act on: greyed
    hovered = False
    imgui.begin_disabled(unselected)
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
        hovered |= imgui.is_item_hovered(imgui.HoveredFlags_.allow_when_disabled)
    imgui.end_disabled()
    if unselected and hovered:  # after: a tooltip begun while disabled is greyed too
        tooltip("select a level first: click it in the outline or the view")
    imgui.separator_text("whole tree")
    for name, op, lo, hi, button in (
        ("taper", "taper", 0.05, 1.0, "taper"),
        ("widths", "widths", 0.1, 10.0, "scale widths"),
        ("scale", "scale", 0.1, 10.0, "scale tree"),
    ):
        imgui.set_next_item_width(120)
        changed, v = imgui.slider_float(f"##{name}", getattr(t, name), lo, hi, "%.3g")
        if changed:
            out.append(ec.SetToolValue(name, as_typed(v, getattr(t, name))))
        if imgui.is_item_hovered():
            tooltip(TIPS[name])
        imgui.same_line()
        if imgui.button(button):
            out.append(ec.WholeTree(op))
        if imgui.is_item_hovered():
            tooltip(TIPS[name])
    imgui.set_next_item_width(180)
    base = t.base or route.base
    changed, b = imgui.drag_float3("##base", list(base), 0.01, 0.0, 0.0, "%.3g")
    if changed:
        out.append(ec.SetToolValue("base", tuple(as_typed(c, o) for c, o in zip(b, base))))
    if imgui.is_item_hovered():
        tooltip(TIPS["base"])
    imgui.same_line()
    if imgui.button("move foot"):
        out.append(ec.WholeTree("base"))
    if imgui.is_item_hovered():
        tooltip(TIPS["base"])
    if t.message:  # wrapped: a narrow panel cuts nothing off
        (red_text if t.refused else imgui.text_wrapped)(t.message)
    if route.growth is not None:
        _growth(route, out, interactions)
    _regrow_dialog(t, out)
    return out


def _component_level(t: StructureTools, route: Route, out: list[Command]) -> None:
    """In a compound: which level of the selected component's route the tools act on."""
    n = len(route.levels)
    names = route_outline(route)
    level = min(t.level, n - 1)
    imgui.text_disabled("on this level of the component's route:")
    imgui.set_next_item_width(160)
    changed, k = imgui.combo("##component level", n - 1 - level, names[::-1])  # trunk first
    if changed or level != t.level:
        out.append(ec.SetToolValue("level", n - 1 - k if changed else level))


def forks_note(route: Route) -> str:
    """What the growth section says where the route's forks no longer match its growth
    parameters (forks inserted, removed or duplicated by hand), "" where they do."""
    forks, grown = len(route.levels) - 1, route.growth.levels
    if forks == grown:
        return ""
    return f"the route has {forks} forks now; grow again makes {grown}"


def _growth(route: Route, out: list[Command], interactions: Interactions) -> None:
    growth = route.growth
    if not imgui.tree_node("growth (edits kept where they can be)"):
        return
    if note := forks_note(route):
        imgui.text_disabled(note)
    longest = max(imgui.calc_text_size(f.name).x for f in fields(Growth))
    imgui.push_item_width(-longest - imgui.get_style().item_inner_spacing.x)  # labels fit
    for f in fields(Growth):
        value = getattr(growth, f.name)
        if value is None or isinstance(value, list):
            continue
        path = growth_field(f.name)
        refused = interactions.refusal(path)  # a refused value stays red in its field
        changed, new = field_widget(f"{f.name}##growth", value, dict(f.metadata), refused)
        key = interactions.key(path)
        if changed:
            out.append(ec.SetGrowth(f.name, new, key))
    imgui.pop_item_width()
    if imgui.button("grow again"):
        out.append(ec.Regrow())
    imgui.tree_pop()


def _regrow_dialog(t: StructureTools, out: list[Command]) -> None:
    if t.pending is not None and not imgui.is_popup_open("grow again?"):
        imgui.open_popup("grow again?")
    if not imgui.begin_popup_modal("grow again?", None, imgui.WindowFlags_.always_auto_resize)[0]:
        return
    lost = t.pending.lost if t.pending else []
    if t.pending:  # what is being applied ("grow again with levels = 18")
        imgui.text(t.pending.label[:1].upper() + t.pending.label[1:] + "?")
    imgui.text("Growing the tree again loses these edits made by hand:")
    for line in lost[:MAX_LISTED]:
        imgui.bullet_text(line)
    if len(lost) > MAX_LISTED:
        imgui.text(f"... and {len(lost) - MAX_LISTED} more")
    answers = [("grow again, losing them", ec.ConfirmRegrow())]
    answer_buttons([*answers, ("cancel (Esc: keep the tree)", ec.CancelRegrow())], out)
    if imgui.is_key_pressed(imgui.Key.escape):  # as the other dialogs
        out.append(ec.CancelRegrow())
    imgui.end_popup()
