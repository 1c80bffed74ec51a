"""Flying through a scene: held keys fly the camera at a speed that follows the distance to
the nearest surface, the look button turns it, orbit mode turns it round a picked point and
dollies towards it, and bookmarks put it back where it was."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..compile.geometry import Compiled
from ..reference.geometry import free_radius
from ..scene import Bookmark, Camera
from .camera import FlyCamera
from .controls import LOOK_BUTTON, ORBIT_BUTTON, Input

LOOK_RADIANS_PER_PIXEL = 0.004
SCROLL_SPEED = 1.25  # one wheel notch scales the flying speed by this


class Navigation:
    def __init__(self, input: Input, camera: Camera):
        self.input = input
        self.speed_factor = 1.0  # × distance to the nearest surface, per second
        self.bookmark_index = -1
        self._free: tuple[Compiled, np.ndarray, float] | None = None  # world, eye, radius
        self.reset(camera)

    def reset(self, camera: Camera) -> None:
        """Fly from ``camera`` (not orbiting)."""
        self.camera = FlyCamera.from_camera(camera)
        self.orbit_pivot: np.ndarray | None = None
        self.input.look_hides_cursor = True

    def toggle_orbit(self, pivot: Callable[[], np.ndarray]) -> str:
        """Orbit the point ``pivot()`` (the surface at the window centre), or fly again."""
        self.orbit_pivot = pivot() if self.orbit_pivot is None else None
        self.input.look_hides_cursor = self.orbit_pivot is None
        return "fly mode" if self.orbit_pivot is None else "orbit mode: left-drag turns, W/S dolly"

    def go_to(self, bookmarks: list[Bookmark], index: int) -> str:
        self.bookmark_index = index
        b = bookmarks[index]
        self.camera = FlyCamera.from_camera(b.camera)
        return f"bookmark {b.name!r}"

    def move(self, dt: float, free: Callable[[], float]) -> bool:
        """One turn of input: held keys fly (or dolly in orbit mode), drags look (or orbit),
        the wheel scales the speed; ``free()`` is the distance to the nearest surface. True
        when the camera moved."""
        scroll = self.input.take_scroll()
        if scroll:
            self.speed_factor *= SCROLL_SPEED**scroll
        dx, dy = self.input.take_drag()
        move = np.array(self.input.movement(), dtype=float)
        buttons, moved = self.input.buttons, False
        if self.orbit_pivot is not None:
            if ORBIT_BUTTON in buttons and (dx or dy):
                turn = (-dx * LOOK_RADIANS_PER_PIXEL, dy * LOOK_RADIANS_PER_PIXEL)
                self.camera.orbit(self.orbit_pivot, *turn)
                moved = True
            if move[2]:
                self.camera.dolly(self.orbit_pivot, 0.5 ** (move[2] * dt * self.speed_factor))
                moved = True
            return moved
        if LOOK_BUTTON in buttons and (dx or dy):
            self.camera.look(-dx * LOOK_RADIANS_PER_PIXEL, -dy * LOOK_RADIANS_PER_PIXEL)
            moved = True
        if move.any():
            # Speed ∝ distance to the nearest surface: fly from a forest into a twig many
            # levels deep without overshooting.
            self.camera.fly(move, self.speed_factor * max(free(), 1e-12) * dt)
            moved = True
        return moved

    def free_distance(self, world: Compiled) -> float:
        """Radius of an empty ball around the eye. Recomputed only after the eye moved a
        quarter of it (a MöKRS needs a batch of Alg. 3 tests, ~10 ms in NumPy), or in a new
        ``world``; in between, r₀ − moved is still empty (the ball around the new eye lies
        inside the old one)."""
        p = self.camera.position
        if self._free is not None and self._free[0] is world:
            _, p0, r0 = self._free
            moved = float(np.linalg.norm(p - p0))
            if moved < 0.25 * r0:
                return r0 - moved
        r = free_radius(world, p)
        self._free = (world, p.copy(), r)
        return r
