"""A bookmark's table in a scene file's own text: appended after it, and taken out again,
the person's comments, layout and numbers kept (the viewer's B writes it at once, and its
undo and redo write the file too: document.py)."""

from __future__ import annotations

import re

from ..scene import Bookmark, Scene, SceneError, scene_to_toml
from ..scene.filetext import Style, saved_text
from ..scene.scene import scene_from_toml
from ..scene.schema import to_dict
from ..scene.toml_writer import dumps


def bookmark_table(bookmark: Bookmark) -> str:
    return dumps({"bookmarks": [to_dict(bookmark)]})


def without_bookmark(text: str, bookmark: Bookmark, before: Scene, want: Scene) -> str:
    """A scene file's ``text``, which holds ``before``, with ``bookmark`` taken out: the
    table :func:`with_bookmark` appended cut off where it is still the file's end (the text
    as it was, byte for byte), else only that change written into the text (filetext)."""
    tail, (body, style) = "\n" + bookmark_table(bookmark), Style.split(text)
    if body.endswith(tail):
        try:
            if scene_from_toml(body[: -len(tail)]) == want:
                return style.apply(body[: -len(tail)])
        except SceneError:
            pass
    return saved_text(text, before, want)


def with_bookmark(text: str, bookmark: Bookmark, want: Scene) -> str:
    """A scene file's ``text`` with ``bookmark`` appended as a table of its own: the person's
    comments, layout and numbers stay as they wrote them. Where that does not read back as
    ``want`` (a file that lists its bookmarks inline, say), the whole scene written anew."""
    table, (text, style) = bookmark_table(bookmark), Style.split(text)
    # the shipped presets say ``bookmarks = []`` above their tables: that line goes
    bases = [text]
    empty = re.search(r"(?m)^bookmarks[ \t]*=[ \t]*\[[ \t]*\][ \t]*(#.*)?\n", text)
    first = re.search(r"(?m)^\[", text)
    if empty and (first is None or empty.start() < first.start()):
        bases.append(text[: empty.start()] + text[empty.end() :])
    for base in bases:
        added = base + ("" if base.endswith("\n") else "\n") + "\n" + table
        try:
            if scene_from_toml(added) == want:
                return style.apply(added)
        except SceneError:
            pass
    return style.apply(scene_to_toml(want))
