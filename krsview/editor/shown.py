"""What the editor's view shows of the scene at the moment shown: the scene as drawn there
(keyed values where their tracks put them, a keyed fork's subtree with it; the sway's turn
left out, since a drag must not write it back), its handles, the route's warnings and the
parts Alg. 1 clips (a compound's component routes placed in the world). Made again only
when the scene or the moment changes (an edit, undo, reload, the timeline)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np

from ..scene import Scene
from ..scene.edits import path_text
from .clipped import scene_clipped
from .handles import Handle, component_routes, handles


def drawn(scene: Scene, posed: Callable[[Scene], Scene]) -> Scene:
    """``scene`` with its tracks applied by ``posed`` at the moment shown, without its sway;
    a scene without tracks as it is."""
    a = scene.animation
    if a is None or not a.tracks:
        return scene
    return posed(replace(scene, animation=replace(a, sway=None)))


def warnings(scene: Scene) -> list[tuple[int, str]]:
    """The route's warnings (``Route.warnings``), each with the outline entry it names: the
    level, or in a compound the component whose route it is; the text names the full path."""
    if scene.route is not None:
        return [
            (int(w[w.index("[") + 1 : w.index("]")]), "route." + w) for w in scene.route.warnings()
        ]
    return [
        (k, f"{path_text(at)}.{w}")
        for k, at, route, _ in component_routes(scene)
        for w in route.warnings()
    ]


class Shown:
    """The scene drawn, its handles, warnings and clipped parts, for one scene and moment."""

    def __init__(self) -> None:
        self._made_for: tuple[Scene, float] | None = None
        self.scene: Scene | None = None
        self.handles: list[Handle] = []
        self.warnings: list[tuple[int, str]] = []  # (outline entry, the warning)
        self.clipped: list[tuple[int, np.ndarray]] = []  # (level or component, world polyline)

    def follow(self, scene: Scene, t: float, posed: Callable[[Scene], Scene]) -> bool:
        """Make everything again for ``scene`` at time ``t`` if either changed; whether it did."""
        if self._made_for is not None and self._made_for[0] is scene and self._made_for[1] == t:
            return False
        self._made_for = (scene, t)
        self.scene = drawn(scene, posed)
        self.handles = handles(self.scene)
        self.warnings = warnings(self.scene)
        self.clipped = scene_clipped(self.scene)
        return True
