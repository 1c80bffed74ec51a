"""Frames of a camera path, and a video of them: what ``krsview render --camera-path`` and
each worker of ``krsview batch`` do. Frame k is ``frame_00042.png`` in the output folder,
written atomically, so a folder holds only whole frames; a run skips the frames already
there, which makes an interrupted run resumable and lets chunks be rendered anywhere. The
scene's time advances with the frames, so a moving scene plays along with the flight."""

from __future__ import annotations

import hashlib
import io
import json
import os
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from PIL import Image

from ..files import write_atomic
from ..scene import Render, Scene, SceneError
from ..scene.camera_path import CameraPath, camera_path_json
from ..scene.scene import scene_to_toml
from ..scene.schema import to_dict

DEFAULT_FPS = 30.0
MANIFEST = "frames.json"  # in the frames' folder: what made them (FrameJob.claim)


def settings_apart(theirs: object, mine: dict) -> str:
    """The render settings two runs differ in, as "lod: 0.5 there, 0.0 here; prepass: …",
    the first three of them."""
    theirs = theirs if isinstance(theirs, dict) else {}
    keys = [k for k in {**theirs, **mine} if theirs.get(k) != mine.get(k)]
    said = [f"{k}: {theirs.get(k, 'unset')} there, {mine.get(k, 'unset')} here" for k in keys]
    more = f"; and {len(said) - 3} more" if len(said) > 3 else ""
    return "; ".join(said[:3]) + more


def frame_file(folder: Path, k: int) -> Path:
    return Path(folder) / f"frame_{k:05d}.png"


def frames_in(folder: Path) -> int:
    """One more than the highest frame number in ``folder`` (0: none there)."""
    numbers = [f.stem[6:] for f in Path(folder).glob("frame_*.png")]
    return max((int(n) + 1 for n in numbers if n.isdigit()), default=0)


@dataclass(frozen=True)
class FrameJob:
    """Everything a renderer needs for frames of one path: plain data, so it can be sent
    to another process or machine (``krsview batch``)."""

    scene: Scene
    path: CameraPath
    fps: float
    size: tuple[int, int]
    folder: Path

    @property
    def count(self) -> int:
        return self.path.frame_count(self.fps)

    def frame_scene(self, k: int) -> Scene:
        """Frame k: the path's camera k / fps seconds in, and the scene's time as far past
        its own (``--time``)."""
        camera = self.path.camera(k, self.fps, self.scene.camera)
        return replace(self.scene, camera=camera).at(self.scene.time + k / self.fps)

    def missing(self, frames: range) -> list[int]:
        """Frames of ``frames`` without a whole frame file yet (what a resumed run still
        renders): none, or one cut short or damaged since (krsview writes whole ones)."""
        return [k for k in frames if not whole_frame(frame_file(self.folder, k), self.size)]

    def made_by(self) -> dict:
        """What makes this run's frames (the folder's MANIFEST): the scene, the camera
        path (digests of their files' text), the frame rate and the size."""
        poses = camera_path_json(list(self.path.poses))
        drawn = scene_to_toml(replace(self.scene, render=Render()))
        return {
            "scene": hashlib.sha256(drawn.encode()).hexdigest()[:16],
            "render": to_dict(self.scene.render),  # itself: a run says which setting differs
            "camera_path": hashlib.sha256(poses.encode()).hexdigest()[:16],
            "fps": self.fps,
            "size": list(self.size),
        }

    def claim(self, what: str = "folder") -> None:
        """Before any frame is drawn: the folder holds no frame of another run, which a
        resumed run would otherwise keep beside its own (another size breaks the video,
        another scene or path shows in it). Its MANIFEST says what made its frames; one
        without (made before krsview wrote it) is taken where its frames have this size.
        Then the MANIFEST says this run's. SceneError names ``what`` and what differs."""
        mine, file = self.made_by(), self.folder / MANIFEST
        if file.exists():
            try:
                theirs = json.loads(file.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                theirs = {}
            differ = [k for k in mine if not isinstance(theirs, dict) or theirs.get(k) != mine[k]]
            if differ == ["render"] and self._frames_there():
                raise SceneError(
                    what,
                    str(self.folder),
                    "holds this run's frames drawn with other render settings "
                    f"({settings_apart(theirs.get('render'), mine['render'])}); resume it with the "
                    "options it was started with (--exact or not), give another folder, or "
                    "empty this one",
                )
            if differ and self._frames_there():
                names = [n.replace("_", " ") for n in differ]
                raise SceneError(
                    what,
                    str(self.folder),
                    f"holds frames of another run (its {' and '.join(names)} "
                    f"{'differ' if len(differ) > 1 else 'differs'}); give "
                    "another folder, or empty this one",
                )
        else:
            for f in self._frames_there():
                if frame_size(f) != self.size:
                    w, h = frame_size(f)
                    held = f"{f.name} of {w}×{h}, not" if w else f"{f.name}, not a PNG image of"
                    raise SceneError(
                        what,
                        str(self.folder),
                        f"holds {held} {self.size[0]}×{self.size[1]}; give another folder, or "
                        "empty this one",
                    )
        write_atomic(file, json.dumps(mine, indent=1) + "\n")

    def _frames_there(self) -> list[Path]:
        """The folder's files of this path's frames (listed once: a long path's frame count
        can be far larger than what the folder holds)."""
        there = (frame_file(self.folder, k) for k in range(min(self.count, frames_in(self.folder))))
        return [f for f in there if f.exists()]


PNG_START = b"\x89PNG\r\n\x1a\n"  # a PNG's signature, and its last chunk (IEND, empty)
PNG_END = b"\x00\x00\x00\x00IEND\xaeB`\x82"


def whole_frame(f: Path, size: tuple[int, int]) -> bool:
    """Whether ``f`` is a whole PNG of ``size``: its signature, its closing chunk and its
    header's size, read without decoding (a resumed run of thousands of frames checks each)."""
    try:
        with f.open("rb") as file:
            start = file.read(len(PNG_START))
            file.seek(-len(PNG_END), os.SEEK_END)
            end = file.read()
    except OSError:  # none, or shorter than the closing chunk
        return False
    return start == PNG_START and end == PNG_END and frame_size(f) == tuple(size)


def frame_size(f: Path) -> tuple[int, int]:
    """A frame file's (width, height), read from its header (None-sized if unreadable)."""
    try:
        with Image.open(f) as im:
            return im.size
    except OSError:
        return (0, 0)


def parse_frames(
    text: str | int | range | None,
    count: int,
    flag: str = "--frames",
    has: str = "the path has frames {} at this frame rate",
) -> range:
    """``"A-B"`` (inclusive), ``"A"``, a frame number, a ``range`` or None (all) → a range
    within 0 … count−1 (``has``: what holds them, said where one is out of range)."""
    if text is None:
        return range(count)
    if isinstance(text, range) and text.step == 1 and len(text):
        lo, hi = text.start, text.stop - 1
    elif isinstance(text, int) and not isinstance(text, bool):
        lo = hi = text
    elif isinstance(text, str):
        try:
            a, dash, b = text.partition("-")
            lo, hi = int(a), int(b if dash else a)  # "3-" is no range: int("") refuses it
        except ValueError:
            raise SceneError(
                flag, text, "expected FIRST-LAST or one frame number, e.g. 0-119"
            ) from None
    else:
        raise SceneError(
            flag,
            text,
            "expected 'FIRST-LAST' or one frame number, e.g. '0-119', 7 or range(0, 120)",
        )
    if not 0 <= lo <= hi < count:
        raise SceneError(
            flag,
            text,
            has.format(f"0-{count - 1}") + "; allowed 0 ≤ FIRST ≤ LAST ≤ " + str(count - 1),
        )
    return range(lo, hi + 1)


def render_frames(
    job: FrameJob, frames: list[int], renderer, done: Callable[[int], None] | None = None
) -> None:
    """Render ``frames`` of ``job`` with ``renderer`` (a gpu Renderer) into its folder;
    ``done(k)`` after each."""
    for k in frames:
        write_frame(job.folder, k, frame_png(job, k, renderer))
        if done is not None:
            done(k)


def frame_png(job: FrameJob, k: int, renderer) -> bytes:
    """Frame k as PNG bytes: what a batch worker sends back (no shared disk needed)."""
    w, h = job.size
    buffers = renderer.render(job.frame_scene(k), w, h)
    out = io.BytesIO()
    Image.fromarray(buffers.rgb8(), "RGB").save(out, format="png")
    return out.getvalue()


def write_frame(folder: Path, k: int, png: bytes) -> None:
    """Frame k, written atomically: the folder only ever holds whole frames."""
    write_atomic(frame_file(folder, k), png)


def write_video(
    folder: Path, frames: range, fps: float, video: Path, done: Callable[[int], None] | None = None
) -> None:
    """An H.264 MP4 of the frames' PNGs (imageio-ffmpeg ships its own ffmpeg), written to a
    temporary file first so a failed run leaves no half video."""
    import imageio.v3 as iio
    import imageio_ffmpeg

    w, h = frame_size(frame_file(folder, frames[0]))
    if w % 2 or h % 2:  # ffmpeg refuses, and writes an empty file
        raise SceneError(
            "folder",
            str(folder),
            f"its frames are {w}×{h}: a video needs an even width and height (H.264, 4:2:0 colour)",
        )
    for k in frames:  # before any is encoded: ffmpeg would write a broken video
        if frame_size(frame_file(folder, k)) != (w, h):
            a, b = frame_size(frame_file(folder, k))
            raise SceneError(
                "folder", str(folder), f"frame_{k:05d}.png is {a}×{b}, frame 0 of the video {w}×{h}"
            )
    video = Path(os.path.realpath(video))  # a link stays a link: the file it names is written
    tmp = video.with_name(f".{video.name}.tmp{video.suffix}")
    writer = imageio_ffmpeg.write_frames(
        str(tmp),
        (w, h),
        fps=fps,
        codec="libx264",
        pix_fmt_out="yuv420p",
        macro_block_size=1,
        quality=8,
    )
    writer.send(None)
    try:
        for k in frames:
            writer.send(iio.imread(frame_file(folder, k))[..., :3].copy(order="C"))
            if done is not None:
                done(k)
        writer.close()
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise RuntimeError(f"ffmpeg wrote nothing for {video} (its messages are above)")
        os.replace(tmp, video)
    finally:
        writer.close()
        tmp.unlink(missing_ok=True)
