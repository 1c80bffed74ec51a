"""What the view draws, a part the viewer holds (``Viewer.drawn``): the moment shown (the
clock, playback.py), the scene posed there (``Posing``), that pose's geometry cut to the levels
kept, and its compiled form for flying and picking. It follows the document: an edit, undo or
reload poses and cuts the new scene; the viewer's camera, pre-pass and HUD stay the viewer's."""

from __future__ import annotations

from typing import Protocol

from ..compile.geometry import Compiled
from ..document.document import Document
from ..gpu.renderer import Renderer
from ..scene import Scene, SceneError
from ..scene.scene import Geometry
from .frames import Frames
from .navigation import Navigation
from .playback import Playback, Posing


class Draws(Protocol):
    """What the drawn part reads and sets of the viewer."""

    doc: Document
    renderer: Renderer  # compiles the geometry drawn
    frames: Frames  # a new image when what is drawn changes
    nav: Navigation  # the keyed camera
    message: str
    error: str

    @property
    def scene(self) -> Scene: ...


class Drawn:
    """The moment shown and the geometry drawn at it: ``geometry`` (the pose's), ``krs`` (it
    cut to the coarsest ``levels``, 0: all) and ``world`` (``krs`` compiled)."""

    geometry: Geometry
    krs: Geometry
    world: Compiled

    def __init__(self, viewer: Draws) -> None:
        self.viewer = viewer
        self.playback = Playback()
        self.posing = Posing()
        self.levels = 0  # 0: all of the scene's levels
        self._seen_version = -1

    def open(self) -> None:
        """A document was opened: its moment (``[animation] time``) and its pose there."""
        self.playback = Playback(self.viewer.scene.time)
        self._follow(self.viewer.scene)

    def sync(self) -> None:
        """Redraw when the document changed (an edit, undo, redo, reload)."""
        if self.viewer.doc.version != self._seen_version:
            self._follow(self.viewer.doc.scene)

    def _follow(self, scene: Scene) -> None:
        """A new scene version: posed at the moment shown (its new keys may move the loop's
        end), drawn again (recompiled only if its variant changed)."""
        self._seen_version = self.viewer.doc.version
        self.playback.duration = scene.duration
        self.playback.seek(self.playback.time)
        pose = self.posed(scene)
        self.posing.changed(pose)
        self._draw(pose.geometry())

    def posed(self, scene: Scene) -> Scene:
        """``scene`` as drawn at the moment shown (``Posing``); a moment that cannot be posed
        shows why until one poses again."""
        v, said = self.viewer, self.posing.error
        pose = self.posing.pose(scene, self.playback.time)
        if self.posing.error:
            v.error = self.posing.error
        elif said and v.error == said:
            v.error = ""
        return pose

    def _time_moved(self) -> None:
        """The moment shown changed: a new image (a moving one while playing, so the
        adaptive resolution counts time as motion), new geometry if tracks or sway move it,
        and the keyed camera where a track moves the camera (between moments, one flies)."""
        v = self.viewer
        pose = self.posed(v.scene)
        a = v.scene.animation
        if a is not None and any(t.path.startswith("camera") for t in a.tracks):
            v.nav.reset(pose.camera)
        geometry = pose.geometry()
        if geometry != self.geometry:
            self._draw(geometry)
        if self.posing.changed(pose):
            v.frames.dirty = True

    def advance(self, dt: float) -> None:
        """The clock moved by ``dt`` seconds of wall time: while playing, the next moment."""
        if self.viewer.scene.animated and self.playback.advance(dt):
            self._time_moved()

    def toggle_play(self) -> None:
        if not self.viewer.scene.animated:
            self.viewer.message = "nothing in this scene moves (no wind, keyframe tracks or sway)"
            return
        self.playback.playing = not self.playback.playing

    def set_time(self, t: float) -> None:
        self.playback.seek(t)
        self._time_moved()

    def set_levels(self, levels: int) -> None:
        """Draw only the coarsest ``levels`` levels (0 or all: the whole scene; below 1, the
        coarsest: a negative count typed into the HUD closed the window)."""
        self.levels = 0 if levels == 0 or levels >= self.geometry.depth else max(1, levels)
        self._cut()

    def _draw(self, geometry: Geometry) -> None:
        """Draw ``geometry``: the levels kept, at most its depth."""
        self.geometry = geometry
        self.levels = min(self.levels, geometry.depth)
        self._cut()

    def _cut(self) -> None:
        v = self.viewer
        try:
            self.krs = self.geometry.truncated(self.levels) if self.levels else self.geometry
        except SceneError as e:  # a MöKRS whose kept levels cannot carry a kernel up
            self.levels, self.krs, v.error = 0, self.geometry, f"{e}; drawing every level"
        self.world = v.renderer.world(self.krs, v.scene.material.albedo)  # speed, picking
        v.frames.dirty = True
