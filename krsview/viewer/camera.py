"""A float64 fly/orbit camera; the renderer receives camera-relative data from it, so deep
zooms keep their precision (docs/architecture.md, Precision)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..algebra.vectors import cross
from ..scene import Camera
from ..scene.camera_path import horizontal_axes, look_direction

MAX_PITCH = math.radians(89.0)


@dataclass
class FlyCamera:
    position: np.ndarray
    yaw: float  # radians around the world up axis
    pitch: float  # radians above the horizon
    fov_y: float
    world_up: np.ndarray = field(default_factory=lambda: np.array([0.0, 1.0, 0.0]))

    @classmethod
    def from_camera(cls, cam: Camera) -> FlyCamera:
        up = np.array(cam.up, dtype=np.float64)
        f = np.array(cam.target, dtype=np.float64) - np.array(cam.position, dtype=np.float64)
        f /= np.linalg.norm(f)
        east, north = horizontal_axes(up)
        pitch = math.asin(max(-1.0, min(1.0, float(f @ up))))
        yaw = math.atan2(float(f @ east), float(f @ north))
        return cls(
            np.array(cam.position, dtype=np.float64),
            yaw,
            max(-MAX_PITCH, min(MAX_PITCH, pitch)),
            cam.fov_y,
            up,
        )

    def forward(self) -> np.ndarray:
        return look_direction(self.yaw, self.pitch, self.world_up)

    def right(self) -> np.ndarray:
        r = cross(self.forward(), self.world_up)
        return r / np.linalg.norm(r)

    def to_camera(self) -> Camera:
        """The scene camera; the target sits one unit ahead (only its direction matters)."""
        f = lambda v: tuple(float(c) for c in v)  # noqa: E731  plain floats for files
        return Camera(
            f(self.position), f(self.position + self.forward()), f(self.world_up), float(self.fov_y)
        )

    def fly(self, local: np.ndarray, distance: float) -> None:
        """Move ``distance`` along local (right, up, forward) components."""
        if not np.any(local):
            return
        d = local[0] * self.right() + local[1] * self.world_up + local[2] * self.forward()
        self.position = self.position + distance * d / np.linalg.norm(d)

    def look(self, d_yaw: float, d_pitch: float) -> None:
        self.yaw += d_yaw
        self.pitch = max(-MAX_PITCH, min(MAX_PITCH, self.pitch + d_pitch))

    def orbit(self, pivot: np.ndarray, d_yaw: float, d_pitch: float) -> None:
        """Turn around ``pivot`` keeping the distance, still looking at it."""
        radius = float(np.linalg.norm(self.position - pivot))
        self.look(d_yaw, d_pitch)
        self.position = pivot - radius * self.forward()

    def dolly(self, pivot: np.ndarray, factor: float) -> None:
        """Scale the distance to ``pivot`` (orbit mode's W/S)."""
        self.position = pivot + (self.position - pivot) * factor
