"""The editor's structure tools [KRS17 §9.2]: insert, remove and duplicate a route's levels
(keys, the outline's right-click menu and the panel's "structure" section, drawn by
structure_panel.py), taper, scale the widths or the tree, move its foot, and grow a baked
tree again from its growth parameters.
In a compound they act on the selected component's route (its level chosen in the section);
a component grown from ratios is baked first, an explicit KRS has no route to act on.

Each operation is a pure function of the route (``scene/restructure.py``,
``scene/regrow.py``); here its result is validated by the scene's schema and committed as one
undo step. A refused operation changes nothing and says why in one line, in the section and
in the status. Re-growing that would lose hand edits lists them and asks first."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, NamedTuple, Protocol

from ..document.document import Document
from ..messages import counted
from ..scene import Route, Scene, SceneError
from ..scene.edits import Path, get_at, holds, parse_path, path_text, replace_at, validated
from ..scene.growth import Growth
from ..scene.regrow import rebake
from ..scene.restructure import (
    duplicate_level,
    duplicate_moves,
    merge_level,
    merge_moves,
    move_base,
    scale_tree,
    scale_widths,
    split_level,
    split_moves,
    taper,
)
from ..scene.retrack import Moves, dropped_note, retracked
from ..scene.schema import Vec3, from_dict, to_dict
from ..viewer.commands import Command
from ..viewer.window import Viewer
from . import commands as ec
from .handles import Handle
from .mokrs_levels import key_op

# Insert / Delete / Ctrl+D act on the selected level (the viewer's keys are letters, F-keys
# and Ctrl+Z/Y; Ctrl+D is free: D alone flies).
STRUCTURE_KEYS: dict[str, Command] = {
    "Insert": ec.InsertLevel(),
    "Delete": ec.RemoveLevel(),
    "ctrl+D": ec.DuplicateLevel(),
}


class Regrowth(NamedTuple):
    """A tree grown again that would lose hand edits: it waits for a yes."""

    at: Path  # the route's path in the scene
    route: Route  # grown again
    lost: list[str]  # the hand edits it drops, a line each
    label: str  # the undo step's


@dataclass
class StructureTools:
    """The structure section's values and its last word."""

    split_at: float = 0.5  # where along the branch a fork is inserted
    taper: float = 0.75  # child / parent radius
    widths: float = 1.25  # × every radius
    scale: float = 1.25  # × the whole tree, about its foot
    base: Vec3 | None = None  # where "move the foot" puts it (None: where it is)
    level: int = 0  # in a compound: the level of the component's route the keys act on
    message: str = ""
    refused: bool = False
    pending: Regrowth | None = None  # a re-grow waiting for a yes


class Structured(Protocol):
    """What the structure tools read and call of the editor."""

    viewer: Viewer
    selected: Handle | None
    structure: StructureTools

    @property
    def doc(self) -> Document: ...
    @property
    def scene(self) -> Scene: ...
    @property
    def handles(self) -> list[Handle]: ...
    def select(self, h: Handle | None) -> None: ...
    def select_level(self, level: int) -> None: ...


def baked(scene: Scene, component: int | None) -> tuple[Scene, str, str]:
    """The scene with its grown tree (or a compound's ``component``'s) baked into a route,
    validated, the undo step's label, and what to say; a SceneError where tracks move the
    growth parameters, which a route does not have (baking tree-growing closed the editor)."""
    if component is None:
        out = replace(scene, tree=None, route=scene.tree.route())
        label, said = (
            "bake the tree into a route",
            "baked: drag forks, control points and mirror normals",
        )
    else:
        c = scene.compound[component]
        out = replace_at(
            scene, ("compound", component), replace(c, tree=None, route=c.tree.route())
        )
        label, said = (
            f"bake component {component}'s tree into a route",
            f"baked component {component}: the structure tools act on its route",
        )
    rest = replace(out, animation=None)
    tracks = out.animation.tracks if out.animation else []
    lost = [tr.path for tr in tracks if not holds(rest, parse_path(tr.path))]
    if lost:
        raise SceneError(
            "animation.tracks",
            ", ".join(lost),
            "these tracks move the grown tree's parameters, which a route does not have: "
            "delete them first (their [[animation.tracks]] in the file)",
        )
    return validated(out), label, said


# ----------------------------------------------------------------------------- applying
def _say(e: Structured, text: str, refused: bool) -> None:
    """In the structure section, and at the window's foot: the section's end may be below
    the panel's fold (a refusal is the error, which the status line shows)."""
    t = e.structure
    t.message, t.refused = text, refused
    if refused:
        e.viewer.error = text
    else:
        e.viewer.error, e.viewer.message = "", text
        e.viewer.say(text)


def component(e: Structured) -> int | None:
    """In a compound, the selected component (None: nothing selected, or no compound)."""
    return e.selected.level if e.scene.compound and e.selected is not None else None


def target(e: Structured) -> tuple[Path | None, str]:
    """Where the route the tools act on lies: ``("route",)``, or a compound's selected
    component's ``("compound", k, "route")``; else None and why not."""
    s = e.scene
    if s.route is not None:
        return ("route",), ""
    if not s.compound:
        bake = "; bake the tree first" if s.tree is not None else " (a tree's)"
        return None, f"structure edits need a route{bake}"
    k = component(e)
    if k is None:
        return None, "select a component first (click it in the outline or the view)"
    c = s.compound[k]
    if c.route is not None:
        return ("compound", k, "route"), ""
    if c.tree is not None:
        return None, f"component {k} is grown from ratios: bake it into a route first"
    return None, f"component {k} is an explicit KRS: structure edits need a tree's route"


def commit_route(
    e: Structured,
    make: Callable[[Route], Route],
    label: str,
    interaction: Any = None,
    at: Path | None = None,
    moves: Callable[[Route], Moves] | None = None,
) -> bool:
    """Replace the route at ``at`` (default: :func:`target`) by ``make(route)``, validated,
    as one undo step; ``moves(route)``: where the levels' tracks go (scene/retrack.py), so
    a key keeps moving the level it was set on. A SceneError (from the operation or the
    schema) changes nothing and is said; tracks dropped with a removed level are said too."""
    why = ""
    if at is None:
        at, why = target(e)
    if at is None:
        _say(e, f"{label}: {why}", True)
        return False
    try:
        before = get_at(e.scene, at)
        scene = replace_at(e.scene, at, make(before))
        scene, dropped = retracked(scene, (*at, "levels"), moves(before) if moves else {})
        scene = validated(scene)
    except SceneError as err:
        _say(e, f"{label} refused: {err}", True)
        return False
    if at != ("route",):
        label += f" (component {at[1]})"
    e.doc.commit(scene, label, interaction)
    e.viewer.sync()
    warned = get_at(scene, at).warnings()
    said = label + (f" ({counted(len(warned), 'warning')})" if warned else "")
    _say(e, said + dropped_note(dropped), False)
    return True


def _level(e: Structured, level: int | None, what: str) -> int | None:
    if level is not None:
        return level
    if e.scene.compound:  # the level chosen in the section, of the component's route
        at, why = target(e)
        if at is None:
            _say(e, f"{what}: {why}", True)
        return None if at is None else e.structure.level
    if e.selected is None or e.scene.route is None:
        _say(e, f"{what}: select a level first (click it in the outline or the view)", True)
        return None
    return e.selected.level


def _choose(e: Structured, level: int) -> None:
    """Select ``level`` after an operation: in the outline, or in a compound the section's
    level of the component's route, and the selection there with it where a handle of that
    route was selected (it stayed at the old index: Delete then removed another level)."""
    if not e.scene.compound:
        e.select_level(level)
        return
    e.structure.level = level
    at, _ = target(e)
    if at is not None and e.selected is not None and e.selected.path[: len(at)] == at:
        here = (*at, "levels", level)
        e.select(next((h for h in e.handles if h.path[: len(here)] == here), None))


def insert(e: Structured, level: int | None) -> None:
    i = _level(e, level, "insert a fork")
    s = e.structure.split_at
    if i is not None and commit_route(
        e,
        lambda r: split_level(r, i, s),
        f"insert a fork in L{i} at {s:.2f}",
        moves=lambda r: split_moves(r, i),
    ):
        _choose(e, i + 1)


def remove(e: Structured, level: int | None) -> None:
    i = _level(e, level, "remove a fork")
    if i is not None and commit_route(
        e,
        lambda r: merge_level(r, i),
        f"remove the fork of L{i}",
        moves=lambda r: merge_moves(r, i),
    ):
        at, _ = target(e)
        _choose(e, min(i, len(get_at(e.scene, at).levels) - 1))


def duplicate(e: Structured, level: int | None) -> None:
    i = _level(e, level, "duplicate a level")
    if i is not None and commit_route(
        e, lambda r: duplicate_level(r, i), f"duplicate L{i}", moves=lambda r: duplicate_moves(r, i)
    ):
        _choose(e, i)


def whole_tree(e: Structured, op: str) -> None:
    t = e.structure
    ops = {
        "taper": (lambda r: taper(r, t.taper), f"taper by {t.taper:.3g} per level"),
        "widths": (lambda r: scale_widths(r, t.widths), f"widths x {t.widths:.3g}"),
        "scale": (lambda r: scale_tree(r, t.scale), f"tree x {t.scale:.3g}"),
        "base": (lambda r: move_base(r, t.base or r.base), f"move the foot to {t.base}"),
    }
    commit_route(e, *ops[op])


def growth_field(name: str) -> Path:
    """The growth parameter's field in the panel (its refusal is said there)."""
    return ("route", "growth", name)


def set_growth(e: Structured, name: str, value: Any, interaction: Any) -> None:
    """Grow again with one parameter changed; ask first when hand edits would be lost. A
    refused value stays in its field, red, with the reason under it (as a field of the
    scene's does), until corrected or Esc; it used to snap back."""
    _grow_again(e, f"grow again with {name} = {value}", interaction, name, value)
    error = e.viewer.error if e.structure.refused else ""
    if e.viewer.interactions.settle(growth_field(name), value, error):
        e.viewer.error, e.structure.message = "", ""


def regrow(e: Structured) -> None:
    _grow_again(e, "grow again from the growth parameters", None)


def _grow_again(e: Structured, label: str, interaction: Any, *change: Any) -> None:
    """Re-grow the target route, with ``change`` (a growth parameter's name and value) if
    given; commit it, or keep it pending when hand edits would be lost."""
    at, why = target(e)
    if at is None:
        _say(e, f"{label}: {why}", True)
        return
    route = get_at(e.scene, at)
    try:
        growth = route.growth
        if change:
            where = path_text((*at, "growth"))
            growth = from_dict(Growth, {**to_dict(growth), change[0]: change[1]}, where)
        new, lost = rebake(route, growth)
    except SceneError as err:
        _say(e, f"{label} refused: {err}", True)
        return
    if lost:
        e.structure.pending = Regrowth(at, new, lost, label)
    else:
        commit_route(e, lambda r: new, label, interaction, at)


def confirm_regrow(e: Structured) -> None:
    p, e.structure.pending = e.structure.pending, None
    if p is not None:
        label = f"{p.label} (losing {len(p.lost)} hand edits)"
        commit_route(e, lambda r: p.route, label, at=p.at)


STRUCTURE_HANDLERS: dict[type[Command], Callable[[Any, Any], None]] = {
    ec.InsertLevel: lambda e, c: key_op(e, c) or insert(e, c.level),
    ec.RemoveLevel: lambda e, c: key_op(e, c) or remove(e, c.level),
    ec.DuplicateLevel: lambda e, c: key_op(e, c) or duplicate(e, c.level),
    ec.WholeTree: lambda e, c: whole_tree(e, c.op),
    ec.SetToolValue: lambda e, c: setattr(e.structure, c.name, c.value),
    ec.SetGrowth: lambda e, c: set_growth(e, c.name, c.value, c.interaction),
    ec.Regrow: lambda e, c: regrow(e),
    ec.ConfirmRegrow: lambda e, c: confirm_regrow(e),
    ec.CancelRegrow: lambda e, c: setattr(e.structure, "pending", None),
}
