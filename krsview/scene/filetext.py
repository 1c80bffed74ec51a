"""A scene file's text kept through a save: only the values that changed are written, into
the person's own text, so their comments, layout and numbers stay (tomlkit keeps a TOML
document's trivia as it edits it). A save used to write the whole scene anew: comments
gone, every default spelled out, a light direction never touched written normalised.

The two scenes are compared as the file schema writes them (``to_dict``): a table's changed
fields are set in place; a list of tables of the same length is changed table by table; one
that grew or shrank (a level inserted) is written anew; a field that became unset goes.
What comes out must read back as the scene saved, else the scene is written anew."""

from __future__ import annotations

from typing import Any

import tomlkit
from tomlkit.exceptions import TOMLKitError

from .scene import Scene, scene_from_toml, scene_to_toml
from .schema import SceneError, to_dict


def saved_text(text: str, before: Scene, after: Scene) -> str:
    """The text of a file that held ``before`` as ``text``, changed to hold ``after``."""
    if after == before:
        return text
    try:
        document = tomlkit.parse(text)
        _patch(document, to_dict(before), to_dict(after))
        out = tomlkit.dumps(document)
        if scene_from_toml(out) == after:
            return out
    except (TOMLKitError, SceneError, ValueError, TypeError):
        pass
    return scene_to_toml(after)


def _patch(table: Any, before: dict, after: dict) -> None:
    """Set in ``table`` (a tomlkit table) what differs from ``before`` in ``after``."""
    for key in [k for k in before if k not in after]:  # unset now (a None field)
        if key in table:
            del table[key]
    for key, value in after.items():
        old = before.get(key)
        if old == value:
            continue
        here = table.get(key) if key in table else None
        if isinstance(value, dict) and isinstance(old, dict) and here is not None:
            _patch(here, old, value)
        elif (
            _tables(value)
            and _tables(old)
            and len(value) == len(old)
            and here is not None
            and len(here) == len(value)
        ):
            for item, was, now in zip(here, old, value):
                _patch(item, was, now)
        else:
            table[key] = _item(value, here)


def _tables(value: Any) -> bool:
    return isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)


def _item(value: Any, here: Any) -> Any:
    """``value`` as tomlkit writes it where ``here`` was: a list of tables as tables of
    their own (``[[...]]``) unless it was written inline; a number list on one line."""
    if _tables(value) and not isinstance(here, tomlkit.items.Array):
        out = tomlkit.aot()
        for v in value:
            out.append(tomlkit.item(v))
        return out
    return tomlkit.item(value)
