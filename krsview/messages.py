"""The one-line error every bad input gets, and the helpers that write its message: a
file, a field's path, its value (briefly) and what is allowed. A base module: the scene, the
frame and everything above raise it."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any


def _brief(value: Any, limit: int = 60) -> str:
    """A value as it is shown in an error: one short line (a table is not printed whole)."""
    if isinstance(value, dict):
        return (
            "{a table with " + (", ".join(map(str, value)) or "no fields") + "}"
            if len(repr(value)) > limit
            else repr(value)
        )
    if isinstance(value, bool):  # as a scene file (TOML) spells it
        return "true" if value else "false"
    if isinstance(value, str) and value.startswith("<") and value.endswith(">"):
        return value  # a description of the value ("<65 levels>"), not the value: no quotes
    if isinstance(value, (list, tuple)) and value and all(_is_real(x) for x in value):
        text = ", ".join(_short(x) for x in value)  # the numbers, not their float noise
        text = f"[{text}]" if isinstance(value, list) else f"({text}{',' * (len(value) == 1)})"
    else:
        text = repr(value)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def counted(n: int, noun: str) -> str:
    """``1 warning``, ``2 warnings``: a count with its noun in the number it takes."""
    return f"{n:,} {noun}" + ("" if n == 1 else "s")


def _short(x: float) -> str:
    """A number as written, or to 6 digits where that is longer (a vector's noise cut a
    message off in its first number)."""
    x = x + 0  # −0.0 is shown as 0.0: the sign of a zero says nothing to a person
    return repr(x) if len(repr(x)) <= 9 else f"{x:.6g}"


def _is_real(x: Any) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def under_a_file(folder: Path) -> str:
    """Why nothing can be written in ``folder`` when it, or the nearest of its parents that
    exists, is a file ("'x' is a file, not a folder"); "" where it is not."""
    above = nearest_existing(folder)
    return f"{str(above)!r} is a file, not a folder" if above and not above.is_dir() else ""


def nearest_existing(folder: Path) -> Path | None:
    """``folder``, or the nearest of its parents that exists; None where none does."""
    return next((p for p in (folder, *folder.parents) if p.exists()), None)


TEMP_ROOM = 16  # bytes a temporary file's name adds to the name of the file it becomes


def name_too_long(path: Path) -> str:
    """Why ``path``'s file name cannot be written, its temporary file beside it first: longer
    than the system allows ("a file name of 300 bytes; …"); "" where it fits."""
    above = nearest_existing(path.parent) or Path("/")
    try:
        limit = os.pathconf(above, "PC_NAME_MAX")
    except (OSError, ValueError):  # no such limit said: the common one
        limit = 255
    size = len(os.fsencode(path.name))
    if size + TEMP_ROOM <= limit:
        return ""
    return (
        f"a file name of {size} bytes; allowed: at most {limit - TEMP_ROOM} (the system's "
        f"{limit}, less room for the temporary file written first)"
    )


# The "paths" of mistakes in a file as a whole (unreadable, too large, not UTF-8 or not TOML),
# not in one of its fields: their message says the file, then where in it, then what is wrong.
WHOLE_FILE = ("<file>", "<syntax>")


class SceneError(ValueError):
    """A user mistake in a scene: names the file, the field path, the value and what is allowed."""

    def __init__(self, path: str, value: Any, allowed: str, file: str | None = None):
        self.file, self.path, self.value, self.allowed = file, path, value, allowed
        super().__init__(self._text())

    def _text(self) -> str:
        if self.path in WHOLE_FILE:  # no field to name: the file, where in it, what is wrong
            parts = [self.file, None if str(self.value) == self.file else str(self.value)]
            return ": ".join([p for p in parts if p] + [self.allowed])
        where = f"{self.file}: " if self.file else ""
        return f"{where}{self.path} = {_brief(self.value)}: {self.allowed}"

    def __reduce__(self):  # picklable: a worker process's error reaches its pool whole
        return (SceneError, (self.path, self.value, self.allowed, self.file))

    def in_file(self, file: str) -> SceneError:
        return SceneError(self.path, self.value, self.allowed, file)
