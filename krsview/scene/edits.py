"""Edits as data: a path into the scene's dataclass tree and a new value, applied as a pure
"replace at path" and validated by the same schema that reads files, so an edit from the
editor is held to exactly the rules of a scene file (DESIGN.md, One seam for edits).

A path is a tuple of field names and list indices, e.g. ``("route", "levels", 3, "fork")``;
it prints as ``route.levels[3].fork``, the form scene-file errors use.
"""

from __future__ import annotations

from dataclasses import fields, is_dataclass, replace
from typing import Any

from .schema import SceneError, Tagged, from_dict, to_dict

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


def parse_path(text: str | Path) -> Path:
    """``"route.levels[3].fork"`` → ``("route", "levels", 3, "fork")`` (a tuple passes)."""
    if not isinstance(text, str):
        return tuple(text)
    out: list[str | int] = []
    for part in text.split("."):
        name, *indices = part.replace("]", "").split("[")
        if not name or not all(i.isdigit() for i in indices):
            raise SceneError(text, "<path>", "expected names and [indices], e.g. render.tracer")
        out += [name, *(int(i) for i in indices)]
    return tuple(out)


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
    try:
        return revalidated(replace_at(scene, path, value), [path])
    except (KeyError, IndexError, TypeError, AttributeError) as e:
        raise SceneError(path_text(path), value, f"not a field of this scene ({e})") from None
