"""`krsview view`: a GLFW window to fly through a scene, with adaptive resolution, an ImGui HUD
and hot reload of the preset and the shaders (files.py). The window owns its state, and holds
what it draws (the moment shown, the pose there, the levels kept: drawn.py) as a part; keys,
the HUD and the file watcher return commands, which :meth:`Viewer.execute` applies through its
HANDLERS."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import glfw  # noqa: E402  (order matters)
import moderngl
import numpy as np
from imgui_bundle import imgui  # noqa: F401  imported before glfw (docs/architecture.md, stack facts)

from ..document.document import Document
from ..document.history import Step
from ..gpu.context import GL_VERSION
from ..gpu.program import SHADER_DIR, ShaderError
from ..gpu.renderer import Renderer
from ..heatmap import VIEW_WHITE
from ..scene import Scene, SceneError
from ..scene.effects import EXCLUSIVE
from ..scene.render import VIEW_PREPASS
from ..scene.settings import ViewerSettings, make_settings
from . import commands as c
from .adaptive import AdaptiveResolution
from .camera import FlyCamera
from .controls import Input
from .drawn import Drawn
from .files import CAMERA_KEPT, ViewerFile
from .frames import Frames
from .hudframe import HudFrame
from .loop import run
from .measured import load_measured
from .navigation import Navigation
from .picking import pick_center
from .platform import Platform
from .screenshots import save_screenshot
from .widgets import Interactions

STATUS_SECONDS = 6.0  # how long the status line stays


class Viewer:
    def __init__(
        self,
        path: Path,
        settings: ViewerSettings | None = None,
        *,
        visible: bool = True,
        shader_dir: Path = SHADER_DIR,
        **options: Any,
    ):
        """``options``: fields of ViewerSettings (size, target_fps, prepass, hud,
        moving_effects) replacing those of ``settings``."""
        self.settings = make_settings(settings or ViewerSettings(), **options)
        self.doc = Document(path)  # a bad file is a SceneError before any window
        self.moving_effects = self.settings.moving_effects  # True: shadow rays per pixel
        self.platform = Platform(self.settings.size, f"krsview — {self.scene.name}", visible)
        self.window = self.platform.window
        self.ctx = moderngl.create_context(require=GL_VERSION)
        self.renderer = Renderer(self.ctx, Path(shader_dir))
        self.input = Input()
        self.interactions = Interactions()
        self.hud = self.settings.hud
        self.view = "shaded"
        self.iteration_scale = VIEW_WHITE  # the iterations view: white at this many
        self.nav = Navigation(self.input, self.scene.camera)
        self.clock = 0.0
        self.status = ("", 0.0)  # text, and the clock it goes at
        self.message, self.error = "", ""
        fb = glfw.get_framebuffer_size(self.window)
        self.frames = Frames(
            self.ctx, self.renderer, AdaptiveResolution(fb, self.settings.target_fps)
        )
        self.frames.full_shadows = self.moving_effects
        self._measured: tuple[str | None, list[dict] | None] = (None, None)  # file name, rows
        self.drawn = Drawn(self)  # the moment shown, its pose, the levels kept
        self.opened()
        self.file = ViewerFile(self, Path(shader_dir))  # the files watched, the camera path
        self.platform.route_events(self.input)

    # ------------------------------------------------------------------------- scene state
    @property
    def scene(self) -> Scene:
        return self.doc.scene

    @property
    def path(self) -> Path:
        return self.doc.path

    @property
    def camera(self) -> FlyCamera:
        return self.nav.camera

    @property
    def prepass(self) -> int:
        """The pre-pass tile the view draws with: the scene's, once the HUD's knob set it;
        until then the command line's, else the file's, else VIEW_PREPASS."""
        if self._view_prepass is not None:
            return self._view_prepass
        p = self.scene.render.prepass
        return VIEW_PREPASS if p is None else p

    def opened(self) -> None:
        """A document was opened: its name in the title bar, its pre-pass, moment and camera
        (files.py watches it)."""
        if self.window is not None:
            glfw.set_window_title(self.window, f"krsview — {self.scene.name}")
        self.message = ""  # what was said of the last scene
        self.iteration_scale = VIEW_WHITE  # another scene: another iteration count
        self._view_prepass = self.settings.prepass
        self.drawn.open()
        self.nav.reset(self.scene.camera)

    @property
    def measured(self) -> list[dict] | None:
        """The preset's measured accuracy (the HUD's section), read once per file name."""
        if self._measured[0] != self.path.stem:
            self._measured = (self.path.stem, load_measured(self.path.stem))
        return self._measured[1]

    def sync(self) -> None:
        """Redraw when the document changed (an edit, undo, redo, reload): what is drawn
        follows it (drawn.py)."""
        self.drawn.sync()

    def view_scene(self) -> Scene:
        """The scene as drawn now: at the moment shown, with the viewer's camera and pre-pass.
        Moving frames have every effect too; unless ``moving_effects``, their shadow rays are
        shared by 2 × 2 pixels at least, 3 × 3 from 240 pixels wide (frames.py)."""
        scene = self.drawn.posed(self.scene)
        return replace(
            scene,
            camera=self.camera.to_camera(),
            render=replace(scene.render, prepass=self.prepass),
        )

    def nearest_distance(self) -> float:
        """Radius of an empty ball around the eye (the flying speed follows it)."""
        return self.nav.free_distance(self.drawn.world)

    # ------------------------------------------------------------------------ the changes
    def execute(self, commands: list[c.Command]) -> None:
        """Apply commands from the keys, the HUD or the file watcher (HANDLERS)."""
        for command in commands:
            handler = HANDLERS.get(type(command))
            if handler is None:
                raise TypeError(f"the viewer has no handler for {type(command).__name__}")
            handler(self, command)

    def edit(self, path: tuple, value, interaction=None) -> bool:
        """Apply one edit through the document; a refused value shows its error and leaves
        the last valid scene in place."""
        try:
            self.doc.apply(path, value, interaction)
        except SceneError as e:  # shown at its field where the HUD draws one (widgets.py)
            self.error = "" if self.interactions.settle(path, value, str(e)) else str(e)
            return False
        self.error = ""
        self.interactions.settle(path, value, "")
        self.sync()
        return True

    def set_render(self, interaction=None, **edits) -> None:
        """Change render settings (the HUD's knobs). Accuracy knobs are uniforms; a new tracer
        is a new shader variant, compiled once and then fetched from the cache. A MöKRS
        keeps the binary tracer (the HUD shows why another choice is refused)."""
        self.edit(("render",), replace(self.scene.render, **edits), interaction)

    def set_effect(self, name: str, on: bool) -> None:
        """Switch an effect: a different define set, so a different (cached) variant. Turning
        on one of an exclusive pair (hard / soft shadows) turns the other off; an effect the
        geometry cannot draw is refused with the scene's own message."""
        partners = {b if a == name else a for a, b in EXCLUSIVE if name in (a, b)}
        effects = [e for e in self.scene.effects if e != name and not (on and e in partners)]
        effects += [name] if on else []
        self.edit(("effects",), effects)

    def set_prepass(self, tile: int, interaction=None) -> None:
        """The scene's pre-pass tile, an edit like the other knobs (undoable, saved by the
        editor); from then on the view draws with the scene's."""
        if self.edit(("render", "prepass"), tile, interaction):
            self._view_prepass, self.frames.dirty = None, True

    def set_target_fps(self, fps: float) -> None:
        self.frames.adaptive.target_fps = fps

    def set_supersample(self, factor: int) -> None:
        self.frames.adaptive.supersample, self.frames.dirty = factor, True

    def set_moving_effects(self, on: bool) -> None:
        self.moving_effects, self.frames.dirty = on, True
        self.frames.full_shadows = on

    def undo(self) -> bool:
        """Ctrl+Z: the scene before the last step; what is said says so (what was said of
        that step, "bookmark added", no longer holds)."""
        return self._stepped(self.doc.undo(), "undid")

    def redo(self) -> bool:
        return self._stepped(self.doc.redo(), "redid")

    def _stepped(self, step: Step | None, verb: str) -> bool:
        """What an undo or redo says; a bookmark's is written to the file too (B wrote it)."""
        if step is None:
            return False
        self.sync()
        self.message = f"{verb} {step.label}"
        if step.written and not self.doc.write_error:
            self.file.follow()  # our own write is not an outside edit
            self.message += f" in {self.doc.path.name}"
        if self.doc.write_error:
            self.error = f"{self.message}: {self.doc.write_error}"
        self.say(self.message)
        return True

    def reset_view(self) -> None:
        """R: the scene's camera at the moment shown (its tracks move it; the file's own
        camera is the first moment's, a close-up on tree-growing)."""
        self.nav.reset(self.drawn.posed(self.scene).camera)
        self.frames.dirty = True
        if self.message.endswith(CAMERA_KEPT):  # R took the file's camera: said no more
            self.message = self.message[: -len(CAMERA_KEPT)]

    def toggle_orbit(self) -> None:
        def centre():
            return pick_center(self.camera, self.frames.image, self.nearest_distance())

        self.message = self.nav.toggle_orbit(centre)

    def go_to_bookmark(self, index: int) -> None:
        self.message, self.frames.dirty = self.nav.go_to(self.scene.bookmarks, index), True

    def next_bookmark(self) -> None:
        """N: the next bookmark; with none, how to add one (N did nothing, without a word)."""
        if self.scene.bookmarks:
            self.go_to_bookmark((self.nav.bookmark_index + 1) % len(self.scene.bookmarks))
        else:
            self.message = "no bookmarks yet: B adds the view as one"
            self.say(self.message)

    # --------------------------------------------------------------------------- the loop
    def run(self) -> None:
        run(self)

    def should_close(self) -> bool:
        return bool(glfw.window_should_close(self.window))

    def is_idle(self) -> bool:
        return (
            self.frames.refined
            and not self.input.held
            and not self.input.buttons
            and self.file.recorder.replay_start is None
            and not (self.drawn.playback.playing and self.scene.animated)
        )

    def step(self, dt: float) -> None:
        """One event-loop turn: keys, camera, reload, a bounded amount of tracing, present,
        HUD. The HUD but the numbers of the frame traced in the turn is built while that
        frame is traced, the numbers once it is on screen (hudframe.py)."""
        self.begin_step(dt)
        self.execute(self.input.commands())
        self.move(dt)
        self.execute(self.file.watcher.poll())
        status = self.status_line()
        ui = HudFrame(self, status) if self.hud or status else None
        self.draw_image(ui.while_tracing if ui else None)
        if ui:
            self.execute(ui.finish())
            ui.draw()
        glfw.swap_buffers(self.window)

    def begin_step(self, dt: float) -> None:
        self.clock += dt
        glfw.make_context_current(self.window)
        self.platform.begin_turn()

    def close(self) -> None:
        if self.window is not None:
            self.platform.close()
            self.window = None

    def move(self, dt: float) -> None:
        """Move the camera by the input (a recording takes the pose, a replay sets it) and
        the clock while playing."""
        self.drawn.advance(dt)
        if self.nav.move(dt, self.nearest_distance):
            self.frames.dirty = True
        if self.file.recorder.tick(self.clock, self.camera):
            self.frames.dirty = True
        self.file.report()

    def draw_image(self, while_tracing: Callable[[], None] | None = None) -> None:
        """Follow the document, trace within the frame budget and show the image;
        ``while_tracing``: the turn's work that needs nothing of a moving frame, done while
        it is traced (Frames.trace)."""
        self.sync()
        try:
            self.frames.trace(self.view_scene(), self.drawn.krs, while_tracing)
        except ShaderError as e:
            self.error = str(e)
        fb = glfw.get_framebuffer_size(self.window)
        self.frames.resize(fb)
        self.ctx.screen.use()
        if self.frames.image is None:  # else the image covers every pixel: no clear to pay
            self.ctx.clear(*self.scene.material.background)
        self.frames.show(self.ctx.screen, fb, self.view, self._scales())

    def _scales(self) -> tuple[float, float]:
        """What the iterations and depth views show as white: the HUD's iteration count,
        the distance from the eye to the scene camera's target."""
        eye_to_target = np.linalg.norm(self.camera.position - np.array(self.scene.camera.target))
        return float(self.iteration_scale), max(float(eye_to_target), 1e-9)

    # -------------------------------------------------------------------------- output
    def screenshot(self) -> Path | None:
        """A full-resolution PNG of the current view and view mode, beside the scene (else in
        the pictures folder); its full path is printed and shown for STATUS_SECONDS."""
        rgb = self.frames.still(self.view_scene(), self.drawn.krs, self.view, self._scales())
        try:
            out = save_screenshot(rgb, self.path, time.strftime("%Y%m%d-%H%M%S"))
        except OSError as e:
            self.error = str(e)
            return None
        self.message = f"screenshot: {out}"
        self.say(self.message)
        print(self.message, flush=True)
        return out

    @property
    def error(self) -> str:
        """The error shown (the HUD's, the editor panel's; its first line the status line's)."""
        return self._error

    @error.setter
    def error(self, text: str) -> None:
        if text and text != self._error:  # the newest word takes the line:
            self.status = ("", 0.0)  # an older "saved …" hid a refusal said after it
        self._error = text

    def say(self, text: str) -> None:
        """Show ``text`` in the status line at the window's foot for STATUS_SECONDS."""
        self.status = (text, self.clock + STATUS_SECONDS)

    def status_line(self) -> str:
        """The status line shown at the window's foot, HUD shown or not: what was said (a
        screenshot's path) while it lasts, else the first line of the error the HUD shows
        whole (a scene file refused on reload), so that none goes unseen: the HUD's may be
        scrolled or folded out of sight."""
        if self.clock < self.status[1]:
            return self.status[0]
        return self.error.splitlines()[0] if self.error else ""

    def status_is_error(self, status: str) -> bool:
        """The status line ``status`` is the error's (drawn in red)."""
        return bool(status) and bool(self.error) and status == self.error.splitlines()[0]

    def read_window(self) -> np.ndarray:
        """The window's pixels (H, W, 3), rows top → bottom (for tests and screenshots)."""
        w, h = glfw.get_framebuffer_size(self.window)
        raw = self.ctx.screen.read(viewport=(0, 0, w, h), components=3)
        _ = self.ctx.error  # screen reads can leave a GL error pending (docs/architecture.md)
        return np.frombuffer(raw, np.uint8).reshape(h, w, 3)[::-1].copy()


# Every command the viewer takes, by class; tests/test_commands.py checks none is missing.
HANDLERS: dict[type[c.Command], Callable[[Viewer, Any], None]] = {
    c.Edit: lambda v, e: v.edit(e.path, e.value, e.interaction),
    c.SetEffect: lambda v, e: v.set_effect(e.name, e.on),
    c.SetPrepass: lambda v, e: v.set_prepass(e.tile, e.interaction),
    c.Undo: lambda v, e: v.undo(),
    c.Redo: lambda v, e: v.redo(),
    c.SetLevels: lambda v, e: v.drawn.set_levels(e.levels),
    c.SetViewMode: lambda v, e: setattr(v, "view", e.mode),
    c.SetIterationScale: lambda v, e: setattr(v, "iteration_scale", max(1, e.iterations)),
    c.SetTargetFps: lambda v, e: v.set_target_fps(e.fps),
    c.SetSupersample: lambda v, e: v.set_supersample(e.factor),
    c.SetMovingEffects: lambda v, e: v.set_moving_effects(e.on),
    c.OpenPreset: lambda v, e: v.file.open(e.path),
    c.SetOpenText: lambda v, e: setattr(v.file, "open_text", e.text),
    c.ResetView: lambda v, e: v.reset_view(),
    c.ToggleOrbit: lambda v, e: v.toggle_orbit(),
    c.Screenshot: lambda v, e: v.screenshot(),
    c.ToggleHud: lambda v, e: setattr(v, "hud", not v.hud),
    c.Quit: lambda v, e: glfw.set_window_should_close(v.window, True),
    c.AddBookmark: lambda v, e: v.file.add_bookmark(),
    c.GoToBookmark: lambda v, e: v.go_to_bookmark(e.index),
    c.NextBookmark: lambda v, e: v.next_bookmark(),
    c.ToggleRecording: lambda v, e: v.file.toggle_recording(),
    c.Replay: lambda v, e: v.file.recorder.replay(v.clock),
    c.ReloadScene: lambda v, e: v.file.reload(),
    c.ReloadShaders: lambda v, e: v.file.reload_shaders(),
    c.TogglePlay: lambda v, e: v.drawn.toggle_play(),
    c.SetTime: lambda v, e: v.drawn.set_time(e.time),
    c.SetSpeed: lambda v, e: v.drawn.playback.set_speed(e.speed),
}
