"""The edit panel's section for a MöKRS [KRS17 §7]: its levels (select, duplicate, insert,
remove, reorder), the selected level's reflection, kernel and transform steps as fields from
the schema (add, remove, reorder steps), and a refused value's message next to what it
refused. With keyframe tracks the fields show the values drawn at the moment shown (as the
handles and the KRS panel do), a tracked field marked, and a change to one keys it there.
Every change is an ``Edit`` of the scene (one undo step, validated by the schema); the panel
returns commands and writes nothing."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from imgui_bundle import imgui

from ..messages import counted
from ..scene.edits import path_text
from ..scene.model import Kernel, kernel_as
from ..scene.mokrs import MobiusStep, linked_levels, linked_steps
from ..viewer.commands import Command, Edit
from ..viewer.widgets import Interactions, one_line, red_text, tooltip
from . import commands as ec
from .keys import key_marks, linked_edits, marked
from .modals import entry_menu
from .mokrs_handles import mokrs_outline
from .mokrs_levels import LEVELS, OPS, level_commands

STEP_KINDS = tuple(MobiusStep.registry)  # translate, scale, rotate, invert
KERNEL_KINDS = tuple(Kernel.registry)
OP_KEYS = {"duplicate": "Ctrl+D", "insert": "Insert", "remove": "Delete"}

Fields = Callable[[Any, tuple, list, Interactions], None]  # the panel's field widgets
HINTS = {  # what dragging each kind of handle changes
    "point": "moves the kernel's point (in its level's space)",
    "by": "moves the origin of the frame after the step: the translation vector",
    "factor": "slides along x of the frame: the dilation factor",
    "degrees": "turn the ring about the axis: the angle",
    "axis": "re-aims the rotation axis (its tip)",
    "center": "moves the inversion's centre (sent to infinity)",
    "radius": "a point on the fixed sphere: its radius",
    "origin": "an identity level: a drag gives it a translate step",
}


class KindsLeft:
    """The kernels a kind change left, so that changing back restores one (a toroidal
    capsule's bend, a sphere's centre) where nothing was edited since: a capsule made from
    a bent toroid and turned back was straight [review]."""

    def __init__(self) -> None:
        self._left: dict[tuple, tuple[Kernel, Kernel]] = {}  # (path, kind) → (left, made)

    def switch(self, path: tuple, kernel: Kernel, kind: str) -> Kernel:
        """``kernel`` (at ``path``) as a kernel of ``kind``: the one it was made from, if
        that had this kind and it is unchanged since, else :func:`kernel_as`."""
        left, made = self._left.get((path, kind), (None, None))
        new = left if left is not None and made == kernel else kernel_as(kernel, kind)
        self._left[(path, kernel.kind)] = (kernel, new)
        return new


def moved(items: list, k: int, by: int) -> list:
    """``items`` with entry k swapped with entry k + by (unchanged at either end)."""
    j = k + by
    out = list(items)
    if 0 <= j < len(out):
        out[k], out[j] = out[j], out[k]
    return out


def removed(items: list, k: int) -> list:
    return [*items[:k], *items[k + 1 :]]


# refusals a MöKRS edit can cause ("view": the viewpoint flown in the editor on a pole)
MINE = ("mokrs", "camera", "bookmarks", "levels", "view")


def refusal_place(error: str, level: int, steps: int) -> str:
    """Where the section shows the viewer's last refusal: under the step or kernel of
    ``level`` it names ("step J", "kernel"), else, for another MöKRS field or a viewpoint
    on a pole, beside the selection ("selection"); "" for none or another part's."""
    path = error.split(" = ", 1)[0]
    if not error or not path.startswith(MINE):
        return ""
    lev = path_text((*LEVELS, level))
    for j in range(steps):
        if _under(path, f"{lev}.transform[{j}]"):
            return f"step {j}"
    return "kernel" if _under(path, f"{lev}.kernel") else "selection"


def _under(path: str, prefix: str) -> bool:
    return path == prefix or path.startswith((prefix + ".", prefix + "["))


def mokrs_section(e: Any, out: list[Command], interactions: Interactions, fields: Fields) -> None:
    """Levels, then the selected level's reflection, kernel and steps."""
    m = e.scene.mokrs
    entries = mokrs_outline(m)
    level = e.selected.level if e.selected is not None else None
    imgui.text("levels (click one, a handle or the geometry)")
    if imgui.begin_child("mokrs levels", imgui.ImVec2(-1, 120), imgui.ChildFlags_.borders):
        for i in range(len(entries) - 1, -1, -1):  # the outermost first
            clicked, _ = imgui.selectable(f"{entries[i]}##m{i}", i == level)
            if clicked:
                out.append(ec.SelectLevel(i))
            out += _level_menu(m.levels, i, entries[i])
            if i == level and e.scroll_outline:
                imgui.set_scroll_here_y()
                out.append(ec.OutlineScrolled())
    imgui.end_child()
    if level is None:
        imgui.text_disabled("select a level: its steps get handles in the view")
        return
    _level(e, m.levels, level, out, interactions, fields)


def _level_menu(levels: list, i: int, name: str) -> list[Command]:
    """Level i's right-click menu, as a route's outline entry has: the level operations."""
    items = [
        (f"{op}: {tip}", OP_KEYS.get(op, ""), lambda op=op: level_commands(i, op))
        for op, tip in OPS.items()
    ]
    return entry_menu(f"mokrs level##{i}", i, name, items)


def _level(e, levels: list, i: int, out: list, interactions: Interactions, fields) -> None:
    """Level i: its structure buttons act on the rest ``levels``; its fields show the level
    as drawn at the moment shown."""
    lv, lev = levels[i], (*LEVELS, i)
    shown = e.handled_scene().mokrs.levels[i]
    error = e.viewer.error
    place = refusal_place(error, i, len(lv.transform))
    sel = e.selected.path if e.selected is not None else ()
    step_selected = sel[: len(lev) + 1] == (*lev, "transform")
    imgui.separator_text(f"level {i} of {len(levels)}")
    if e.selected is not None and e.selected.level == i:  # two lines, whichever handle:
        imgui.text(e.selected.label)  # a wrapped hint moved the rows below it [review]
        one_line(HINTS.get(e.selected.role, ""))
    for op, tip in OPS.items():
        if imgui.small_button(f"{op}##lv"):
            out += level_commands(i, op)
        if imgui.is_item_hovered():
            tooltip(tip + ("" if op in ("inward", "outward") else f" ({OP_KEYS[op]})"))
        imgui.same_line()
    imgui.new_line()
    with marked(key_marks(e.scene, e.viewer.drawn.playback.time).get((*lev, "reflect"))):
        changed, on = imgui.checkbox("reflect (x = 0 of this level)", shown.reflect)
    if changed:
        out.append(Edit((*lev, "reflect"), on))
    linked = len(linked_levels(e.scene.mokrs, i)) - 1  # the option stays, none linked too
    now = counted(linked, "linked level") if linked else "linked levels (none now)"
    changed, on = imgui.checkbox(f"step edits also go to {now}", e.carry)
    if changed:
        out.append(ec.SetCarry(on))
    if imgui.is_item_hovered():
        tooltip("the finer levels whose steps equal this level's (linked), for every level")
    kinds = list(KERNEL_KINDS)
    changed, k = imgui.combo("kernel", kinds.index(lv.kernel.kind), kinds)
    interactions.place((*lev, "kernel", "kind"))
    if changed and kinds[k] != lv.kernel.kind:
        out.append(Edit((*lev, "kernel"), e.kinds_left.switch(lev, lv.kernel, kinds[k])))
    fields(shown.kernel, (*lev, "kernel"), out, interactions)
    red_text(error if place == "kernel" else "")
    for j, s in enumerate(shown.transform):  # as drawn now; reordered as the rest levels
        mine = step_selected and sel[len(lev) + 1] == j
        here = place == f"step {j}" or (place == "selection" and mine)
        _step(e, lv, i, j, s, mine, error if here else "", out, interactions, fields)
    imgui.set_next_item_width(110)
    changed, k = imgui.combo("##newstep", 0, ["add a step", *STEP_KINDS])
    if changed and k > 0:
        step = MobiusStep.registry[STEP_KINDS[k - 1]]()
        out.append(_steps(e, i, [*lv.transform, step]))
    red_text(error if place == "selection" and not step_selected else "")


def _steps(e, i: int, steps: list) -> Edit:
    """Level i's step list set to ``steps`` (a step added, removed or moved), in its linked
    finer levels too while step edits go to them (they stay linked)."""
    if e.carry:
        return Edit(*linked_steps(e.scene.mokrs, i, steps))
    return Edit((*LEVELS, i, "transform"), steps)


def _linked(scene, c: Command, t: float) -> list[Command]:
    """A step field's command with step edits going to linked levels: an edit, as the same
    edit of each linked level (keyed where a track moves it); any other command as it is
    (ShowKeys: the strip takes the linked levels itself)."""
    if not isinstance(c, Edit):
        return [c]
    return [
        Edit(path, value, c.interaction, field=(c.path, c.value))
        for path, value in linked_edits(scene, c.path, c.value, t)
    ]


def _step(e, lv, i: int, j: int, s, mine: bool, error: str, out: list, interactions, fields):
    """One step: a header that selects its handle, reorder and remove buttons, its fields,
    and a refusal of one of them (or of a drag of its handle: a pole) beneath."""
    sp, steps = (*LEVELS, i, "transform", j), lv.transform
    clicked, _ = imgui.selectable(f"step {j}: {s.kind}##s{j}", mine, size=imgui.ImVec2(150, 0))
    if clicked:
        first = next((h for h in e.handles if h.owner == sp), None)
        out.append(ec.Select(first))
    for label, value in (
        ("up", moved(steps, j, -1)),
        ("down", moved(steps, j, 1)),
        ("x", removed(steps, j)),
    ):
        imgui.same_line()
        if imgui.small_button(f"{label}##s{j}"):
            out.append(_steps(e, i, value))
    imgui.indent()
    first = len(out)
    fields(s, sp, out, interactions)
    if e.carry:  # linked: the same change in the finer levels with the same steps (keyed
        t = e.viewer.drawn.playback.time  # where a track moves it)
        out[first:] = [linked for c in out[first:] for linked in _linked(e.scene, c, t)]
    imgui.unindent()
    red_text(error)
