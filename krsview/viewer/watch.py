"""File watching: the scene file and the shader folder are checked twice a second; a change
becomes a command (reload the scene, or the shaders) for the window to apply."""

from __future__ import annotations

import time
from pathlib import Path

from .commands import Command, ReloadScene, ReloadShaders

RELOAD_INTERVAL = 0.5  # seconds between checks of the preset and shader files


def _mtime(p: Path) -> float:
    try:
        return p.stat().st_mtime
    except OSError:
        return 0.0


class FileWatcher:
    def __init__(self, scene_file: Path, shader_dir: Path):
        self.scene_file, self.shader_dir = scene_file, shader_dir
        self._stamps = self._now()
        self._last_check = time.perf_counter()

    def _now(self) -> tuple:
        shaders = sorted(self.shader_dir.iterdir())
        return (_mtime(self.scene_file), tuple(_mtime(p) for p in shaders))

    def watch(self, scene_file: Path) -> None:
        """Watch ``scene_file`` from now on (another scene opened, or saved under a new name)."""
        self.scene_file = scene_file
        self.forget()

    def forget(self) -> None:
        """The files as they are now are not a change (our own save)."""
        self._stamps = self._now()

    def poll(self) -> list[Command]:
        """What changed since the last check (at most one check per RELOAD_INTERVAL)."""
        now = time.perf_counter()
        if now - self._last_check < RELOAD_INTERVAL:
            return []
        self._last_check = now
        stamps = self._now()
        if stamps == self._stamps:
            return []
        scene_changed = stamps[0] != self._stamps[0]
        self._stamps = stamps
        return [ReloadScene()] if scene_changed else [ReloadShaders()]
