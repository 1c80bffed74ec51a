"""Scheduling the tracing: after a change of view one moving frame at the adaptive resolution;
when the view stops, the refinement's images (adaptive.py), each traced in bands within the
frame budget (up to two while the rest of the turn takes as long: refining_budget) and shown
when done, so input is never blocked by a slow frame. Moving frames
light like still ones: their shadow rays are traced per 2 × 2 pixels (gpu/passes.py), per
3 × 3 in frames at least 240 pixels wide (adaptive.moving_ratio), or per the scene's larger
blocks (``[render] shadow_block``), and blended as the still image's."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import moderngl
import numpy as np

from ..compile.constants import VIEW_MODES
from ..gpu.display import Display
from ..gpu.passes import PassImage, Targets, splits_shadows
from ..gpu.program import ProgramCache, ShaderError
from ..gpu.renderer import Renderer
from ..scene import Scene
from ..scene.scene import Geometry
from .adaptive import (
    SHADOW_RATIO,
    AdaptiveResolution,
    Refinement,
    moving_ratio,
    refinement_steps,
    refining_budget,
)

KEPT_FRAME_TIMES = 240  # for the HUD's frame-time plot


@dataclass(frozen=True)
class FrameState:
    """The image on screen, as the HUD reports it: ``state`` is "moving" (adaptive
    resolution), "refining" (image ``step`` = (k, n) of the refinement, k < n; the next one
    is being traced) or "still" (the last one: final); ``seconds`` is the time its tracing
    took (all its bands for a refinement's), ``shadows`` the side of the pixel blocks that
    share a shadow ray (1: each pixel its own), ``blocks_of`` the size of the earlier image
    whose blocks it took (a primary image: its own shadow rays come next), else (0, 0);
    ``since_stop`` the tracing of the refinement's images up to this one (0: a moving
    frame)."""

    state: str
    size: tuple[int, int]  # internal resolution of the image on screen
    window: tuple[int, int]  # the window's framebuffer
    seconds: float
    step: tuple[int, int] = (0, 0)  # refining: (k, n)
    shadows: int = 1
    blocks_of: tuple[int, int] = (0, 0)
    since_stop: float = 0.0  # the refinement's tracing so far, this image's included

    def text(self) -> str:
        w, h = self.size
        share = w / max(self.window[0], 1)
        k, n = self.step
        state = f"refining {k}/{n}" if self.state == "refining" else self.state
        if self.state == "still" and self.since_stop > self.seconds:  # after steps before it
            state += f" (refined in {self.since_stop:.2f} s)"
        state += ", shadows next" if self.blocks_of[0] else ""
        return f"{state}: {w}×{h} ({share:.0%} of the window's width)"

    def timing(self) -> str:
        """How it was traced: time, and the shadow rays' blocks where they are shared."""
        rays = f", shadows per {self.shadows}×{self.shadows} px" if self.shadows > 1 else ""
        if self.blocks_of[0]:
            rays += " of the {}×{} image".format(*self.blocks_of)
        return f"traced in {self.seconds * 1e3:.1f} ms{rays}"


class Frames:
    def __init__(self, ctx: moderngl.Context, renderer: Renderer, adaptive: AdaptiveResolution):
        self.ctx, self.renderer, self.adaptive = ctx, renderer, adaptive
        self.display = Display(ctx, renderer.programs)
        self.targets = Targets(ctx)
        self.dirty = True  # the view changed: trace a moving frame next
        self.full_shadows = False  # moving frames and steps trace shadow rays as still ones
        self.image: tuple[moderngl.Framebuffer, tuple[int, int]] | None = None
        self.refinement: Refinement | None = None
        self.frame_seconds: list[float] = []  # moving frames while moving (see _moving)
        self._moved_last = False  # the last turn traced a moving frame
        self.shown = FrameState("moving", (0, 0), adaptive.full, 0.0)  # no image yet
        self._on_screen: PassImage | None = None
        self._tracing: PassImage | None = None  # the refinement's next image
        self._cost: dict[str, float] = {}  # seconds per pixel of each pass, kept across
        self._profile: dict[str, list[float]] = {}  # ... and per slice of rows (Refinement)
        self._step_seconds = 0.0
        self._since_stop = 0.0  # the refinement's tracing so far
        self._traced_at = 0.0  # when the last turn's tracing ended (0: it traced nothing)
        # the moving frames' size when the view last came to rest (the HUD's measured
        # accuracy suggests for it: a size that does not change while flying)
        self.rest_size: tuple[int, int] | None = None

    @property
    def refined(self) -> bool:
        """The window shows the final image of the current view."""
        return not self.dirty and (self.refinement is None or self.refinement.done)

    def frame_state(self) -> FrameState:
        """The image on screen: its state, internal resolution and tracing time."""
        return self.shown

    def resize(self, fb: tuple[int, int]) -> None:
        """The window's framebuffer is ``fb`` pixels: a new size redraws."""
        if fb != self.adaptive.full and fb[0] > 0 and fb[1] > 0:
            self.adaptive.full = fb
            self.dirty = True

    def trace(
        self, scene: Scene, krs: Geometry, while_tracing: Callable[[], None] | None = None
    ) -> None:
        """One turn's tracing: a moving frame of ``scene`` after a change, else some bands of
        the refinement's next image. A ShaderError leaves the last image in place.
        ``while_tracing``: work of the turn that needs nothing of the new image, called once
        a moving frame's first pass is issued (see :meth:`_moving`)."""
        now = time.perf_counter()
        # the rest of the last turn, where it traced (else its time holds an idle wait)
        rest = now - self._traced_at if self._traced_at else None
        traced = self.dirty or not self.refined
        moving, self._moved_last = self._moved_last, self.dirty
        try:
            if self.dirty:
                self.dirty = False  # a shader error is not retried every turn
                self._moving(scene, krs, rest, while_tracing, moving)
            elif traced:
                self._refine(scene, krs, rest or 0.0)
        finally:
            self._traced_at = time.perf_counter() if traced else 0.0

    def _moving(
        self,
        scene: Scene,
        krs: Geometry,
        rest: float | None,
        while_tracing: Callable[[], None] | None = None,
        moving: bool = True,
    ) -> None:
        """A moving frame at the adaptive resolution; ``rest``: the last turn's time besides
        its tracing (None: it traced nothing), for the resolution's controller. After its
        first pass is issued, ``while_tracing()`` runs (it starts that pass with a glFlush,
        which moderngl lacks): llvmpipe's threads trace while this thread does the turn's
        other work (the HUD), on a core that the passes leave idle part of the time
        (docs/speed.md, "The HUD built while the frame is traced"). A frame that compiled a
        shader (the first one, a knob changed) is not counted: its time is mostly compiling.
        ``moving``: the turn before traced a moving frame too; the HUD's moving frames are
        those (a flight, a scene playing), not one drawn after a reload, a bookmark or a
        resize, whose image a rest refines at once."""
        t0 = time.perf_counter()
        compiles = self.renderer.programs.compiles
        r = self.refinement
        if r is not None and (r.k or r.started):  # the first moving frame after a rest
            self.adaptive.predict(self.moving_cost())
        size = self.adaptive.moving_size()
        scale = size[0] / self.adaptive.full[0]
        # the still image's passes: 0 one pass, 1 shadow rays per pixel in a pass of their
        # own, ≥ 2 per block; moving frames share a shadow ray per 2 × 2 or 3 × 3 pixels
        still = scene.render.shadow_block if splits_shadows(scene) else 0
        ratio = moving_ratio(size[0], still) if still and not self.full_shadows else still
        image = PassImage(
            self.renderer, self.targets, scene, size, krs, ratio, detail_height=self.detail(size)
        )
        image.draw_all(issued=while_tracing)
        self.ctx.finish()  # the frame's time is read: the controller needs it
        seconds = time.perf_counter() - t0
        if self.renderer.programs.compiles == compiles:  # else its time is mostly compiling
            self.adaptive.frame_done(seconds, rest)
            if moving:
                self.frame_seconds = (self.frame_seconds + [seconds])[-KEPT_FRAME_TIMES:]
        steps = refinement_steps(scale, seconds, self.adaptive.supersample, ratio, still)
        self.refinement = Refinement(steps, self._cost, profile=self._profile) if steps else None
        self._tracing = None
        state = "moving" if steps else "still"
        self._show(image, FrameState(state, size, self.adaptive.full, seconds))

    def detail(self, size: tuple[int, int]) -> int:
        """The detail an image of ``size`` draws (PassImage's ``detail_height``): below the
        window's size, the window's pixel's, so that moving and refining images draw and shade
        the still image's very geometry, textures and normals, only sampled more coarsely;
        else its own (0). At its own pixel's ε every twig was a coarse pixel fatter (crowns
        went solid while moving and thinned at once when the camera stopped), and a texture
        filtered at a coarse pixel lost the contrast that darkens the bark and leaves (tree's
        crown 24 % brighter at 96×54 than at 960×540)."""
        window = self.adaptive.full[1]
        return window if size[1] < window else 0

    def moving_cost(self) -> float:
        """Seconds per pixel of a moving frame, from the refinement's measured passes (0:
        none measured): tracing, shading, and the shadow rays per SHADOW_RATIO² pixels."""
        c = self._cost
        if "render" in c:  # every effect in one pass
            return c["render"]
        if "trace" not in c:
            return 0.0
        shade = c.get("shade", c.get("shadows+shade", 0.0))
        return c["trace"] + shade + c.get("visibility", 0.0) / SHADOW_RATIO**2

    def _show(self, image: PassImage, state: FrameState) -> None:
        """``image`` goes on screen; ``state`` says what it is."""
        self.image, self._on_screen = (image.output, image.size), image
        self.shown = replace(state, shadows=max(image.ratio, 1))

    def _refine(self, scene: Scene, krs: Geometry, rest: float) -> None:
        """Bands of the refinement's next image for as long as ``rest``, the last turn's time
        besides its tracing, within refining_budget."""
        r = self.refinement
        if r.k == 0 and not r.started:  # the view came to rest
            self.rest_size = self.adaptive.moving_size()
            self._since_stop = 0.0
        spent, budget = 0.0, refining_budget(self.adaptive.budget, rest)
        prepared = None
        while not r.done and spent < budget:
            if not r.started:
                step = r.steps[r.k]
                size = self.adaptive.size_at(step.scale)
                shown = self._on_screen  # its tracing is reused where it has this size
                traced = shown if step.ratio >= 1 and shown and shown.has_trace(size) else None
                blocks = shown if step.primary else None  # its shadow blocks, for a primary step
                self._tracing = PassImage(
                    self.renderer,
                    self.targets,
                    scene,
                    size,
                    krs,
                    step.ratio,
                    traced,
                    blocks,
                    detail_height=self.detail(size),
                )
                r.begin(self._tracing.passes)
                self._step_seconds = 0.0
            if prepared is not self._tracing:
                self._tracing.prepare()  # once a turn: other drawing may have come between
                prepared = self._tracing
            band = r.next_band(budget - spent)
            t0 = time.perf_counter()
            self._tracing.draw(*band)
            self.ctx.finish()
            seconds = time.perf_counter() - t0
            spent += seconds
            self._step_seconds += seconds
            self._since_stop += seconds
            if r.band_done(band, seconds):
                k, n = r.k, len(r.steps)
                state = FrameState(
                    "still" if k == n else "refining",
                    self._tracing.size,
                    self.adaptive.full,
                    self._step_seconds,
                    (k, n) if k < n else (0, 0),
                    blocks_of=self._tracing.blocks[0] if r.steps[k - 1].primary else (0, 0),
                    since_stop=self._since_stop,
                )
                self._show(self._tracing, state)
                self._tracing = None

    def show(
        self,
        target: moderngl.Framebuffer,
        size: tuple[int, int],
        mode: str,
        scales: tuple[float, float],
    ) -> None:
        """The last image into ``target`` of ``size`` pixels (scaled to it), in view ``mode``;
        ``scales``: what the iterations and the depth views show as white."""
        if self.image is not None:
            fbo, image = self.image
            self.display.show(fbo, target, size, mode, *scales, image)

    def still(
        self, scene: Scene, krs: Geometry, mode: str, scales: tuple[float, float]
    ) -> np.ndarray:
        """The full-resolution image of ``scene`` traced at once, in view ``mode``: (H, W, 3)
        bytes, rows top → bottom."""
        size = self.adaptive.still_size()
        prog = self.renderer.prepare(scene, *size, krs)
        fbo = self.renderer.draw(prog, *size)
        target = self.ctx.simple_framebuffer(size, components=4)
        self.display.show(fbo, target, size, mode, *scales, size)
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
            display = Display(self.ctx, programs, VIEW_MODES)  # every mode checked
        except ShaderError:
            self.renderer.programs = old
            raise
        self.display, self.dirty = display, True
