"""A MöKRS's levels changed as a list: a level duplicated, an identity level inserted above
it, one removed, or moved inward or outward [KRS17 §7]. The panel's buttons and the keys the
route's levels take (Insert, Delete, Ctrl+D) both come here. Each is one ``Edit`` of the
scene (one undo step, validated by the schema), and the selection follows the level acted
on (it used to stay at the index, now another level, so a second "inward" swapped back)."""

from __future__ import annotations

from typing import Any

from ..compile.mokrs import check_drawable
from ..scene import SceneError
from ..scene.edits import replace_at, validated
from ..scene.model import Empty
from ..scene.mokrs import MobiusLevel
from ..scene.retrack import Moves, dropped_note, retracked, shifted
from ..viewer.commands import Command
from . import commands as ec

LEVELS = ("mokrs", "levels")
VIEW = "view.position"  # the viewpoint flown in the editor, in a refused edit's message
OPS = {  # name → what it does, as the panel's tooltip says it
    "duplicate": "a copy of this level above it",
    "insert": "an identity level above this one",
    "remove": "remove this level",
    "inward": "swap with the level inside it",
    "outward": "swap with the level outside it",
}


def changed(levels: list, i: int, op: str) -> tuple[list, int, Moves]:
    """The level list after ``op`` on level ``i``, the level to select then, and where
    each level's tracks go (scene/retrack.py): a copy's tracks are copied with it."""
    n = len(levels)
    if op == "duplicate":
        moves = {i: [(i, None), (i + 1, None)], **shifted(i + 1, n, 1)}
        return [*levels[: i + 1], levels[i], *levels[i + 1 :]], i, moves
    if op == "insert":
        new = [*levels[: i + 1], MobiusLevel(Empty(), [], False), *levels[i + 1 :]]
        return new, i + 1, shifted(i + 1, n, 1)
    if op == "remove":
        return (
            [*levels[:i], *levels[i + 1 :]],
            max(0, min(i, n - 2)),
            {i: []} | shifted(i + 1, n, -1),
        )
    j = i + (-1 if op == "inward" else 1)
    if not 0 <= j < n:
        return list(levels), i, {}
    out = list(levels)
    out[i], out[j] = out[j], out[i]
    return out, j, {i: [(j, None)], j: [(i, None)]}


def level_commands(i: int, op: str) -> list[Command]:
    """``op`` on level ``i`` as the editor's command (:func:`apply_op`)."""
    return [ec.LevelOp(i, op)]


def apply_op(e: Any, i: int, op: str) -> None:
    """``op`` on the MöKRS's level ``i`` as one undo step, its tracks following their levels,
    validated as a file (and the viewpoint kept off every pole); then the level acted on is
    selected. A refusal changes nothing, the selection included, and says why."""
    v, label = e.viewer, f"{op} level {i}"
    new, select, moves = changed(e.scene.mokrs.levels, i, op)
    try:
        scene, dropped = retracked(replace_at(e.scene, LEVELS, new), LEVELS, moves)
        scene = validated(scene)
        check_drawable(scene.mokrs, tuple(v.camera.position), VIEW)
    except SceneError as err:
        v.error = f"{label} refused: {err}"
        return
    e.doc.commit(scene, label)
    v.sync()
    v.error, v.message = "", label + dropped_note(dropped)
    v.say(v.message)
    e.select_level(select)


KEY_OPS = {ec.InsertLevel: "insert", ec.RemoveLevel: "remove", ec.DuplicateLevel: "duplicate"}


def key_op(e: Any, command: Any) -> bool:
    """Insert / Delete / Ctrl+D on a MöKRS (the editor's structure keys): its selected
    level's op (True), or not a MöKRS (False: the route's structure tools act)."""
    if e.scene.mokrs is None:
        return False
    i = command.level if command.level is not None else (e.selected and e.selected.level)
    if i is None:
        e.viewer.error = f"{KEY_OPS[type(command)]} a level: select one first (the outline)"
        return True
    apply_op(e, i, KEY_OPS[type(command)])
    return True
