"""`krsview edit`: a viewer plus direct manipulation. Click a handle, an outline entry or the
geometry to select; drag with the ImGuizmo translate gizmo (a normal by its arrow tip); every
change is an edit through the document, so Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo it,
Ctrl+S saves atomically, and unsaved work is autosaved beside the scene.

The editor composes a :class:`Viewer`: it turns the event loop itself, calling the viewer's
parts (keys, camera, file watching, tracing, HUD) and adding its overlay, panels and gizmo.
Commands of its own go to EDITOR_HANDLERS, and those the editor decides differently
(bookmark, open, a file changed on disk); the rest to the viewer's.

A drag changes only uniforms (kernel records and mirrors): the shader variant stays, so a
drag never recompiles; while dragging the adaptive resolution keeps the view fluid."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import glfw  # noqa: E402  (after imgui, as the viewer)
import numpy as np
from imgui_bundle import imgui

from ..compile.camera import View, pixel_ray, project, view_of
from ..document.document import ConflictError, Document
from ..gpu.overlay import FAR, NEAR, Overlay, Shapes, camera_matrices
from ..reference.geometry import nearest
from ..scene import Bookmark, Scene, SceneError
from ..scene.settings import EDITOR_SETTINGS, ViewerSettings, make_settings
from ..viewer import commands as vc
from ..viewer.controls import VIEWER_KEYS
from ..viewer.hud import draw_hud, draw_status
from ..viewer.loop import run
from ..viewer.picking import depth_at
from ..viewer.window import Viewer
from . import commands as ec
from .gizmo import Gizmo
from .handles import Handle, handles, polyline
from .mokrs_handles import MobiusHandle, guide_lines
from .panels import edit_panel

PICK_PIXELS = 12.0  # a click this close to a handle grabs it
FORK, CONTROL, NORMAL, SELECTED = (
    (1.0, 0.6, 0.15, 1.0),
    (0.3, 0.85, 1.0, 1.0),
    (1.0, 0.3, 0.8, 1.0),
    (1.0, 1.0, 0.3, 1.0),
)
ROUTE = (1.0, 0.9, 0.5, 0.9)
DISC = (0.5, 0.8, 1.0, 0.25)
EDITOR_KEYS = {**VIEWER_KEYS, "ctrl+S": ec.Save(), "ctrl+shift+S": ec.SaveAs()}


class Editor:
    def __init__(self, path: Path, settings: ViewerSettings | None = None, **options: Any):
        """``options``: ``visible``, ``shader_dir``, or fields of ViewerSettings."""
        window = {k: options.pop(k) for k in ("visible", "shader_dir") if k in options}
        settings = make_settings(settings or EDITOR_SETTINGS, **options)
        self.viewer = Viewer(path, settings, **window)
        self.viewer.input.keymap = dict(EDITOR_KEYS)
        self.overlay = Overlay(self.viewer.ctx, self.viewer.renderer.programs)
        self.gizmo = Gizmo()
        self.snap = self.gizmo.snap
        self.carry = True  # a fork drag takes its subtree along
        self.selected: Handle | None = None
        self._handles_of: Scene | None = None  # the scene the handles were made for
        self._handles: list[Handle] = []
        self.warnings: list[str] = []
        self.save_as_text = str(self.path)
        self.asking: tuple[str, Path | None] | None = None  # unsaved edits: close / open?
        self.recovered = self.doc.recovery()  # offered in a modal
        self.conflict = False
        self.scroll_outline = False
        self._quit = False
        self._title = ""
        self._update_title()

    # ------------------------------------------------------------------------- the scene
    @property
    def doc(self) -> Document:
        return self.viewer.doc

    @property
    def scene(self) -> Scene:
        return self.viewer.scene

    @property
    def path(self) -> Path:
        return self.viewer.path

    @property
    def handles(self) -> list[Handle]:
        """The scene's handles, made again when the scene changed (an edit, undo, reload);
        the selection and the route's warnings follow."""
        self._follow()
        return self._handles

    def _follow(self) -> None:
        if self._handles_of is not self.scene:
            self._handles_of = self.scene
            self._handles = handles(self.scene)
            route = self.scene.route
            self.warnings = route.warnings() if route else []
            if self.selected is not None:  # keep the selection across edits, undo, reload
                self.selected = next((h for h in self._handles if h.same(self.selected)), None)

    def edit(self, path: tuple, value, interaction=None) -> bool:
        return self.viewer.edit(path, value, interaction)

    def _update_title(self) -> None:
        title = f"krsview edit — {self.doc.title}"
        if title != self._title:
            glfw.set_window_title(self.viewer.window, title)
            self._title = title

    # ------------------------------------------------------------------------ the loop
    def run(self) -> None:
        run(self)

    def is_idle(self) -> bool:
        return self.viewer.is_idle()

    def close(self) -> None:
        self.viewer.close()

    def step(self, dt: float) -> None:
        """The viewer's turn with the editor's parts: picking by a click, the overlay, the
        panels and the gizmo; then the autosave."""
        v = self.viewer
        v.begin_step(dt)
        self.execute(v.input.commands())
        click = v.input.take_click()
        if click is not None and v.hud:
            self.pick(*click)
        v.move(dt)
        self.execute(v.watcher.poll())
        v.draw_image()
        self._follow()
        status = v.status_line()
        if v.hud or status:
            v.platform.new_frame()
            if v.hud:
                self._draw_ui()
            draw_status(status)
            v.platform.render()
        v.input.claimed = v.hud and self.gizmo.claims_mouse()
        glfw.swap_buffers(v.window)
        self.doc.autosave(time.monotonic())
        self._update_title()

    def should_close(self) -> bool:
        if self._quit:
            return True
        if glfw.window_should_close(self.viewer.window):
            glfw.set_window_should_close(self.viewer.window, False)
            if not self.doc.dirty:
                return True
            self.asking, self.viewer.hud = ("close", None), True
        return False

    def execute(self, commands: list[vc.Command]) -> None:
        """Apply commands: the editor's own and those it decides itself here, the rest by
        the viewer."""
        for command in commands:
            handler = EDITOR_HANDLERS.get(type(command))
            if handler is None:
                self.viewer.execute([command])
            else:
                handler(self, command)

    # --------------------------------------------------------------------------- actions
    def add_bookmark(self) -> None:
        """In the editor a bookmark is an edit like any other (saved with the scene)."""
        b = Bookmark(f"view {len(self.scene.bookmarks) + 1}", self.viewer.camera.to_camera())
        if self.edit(("bookmarks",), self.scene.bookmarks + [b]):
            self.viewer.message = f"bookmark {b.name!r} added (Ctrl+S saves it)"

    def reload_scene(self) -> None:
        """Unsaved edits are never overwritten by the file's new contents: ask first."""
        if not self.doc.changed_on_disk():
            return
        if self.doc.dirty:
            self.conflict = True
        else:
            self.viewer.take_file()

    def save(self, path: str | None = None, overwrite: bool = False) -> bool:
        v = self.viewer
        try:
            saved = self.doc.save(path or None, overwrite=overwrite)
        except ConflictError as e:
            v.error, self.conflict = str(e), True
            return False
        except SceneError as e:
            v.error = str(e)
            return False
        v.follow_file()
        v.error, v.message, self.conflict = "", f"saved {saved.resolve()}", False
        self.save_as_text = str(saved)
        return True

    def save_as(self, text: str) -> None:
        target = Path(text.strip()).expanduser()
        if target.suffix != ".toml" or target.is_dir():
            self.viewer.error = f"save as: {text!r}: a scene file needs a name ending in .toml"
            return
        self.save(str(target))

    def bake(self) -> None:
        """Grown tree → route (one undo step): every fork becomes a handle."""
        t = self.scene.tree
        self.doc.commit(
            replace(self.scene, tree=None, route=t.route()), "bake the tree into a route"
        )
        self.viewer.sync()
        self.viewer.message = "baked: drag forks, control points and mirror normals"

    def select(self, h: Handle | None) -> None:
        self.selected = h
        self.scroll_outline = True

    def select_level(self, level: int) -> None:
        self.select(next((h for h in self.handles if h.level == level), None))

    def take_file(self) -> None:
        self.conflict = False
        self.viewer.take_file()

    def keep_mine(self) -> None:
        self.conflict = False
        self.viewer.message = "kept your edits; saving will ask to overwrite"

    def restore(self) -> None:
        self.doc.restore_recovery()
        self.recovered = None
        self.viewer.sync()
        self.viewer.message = "restored the unsaved edits (Ctrl+Z undoes the restore)"

    def discard_recovery(self) -> None:
        self.doc.discard_recovery()
        self.recovered = None

    def answer_save(self) -> None:
        if self.save():
            self._answered()

    def answer_discard(self) -> None:
        self.doc.discard_recovery()
        self._answered()

    def answer_cancel(self) -> None:
        self.asking = None

    def _answered(self) -> None:
        what, path = self.asking or (None, None)
        self.asking = None
        if what == "close":
            self._quit = True
        elif what == "open" and path is not None:
            self._open(path)

    def open_preset(self, path: Path) -> None:
        if self.doc.dirty:
            self.asking, self.viewer.hud = ("open", Path(path)), True
        else:
            self._open(path)

    def _open(self, path: Path) -> None:
        self.viewer.open_preset(path)
        self.selected, self.recovered, self.conflict = None, self.doc.recovery(), False
        self.save_as_text = str(self.path)

    # ------------------------------------------------------------------- mouse and picking
    def window_view(self) -> View:
        w, h = glfw.get_window_size(self.viewer.window)
        return view_of(self.viewer.camera.to_camera(), max(w, 1), max(h, 1))

    def pick(self, x: float, y: float) -> Handle | None:
        """Select what is under window point (x, y): the nearest handle within PICK_PIXELS,
        else the level of the kernel nearest to the traced surface point there."""
        v = self.window_view()
        best, best_d = None, PICK_PIXELS
        for h in self.handles:
            px, py, z = project(v, h.position)
            d = math.hypot(px - x, py - y) if z > 0 else math.inf
            if d < best_d:
                best, best_d = h, d
        if best is None:
            best = self._pick_surface(v, x, y)
        self.select(best)
        return best

    def _pick_surface(self, v: View, x: float, y: float) -> Handle | None:
        if self.viewer.frames.image is None:
            return None
        fbo, (w, h) = self.viewer.frames.image
        px = min(max(int(x / v.width * w), 0), w - 1)
        py = min(max(int((v.height - y) / v.height * h), 0), h - 1)
        t = depth_at(fbo, px, py)
        if not t > 0:
            return None
        point = v.origin + t * pixel_ray(v, x, y)
        slot = int(nearest(self.viewer.world, point[None])[0][0])
        level = self._entry_of_slot(slot)
        return next((h for h in self.handles if h.level == level), None)

    def _entry_of_slot(self, slot: int) -> int:
        """Outline entry of a compiled level slot: the level itself (shifted by the finest
        levels the levels slider cut away), or a compound's component (slots are numbered
        component after component)."""
        if not self.scene.compound:
            return slot + self.viewer.geometry.depth - self.viewer.krs.depth
        bases = list(getattr(self.viewer.world, "bases", (0,)))
        return max(k for k, b in enumerate(bases) if b <= slot)

    # ----------------------------------------------------------------------- drawing
    def _draw_ui(self) -> None:
        """Inside the ImGui frame: the overlay over the image, the viewer's HUD (collapsed
        at first: the view stays free), the edit panel and the gizmo."""
        v = self.viewer
        view = self.window_view()
        if v.frames.image is not None:
            fb = glfw.get_framebuffer_size(v.window)
            view_matrix, proj = camera_matrices(view, NEAR, FAR)
            matrix = proj @ view_matrix
            self.overlay.draw(
                self._shapes(), v.frames.image[0], v.ctx.screen, fb, matrix, view.origin
            )
        self.gizmo.begin_frame()
        imgui.set_next_window_collapsed(True, imgui.Cond_.first_use_ever)
        self.execute(draw_hud(v, v.interactions))
        self.execute(edit_panel(self, v.interactions))
        if self.selected is not None:
            moved = self.gizmo.manipulate(self.selected, view)
            if moved is not None:
                p, drag = moved
                self.edit(*self.selected.edit_to(self.scene, p, self.carry), drag)

    def _shapes(self) -> Shapes:
        s = Shapes()
        route = polyline(self.scene)
        for a, b in zip(route[:-1], route[1:]):
            s.lines.append((a, b, ROUTE))
        sel = self.selected
        for h in self.handles:
            colour = {"normal": NORMAL}.get(h.kind, CONTROL if h.path[-1] == "control" else FORK)
            big = sel is not None and h.level == sel.level
            if h.same(sel):
                colour = SELECTED
            s.points.append((h.position, colour, 13.0 if big else 8.0))
            if h.kind == "normal" and big:
                s.lines.append((h.pivot, h.position, NORMAL))
        if sel is not None:
            self._mirror_disc(s, sel)
        if isinstance(sel, MobiusHandle):  # a MöKRS step's circle, sphere or vector
            s.lines += guide_lines(sel, NORMAL)
        return s

    def _mirror_disc(self, s: Shapes, sel: Handle) -> None:
        """The selected level's mirror as a translucent disc through its fork."""
        arrow = next((h for h in self.handles if h.level == sel.level and h.kind == "normal"), None)
        if arrow is None:
            return
        d = arrow.position - arrow.pivot
        r = float(np.linalg.norm(d))
        if r > 0:
            s.disc(arrow.pivot, d / r, 1.6 * r, DISC)


# The editor's commands, and the viewer's that the editor decides itself (a bookmark is an
# edit, opening or reloading asks about unsaved edits); tests/test_commands.py checks them.
EDITOR_HANDLERS: dict[type[vc.Command], Callable[[Editor, Any], None]] = {
    ec.Bake: lambda e, c: e.bake(),
    ec.Select: lambda e, c: e.select(c.handle),
    ec.SelectLevel: lambda e, c: e.select_level(c.level),
    ec.OutlineScrolled: lambda e, c: setattr(e, "scroll_outline", False),
    ec.SetSnap: lambda e, c: setattr(e.snap, "on", c.on),
    ec.SetCarry: lambda e, c: setattr(e, "carry", c.on),
    ec.Save: lambda e, c: e.save(),
    ec.SaveAs: lambda e, c: e.save_as(e.save_as_text),
    ec.SetSaveAsText: lambda e, c: setattr(e, "save_as_text", c.text),
    ec.TakeFile: lambda e, c: e.take_file(),
    ec.KeepMine: lambda e, c: e.keep_mine(),
    ec.Restore: lambda e, c: e.restore(),
    ec.DiscardRecovery: lambda e, c: e.discard_recovery(),
    ec.AnswerSave: lambda e, c: e.answer_save(),
    ec.AnswerDiscard: lambda e, c: e.answer_discard(),
    ec.AnswerCancel: lambda e, c: e.answer_cancel(),
    vc.AddBookmark: lambda e, c: e.add_bookmark(),
    vc.OpenPreset: lambda e, c: e.open_preset(c.path),
    vc.ReloadScene: lambda e, c: e.reload_scene(),
}
