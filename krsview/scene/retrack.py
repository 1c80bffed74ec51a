"""Tracks follow their levels through a change of a level list [KRS17 §7, §9]: a level
inserted, removed, duplicated or moved in a route's or a MöKRS's list re-points the tracks
of the levels that moved, drops those of a level removed (the caller says which), and copies
those of a level copied. Where a level's rest position moved (the finer levels carried by a
route's duplicate), its keyed positions move with it, so each key keeps its offset from rest
(the offset is what poses the subtree, animation.bone_offsets)."""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from ..messages import counted
from .animation import Key
from .edits import Path, parse_path, path_text

# Old level index → where its tracks go: (new index, shift of its keyed positions or None).
# An index not listed keeps its place; one listed with no target is removed, tracks and all.
Moves = dict[int, list[tuple[int, Any]]]
POSITIONS = (("fork",), ("control",))  # the fields a rest position's shift moves


def shifted(i: int, n: int, by: int) -> Moves:
    """Levels i..n−1 move ``by`` places (an insert above i − 1, a removal below i)."""
    return {j: [(j + by, None)] for j in range(i, n)}


def retracked(scene: Any, levels: Path, moves: Moves) -> tuple[Any, list[str]]:
    """``scene`` with the tracks into the list at ``levels`` moved as ``moves`` says, and
    the paths of the tracks dropped with their levels."""
    a = scene.animation
    if a is None or not a.tracks or not moves:
        return scene, []
    n, tracks, dropped = len(levels), [], []
    for tr in a.tracks:
        p = parse_path(tr.path)
        if p[:n] != levels or len(p) == n or p[n] not in moves:
            tracks.append(tr)
            continue
        if not moves[p[n]]:
            dropped.append(tr.path)
        for j, shift in moves[p[n]]:
            keys = tr.keys
            if shift is not None and p[n + 1 :] in POSITIONS:
                keys = [Key(k.time, tuple(np.add(k.value, shift).tolist())) for k in keys]
            tracks.append(replace(tr, path=path_text((*levels, j, *p[n + 1 :])), keys=keys))
    return replace(scene, animation=replace(a, tracks=tracks)), dropped


def dropped_note(dropped: list[str]) -> str:
    """What a level operation says of the tracks it dropped with their level ("" if none)."""
    if not dropped:
        return ""
    return f"; its {counted(len(dropped), 'track')} went with it ({', '.join(dropped)})"
