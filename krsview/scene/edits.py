"""Edits as data: a path into the scene's dataclass tree and a new value, applied as a pure
"replace at path" and validated by the same schema that reads files, so an edit from the
editor is held to exactly the rules of a scene file (docs/architecture.md, One seam for edits).

A path is a tuple of field names and list indices, e.g. ``("route", "levels", 3, "fork")``;
it prints as ``route.levels[3].fork``, the form scene-file errors use.
"""

from __future__ import annotations

import numbers
import re
from dataclasses import fields, is_dataclass, replace
from typing import Any

from ..messages import SceneError
from .schema import Tagged, from_dict, to_dict

Path = tuple[str | int, ...]


def path_text(path: Path) -> str:
    out = ""
    for key in path:
        out += f"[{key}]" if isinstance(key, int) else (f".{key}" if out else key)
    return out or "<scene>"


def get_at(obj: Any, path: Path) -> Any:
    for key in path:
        obj = obj[key] if isinstance(key, int) else getattr(obj, key)
    return obj


def holds(obj: Any, path: Path) -> bool:
    """Whether ``obj`` has a value at ``path`` (each field there, each index in range)."""
    try:
        get_at(obj, path)
    except (AttributeError, IndexError, KeyError, TypeError):
        return False
    return True


def replace_at(obj: Any, path: Path, value: Any) -> Any:
    """A copy of ``obj`` with the value at ``path`` replaced; everything else is shared."""
    if not path:
        return value
    key, rest = path[0], path[1:]
    if isinstance(key, int):
        items = list(obj)
        items[key] = replace_at(items[key], rest, value)
        return type(obj)(items)
    if not (is_dataclass(obj) and key in {f.name for f in fields(obj)}):
        raise KeyError(f"no field {key!r} in {type(obj).__name__}")
    return replace(obj, **{key: replace_at(getattr(obj, key), rest, value)})


def validated(scene: Any) -> Any:
    """The scene as a file holding it would load: every field checked and normalised (unit
    vectors), or a SceneError naming the field. Values already valid come back bit-exact."""
    return from_dict(type(scene), to_dict(scene))


def checked(scene: Any) -> Any:
    """:func:`validated`, once per contents: a scene vouched for (:func:`vouched`) or
    checked before whose values are unchanged comes back as it is, with its compiled
    caches; one changed in place since (its lists are Python lists) is validated anew into
    fresh objects, so no cache of the old contents survives."""
    data = to_dict(scene)  # about 1 ms; validating an animated MöKRS takes 0.5 s
    seen = scene.__dict__.get("_checked")
    if seen is not None and seen[0] == data:
        return seen[1]
    good = validated(scene)
    try:  # the same values, of the same types: keep its caches (NumPy inside: the new one)
        same = seen is None and bool(good == scene)
    except ValueError:
        same = False
    if same:
        good = scene
    object.__setattr__(scene, "_checked", (data, good))
    return good


def vouched(scene: Any) -> Any:
    """``scene``, known valid (read from a file, or edited through the schema): recorded,
    so that :func:`checked` does not validate it again while its values stay."""
    object.__setattr__(scene, "_checked", (to_dict(scene), scene))
    return scene


def still_checked(before: Any, after: Any) -> Any:
    """``after``, made from ``before`` by changes that keep a valid scene valid (an edit
    validated by :func:`revalidated`, or constants within the schema's ranges): vouched
    for where ``before`` was (its values unchanged since), so that :func:`checked` does
    not validate it whole again (1.1 s on animated palm-curl); else as it is."""
    seen = before.__dict__.get("_checked")
    if seen is not None and seen[1] is before and seen[0] == to_dict(before):
        return vouched(after)
    return after


PATH_FORM = (
    "expected field names and list indices ≥ 0, e.g. 'route.levels[3].fork' or "
    "('route', 'levels', 3, 'fork')"
)


def parse_path(text: str | Path) -> Path:
    """``"route.levels[3].fork"`` → ``("route", "levels", 3, "fork")``; a tuple is checked
    (names, and indices ≥ 0: a NumPy integer is taken as one, True is not, and -1 does not
    count from the end) and passes."""
    if isinstance(text, tuple):
        out = tuple(_part(text, part) for part in text)
        if not out:
            raise SceneError("path", text, PATH_FORM)
        return out
    if not isinstance(text, str):
        raise SceneError("path", text, "expected a path such as 'render.tracer', or a tuple")
    out: list[str | int] = []
    for part in text.split("."):
        if not re.fullmatch(r"[A-Za-z_]\w*(\[\d+\])*", part):
            raise SceneError("path", text, PATH_FORM)
        name, *indices = part.replace("]", "").split("[")
        out += [name, *(int(i) for i in indices)]
    return tuple(out)


def _part(path: tuple, part: Any) -> str | int:
    """One part of a tuple path: a field name, or a list index ≥ 0."""
    if isinstance(part, str) and part.isidentifier():
        return part
    if isinstance(part, numbers.Integral) and not isinstance(part, bool) and part >= 0:
        return int(part)
    raise SceneError("path", path, PATH_FORM)


def revalidated(scene: Any, paths: list[Path]) -> Any:
    """``scene`` (valid before the values at ``paths`` were replaced) as a file holding it
    would load: each table holding a replaced value is rebuilt from its data (checked and
    normalised as a file's), and the tables around it run their own rules (``validate``),
    innermost first, up to the scene's. The rest was valid and is shared, not rebuilt: a
    palm's edit validates in a fraction of the time the whole scene takes."""
    owners = {_owner(scene, p) for p in paths}
    around = {q[:n] for q in owners for n in range(len(q))} - owners
    for prefix in sorted(owners | around, key=len, reverse=True):
        obj, text = get_at(scene, prefix), path_text(prefix) if prefix else ""
        if prefix in owners:
            data = to_dict(obj)
            fresh = (
                type(obj).from_toml(data, text)
                if isinstance(obj, Tagged)
                else from_dict(type(obj), data, text)
            )
            scene = replace_at(scene, prefix, fresh)
        elif not prefix and hasattr(obj, "validate_edit"):  # the scene: its rules that
            obj.validate_edit(text, {p[0] for p in paths})  # read the tables changed
        elif is_dataclass(obj) and hasattr(obj, "validate"):
            obj.validate(text)
    return scene


def _owner(scene: Any, path: Path) -> Path:
    """The longest proper prefix of ``path`` that names a table (a dataclass): the table
    whose field the path changes."""
    obj, owner = scene, ()
    for n, key in enumerate(path[:-1], 1):
        obj = obj[key] if isinstance(key, int) else getattr(obj, key)
        if is_dataclass(obj):
            owner = path[:n]
    return owner


def apply_edit(scene: Any, path: Path, value: Any) -> Any:
    """Replace the value at ``path`` and validate the result; a SceneError leaves nothing
    changed (the caller keeps its last valid scene)."""
    why = _not_there(scene, path)
    if why:
        raise SceneError(path_text(path), value, f"not a field of this scene: {why}")
    try:
        return still_checked(scene, revalidated(replace_at(scene, path, value), [path]))
    except (KeyError, IndexError, TypeError, AttributeError) as e:
        raise SceneError(path_text(path), value, f"not a field of this scene ({e})") from None


def _not_there(scene: Any, path: Path) -> str:
    """Why ``path`` names nothing in ``scene`` (a table it lacks, a field no table of that
    kind has, an index past a list's end), or "" where it names a value."""
    obj = scene
    for n, key in enumerate(path):
        here = path_text(path[:n])
        if isinstance(key, int):
            if not isinstance(obj, (list, tuple)):
                return f"{here} is not a list"
            if not 0 <= key < len(obj):
                return f"{here} has {len(obj)} items" + (f" (0..{len(obj) - 1})" if obj else "")
            obj = obj[key]
        elif obj is None:
            return f"this scene has no [{here}] table"
        elif not is_dataclass(obj) or key not in {f.name for f in fields(obj) if f.init}:
            if not is_dataclass(obj):
                return f"{here or 'the scene'} has no fields"
            known = ", ".join(f.name for f in fields(obj) if f.init)
            return f"{here or 'the scene'} has no field {key!r}; its fields: {known}"
        else:
            obj = getattr(obj, key)
    return ""
