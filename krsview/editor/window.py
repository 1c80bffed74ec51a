"""`krsview edit`: the viewer plus direct manipulation. Click a handle, an outline entry or the
geometry to select; drag with the ImGuizmo translate gizmo (a normal by its arrow tip); every
change is an edit through the document, so Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo it,
Ctrl+S saves atomically, and unsaved work is autosaved beside the scene.

A drag changes only uniforms (kernel records and mirrors): the shader variant stays, so a
drag never recompiles; while dragging the adaptive resolution keeps the view fluid."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import glfw  # noqa: E402  (after imgui, as the viewer)
import numpy as np
from imgui_bundle import imgui, imguizmo

from ..compile.camera import View, pixel_ray, project, view_of
from ..document.document import ConflictError
from ..gpu.overlay import FAR, NEAR, Overlay, Shapes, camera_matrices
from ..reference.geometry import nearest
from ..scene import Bookmark, SceneError
from ..viewer.window import Viewer
from .handles import Handle, handles, polyline
from .panels import edit_panel

gizmo = imguizmo.im_guizmo
PICK_PIXELS = 12.0  # a click this close to a handle grabs it
CLICK_PIXELS = 4.0  # a press and release closer than this is a click, not a drag
FORK, CONTROL, NORMAL, SELECTED = (
    (1.0, 0.6, 0.15, 1.0),
    (0.3, 0.85, 1.0, 1.0),
    (1.0, 0.3, 0.8, 1.0),
    (1.0, 1.0, 0.3, 1.0),
)
ROUTE = (1.0, 0.9, 0.5, 0.9)
DISC = (0.5, 0.8, 1.0, 0.25)


@dataclass
class Snap:
    on: bool = False
    grid: float = 0.05  # units, for a translate drag
    angle: float = 5.0  # degrees (a normal's arrow tip snaps to the grid on its circle)


class Editor(Viewer):
    def __init__(self, path: Path, **kw):
        self.selected: Handle | None = None
        self.handles: list[Handle] = []
        self.warnings: list[str] = []
        super().__init__(path, **kw)
        self.overlay = Overlay(self.ctx, self.renderer.programs)
        self.snap = Snap()
        self.carry = True  # a fork drag takes its subtree along
        self.save_as_text = str(self.path)
        self.asking: tuple[str, Path | None] | None = None  # unsaved edits: close / open?
        self.recovered = self.doc.recovery()  # offered in a modal
        self.conflict = False
        self.scroll_outline = False
        self._gizmo_drag = 0
        self._was_using = False
        self._press: tuple[float, float] | None = None
        self._quit = False
        self._title = ""
        self._update_title()

    # -------------------------------------------------------------------- document hooks
    def window_title(self) -> str:
        return f"krsview edit — {self.doc.title}"

    def _set_scene(self, scene, reset_camera: bool = False) -> None:
        super()._set_scene(scene, reset_camera)
        self.handles = handles(scene)
        self.warnings = scene.route.warnings() if scene.route else []  # per edit, not frame
        if self.selected is not None:  # keep the selection across edits, undo, reload
            self.selected = next((h for h in self.handles if h.same(self.selected)), None)

    def _update_title(self) -> None:
        title = self.window_title()
        if title != self._title:
            glfw.set_window_title(self.window, title)
            self._title = title

    def step(self, dt: float) -> None:
        super().step(dt)
        self.doc.autosave(time.monotonic())
        self._update_title()

    def add_bookmark(self) -> None:
        """In the editor a bookmark is an edit like any other (saved with the scene)."""
        b = Bookmark(f"view {len(self.scene.bookmarks) + 1}", self.camera.to_camera())
        if self.edit(("bookmarks",), self.scene.bookmarks + [b]):
            self.message = f"bookmark {b.name!r} added (Ctrl+S saves it)"

    def file_changed(self) -> None:
        """Unsaved edits are never overwritten by the file's new contents: ask first."""
        if self.doc.dirty:
            self.conflict = True
        else:
            super().file_changed()

    # --------------------------------------------------------------------------- actions
    def undo(self) -> None:
        if self.doc.undo():
            self._sync()

    def redo(self) -> None:
        if self.doc.redo():
            self._sync()

    def save(self, path: str | None = None, overwrite: bool = False) -> bool:
        try:
            saved = self.doc.save(path or None, overwrite=overwrite)
        except ConflictError as e:
            self.error, self.conflict = str(e), True
            return False
        except SceneError as e:
            self.error = str(e)
            return False
        self._stamps = self._file_stamps()
        self.error, self.message, self.conflict = "", f"saved {saved.resolve()}", False
        self.save_as_text = str(saved)
        return True

    def save_as(self, text: str) -> None:
        target = Path(text.strip()).expanduser()
        if target.suffix != ".toml" or target.is_dir():
            self.error = f"save as: {text!r}: a scene file needs a name ending in .toml"
            return
        self.save(str(target))

    def bake(self) -> None:
        """Grown tree → route (one undo step): every fork becomes a handle."""
        t = self.scene.tree
        self.doc.commit(
            replace(self.scene, tree=None, route=t.route()), "bake the tree into a route"
        )
        self._sync()
        self.message = "baked: drag forks, control points and mirror normals"

    def select(self, h: Handle | None) -> None:
        self.selected = h
        self.scroll_outline = True

    def select_level(self, level: int) -> None:
        self.select(next((h for h in self.handles if h.level == level), None))

    def set_snap(self, on: bool) -> None:
        self.snap.on = on

    def set_carry(self, on: bool) -> None:
        self.carry = on

    def take_file(self) -> None:
        self.conflict = False
        super().file_changed()

    def keep_mine(self) -> None:
        self.conflict, self.message = False, "kept your edits; saving will ask to overwrite"

    def restore(self) -> None:
        self.doc.restore_recovery()
        self.recovered = None
        self._sync()
        self.message = "restored the unsaved edits (Ctrl+Z undoes the restore)"

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

    def shortcut(self, key: int, shift: bool) -> None:
        if key == glfw.KEY_Z:
            self.redo() if shift else self.undo()
        elif key == glfw.KEY_Y:
            self.redo()
        elif key == glfw.KEY_S:
            self.save_as(self.save_as_text) if shift else self.save()

    # ---------------------------------------------------------------- closing and opening
    def should_close(self) -> bool:
        if self._quit:
            return True
        if glfw.window_should_close(self.window):
            glfw.set_window_should_close(self.window, False)
            if not self.doc.dirty:
                return True
            self.asking, self.hud = ("close", None), True
        return False

    def open_preset(self, path: Path) -> None:
        if self.doc.dirty:
            self.asking, self.hud = ("open", Path(path)), True
        else:
            self._open(path)

    def _open(self, path: Path) -> None:
        super().open_preset(path)
        self.selected, self.recovered, self.conflict = None, self.doc.recovery(), False
        self.save_as_text = str(self.path)

    # ------------------------------------------------------------------- mouse and picking
    def window_view(self) -> View:
        w, h = glfw.get_window_size(self.window)
        return view_of(self.camera.to_camera(), max(w, 1), max(h, 1))

    def mouse_claimed(self) -> bool:
        return self.hud and (gizmo.is_over() or gizmo.is_using())

    def left_button(self, down: bool) -> None:
        x, y = self.input.cursor
        if down:
            self._press = (x, y)
        elif self._press is not None:
            moved = math.hypot(x - self._press[0], y - self._press[1])
            self._press = None
            if moved <= CLICK_PIXELS and self.hud:
                self.pick(x, y)

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
        if self.image is None:
            return None
        fbo, (w, h) = self.image
        px = min(max(int(x / v.width * w), 0), w - 1)
        py = min(max(int((v.height - y) / v.height * h), 0), h - 1)
        raw = fbo.read(viewport=(px, py, 1, 1), attachment=1, components=4, dtype="f4")
        t = float(np.frombuffer(raw, np.float32)[3])
        if not t > 0:
            return None
        point = v.origin + t * pixel_ray(v, x, y)
        slot = int(nearest(self.world, point[None])[0][0])
        level = self._entry_of_slot(slot)
        return next((h for h in self.handles if h.level == level), None)

    def _entry_of_slot(self, slot: int) -> int:
        """Outline entry of a compiled level slot: the level itself (shifted by the finest
        levels the levels slider cut away), or a compound's component (slots are numbered
        component after component)."""
        if not self.scene.compound:
            return slot + self.geometry.depth - self.krs.depth
        bases = list(getattr(self.world, "bases", (0,)))
        return max(k for k, b in enumerate(bases) if b <= slot)

    # ----------------------------------------------------------------------- drawing
    def draw_ui(self, fb: tuple[int, int]) -> None:
        v = self.window_view()
        if self.image is not None:
            self.overlay.draw(
                self._shapes(v), self.image[0], self.ctx.screen, fb, self._matrix(v), v.origin
            )
        gizmo.begin_frame()
        imgui.set_next_window_collapsed(True, imgui.Cond_.first_use_ever)  # the view stays free
        super().draw_ui(fb)
        self.execute(edit_panel(self, self.interactions))
        self._gizmo(v)

    def _matrix(self, v: View) -> np.ndarray:
        view, proj = camera_matrices(v, NEAR, FAR)
        return proj @ view

    def _shapes(self, v: View) -> Shapes:
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

    def _gizmo(self, v: View) -> None:
        h = self.selected
        if h is None:
            return
        io = imgui.get_io()
        gizmo.set_drawlist(imgui.get_background_draw_list())
        gizmo.set_rect(0.0, 0.0, io.display_size.x, io.display_size.y)
        near = 1e-3 * max(float(np.linalg.norm(h.position - v.origin)), 1e-12)
        view, proj = camera_matrices(v, near, 1e6 * near)
        obj = np.eye(4)
        obj[:3, 3] = h.position - v.origin  # camera-relative: float32 stays precise
        m = gizmo.Matrix16(list(obj.T.flatten()))
        snap = self.snap.on or bool(io.key_shift)
        step = gizmo.Matrix3([self.snap.grid] * 3) if snap and h.kind == "point" else None
        changed = gizmo.manipulate(
            gizmo.Matrix16(list(view.T.flatten())),
            gizmo.Matrix16(list(proj.T.flatten())),
            gizmo.OPERATION.translate,
            gizmo.MODE.world,
            m,
            None,
            step,
        )
        using = gizmo.is_using()
        if using and not self._was_using:
            self._gizmo_drag += 1  # a new drag: a new undo step
        self._was_using = using
        if changed and using:
            p = np.array(m.values[12:15], dtype=np.float64) + v.origin
            if snap and h.kind == "normal":
                p = h.pivot + _snap_direction(p - h.pivot, self.snap.angle)
            self.edit(*h.edit_to(self.scene, p, self.carry), ("gizmo", self._gizmo_drag))


def _snap_direction(d: np.ndarray, degrees: float) -> np.ndarray:
    """d with its polar angles (from +y, around y) rounded to multiples of ``degrees``."""
    r = float(np.linalg.norm(d))
    if r == 0:
        return d
    step = math.radians(degrees)
    theta = round(math.acos(max(-1.0, min(1.0, d[1] / r))) / step) * step
    phi = round(math.atan2(d[2], d[0]) / step) * step
    return r * np.array(
        [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
    )
