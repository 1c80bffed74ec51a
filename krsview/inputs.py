"""The Python API's arguments that are not scene fields, checked before any work: the scene
itself (a preset's name, a file, or a :class:`Scene` built or changed in Python, validated
as a file holding it would be), image sizes, switches, whole numbers, and the files and
folders written. A bad one raises :class:`SceneError` in one line naming the argument, the
value and what is allowed, as a bad field of a scene file does. The CLI's options reach
the same checks through the API."""

from __future__ import annotations

import contextlib
import math
import numbers
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from .messages import name_too_long, under_a_file
from .scene import Scene, SceneError
from .scene.edits import checked
from .scene.presets import resolve
from .scene.scene import load_scene
from .scene.schema import COORDINATE_LIMIT
from .scene.settings import MAX_SIDE


def scene_of(x: Any, what: str = "scene") -> Scene:
    """``x`` as a scene the API may draw: a preset's name or a ``.toml`` path is loaded; a
    :class:`Scene` is validated as a file holding it would be (one built from the scene's
    classes in Python, or one whose lists were changed in place, is checked too), once per
    contents: unchanged, the same validated scene comes back, with its compiled caches."""
    if isinstance(x, Scene):
        return checked(x)
    if isinstance(x, (str, Path)) and str(x) != "":
        return load_scene(resolve(str(x), what))
    hint = "; a dict: krsview.load_dict(d)" if isinstance(x, dict) else ""  # "" too
    raise SceneError(what, x, "expected a Scene, a preset's name or a .toml path" + hint)


def size_of(size: Any, what: str = "size") -> tuple[int, int]:
    """(width, height) in whole pixels, 1..MAX_SIDE each (NumPy integers too)."""
    allowed = f"expected (width, height), whole numbers of pixels 1..{MAX_SIDE}"
    if isinstance(size, (str, bytes)) or not isinstance(size, Iterable):
        raise SceneError(what, size, allowed)
    pair = tuple(size)
    if len(pair) != 2 or not all(_is_whole(v) and 1 <= v <= MAX_SIDE for v in pair):
        raise SceneError(what, pair, allowed)
    return int(pair[0]), int(pair[1])


def whole(value: Any, what: str, lo: int, hi: int | None = None) -> int:
    """A whole number (NumPy integers too) in lo..hi."""
    span = f"≥ {lo}" if hi is None else f"{lo}..{hi}"
    if not _is_whole(value) or value < lo or (hi is not None and value > hi):
        raise SceneError(what, value, f"allowed: a whole number {span}")
    return int(value)


def real(value: Any, what: str, lo: float, hi: float) -> float:
    """A finite number in lo..hi (NumPy numbers too)."""
    if not isinstance(value, numbers.Real) or isinstance(value, bool):
        raise SceneError(what, value, f"expected a number, {lo:g}..{hi:g}")
    if not (math.isfinite(value) and lo <= value <= hi):
        raise SceneError(what, value, f"allowed: {lo:g} ≤ value ≤ {hi:g}")
    return float(value)


def region(box: Any, what: str) -> tuple[float, ...]:
    """(XMIN, YMIN, ZMIN, XMAX, YMAX, ZMAX): six numbers within the scene's coordinate limit,
    each max above its min."""
    allowed = (
        f"expected six numbers within ±{COORDINATE_LIMIT:g} (XMIN, YMIN, ZMIN, XMAX, YMAX, ZMAX)"
    )
    if isinstance(box, (str, bytes)) or not isinstance(box, Iterable):
        raise SceneError(what, box, allowed)
    values = tuple(box)
    if len(values) != 6 or not all(
        isinstance(v, numbers.Real) and not isinstance(v, bool) and abs(v) <= COORDINATE_LIMIT
        for v in values
    ):
        raise SceneError(what, values, allowed)
    if not all(values[k + 3] > values[k] for k in range(3)):
        raise SceneError(what, values, "each max (the last three) must exceed its min")
    return tuple(float(v) for v in values)


def switch(value: Any, what: str) -> bool:
    """True or False, nothing else (a string such as "no" would read as true)."""
    if not isinstance(value, bool):
        raise SceneError(what, value, "expected True or False")
    return value


def _is_whole(v: Any) -> bool:
    return isinstance(v, numbers.Integral) and not isinstance(v, bool)


def output_file(path: Any, what: str, suffixes: Iterable[str]) -> Path:
    """Before any work: ``path`` ends in one of ``suffixes`` (the format written), is not a
    folder, and its folder exists or can be made and is writable (a render must not fail
    after it ran)."""
    if not isinstance(path, (str, Path)) or str(path) == "":
        raise SceneError(what, path, "expected a file's path")
    p, allowed = Path(path), tuple(suffixes)
    if p.suffix.lower() not in allowed:
        names = ", ".join(allowed[:-1]) + " or " * (len(allowed) > 1) + allowed[-1]
        raise SceneError(what, str(path), "the file must end in " + names)
    if why := name_too_long(p):
        raise SceneError(what, str(path), why)
    if p.is_dir():
        raise SceneError(what, str(path), "is a folder; give a file name ending in " + allowed[0])
    # the probe's own short name: one after the file's (".NAME.write-test") refused a file
    # name within 12 characters of the system's limit as too long
    _probe(p.parent, f".krsview-{os.getpid()}.write-test", what, str(path))
    return p


def output_dir(path: Any, what: str) -> Path:
    """Before any work: the folder exists or can be made, and is writable."""
    if not isinstance(path, (str, Path)) or str(path) == "":
        raise SceneError(what, path, "expected a folder's path")
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise SceneError(what, str(path), "is a file; give a folder")
    _probe(p, ".write-test", what, str(path))
    return p


# Folders the output checks made, deepest last: a command refused after its outputs were
# checked takes back those still empty (unmake_folders), and leaves nothing behind.
MADE: list[Path] = []


def unmake_folders() -> None:
    """Remove the folders the output checks made that are still empty, deepest first."""
    for folder in reversed(MADE):
        with contextlib.suppress(OSError):
            folder.rmdir()
    MADE.clear()


def _probe(folder: Path, name: str, what: str, given: str) -> None:
    if why := under_a_file(folder):
        raise SceneError(what, given, why)
    new = [p for p in (folder, *folder.parents) if not p.exists()]
    try:
        folder.mkdir(parents=True, exist_ok=True)
        MADE.extend(reversed(new))
        (folder / name).write_text("")
        (folder / name).unlink()
    except OSError as e:
        raise SceneError(what, given, f"cannot write there: {e.strerror}") from None
