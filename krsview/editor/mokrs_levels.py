"""A MöKRS's levels changed as a list: a level duplicated, an identity level inserted above
it, one removed, or moved inward or outward [KRS17 §7]. The panel's buttons and the keys the
route's levels take (Insert, Delete, Ctrl+D) both come here. Each is one ``Edit`` of the
scene (one undo step, validated by the schema), and the selection follows the level acted
on (it used to stay at the index, now another level, so a second "inward" swapped back)."""

from __future__ import annotations

from typing import Any

from ..scene.model import Empty
from ..scene.mokrs import MobiusLevel
from ..viewer.commands import Command, Edit
from . import commands as ec

LEVELS = ("mokrs", "levels")
OPS = {  # name → what it does, as the panel's tooltip says it
    "duplicate": "a copy of this level above it",
    "insert": "an identity level above this one",
    "remove": "remove this level",
    "inward": "swap with the level inside it",
    "outward": "swap with the level outside it",
}


def changed(levels: list, i: int, op: str) -> tuple[list, int]:
    """The level list after ``op`` on level ``i``, and the level to select then."""
    if op == "duplicate":
        return [*levels[: i + 1], levels[i], *levels[i + 1 :]], i
    if op == "insert":
        return [*levels[: i + 1], MobiusLevel(Empty(), [], False), *levels[i + 1 :]], i + 1
    if op == "remove":
        return [*levels[:i], *levels[i + 1 :]], max(0, min(i, len(levels) - 2))
    j = i + (-1 if op == "inward" else 1)
    if not 0 <= j < len(levels):
        return list(levels), i
    out = list(levels)
    out[i], out[j] = out[j], out[i]
    return out, j


def level_commands(levels: list, i: int, op: str) -> list[Command]:
    """``op`` on level ``i`` as the editor's commands: the edit, then the selection."""
    new, select = changed(levels, i, op)
    return [Edit(LEVELS, new), ec.SelectLevel(select)]


KEY_OPS = {ec.InsertLevel: "insert", ec.RemoveLevel: "remove", ec.DuplicateLevel: "duplicate"}


def key_op(e: Any, command: Any) -> bool:
    """Insert / Delete / Ctrl+D on a MöKRS (the editor's structure keys): its selected
    level's op (True), or not a MöKRS (False: the route's structure tools act)."""
    m = e.scene.mokrs
    if m is None:
        return False
    i = command.level if command.level is not None else (e.selected and e.selected.level)
    if i is None:
        e.viewer.error = f"{KEY_OPS[type(command)]} a level: select one first (the outline)"
        return True
    e.execute(level_commands(m.levels, i, KEY_OPS[type(command)]))
    return True
