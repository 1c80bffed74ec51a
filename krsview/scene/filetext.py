"""A scene file's text kept through a save: only the values that changed are written, into
the person's own text, so their comments, layout and numbers stay (tomlkit keeps a TOML
document's trivia as it edits it). A save used to write the whole scene anew: comments
gone, every default spelled out, a light direction never touched written normalised.

The two scenes are compared as the file schema writes them (``to_dict``): a table's changed
fields are set in place; a list of tables is matched item by item (difflib), so a level
inserted, duplicated or removed adds or drops its own table alone, written in the style of
its neighbours (inline kernels stay inline), and the others are changed in place; a field
that became unset goes. What comes out must read back as the scene saved, else the scene is
written anew."""

from __future__ import annotations

import difflib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import tomlkit
from tomlkit.exceptions import TOMLKitError

from ..messages import SceneError
from .scene import BOM, Scene, scene_from_toml, scene_to_toml
from .schema import to_dict


def read_file_text(path: str | os.PathLike) -> str:
    """A scene file's text as written: a byte-order mark and CRLF line ends kept (Python's
    text mode turns CRLF into LF), so that a save writes them back (:class:`Style`)."""
    return Path(path).read_bytes().decode("utf-8")


@dataclass(frozen=True)
class Style:
    """What a file's text holds besides its TOML: a byte-order mark, CRLF line ends."""

    mark: str = ""
    crlf: bool = False

    @staticmethod
    def split(text: str) -> tuple[str, Style]:
        """``text`` as LF text without a mark, and its style."""
        mark, body = (BOM, text[1:]) if text.startswith(BOM) else ("", text)
        crlf = "\r\n" in body
        return (body.replace("\r\n", "\n") if crlf else body), Style(mark, crlf)

    def apply(self, body: str) -> str:
        """LF text ``body`` given this style."""
        return self.mark + (body.replace("\n", "\r\n") if self.crlf else body)


def saved_text(text: str, before: Scene, after: Scene) -> str:
    """The text of a file that held ``before`` as ``text``, changed to hold ``after``, in
    the file's own style (a save over a file with a byte-order mark wrote the whole scene
    anew, its comments gone; one with CRLF line ends came back LF throughout)."""
    if after == before:
        return text
    body, style = Style.split(text)
    return style.apply(_saved(body, before, after))


def _saved(text: str, before: Scene, after: Scene) -> str:
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
            and isinstance(here, (tomlkit.items.AoT, tomlkit.items.Array))
            and len(here) == len(old)
        ):
            _patch_tables(here, old, value)
        else:
            table[key] = _item(value, here)


def _patch_tables(here: Any, before: list[dict], after: list[dict]) -> None:
    """``here`` (the file's list of tables, holding ``before``) changed to hold ``after``:
    the items matched by difflib stay as written, a replaced run of the same length is
    patched item by item, and the rest are inserted or deleted where they lie."""
    keys = [[repr(v) for v in items] for items in (before, after)]
    ops = difflib.SequenceMatcher(None, *keys, autojunk=False).get_opcodes()
    for tag, i1, i2, j1, j2 in reversed(ops):  # from the end: earlier indices stay valid
        if tag == "equal":
            continue
        if i2 - i1 == j2 - j1:
            for k in range(i2 - i1):
                _patch(here[i1 + k], before[i1 + k], after[j1 + k])
            continue
        model = here[0] if len(here) else None
        for k in reversed(range(i1, i2)):
            del here[k]
        for k in range(j1, j2):
            here.insert(
                i1 + k - j1, _like(after[k], model, inline=isinstance(here, tomlkit.items.Array))
            )


def _like(value: dict, model: Any, inline: bool) -> Any:
    """A new table holding ``value`` written as ``model`` (a sibling) is: its tables inline
    where the sibling's are; an item of an inline list inline throughout."""
    if inline:
        return _inline(value, _spaced(model))
    out = tomlkit.table()
    for key, v in value.items():
        was = model.get(key) if model is not None else None
        inline_was = isinstance(was, tomlkit.items.InlineTable)
        out[key] = _inline(v, _spaced(was)) if inline_was else tomlkit.item(v)
    out.add(tomlkit.nl())  # a blank line before the next table, as between the others
    return out


def _spaced(model: Any) -> bool:
    """Whether an inline table is written ``{ a = 1 }`` (as krsview writes) or ``{a = 1}``."""
    return model is None or model.as_string().startswith("{ ")


def _inline(value: Any, spaced: bool = True) -> Any:
    """``value`` with every table in it inline, ``{ a = 1 }`` or, not ``spaced``,
    ``{a = 1}``."""
    if isinstance(value, dict):
        body = ", ".join(f"{k} = {_inline(v, spaced).as_string()}" for k, v in value.items())
        return tomlkit.parse(f"x = {{ {body} }}" if spaced else f"x = {{{body}}}")["x"]
    if isinstance(value, list):
        return tomlkit.item([_inline(v, spaced) for v in value])
    return tomlkit.item(value)


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
