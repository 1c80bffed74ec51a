"""`krsview edit`: a viewer plus direct manipulation. Click a handle, an outline entry or the
geometry to select; drag a point with the ImGuizmo translate gizmo, turn a normal by dragging
its arrow tip (a trackball about its foot); every change is an edit through the document, so
Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo it, Ctrl+S saves atomically, and unsaved work is
autosaved beside the scene.

The editor composes a :class:`Viewer`: it turns the event loop itself, calling the viewer's
parts (keys, camera, file watching, tracing, HUD) and adding its overlay (shapes.py), panels,
gizmo, trackball and picking (picking.py). Commands of its own go to EDITOR_HANDLERS
(handlers.py), and those the editor decides differently (bookmark, open, a file changed on disk,
a field's edit, reset view); the rest to the viewer's. Its other jobs live beside it: the file,
a part it holds (``self.file``, file_actions.py), what the view shows at the moment shown
(shown.py) and a drag's edits (dragging.py).

A drag changes only uniforms (kernel records and mirrors): the shader variant stays, so a
drag never recompiles; while dragging the adaptive resolution keeps the view fluid."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import glfw  # noqa: E402  (after imgui, as the viewer)
import numpy as np

from ..compile.camera import View, view_of
from ..compile.geometry import scene_ball
from ..compile.mokrs import check_drawable
from ..document.document import Document
from ..gpu.overlay import Overlay
from ..scene import Scene, SceneError
from ..scene.edits import apply_edit, path_text
from ..scene.settings import EDITOR_SETTINGS, ViewerSettings, make_settings
from ..viewer import commands as vc
from ..viewer.controls import VIEWER_KEYS
from ..viewer.loop import run
from ..viewer.status import draw_status
from ..viewer.window import Viewer
from . import commands as ec
from .dragging import manipulate
from .drawing import draw_ui
from .file_actions import FileActions
from .gizmo import Gizmo
from .grab import Grabbing
from .handlers import EDITOR_HANDLERS
from .handles import Handle, level_handle
from .keys import Timeline, keyed_edit
from .layout import Layout, frame, shift
from .mokrs_levels import VIEW
from .mokrs_panel import KindsLeft
from .picking import pick, visible
from .saving import autosave
from .shown import Shown
from .structure import STRUCTURE_KEYS, StructureTools, baked
from .trackball import Trackball
from .words import Words

EDITOR_KEYS = {
    **VIEWER_KEYS,
    "ctrl+S": ec.Save(),
    "ctrl+shift+S": ec.AskSaveAs(),
    "K": ec.SetKey(),
    **STRUCTURE_KEYS,
}


class Editor:
    def __init__(self, path: Path, settings: ViewerSettings | None = None, **options: Any):
        """``options``: ``visible``, ``shader_dir``, or fields of ViewerSettings."""
        window = {k: options.pop(k) for k in ("visible", "shader_dir") if k in options}
        settings = make_settings(settings or EDITOR_SETTINGS, **options)
        self.viewer = Viewer(path, settings, **window)
        self.viewer.input.keymap = dict(EDITOR_KEYS)
        self.viewer.input.judged_by_frame = True  # a press on the gizmo shows in the frame
        self.overlay = Overlay(self.viewer.ctx, self.viewer.renderer.programs)
        self.gizmo = Gizmo()
        self.snap = self.gizmo.snap
        self.trackball = Trackball(self.snap)
        self.grabbing = Grabbing()  # a point handle pressed on and dragged at once
        self.layout = Layout()
        self.carry = True  # a fork drag takes its subtree along
        self.kinds_left = KindsLeft()  # a MöKRS kernel's kind changed back restores it
        self.structure = StructureTools()
        self.timeline = Timeline()
        self.selected: Handle | None = None
        self.shown_now = Shown()  # the scene drawn now, its handles, warnings, clipped parts
        self.file = FileActions(self.viewer, self.edit, self._opened)
        self.scroll_outline = False
        self._again = False  # a turn at once: a pick's gizmo
        self._held: set[str] = set()  # the view's buttons held at the last turn's end
        self._title = ""
        self.words = Words()  # the panel's last words, gone once stale (words.py)
        self.doc.memo = self._memo
        self._update_title()
        self.frame()

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
        """The scene's handles, made again when the scene changed (an edit, undo, reload)
        or the moment shown; the selection and the route's warnings follow."""
        self._follow()
        return self.shown_now.handles

    @property
    def warnings(self) -> list[tuple[int, str]]:
        """The route's warnings, each with the outline entry it names (shown.py)."""
        self._follow()
        return self.shown_now.warnings

    @property
    def clipped(self) -> list[tuple[int, np.ndarray]]:
        """What Alg. 1 clips of the route drawn (red in the view)."""
        self._follow()
        return self.shown_now.clipped

    def _follow(self) -> None:
        now, drawn = self.shown_now, self.viewer.drawn
        if now.follow(self.scene, drawn.playback.time, drawn.posed) and self.selected:
            # keep the selection across edits, undo, reload; where its handle went (a MöKRS
            # step removed), its level stays selected
            old = self.selected
            same = next((h for h in now.handles if h.same(old)), None)
            self.selected = same or level_handle(now.handles, old.level)

    def handled_scene(self) -> Scene:
        """The scene whose values the handles and panels show (shown.py's ``drawn``)."""
        self._follow()
        return self.shown_now.scene

    def edit(self, path: tuple, value, interaction=None, label=None, field=None) -> bool:
        """An edit through the document, validated by the schema; in a MöKRS the viewpoint
        the person flies must stay off every pole too, not only the file's camera
        [KRS17 §7]. A value refused for a field the panel shows keeps its message at that
        field (viewer/widgets.py), any other in the panel's error line. A value a track
        moves is keyed at the moment shown instead (keys.py), as a drag or a typed value.
        ``label`` names the undo step (the undo button's tooltip, what Ctrl+Z says); by
        default the field the person changed, set or keyed. ``field``: the (path, value) the
        person changed where ``path`` is a larger edit (a step carried to its linked
        levels): a refusal names it first and stays at it. What was said before no longer
        describes the scene once it changed: it goes."""
        v, t = self.viewer, self.viewer.drawn.playback.time
        changed = path_text(field[0] if field is not None else path)
        typed = field if field is not None else (path, value)
        path, value = keyed_edit(self.scene, path, value, t)
        keyed = path == ("animation",) and not changed.startswith("animation")
        label = label or (f"key {changed} at {t:.2f} s" if keyed else f"set {changed}")
        try:
            scene = apply_edit(self.scene, path, value)
            if scene.mokrs is not None:
                check_drawable(scene.mokrs, tuple(v.camera.position), VIEW)
        except SceneError as e:
            refusal = self._key_refusal(e, *typed) if keyed else e
            if field is not None and refusal.path != path_text(field[0]):  # where it was typed
                refusal = SceneError(path_text(field[0]), field[1], str(refusal))
            v.error = str(refusal)
        else:
            self.doc.commit(scene, label, interaction)
            v.error = v.message = ""
            v.sync()
        ok = not v.error
        if field is not None or keyed:
            path, value = typed  # a refusal stays at the field typed in, keyed or not
        if v.interactions.settle(path, value, v.error):
            v.error = ""
        return ok

    def _key_refusal(self, e: SceneError, path: tuple, value: Any) -> SceneError:
        """A key refused: said of the field typed in where the value itself breaks its
        rule ("tree.levels = 0: allowed: 1 ≤ value ≤ 63", "… = inf: NaN and infinity are
        not allowed"), not of the track's key (``animation.tracks[0].keys[0]``, which
        called an infinity no number); else the key's own reason."""
        try:
            apply_edit(self.scene, path, value)  # the value as the field's rest value
        except SceneError as own:
            if own.path == path_text(path):
                return own
        return e

    def _update_title(self) -> None:
        title = f"krsview edit — {self.doc.title}"
        if title != self._title:
            glfw.set_window_title(self.viewer.window, title)
            self._title = title

    # ------------------------------------------------------------------------ the loop
    def run(self) -> None:
        run(self)

    def is_idle(self) -> bool:
        """The viewer's idle, but never right after a pick (its gizmo is drawn next turn)."""
        return not self._again and self.viewer.is_idle()

    def close(self) -> None:
        self.viewer.close()

    def step(self, dt: float) -> None:
        """The viewer's turn with the editor's parts: the gizmo, picking by a click, the
        overlay and the panels; then the autosave. A click picks after the gizmo has seen the
        pointer where it clicked, still before the overlay is drawn (the gizmo of what it
        picked comes the turn after, at once); a press onto the gizmo, as this frame finds
        it, is the gizmo's, and the view lets go of it; a press onto a shown point handle
        that the gizmo does not claim grabs that handle (grab.py), and the view lets go of it
        too; the motion since the press waits for that finding (Input.judged), so neither
        orbits the camera by a poll's motion first."""
        v = self.viewer
        v.begin_step(dt)
        self.execute(v.input.commands())
        if self.layout.hidden == v.hud:  # F1 (or a question showing the panel again)
            self._relayout(replace(self.layout, hidden=not v.hud))
        click, flick = v.input.take_click(), v.input.take_flick()
        v.move(dt)
        self.execute(v.file.watcher.poll())
        self.words.forget_stale(v, self.structure, self.scene, self.selected, self.doc.saved)
        self._follow()
        status = v.status_line()
        ui = v.hud or bool(status)
        if ui:
            v.platform.new_frame()
        self._again = False
        if v.hud:  # the drag first, so this turn traces its edit (a turn less latency)
            manipulate(self)
            pressed = "left" in v.input.buttons - self._held and v.input.press is not None
            if not self._claimed():
                if pressed and self._grab(v.input.press):
                    v.input.let_go("left")  # the handle's press: no orbit, no click
                    self._again = True
                elif flick is not None and self._grab(flick[0]):
                    self.grabbing.fling(self, flick[1])
                    self._again = True
                elif click is not None:
                    self.pick(*click)
                    self._again = True
            elif pressed:  # pressed onto the gizmo
                v.input.let_go("left")
            held = glfw.get_mouse_button(v.window, glfw.MOUSE_BUTTON_LEFT) == glfw.PRESS
            self.grabbing.follow(self, v.input.cursor, held)
        v.input.judged()  # else the press is the view's, and so is its motion
        v.draw_image()
        self._follow()
        if ui:
            if v.hud:
                draw_ui(self, status)
            draw_status(status, v.status_is_error(status))
            v.platform.render()
        v.input.claimed = v.hud and self._dragging()
        self._held = set(v.input.buttons)
        glfw.swap_buffers(v.window)
        autosave(self.file, time.monotonic())
        self._update_title()

    def should_close(self) -> bool:
        """The question about unsaved edits answered, or the close button pressed with none
        (with some, the file part asks first)."""
        if self.file.quit:
            return True
        if glfw.window_should_close(self.viewer.window):
            glfw.set_window_should_close(self.viewer.window, False)
            return self.file.may_close()
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
    def bake(self, component: int | None = None) -> None:
        """Grown tree → route (one undo step): every fork becomes a handle; or the tree of a
        compound's ``component`` (the structure tools then act on its route); refused, said
        why, where tracks move the grown tree's parameters."""
        try:
            scene, label, said = baked(self.scene, component)
        except SceneError as e:
            self.viewer.error = f"bake: {e}"
            return
        self.doc.commit(scene, label)
        self.viewer.sync()
        self.viewer.message = said

    def select(self, h: Handle | None) -> None:
        """Select ``h``; a compound component's fork also picks its level for the tools."""
        self.selected = h
        self.timeline.field = None  # the strip shows the selection's keys
        self.scroll_outline = True
        if h is not None and self.scene.compound and "levels" in h.path:
            self.structure.level = h.path[h.path.index("levels") + 1]

    def select_level(self, level: int) -> None:
        self.select(level_handle(self.handles, level))

    def place_panel(self, side: str, width: float) -> None:
        """Dock the panel on ``side`` at ``width``; what was in the middle of the view stays
        in the middle of the part the panel leaves."""
        self._relayout(replace(self.layout, side=side, width=width))

    def fold_panel(self, folded: bool) -> None:
        """The panel folded (the view has the whole window) or unfolded: what was in the
        middle of the view stays there."""
        self._relayout(replace(self.layout, folded=folded))

    def _relayout(self, layout: Layout) -> None:
        size = glfw.get_window_size(self.viewer.window)
        if shift(self.viewer.camera, size, self.layout.free(size), layout.free(size)):
            self.viewer.frames.dirty = True
        self.layout = layout

    def reset_view(self) -> None:
        self.viewer.reset_view()
        self.frame()

    def _opened(self) -> None:
        """Another scene was opened (file_actions.py): nothing selected, the scene framed."""
        self.selected = None
        self.doc.memo = self._memo
        self.frame()

    def _memo(self) -> tuple | None:
        """What an undo step keeps of the editor: the selection (history.py)."""
        return None if self.selected is None else (self.selected.path, self.selected.kind)

    def undo(self, redo: bool = False) -> None:
        """Ctrl+Z (``redo``: Ctrl+Shift+Z): the scene of the step before (after), and the
        selection it was taken (undone) with, as Blender brings both back."""
        if not (self.viewer.redo() if redo else self.viewer.undo()):
            return
        memo, handles = self.doc.restored, self.handles
        self.select(next((h for h in handles if (h.path, h.kind) == memo), None))

    def frame(self) -> None:
        """Turn the camera so the scene camera's target sits in the middle of the part of the
        window the panel leaves."""
        v, size = self.viewer, glfw.get_window_size(self.viewer.window)
        target = np.array(self.scene.camera.target)
        frame(v.camera, target, size, self.layout.free(size), scene_ball(v.drawn.world))
        v.frames.dirty = True

    # ------------------------------------------------------------------- mouse and picking
    def window_view(self) -> View:
        w, h = glfw.get_window_size(self.viewer.window)
        return view_of(self.viewer.camera.to_camera(), max(w, 1), max(h, 1))

    def shown(self) -> list[Handle]:
        """The handles drawn and picked now (picking.visible)."""
        return visible(self.handles, self.selected)

    def pick(self, x: float, y: float) -> Handle | None:
        """Select what is under window point (x, y): a shown handle within PICK_PIXELS, else
        the level of the kernel nearest to the traced surface point there."""
        best = pick(self, self.window_view(), x, y)
        self.select(best)
        return best

    def _grab(self, press: tuple[float, float]) -> bool:
        """A left press at window point ``press`` on a shown point handle: it is selected and
        follows the pointer from now on (grab.py); on a dial handle's point, or a mirror
        normal's arrow tip, it is selected and its dial or trackball turns with the pointer
        (dial.py, trackball.py)."""
        view = self.window_view()
        h = self.grabbing.begin(self.shown(), view, press)
        if h is not None:
            self.select(h)
            if h.kind == "dial":
                self.gizmo.dial.start(h, view, *press)
            elif h.kind == "normal":
                self.trackball.start(h, *press)
        return h is not None

    def _claimed(self) -> bool:
        """The gizmo, or the trackball on a selected normal, is under the pointer or dragged:
        a press there is neither the camera's nor a pick."""
        turning = self.selected is not None and self.selected.kind == "normal"
        return self.gizmo.claims_mouse() or (turning and self.trackball.claims_mouse())

    def _dragging(self) -> bool:
        """The gizmo, the dial or the trackball is dragged: a press of another button is not
        the camera's. (Whether a press lands on one, only the frame after it can tell: the
        pointer may have moved since this frame.)"""
        return self.gizmo.dragging() or self.trackball.active or self.grabbing.now is not None
