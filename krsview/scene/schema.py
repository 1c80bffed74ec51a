"""One parameter schema for every consumer: dataclass fields carry range, unit and help.

A field is declared with :func:`param`; :func:`from_dict` builds and validates a dataclass
tree from TOML data and :func:`to_dict` writes it back, so validation, files and (later) GUI
panels read the same metadata (the Fragmentarium habit, see docs/architecture.md).
"""

from __future__ import annotations

import functools
import math
import types
import typing
import unicodedata
from dataclasses import MISSING, field, fields, is_dataclass
from typing import Any, ClassVar

import numpy as np

from ..messages import SceneError

Vec3 = tuple[float, float, float]
UNIT_TOLERANCE = 1e-6  # how far a plane normal's length may be from 1 before it is an error


def cached(obj: Any, name: str, make: Any) -> Any:
    """``make()`` computed once per frozen instance and kept beside its fields (an array
    read-only): a drag's edit, or a frame of a playing scene, asks the same unchanged kernels,
    steps and levels for their arcs, matrices and condition numbers many times."""
    if name not in obj.__dict__:
        value = make()
        if hasattr(value, "flags"):
            value.flags.writeable = False
        object.__setattr__(obj, name, value)
    return obj.__dict__[name]


def cached_each(objs: list, name: str, make: Any) -> list:
    """:func:`cached` for each of ``objs``: those without a kept value get theirs from one
    call ``make(those)`` (a list in their order), so a new pose's arcs or condition numbers
    are found in one NumPy pass, not one per object."""
    new = [obj for obj in objs if name not in obj.__dict__]
    for obj, value in zip(new, make(new) if new else ()):
        cached(obj, name, lambda value=value: value)
    return [obj.__dict__[name] for obj in objs]


def param(
    default: Any = MISSING,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    unit: str = "",
    help: str = "",
    choices: tuple | None = None,
    unit_vector: str | None = None,
) -> Any:
    """A scene field with its allowed range (closed unless ``lo_open``), unit and help text.

    ``unit_vector``: "normalise" scales a direction to length 1; "require" rejects a normal
    whose length is not 1 (a plane's offset is measured in units of its normal)."""
    meta = dict(
        lo=lo,
        hi=hi,
        lo_open=lo_open,
        unit=unit,
        help=help,
        choices=choices,
        unit_vector=unit_vector,
    )
    if isinstance(default, (list, dict)):
        return field(default_factory=lambda d=default: type(d)(d), metadata=meta)
    return field(default=default, metadata=meta)


COLOR = dict(lo=0.0, hi=1.0, help="linear RGB")  # a colour field's range: param(..., **COLOR)

MAX_ITEMS = 1024  # any list in a scene file (the fields' own limits are far lower)

# Scene lengths and coordinates without a range of their own: the GPU squares them in
# float32 (max 3.4e38), so beyond 1e9 a distance overflows to infinity and the image is flat.
COORDINATE_LIMIT = 1e9


def _bounds(meta: dict, kind: type = float) -> tuple[float | None, float | None]:
    lo, hi = meta.get("lo"), meta.get("hi")
    if kind is float and meta.get("choices") is None:
        lo = -COORDINATE_LIMIT if lo is None else lo
        hi = COORDINATE_LIMIT if hi is None else hi
    return lo, hi


class _Short(float):
    """A bound as people write it: 1e+09, not 1000000000.0; 89, not 89.0."""

    def __str__(self) -> str:
        return f"{float(self):g}"


def describe_range(meta: dict, kind: type = float) -> str:
    lo, hi = (x if x is None or isinstance(x, int) else _Short(x) for x in _bounds(meta, kind))
    unit = f" {meta['unit']}" if meta.get("unit") else ""
    if lo is not None and hi is not None:
        return f"allowed: {lo} {'<' if meta.get('lo_open') else '≤'} value ≤ {hi}{unit}"
    if lo is not None:
        return f"allowed: value {'>' if meta.get('lo_open') else '≥'} {lo}{unit}"
    if hi is not None:
        return f"allowed: value ≤ {hi}{unit}"
    return "allowed: a finite number"


def _plain(x: Any) -> Any:
    """A NumPy scalar as the Python number it holds, an array as a list (values from NumPy
    code are taken as a file's numbers are)."""
    if isinstance(x, np.generic):
        return x.item()
    return x.tolist() if isinstance(x, np.ndarray) else x


def _check_number(x: Any, path: str, meta: dict, kind: type) -> float | int:
    x = _plain(x)
    if isinstance(x, bool) or not isinstance(x, (int, float)):
        raise SceneError(path, x, f"expected a number ({kind.__name__})")
    if not math.isfinite(x):
        raise SceneError(path, x, "NaN and infinity are not allowed; " + describe_range(meta, kind))
    lo, hi = _bounds(meta, kind)
    below = lo is not None and (x <= lo if meta.get("lo_open") else x < lo)
    if below or (hi is not None and x > hi):  # first: 1e30 for a count is out of range
        raise SceneError(path, x, describe_range(meta, kind))
    if kind is int and not isinstance(x, int):
        raise SceneError(path, x, "expected a whole number")
    return kind(x)


def _check_vec3(x: Any, path: str, meta: dict) -> Vec3:
    x = _plain(x)
    if not isinstance(x, (list, tuple)) or len(x) != 3:
        raise SceneError(path, x, "expected a list of 3 numbers [x, y, z]")
    v = tuple(_check_number(c, f"{path}[{i}]", meta, float) for i, c in enumerate(x))
    mode = meta.get("unit_vector")
    if mode:
        n = math.hypot(*v)  # no overflow for huge components
        if n < 1e-9:
            raise SceneError(path, list(x), "a direction must not be the zero vector")
        if mode == "require" and abs(n - 1.0) > UNIT_TOLERANCE:
            hint = ", ".join(f"{c / n:.9g}" for c in v)
            raise SceneError(
                path,
                list(x),
                f"must be a unit vector (length {n:.6g}, allowed "
                f"1 ± {UNIT_TOLERANCE:g}, because the offset is measured in its "
                f"units); normalised it is [{hint}]",
            )
        if abs(n - 1.0) > 1e-12:
            v = tuple(c / n for c in v)  # normalise once; already-unit input is kept bit-exact
    return v  # type: ignore[return-value]


def _hint_args(hint: Any) -> tuple[Any, tuple]:
    origin = typing.get_origin(hint)
    return origin, typing.get_args(hint)


def check_value(hint: Any, x: Any, path: str, meta: dict) -> Any:
    """Validate one value against a field type hint; returns the normalised value."""
    origin, args = _hint_args(hint)
    if origin in (typing.Union, types.UnionType):
        if x is None and type(None) in args:
            return None
        (inner,) = [a for a in args if a is not type(None)]
        return check_value(inner, x, path, meta)
    if hint is float or hint is int:
        return _check_number(x, path, meta, hint)
    if hint is bool:
        x = _plain(x)
        if not isinstance(x, bool):
            raise SceneError(path, x, "expected true or false")
        return x
    if hint is str:
        if not isinstance(x, str):
            choices = meta.get("choices")
            one_of = f"; allowed: {', '.join(map(repr, choices))}" if choices else ""
            raise SceneError(path, x, "expected a string" + one_of)
        if meta.get("choices") and x not in meta["choices"]:
            raise SceneError(path, x, "allowed: " + ", ".join(map(repr, meta["choices"])))
        if any(unicodedata.category(c) in ("Cc", "Cs") and c != "\t" for c in x):
            raise SceneError(  # a newline or an escape split or coloured the lines it is in
                path,
                x,
                "allowed: one line of text, without control characters (newlines, escapes) "
                "or lone surrogates (no UTF-8 file can hold one)",
            )
        return x
    if origin is tuple:  # Vec3
        return _check_vec3(x, path, meta)
    if origin is list:
        x = list(x) if isinstance(x, tuple) else _plain(x)
        if not isinstance(x, list):
            raise SceneError(path, x, "expected a list")
        if len(x) > MAX_ITEMS:  # before converting: 500,000 levels took 100 s and 900 MB
            raise SceneError(
                path,
                f"<a list of {len(x):,} items>",
                f"too long; allowed: at most {MAX_ITEMS} items (64 levels, 8 "
                "components, 4 lights, … are the real limits)",
            )
        (inner,) = args
        return [check_value(inner, v, f"{path}[{i}]", meta) for i, v in enumerate(x)]
    if is_dataclass(hint):
        return from_dict(hint, x, path)
    if callable(getattr(hint, "from_toml", None)):
        return hint.from_toml(x, path)
    raise TypeError(f"unsupported field type {hint!r} at {path}")  # a programming error


@functools.cache
def type_hints(cls: type) -> dict[str, Any]:
    """A dataclass's field types, resolved once per class: resolving them is most of the
    cost of validating a scene, and a drag validates one per step."""
    return typing.get_type_hints(cls)


def from_dict(cls: type, data: Any, path: str = "") -> Any:
    """Build dataclass ``cls`` from TOML data, rejecting unknown keys and bad values."""
    if not isinstance(data, dict):
        raise SceneError(path or "<root>", data, f"expected a table of {cls.__name__} fields")
    hints = type_hints(cls)
    known = {f.name for f in fields(cls) if f.init}
    for key in data:
        if key not in known:
            why = getattr(cls, "UNKNOWN_FIELDS", {}).get(key, "unknown field")
            raise SceneError(
                _join(path, key), data[key], f"{why}; allowed fields: {', '.join(sorted(known))}"
            )
    kwargs = {}
    for f in fields(cls):
        if not f.init:
            continue
        if f.name in data:
            kwargs[f.name] = check_value(
                hints[f.name], data[f.name], _join(path, f.name), dict(f.metadata)
            )
        elif f.default is MISSING and f.default_factory is MISSING:
            raise SceneError(_join(path, f.name), "<missing>", "this field is required")
    obj = cls(**kwargs)
    check = getattr(obj, "validate", None)
    if check is not None:
        check(path)
    return obj


def to_dict(obj: Any) -> Any:
    """The TOML-ready form of a dataclass tree (None fields are omitted)."""
    if hasattr(obj, "to_toml"):
        return obj.to_toml()
    if is_dataclass(obj):
        out = {}
        for f in fields(obj):
            if not f.init:
                continue
            v = getattr(obj, f.name)
            if v is not None:
                out[f.name] = to_dict(v)
        return out
    if isinstance(obj, (list, tuple)):
        return [to_dict(v) for v in obj]
    return _plain(obj)  # a NumPy number or array given in Python: as a file writes it


class Tagged:
    """Base of a family of dataclasses told apart by a ``type`` key in the file (kernels,
    Möbius steps). Each family base declares ``registry`` and ``noun``; each member ``kind``."""

    kind: ClassVar[str]
    registry: ClassVar[dict[str, type]]
    noun: ClassVar[str]

    def __init_subclass__(cls, **kw: Any):
        super().__init_subclass__(**kw)
        if "kind" in cls.__dict__:
            cls.registry[cls.kind] = cls

    @classmethod
    def from_toml(cls, data: Any, path: str) -> Any:
        allowed = ", ".join(cls.registry)
        if not isinstance(data, dict) or "type" not in data:
            raise SceneError(
                path, data, f"expected a {cls.noun} table with a 'type'; allowed types: {allowed}"
            )
        kind = data["type"]
        if not isinstance(kind, str) or kind not in cls.registry:
            raise SceneError(f"{path}.type", kind, f"unknown {cls.noun} type; allowed: {allowed}")
        return from_dict(cls.registry[kind], {k: v for k, v in data.items() if k != "type"}, path)

    def to_toml(self) -> dict:
        out: dict[str, Any] = {"type": self.kind}
        for f in fields(self):  # type: ignore[arg-type]
            v = getattr(self, f.name)
            if v is not None:
                out[f.name] = to_dict(v)
        return out


def _join(path: str, key: str) -> str:
    return f"{path}.{key}" if path else key
