"""Find scene files: a path, or the name of a preset shipped with krsview. The presets are
data in the top-level ``presets/`` folder, installed as the package ``krsview.presets`` (so a
wheel has them too); this module is the code that finds them."""

from __future__ import annotations

import difflib
from importlib.resources import files
from pathlib import Path

from ..messages import SceneError

PRESET_DIR = Path(str(files("krsview.presets")))
DEFAULT_PRESET = "tree"


def preset_names() -> list[str]:
    return sorted(p.stem for p in PRESET_DIR.glob("*.toml"))


def resolve(name_or_path: str, what: str = "PRESET") -> Path:
    """The scene file a preset's name or a path names; a SceneError naming ``what`` (the
    CLI's PRESET, the API's argument) says which presets there are, the nearest first."""
    p = Path(name_or_path)
    if not name_or_path:
        raise SceneError(what, name_or_path, "expected a preset's name or a scene file (.toml)")
    if p.suffix == ".toml" or p.exists():
        if p.is_dir():
            raise SceneError(
                what,
                name_or_path,
                "is a folder; give a scene file (.toml) or a preset: " + ", ".join(preset_names()),
            )
        if not p.is_file():
            hint = (
                f"; the preset of that name is `{p.stem}` (no .toml)"
                if (PRESET_DIR / p.name).is_file()
                else "; presets: " + ", ".join(preset_names())
            )
            raise SceneError(what, name_or_path, "no such scene file" + hint)
        return p
    candidate = PRESET_DIR / f"{name_or_path}.toml"
    if candidate.is_file():
        return candidate
    raise SceneError(what, name_or_path, "not a file and not a preset" + _nearest(name_or_path))


def _nearest(name: str) -> str:
    """ "; did you mean `tree`? presets: …": the presets nearest ``name``, spelt in any case."""
    names = preset_names()
    near = difflib.get_close_matches(name.lower(), names, n=2, cutoff=0.6)
    ask = f"; did you mean {' or '.join(f'`{n}`' for n in near)}?" if near else ";"
    return ask + " presets: " + ", ".join(names)
