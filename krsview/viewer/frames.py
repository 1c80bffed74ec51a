"""Scheduling the tracing: after a change of view one moving frame at the adaptive resolution;
while the view is still, the full-resolution image in tiles within the frame budget, so input
is never blocked by a slow frame."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import moderngl
import numpy as np

from ..gpu.display import Display
from ..gpu.program import ProgramCache, ShaderError
from ..gpu.renderer import Renderer
from ..scene import Scene
from ..scene.scene import Geometry
from .adaptive import AdaptiveResolution, Refinement

KEPT_FRAME_TIMES = 240  # for the HUD's frame-time plot


@dataclass(frozen=True)
class FrameState:
    """The image on screen, as the HUD reports it: ``state`` is "moving" (adaptive resolution),
    "refining" (the still image is being traced in tiles; this image stays until it is done)
    or "still" (final); ``seconds`` is the time its tracing took (all tiles for a still one)."""

    state: str
    size: tuple[int, int]  # internal resolution of the image on screen
    window: tuple[int, int]  # the window's framebuffer
    seconds: float
    rows: tuple[int, int] = (0, 0)  # refining: rows of the still image done, of all

    def text(self) -> str:
        w, h = self.size
        share = w / max(self.window[0], 1)
        state = (
            f"refining {self.rows[0]}/{self.rows[1]} rows"
            if self.state == "refining"
            else self.state
        )
        return f"{state}: {w}×{h} ({share:.0%} of the window)"


class Frames:
    def __init__(self, ctx: moderngl.Context, renderer: Renderer, adaptive: AdaptiveResolution):
        self.ctx, self.renderer, self.adaptive = ctx, renderer, adaptive
        self.display = Display(ctx, renderer.programs)
        self.dirty = True  # the view changed: trace a moving frame next
        self.image: tuple[moderngl.Framebuffer, tuple[int, int]] | None = None
        self.refinement: Refinement | None = None
        self.frame_seconds: list[float] = []  # moving frames
        self.shown = FrameState("moving", (0, 0), adaptive.full, 0.0)  # no image yet
        self._tile_seconds = 0.0  # the refinement's tiles so far

    @property
    def refined(self) -> bool:
        """The window shows the full-resolution image of the current view."""
        return not self.dirty and (self.refinement is None or self.refinement.done)

    def frame_state(self) -> FrameState:
        """The image on screen: its state, internal resolution and tracing time; a moving
        frame stays "moving" until the first tile of the still image is traced."""
        r = self.refinement
        if self.shown.state == "moving" and r is not None and r.next_row > 0:
            return FrameState(
                "refining",
                self.shown.size,
                self.adaptive.full,
                self.shown.seconds,
                (min(r.next_row, r.size[1]), r.size[1]),
            )
        return self.shown

    def resize(self, fb: tuple[int, int]) -> None:
        """The window's framebuffer is ``fb`` pixels: a new size redraws."""
        if fb != self.adaptive.full and fb[0] > 0 and fb[1] > 0:
            self.adaptive.full = fb
            self.dirty = True

    def trace(self, moving: Scene, still: Scene, krs: Geometry) -> None:
        """One turn's tracing: a moving frame of ``moving`` after a change, else some tiles of
        the still image of ``still``. A ShaderError leaves the last image in place."""
        if self.dirty:
            self.dirty = False  # a shader error is not retried every turn
            size = self.adaptive.moving_size()
            t0 = time.perf_counter()
            prog = self.renderer.prepare(moving, *size, krs)
            fbo = self.renderer.draw(prog, *size)
            self.ctx.finish()
            seconds = time.perf_counter() - t0
            self.adaptive.frame_done(seconds)
            self.frame_seconds = (self.frame_seconds + [seconds])[-KEPT_FRAME_TIMES:]
            self.image = (fbo, size)
            full = self.adaptive.still_size()
            final = full == size and moving.effects == still.effects
            self.refinement = None if final else Refinement(full)
            self.shown = FrameState("still" if final else "moving", size, full, seconds)
            self._tile_seconds = 0.0
        elif self.refinement is not None and not self.refinement.done:
            self._refine(still, krs)

    def _refine(self, still: Scene, krs: Geometry) -> None:
        r = self.refinement
        prog = self.renderer.prepare(still, *r.size, krs)
        spent, budget = 0.0, 0.8 * self.adaptive.budget
        while not r.done and spent < budget:
            tile = r.next_tile(budget - spent)
            t0 = time.perf_counter()
            fbo = self.renderer.draw(prog, *r.size, tile)
            self.ctx.finish()
            seconds = time.perf_counter() - t0
            r.tile_done(tile, seconds)
            spent += seconds
        self._tile_seconds += spent
        if r.done:
            self.image = (fbo, r.size)
            self.shown = FrameState("still", r.size, self.adaptive.full, self._tile_seconds)

    def show(
        self,
        target: moderngl.Framebuffer,
        size: tuple[int, int],
        mode: str,
        scene: Scene,
        depth: float,
    ) -> None:
        """The last image into ``target`` of ``size`` pixels (scaled to it), in view ``mode``;
        ``depth`` scales the depth view."""
        if self.image is not None:
            self.display.show(self.image[0], target, size, mode, scene.render.max_iterations, depth)

    def still(self, scene: Scene, krs: Geometry, mode: str, depth: float) -> np.ndarray:
        """The full-resolution image of ``scene`` traced at once, in view ``mode``: (H, W, 3)
        bytes, rows top → bottom."""
        size = self.adaptive.still_size()
        prog = self.renderer.prepare(scene, *size, krs)
        fbo = self.renderer.draw(prog, *size)
        target = self.ctx.simple_framebuffer(size, components=4)
        self.display.show(fbo, target, size, mode, scene.render.max_iterations, depth)
        rgb = np.frombuffer(target.read(components=3), np.uint8).reshape(size[1], size[0], 3)
        target.release()
        return rgb[::-1]

    def reload_programs(self, shader_dir: Path, scene: Scene, krs: Geometry) -> None:
        """Compile the variant of ``scene`` and the display from the files in ``shader_dir``
        again, then redraw; a ShaderError keeps the old programs."""
        programs = ProgramCache(self.ctx, shader_dir)
        old = self.renderer.programs
        try:
            self.renderer.programs = programs
            self.renderer.prepare(scene, 1, 1, krs)
            display = Display(self.ctx, programs)
        except ShaderError:
            self.renderer.programs = old
            raise
        self.display, self.dirty = display, True
