"""`krsview view`: a GLFW window to fly through a scene, with adaptive resolution, an ImGui HUD
and hot reload of the preset and the shaders."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import glfw  # noqa: E402  (order matters)
import moderngl
import numpy as np
from imgui_bundle import imgui  # noqa: F401  imported before glfw (DESIGN.md, stack facts)

from ..compile.geometry import compile_geometry
from ..document.document import Document
from ..gpu.context import GL_VERSION
from ..gpu.display import Display
from ..gpu.program import SHADER_DIR, ProgramCache, ShaderError
from ..gpu.renderer import Renderer
from ..reference.geometry import free_radius
from ..scene import Bookmark, Scene, SceneError, load_scene, save_scene
from ..scene.camera_path import CameraPath, Pose, camera_path_json, load_camera_path
from ..scene.effects import EFFECTS, EXCLUSIVE
from ..scene.model import VIEW_PREPASS
from ..scene.scene import write_atomic
from .adaptive import AdaptiveResolution, Refinement
from .camera import FlyCamera
from .commands import Command, Edit
from .controls import LOOK_BUTTON, ORBIT_BUTTON, Input
from .hud import draw_hud
from .measured import load_measured
from .platform import Platform
from .widgets import Interactions

LOOK_RADIANS_PER_PIXEL = 0.004
RELOAD_INTERVAL = 0.5  # seconds between checks of the preset and shader files


class Viewer:
    def __init__(
        self,
        path: Path,
        size: tuple[int, int] = (960, 540),
        hud: bool = True,
        target_fps: float = 30.0,
        visible: bool = True,
        shader_dir: Path = SHADER_DIR,
        prepass: int | None = None,
        moving_effects: bool = False,
    ):
        self.shader_dir = Path(shader_dir)
        self.doc = Document(path)  # a bad file is a SceneError before any window
        # the pre-pass tile the viewer draws with: given, else the file's, else VIEW_PREPASS
        self.prepass = (
            prepass if prepass is not None else self.doc.scene.render.prepass or VIEW_PREPASS
        )
        self.moving_effects = moving_effects  # False: moving frames skip secondary effects
        self.platform = Platform(size, self.window_title(), visible)
        self.window = self.platform.window
        self.ctx = moderngl.create_context(require=GL_VERSION)
        self.renderer = Renderer(self.ctx, self.shader_dir)
        self.display = Display(self.ctx, self.renderer.programs)
        self.input = Input()
        self.interactions = Interactions()
        self.hud = hud
        self.view = "shaded"
        self.levels = 0  # 0: all of the scene's levels
        self.speed_factor = 1.0  # × distance to the nearest surface, per second
        self.orbit_pivot: np.ndarray | None = None
        self.message, self.error = "", ""
        self.recording: list[Pose] | None = None
        self.camera_path: CameraPath | None = None  # NAME.path.json, recorded or loaded
        self.replay_start: float | None = None
        self.bookmark_index = -1
        self.clock = 0.0
        fb = glfw.get_framebuffer_size(self.window)
        self.adaptive = AdaptiveResolution(fb, target_fps)
        self.image: tuple[moderngl.Framebuffer, tuple[int, int]] | None = None
        self.refinement: Refinement | None = None
        self.frame_seconds: list[float] = []
        self._stamps = self._file_stamps()
        self._last_check = time.perf_counter()
        self._set_scene(self.doc.scene, reset_camera=True)
        self.load_path()
        self.platform.route_events(self)

    # ------------------------------------------------------------------------- scene state
    @property
    def scene(self) -> Scene:
        return self.doc.scene

    @property
    def path(self) -> Path:
        return self.doc.path

    def window_title(self) -> str:
        return f"krsview — {self.doc.scene.name}"

    def _set_scene(self, scene: Scene, reset_camera: bool = False) -> None:
        """Follow the document: a new scene version redraws (and recompiles only if its
        variant changed: effects, tracer, geometry family)."""
        self._seen_version = self.doc.version
        if getattr(self, "_measured_for", None) != self.path.stem:  # per preset, not per edit
            self.measured, self._measured_for = load_measured(self.path.stem), self.path.stem
        self.geometry = scene.geometry()
        self.levels = min(self.levels, self.geometry.depth)
        self._apply_levels()
        if reset_camera:
            self.camera = FlyCamera.from_camera(scene.camera)
        self.dirty = True

    def _sync(self) -> None:
        """Redraw when the document changed (an edit, undo, redo, reload)."""
        if self.doc.version != self._seen_version:
            self._set_scene(self.doc.scene)

    def open_preset(self, path: Path) -> None:
        """Show another scene file from its own camera; it becomes the one watched for edits."""
        try:
            self.doc = Document(path)
        except SceneError as e:
            self.error = str(e)
            return
        self._set_scene(self.doc.scene, reset_camera=True)
        self._stamps, self.error = self._file_stamps(), ""
        self.load_path()

    def set_levels(self, levels: int) -> None:
        """Draw only the coarsest ``levels`` levels (0 or all: the whole scene)."""
        self.levels = 0 if levels >= self.geometry.depth else levels
        self._apply_levels()

    def _apply_levels(self) -> None:
        self.krs = self.geometry.truncated(self.levels) if self.levels else self.geometry
        self.world = compile_geometry(self.krs, self.scene.material.albedo)  # speed, picking
        self._free: tuple[np.ndarray, float] | None = None  # cached nearest_distance
        self.dirty = True

    def edit(self, path: tuple, value, interaction=None) -> bool:
        """Apply one edit through the document; a refused value shows its error and leaves
        the last valid scene in place."""
        try:
            self.doc.apply(path, value, interaction)
        except SceneError as e:
            self.error = str(e)
            return False
        self.error = ""
        self._sync()
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

    def view_scene(self, moving: bool = False) -> Scene:
        """The scene as drawn now: the viewer's camera and settings. A moving frame leaves out
        the effects that trace the geometry again per pixel (shadow rays, occlusion samples:
        40 % of a `tree` frame) unless ``moving_effects``; the still image has them all."""
        effects = self.scene.effects
        if moving and not self.moving_effects:
            effects = [e for e in effects if not EFFECTS[e].secondary]
        return replace(
            self.scene,
            camera=self.camera.to_camera(),
            effects=effects,
            render=replace(self.scene.render, prepass=self.prepass),
        )

    def nearest_distance(self) -> float:
        """Radius of an empty ball around the eye. Recomputed only after the eye moved a
        quarter of it (a MöKRS needs a batch of Alg. 3 tests, ~10 ms in NumPy); in between,
        r₀ − moved is still empty (the ball around the new eye lies inside the old one)."""
        p = self.camera.position
        if self._free is not None:
            p0, r0 = self._free
            moved = float(np.linalg.norm(p - p0))
            if moved < 0.25 * r0:
                return r0 - moved
        r = free_radius(self.world, p)
        self._free = (p.copy(), r)
        return r

    # --------------------------------------------------------------------------- the loop
    def run(self) -> None:
        last = time.perf_counter()
        try:
            while not self.should_close():
                if self.is_idle():
                    glfw.wait_events_timeout(0.05)
                else:
                    glfw.poll_events()
                now = time.perf_counter()
                self.step(now - last)
                last = now
        finally:
            self.close()

    def should_close(self) -> bool:
        """The window was asked to close (the editor first asks about unsaved edits)."""
        return bool(glfw.window_should_close(self.window))

    def is_idle(self) -> bool:
        return (
            not self.dirty
            and (self.refinement is None or self.refinement.done)
            and not self.input.held
            and not self.input.buttons
            and self.replay_start is None
        )

    def step(self, dt: float) -> None:
        """One event-loop turn: input, reload, a bounded amount of tracing, present, HUD."""
        self.clock += dt
        glfw.make_context_current(self.window)
        self._handle_input(dt)
        self._replay()
        self._hot_reload()
        self._sync()
        self._trace()
        self._present()
        glfw.swap_buffers(self.window)

    def close(self) -> None:
        if self.window is not None:
            self.platform.close()
            self.window = None

    # -------------------------------------------------------------------------- tracing
    def _trace(self) -> None:
        scene = self.view_scene()
        if self.dirty:
            size = self.adaptive.moving_size()
            t0 = time.perf_counter()
            moving = self.view_scene(moving=True)
            try:
                prog = self.renderer.prepare(moving, *size, self.krs)
            except ShaderError as e:
                self.error, self.dirty = str(e), False
                return
            fbo = self.renderer.draw(prog, *size)
            self.ctx.finish()
            seconds = time.perf_counter() - t0
            self.adaptive.frame_done(seconds)
            self.frame_seconds = (self.frame_seconds + [seconds])[-240:]
            self.image = (fbo, size)
            still = self.adaptive.still_size()
            final = still == size and moving.effects == scene.effects
            self.refinement = None if final else Refinement(still)
            self.dirty = False
        elif self.refinement is not None and not self.refinement.done:
            r = self.refinement
            prog = self.renderer.prepare(scene, *r.size, self.krs)
            spent, budget = 0.0, 0.8 * self.adaptive.budget
            while not r.done and spent < budget:
                tile = r.next_tile(budget - spent)
                t0 = time.perf_counter()
                fbo = self.renderer.draw(prog, *r.size, tile)
                self.ctx.finish()
                seconds = time.perf_counter() - t0
                r.tile_done(tile, seconds)
                spent += seconds
            if r.done:
                self.image = (fbo, r.size)

    @property
    def refined(self) -> bool:
        """The window shows the full-resolution image of the current view."""
        return not self.dirty and (self.refinement is None or self.refinement.done)

    def _present(self) -> None:
        fb = glfw.get_framebuffer_size(self.window)
        if fb != self.adaptive.full and fb[0] > 0 and fb[1] > 0:
            self.adaptive.full = fb
            self.dirty = True
        self.ctx.screen.use()
        self.ctx.clear(*self.scene.material.background)
        if self.image is not None:
            self.display.show(
                self.image[0],
                self.ctx.screen,
                fb,
                self.view,
                self.scene.render.max_iterations,
                self._depth_scale(),
            )
        if self.hud:
            self.platform.new_frame()
            self.draw_ui(fb)
            self.platform.render()

    def draw_ui(self, fb: tuple[int, int]) -> None:
        """Everything drawn over the image inside one ImGui frame: the viewer's HUD."""
        self.execute(draw_hud(self, self.interactions))

    def execute(self, commands: list[Command]) -> None:
        """Apply what the panels returned: scene edits through the document, calls of this
        window's own methods."""
        for c in commands:
            if isinstance(c, Edit):
                self.edit(c.path, c.value, c.interaction)
            else:
                getattr(self, c.action)(*c.args)

    def _depth_scale(self) -> float:
        return max(
            float(np.linalg.norm(self.camera.position - np.array(self.scene.camera.target))), 1e-9
        )

    # ---------------------------------------------------------------------------- input
    def _handle_input(self, dt: float) -> None:
        for action in self.input.actions():
            self.act(action)
        scroll = self.input.take_scroll()
        if scroll:
            self.speed_factor *= 1.25**scroll
        dx, dy = self.input.take_drag()
        move = np.array(self.input.movement(), dtype=float)
        if self.orbit_pivot is not None:
            if ORBIT_BUTTON in self.input.buttons and (dx or dy):
                self.camera.orbit(
                    self.orbit_pivot, -dx * LOOK_RADIANS_PER_PIXEL, dy * LOOK_RADIANS_PER_PIXEL
                )
                self.dirty = True
            if move[2]:
                self.camera.dolly(self.orbit_pivot, 0.5 ** (move[2] * dt * self.speed_factor))
                self.dirty = True
            return
        if LOOK_BUTTON in self.input.buttons and (dx or dy):
            self.camera.look(-dx * LOOK_RADIANS_PER_PIXEL, -dy * LOOK_RADIANS_PER_PIXEL)
            self.dirty = True
        if move.any():
            # Speed ∝ distance to the nearest surface: fly from a forest into a twig many
            # levels deep without overshooting.
            speed = self.speed_factor * max(self.nearest_distance(), 1e-12)
            self.camera.fly(move, speed * dt)
            self.dirty = True

    def act(self, action: str) -> None:
        if action == "reset":
            self.camera = FlyCamera.from_camera(self.scene.camera)
            self.orbit_pivot, self.dirty = None, True
        elif action == "orbit":
            self.orbit_pivot = None if self.orbit_pivot is not None else self.pick_center()
            self.message = (
                "orbit mode: left-drag turns, W/S dolly"
                if self.orbit_pivot is not None
                else "fly mode"
            )
        elif action == "screenshot":
            self.screenshot()
        elif action == "hud":
            self.hud = not self.hud
        elif action == "bookmark":
            self.add_bookmark()
        elif action == "next_bookmark" and self.scene.bookmarks:
            self.go_to_bookmark((self.bookmark_index + 1) % len(self.scene.bookmarks))
        elif action == "record":
            if self.recording is None:
                self.recording, self.message = [], "recording the camera path (F5 stops)"
            else:
                if self.recording:
                    self.camera_path = CameraPath(tuple(self.recording))
                    self.save_path()
                self.recording = None
        elif action == "replay" and self.camera_path is not None:
            self.replay_start = self.clock

    def go_to_bookmark(self, index: int) -> None:
        self.bookmark_index = index
        b = self.scene.bookmarks[index]
        self.camera, self.dirty = FlyCamera.from_camera(b.camera), True
        self.message = f"bookmark {b.name!r}"

    def set_prepass(self, tile: int) -> None:
        self.prepass, self.dirty = tile, True

    def set_moving_effects(self, on: bool) -> None:
        self.moving_effects, self.dirty = on, True

    def set_target_fps(self, fps: float) -> None:
        self.adaptive.target_fps = fps

    def set_supersample(self, factor: int) -> None:
        self.adaptive.supersample, self.dirty = factor, True

    def set_view_mode(self, mode: str) -> None:
        self.view = mode

    def shortcut(self, key: int, shift: bool) -> None:
        """Ctrl+key: the viewer has none; the editor's undo, redo and save."""

    def mouse_claimed(self) -> bool:
        """A press the camera must not take (the editor's gizmo is under the cursor)."""
        return False

    def left_button(self, down: bool) -> None:
        """Left press or release on the image (the editor picks with a click)."""

    def path_file(self) -> Path:
        """Where the camera path of this preset is kept: beside it, ``NAME.path.json``."""
        return self.path.with_name(self.path.stem + ".path.json")

    def save_path(self) -> None:
        poses = list(self.camera_path.poses)
        try:
            write_atomic(self.path_file(), camera_path_json(poses))
            self.message = (
                f"recorded {len(poses)} poses to {self.path_file().name} "
                "(F6 replays; `krsview render --camera-path` renders its frames)"
            )
        except OSError as e:
            self.error = f"{self.path_file()}: cannot save the camera path: {e.strerror}"

    def load_path(self) -> None:
        """The preset's saved camera path, if any; a damaged file is reported, not fatal."""
        f = self.path_file()
        self.camera_path = None
        if f.exists():
            try:
                self.camera_path = load_camera_path(f)
            except SceneError as e:
                self.error = str(e)

    def pick_center(self) -> np.ndarray:
        """The surface point under the window centre, from the last traced depth; else a point
        ahead at the distance of the nearest surface."""
        if self.image is not None:
            fbo, (w, h) = self.image
            x, y = w // 2, h // 2
            raw = fbo.read(viewport=(x, y, 1, 1), attachment=1, components=4, dtype="f4")
            depth = float(np.frombuffer(raw, np.float32)[3])
            if depth > 0:
                return self.camera.position + depth * self.camera.forward()
        return self.camera.position + max(self.nearest_distance(), 1e-9) * self.camera.forward()

    def _replay(self) -> None:
        if self.recording is not None:
            self.recording.append(
                Pose(
                    self.clock,
                    tuple(float(c) for c in self.camera.position),
                    self.camera.yaw,
                    self.camera.pitch,
                )
            )
        if self.replay_start is None:
            return
        path = self.camera_path
        t = self.clock - self.replay_start
        if t >= path.duration:
            self.replay_start, self.message = None, "replay finished"
        pose = path.pose_at(t)
        self.camera.position = np.array(pose.position, dtype=np.float64)
        self.camera.yaw, self.camera.pitch = pose.yaw, pose.pitch
        self.dirty = True

    # ------------------------------------------------------------------ files and output
    def _file_stamps(self) -> tuple:
        def mtime(p: Path) -> float:
            try:
                return p.stat().st_mtime
            except OSError:
                return 0.0

        shaders = sorted(self.shader_dir.iterdir())
        return (mtime(self.path), tuple(mtime(p) for p in shaders))

    def _hot_reload(self) -> None:
        now = time.perf_counter()
        if now - self._last_check < RELOAD_INTERVAL:
            return
        self._last_check = now
        stamps = self._file_stamps()
        if stamps == self._stamps:
            return
        preset_changed = stamps[0] != self._stamps[0]
        self._stamps = stamps
        if preset_changed and self.doc.changed_on_disk():
            self.file_changed()
        elif not preset_changed:
            self.reload_shaders()

    def file_changed(self) -> None:
        """The scene file changed on disk: take it (an undoable step). A viewer has no edits
        of its own to lose; the editor asks first when it has unsaved ones."""
        try:
            self.doc.reload()
            self.error, self.message = "", f"reloaded {self.path.name}"
        except SceneError as e:
            self.error = str(e)  # keep the last good scene and image

    def reload_shaders(self) -> None:
        """Compile the current variant from the edited files; on failure keep the old ones."""
        programs = ProgramCache(self.ctx, self.shader_dir)
        old = self.renderer.programs
        try:
            self.renderer.programs = programs
            self.renderer.prepare(self.view_scene(), 1, 1, self.krs)
            display = Display(self.ctx, programs)
        except ShaderError as e:
            self.renderer.programs, self.error = old, str(e)
            return
        self.display, self.error, self.message = display, "", "shaders reloaded"
        self.dirty = True

    def screenshot(self, path: Path | None = None) -> Path:
        """A full-resolution PNG of the current view and view mode."""
        size = self.adaptive.still_size()
        out = path or Path("screenshots") / f"{self.path.stem}-{time.strftime('%Y%m%d-%H%M%S')}.png"
        out.parent.mkdir(parents=True, exist_ok=True)
        prog = self.renderer.prepare(self.view_scene(), *size, self.krs)
        fbo = self.renderer.draw(prog, *size)
        target = self.ctx.simple_framebuffer(size, components=4)
        self.display.show(
            fbo, target, size, self.view, self.scene.render.max_iterations, self._depth_scale()
        )
        rgb = np.frombuffer(target.read(components=3), np.uint8).reshape(size[1], size[0], 3)
        from PIL import Image

        Image.fromarray(rgb[::-1]).save(out)
        target.release()
        self.message = f"screenshot: {out.resolve()}"
        return out

    def add_bookmark(self) -> None:
        """Append the current camera to the preset file's bookmarks (atomic save)."""
        try:
            on_disk = load_scene(self.path)
        except SceneError as e:
            self.error = f"bookmark not saved: {e}"
            return
        b = Bookmark(f"view {len(on_disk.bookmarks) + 1}", self.camera.to_camera())
        save_scene(replace(on_disk, bookmarks=on_disk.bookmarks + [b]), self.path)
        self._stamps = self._file_stamps()  # our own save is not an outside edit
        self.edit(("bookmarks",), on_disk.bookmarks + [b])
        self.doc.mark_saved(replace(on_disk, bookmarks=on_disk.bookmarks + [b]))
        self.message = f"saved bookmark {b.name!r} in {self.path.name}"

    def read_window(self) -> np.ndarray:
        """The window's pixels (H, W, 3), rows top → bottom (for tests and screenshots)."""
        w, h = glfw.get_framebuffer_size(self.window)
        raw = self.ctx.screen.read(viewport=(0, 0, w, h), components=3)
        _ = self.ctx.error  # screen reads can leave a GL error pending (DESIGN.md)
        return np.frombuffer(raw, np.uint8).reshape(h, w, 3)[::-1].copy()
