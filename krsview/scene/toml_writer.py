"""A small TOML writer for scene files: vectors and kernels inline, one level per table.

Floats are written with ``repr`` (shortest round-trip form), so save → load is bit-exact.
"""

from __future__ import annotations

import json
import math
from typing import Any


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(float(v))  # float(): numpy scalars repr as np.float64(…)
    if isinstance(v, str):
        # JSON escapes are TOML escapes; TOML also forbids a raw DEL character.
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else json.dumps(k)


def _is_table_list(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def _emit(table: dict, name: str, out: list[str], header: str | None) -> None:
    plain = {
        k: v
        for k, v in table.items()
        if not (isinstance(v, dict) and header != "[[") and not _is_table_list(v)
    }
    if header is not None:
        out.append(f"\n{header}{name}{']]' if header == '[[' else ']'}")
    out += [f"{_key(k)} = {_value(v)}" for k, v in plain.items()]
    for k, v in table.items():
        if k in plain:
            continue
        child = f"{name}.{_key(k)}" if name else _key(k)
        if isinstance(v, dict):
            _emit(v, child, out, "[")
        else:
            for item in v:
                _emit(item, child, out, "[[")


def dumps(data: dict) -> str:
    """TOML text for ``data``; tables inside arrays of tables are written inline."""
    out: list[str] = []
    _emit(data, "", out, None)
    return "\n".join(out).lstrip("\n") + "\n"
