"""Find scene files: a path, or the name of a shipped preset in ``presets/``."""
from __future__ import annotations

from pathlib import Path

from .scene import SceneError

PRESET_DIR = Path(__file__).resolve().parent.parent / "presets"
DEFAULT_PRESET = "tree"


def preset_names() -> list[str]:
    return sorted(p.stem for p in PRESET_DIR.glob("*.toml"))


def resolve(name_or_path: str) -> Path:
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists():
        if not p.is_file():
            raise SceneError("PRESET", name_or_path, "no such scene file")
        return p
    candidate = PRESET_DIR / f"{name_or_path}.toml"
    if candidate.is_file():
        return candidate
    raise SceneError("PRESET", name_or_path,
                     "not a file and not a preset; presets: " + ", ".join(preset_names()))
