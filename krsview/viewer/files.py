"""The files the viewer follows: the scene file (opening another, taking its new contents
when it changes on disk, a bookmark saved into it: a shipped preset's go to its copy), the
shaders (compiled again when one changes), and the camera path kept beside the scene."""

from __future__ import annotations

from pathlib import Path
from typing import Protocol

from ..document.document import Document, shipped
from ..gpu.program import ShaderError
from ..scene import Scene, SceneError
from .camera import FlyCamera
from .drawn import Drawn
from .frames import Frames
from .recording import Recorder, path_file
from .watch import FileWatcher

CAMERA_KEPT = "; the view stays where it is (R: the file's camera)"  # said on a reload


class Shows(Protocol):
    """What the file part reads and sets of the viewer."""

    doc: Document
    camera: FlyCamera
    message: str
    error: str
    frames: Frames  # the programs it draws with
    drawn: Drawn  # the geometry drawn

    hud: bool

    def say(self, text: str) -> None: ...  # a line at the window's foot for a few seconds
    def sync(self) -> None: ...  # redraw when the document changed
    def opened(self) -> None: ...  # a new document: its camera, pre-pass and moment
    def view_scene(self) -> Scene: ...  # the scene as drawn now


class ViewerFile:
    """The files the viewer follows: the document is the viewer's; the watcher and the
    camera path follow the scene file's name (a save as, a shipped preset's copy)."""

    def __init__(self, viewer: Shows, shader_dir: Path):
        self.viewer = viewer
        self.shader_dir = shader_dir
        self.refused = ""  # the error of the file's contents last refused, until it changes
        self.mine: Path | None = None  # the last scene file of the person's own shown
        self.open_text = ""  # the HUD's "open a file" field
        self.watch()

    @property
    def path(self) -> Path:
        return self.viewer.doc.path

    def watch(self) -> None:
        """A document was opened: watch its file and the shaders; its camera path beside it.
        A file of the person's own is remembered (``mine``): the HUD offers it back."""
        if not shipped(self.path):
            self.mine = self.path
        self.watcher = FileWatcher(self.path, self.shader_dir)
        self.recorder = Recorder(self.path)
        self.report()

    def report(self) -> None:
        """Show what the camera-path recorder has to say, once (at the window's foot too
        while the HUD is hidden)."""
        v, r = self.viewer, self.recorder
        if r.message:
            if not v.hud:
                v.say(r.message)
            v.message, r.message = r.message, ""
        if r.error:
            v.error, r.error = r.error, ""

    def open(self, path: Path) -> None:
        """Show another scene file from its own camera; it becomes the one watched for edits."""
        v = self.viewer
        try:
            v.doc = Document(path)
        except SceneError as e:
            v.error = str(e)
            return
        v.error = ""
        v.opened()
        self.watch()

    def follow(self) -> None:
        """The document was saved, perhaps under a new name: watch that file, and keep the
        camera path beside it."""
        self.watcher.watch(self.path)
        self.recorder.file = path_file(self.path)
        if not shipped(self.path):
            self.mine = self.path

    def reload(self) -> None:
        """The scene file changed on disk: take it. A viewer has no edits of its own to lose
        (the editor asks first when it has unsaved ones). Changed back to what was last
        read, it holds the scene shown: a refusal of the contents in between is gone."""
        v = self.viewer
        if v.doc.changed_on_disk():
            self.take()
        elif self.refused:
            if v.error == self.refused:
                v.error, v.message = "", f"{self.path.name} is as it was"
            self.refused = ""

    def take(self) -> None:
        """The file's contents become the scene (an undoable step); a bad file keeps the last
        good scene and shows why."""
        v = self.viewer
        dirty = v.doc.dirty  # changes made in the HUD: the file's contents replace them
        camera = v.doc.scene.camera
        try:
            v.doc.reload()
            kept = "; the HUD's changes before it are one Ctrl+Z back" if dirty else ""
            if v.doc.scene.camera != camera:  # the view is the person's: said, not taken
                kept += CAMERA_KEPT
            v.error, v.message, self.refused = "", f"reloaded {self.path.name}{kept}", ""
        except SceneError as e:  # keep the last good scene and image; say only this
            v.error = self.refused = str(e)
            v.message = ""
        v.sync()

    def add_bookmark(self) -> None:
        """Append the current camera to the scene file's bookmarks (Document.add_bookmark: a
        shipped preset's go to its copy, which the viewer shows and watches from then on)."""
        v = self.viewer
        try:
            name, saved = v.doc.add_bookmark(v.camera.to_camera())
        except SceneError as e:
            v.error = f"bookmark not saved: {e}"
            return
        v.sync()
        self.follow()  # our own save is not an outside edit
        v.message = f"saved bookmark {name!r} in {saved}"
        v.say(v.message)  # over what the foot said before ("no bookmarks yet …")

    def reload_shaders(self) -> None:
        """Compile the current variant from the edited files; on failure keep the old ones."""
        v = self.viewer
        try:
            v.frames.reload_programs(self.shader_dir, v.view_scene(), v.drawn.krs)
        except ShaderError as e:
            v.error = str(e)
            return
        v.error, v.message = "", "shaders reloaded"

    def toggle_recording(self) -> None:
        self.recorder.toggle()
        self.report()
