"""The viewer's clock for scenes that move (issue 29): the moment shown, play/pause and speed.
Time is view state, like the flying camera: playing never edits the document (no undo step
per frame); the document's ``[animation] time`` is where a viewer opens. No GL."""

from __future__ import annotations

from dataclasses import dataclass

from ..scene.animation import DEFAULT_DURATION

SPEED_RANGE = (0.05, 8.0)  # × real time, the HUD's slider


@dataclass
class Playback:
    time: float = 0.0  # seconds, within [0, duration]
    duration: float = DEFAULT_DURATION  # one loop, the scene's [animation] duration
    playing: bool = False
    speed: float = 1.0

    def advance(self, dt: float) -> bool:
        """Move the clock by ``dt`` seconds of wall time while playing, round the loop;
        whether the moment shown changed."""
        if not self.playing or dt <= 0.0:
            return False
        self.time = (self.time + dt * self.speed) % self.duration
        return True

    def seek(self, t: float) -> None:
        """Show moment ``t`` (clamped into the loop)."""
        self.time = min(max(float(t), 0.0), self.duration)

    def set_speed(self, speed: float) -> None:
        self.speed = min(max(float(speed), SPEED_RANGE[0]), SPEED_RANGE[1])
