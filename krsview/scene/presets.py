"""Find scene files: a path, or the name of a preset shipped with krsview. The presets are
data in the top-level ``presets/`` folder, installed as the package ``krsview.presets`` (so a
wheel has them too); this module is the code that finds them."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

from ..messages import SceneError

PRESET_DIR = Path(str(files("krsview.presets")))
DEFAULT_PRESET = "tree"


def preset_names() -> list[str]:
    return sorted(p.stem for p in PRESET_DIR.glob("*.toml"))


def resolve(name_or_path: str) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if p.is_dir():
            raise SceneError(
                "PRESET",
                name_or_path,
                "is a folder; give a scene file (.toml) or a preset: " + ", ".join(preset_names()),
            )
        if not p.is_file():
            hint = (
                f"; the preset of that name is `{p.stem}` (no .toml)"
                if (PRESET_DIR / p.name).is_file()
                else "; presets: " + ", ".join(preset_names())
            )
            raise SceneError("PRESET", name_or_path, "no such scene file" + hint)
        return p
    candidate = PRESET_DIR / f"{name_or_path}.toml"
    if candidate.is_file():
        return candidate
    raise SceneError(
        "PRESET", name_or_path, "not a file and not a preset; presets: " + ", ".join(preset_names())
    )
