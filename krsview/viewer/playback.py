"""The viewer's clock for scenes that move (issue 29): the moment shown, play/pause and speed.
Time is view state, like the flying camera: playing never edits the document (no undo step
per frame); the document's ``[animation] time`` is where a viewer opens. ``Posing`` keeps the
scene posed at that moment. No GL."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from ..scene import Scene, SceneError
from ..scene.animation import DEFAULT_DURATION, reads_time

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
        """Show moment ``t`` (clamped into the loop; a value typed as NaN is ignored)."""
        if not math.isnan(t):
            self.time = min(max(float(t), 0.0), self.duration)

    def set_speed(self, speed: float) -> None:
        """Play at ``speed`` × real time (clamped into SPEED_RANGE; NaN is ignored: it froze
        the clock at a time of NaN)."""
        if not math.isnan(speed):
            self.speed = min(max(float(speed), SPEED_RANGE[0]), SPEED_RANGE[1])


class Posing:
    """The scene as drawn at the moment shown: its tracks and sway applied there. A moment
    whose pose breaks a field's rule (a value between keys) keeps the last pose drawn, with
    ``error`` saying why, until a moment poses again."""

    def __init__(self) -> None:
        self.error = ""
        self._last: Scene | None = None
        self._drawn: Scene | None = None  # the last pose, time aside
        self._asked: tuple[Scene, float, Scene] | None = None  # the last (scene, t) and its pose

    def pose(self, scene: Scene, t: float) -> Scene:
        """``scene`` posed at ``t``; asked again for the same scene and moment (a turn asks
        twice: for the geometry and for the image), the pose made then, not posed anew."""
        asked = self._asked
        if asked is not None and asked[0] is scene and asked[1] == t:
            return asked[2]
        try:
            pose = scene.at(t).posed()
        except SceneError as e:
            self.error = str(e)
            pose = self._last if self._last is not None else scene.at(0.0).posed()
        else:
            self.error, self._last = "", pose
        self._asked = (scene, t, pose)
        return pose

    def changed(self, pose: Scene) -> bool:
        """Whether ``pose`` needs a new image: it differs from the last one but for the
        shader's time, or the shader reads time (past the last key nothing else moves)."""
        drawn = replace(pose, animation=None)
        changed = drawn != self._drawn or reads_time(pose.effects)
        self._drawn = drawn
        return changed
