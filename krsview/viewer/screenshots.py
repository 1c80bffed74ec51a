"""Where F12 writes: a folder beside the user's scene, ``NAME.screenshots/``, where the user
finds it again; the user's pictures folder for a shipped preset (its folder is the package's,
read-only when installed, a checkout's source folder otherwise) and when the scene's folder
cannot be written."""

from __future__ import annotations

import io
import shutil
import subprocess
from pathlib import Path

import numpy as np
from PIL import Image

from ..files import write_atomic
from ..scene.presets import PRESET_DIR


def pictures_folder() -> Path:
    """``krsview/`` in the user's pictures folder: ``xdg-user-dir PICTURES`` when it names
    one (it answers the home folder when none is set), else ``~/Pictures``."""
    home = Path.home()
    tool = shutil.which("xdg-user-dir")
    if tool:
        try:
            answer = subprocess.run(
                [tool, "PICTURES"], capture_output=True, text=True, timeout=5
            ).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            answer = ""
        if answer and Path(answer) != home:
            return Path(answer) / "krsview"
    return home / "Pictures" / "krsview"


def screenshot_folders(scene: Path) -> tuple[Path, ...]:
    """The folders tried in turn: beside the scene (not a shipped preset's), then the
    pictures folder."""
    if scene.resolve().parent == PRESET_DIR.resolve():
        return (pictures_folder(),)
    return scene.parent / f"{scene.stem}.screenshots", pictures_folder()


def save_screenshot(rgb: np.ndarray, scene: Path, stamp: str) -> Path:
    """Write ``rgb`` (H, W, 3 bytes) as ``SCENE-STAMP.png``, whole or not at all, in the first
    of :func:`screenshot_folders` that can be written; returns its full path. A second shot
    in the same second is ``SCENE-STAMP-2.png``: none overwrites another."""
    png = io.BytesIO()
    Image.fromarray(rgb).save(png, format="PNG")
    failed = []
    for folder in screenshot_folders(scene):
        out = folder.absolute() / f"{scene.stem}-{stamp}.png"
        k = 1
        while out.exists():
            k += 1
            out = folder.absolute() / f"{scene.stem}-{stamp}-{k}.png"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            write_atomic(out, png.getvalue())
            return out
        except OSError as e:
            failed.append(f"{folder}: {e.strerror or e}")
    raise OSError(f"screenshot not written: {'; '.join(failed)}")
