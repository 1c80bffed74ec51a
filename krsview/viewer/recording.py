"""Camera-path record and replay: F5 records the poses of the flying camera, saved beside the
preset as ``NAME.path.json`` (`krsview render --camera-path` renders its frames); F6 flies
the recorded path again."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..document.document import copy_target, shipped
from ..files import write_atomic
from ..scene import SceneError
from ..scene.camera_path import CameraPath, Pose, camera_path_json, load_camera_path
from ..scene.presets import PRESET_DIR
from .camera import FlyCamera

# The command that renders a recorded path, its spaces unbreakable: the HUD wraps the message
# around it, never inside it.
RENDER_PATH = "`krsview render --camera-path`".replace(" ", "\u00a0")


def path_file(scene_file: Path) -> Path:
    """Where the camera path of a preset is kept: beside it, ``NAME.path.json``; for a
    preset shipped in the package (a template, never written), beside its copy."""
    if shipped(scene_file):
        scene_file = copy_target(scene_file)
    return scene_file.with_name(scene_file.stem + ".path.json")


class Recorder:
    """The camera path of one preset: recorded here or loaded from its file, and replayed."""

    def __init__(self, scene_file: Path):
        self.file = path_file(scene_file)  # where a recording is saved
        self.recording: list[Pose] | None = None
        self.path: CameraPath | None = None
        self.replay_start: float | None = None
        self.message, self.error = "", ""
        # a shipped preset's own path (grove-wind's), opened by name or as a copy, until one
        # is recorded beside the copy
        own = scene_file.with_name(scene_file.stem + ".path.json")
        if not own.exists():
            own = PRESET_DIR / own.name
        source = self.file if self.file.exists() or not own.exists() else own
        if source.exists():  # a damaged file is reported, not fatal
            try:
                self.path = load_camera_path(source)
            except SceneError as e:
                self.error = str(e)
        self.source = source

    def toggle(self) -> None:
        """Start recording, or stop and save what was recorded."""
        if self.recording is None:
            self.recording, self.message = [], "recording the camera path (F5 stops)"
            return
        if self.recording:
            self.path = CameraPath(tuple(self.recording))
            self.save()
        self.recording = None

    def save(self) -> None:
        poses = list(self.path.poses)
        try:
            self.file.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(self.file, camera_path_json(poses))
            self.source = self.file
            self.message = (
                f"recorded {len(poses)} poses to {self.file.name} "
                f"(F6 replays; {RENDER_PATH} renders its frames)"
            )
        except OSError as e:
            self.error = f"{self.file}: cannot save the camera path: {e.strerror}"

    def replay(self, clock: float) -> None:
        """Fly the recorded path from ``clock`` on; without one, say how to record one."""
        if self.path is None:
            self.message = "no camera path to replay yet: F5 records one"
            return
        self.replay_start = clock
        self.message = f"replaying {self.source.name} ({self.path.duration:.1f} s)"

    def tick(self, clock: float, camera: FlyCamera) -> bool:
        """One event-loop turn: record the camera's pose, or put the camera on the replayed
        path. True when the camera was moved."""
        if self.recording is not None:
            self.recording.append(
                Pose(clock, tuple(float(c) for c in camera.position), camera.yaw, camera.pitch)
            )
        if self.replay_start is None:
            return False
        t = clock - self.replay_start
        if t >= self.path.duration:
            self.replay_start, self.message = None, "replay finished"
        pose = self.path.pose_at(t)
        camera.position = np.array(pose.position, dtype=np.float64)
        camera.yaw, camera.pitch = pose.yaw, pose.pitch
        return True
