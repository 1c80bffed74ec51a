"""Ways out of krsview, as functions: a self-contained web page, a Shadertoy shader, a
triangle mesh, the frames of a camera path and their video. The CLI's ``export``,
``render --camera-path`` and ``batch`` are users of these (the work lives in
:mod:`krsview.share`).

>>> import krsview, krsview.export, tempfile, pathlib
>>> out = pathlib.Path(tempfile.mkdtemp()) / "rock.html"
>>> notes = krsview.export.html(krsview.load("rock"), out)
>>> out.read_text().count("<canvas") >= 1
True
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from .scene import Scene
from .scene.camera_path import CameraPath, load_camera_path
from .scene.scene import write_atomic
from .share.frames import (
    DEFAULT_FPS,
    FrameJob,
    frame_file,
    parse_frames,
    render_frames,
    write_video,
)


def html(scene: Scene, path: str | Path) -> list[str]:
    """One page (no server, no network) running the scene's own specialised tracer in
    WebGL2, written atomically to ``path``; returns notes on what the web cannot carry
    (double precision, the pre-pass, the compute path)."""
    from .share.web import export_notes, html_page

    write_atomic(path, html_page(scene))
    return export_notes(scene)


def shadertoy(scene: Scene, path: str | Path) -> list[str]:
    """The same tracer as one Shadertoy ``mainImage`` (scene baked in as constants)."""
    from .share.web import export_notes, shadertoy_source

    write_atomic(path, shadertoy_source(scene))
    return export_notes(scene, shadertoy=True)


def mesh(
    scene: Scene,
    path: str | Path,
    resolution: int = 256,
    lod: float = 0.5,
    box: tuple[float, ...] | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """A triangle mesh of the surface (``.glb``, ``.ply``, ``.stl``, ``.obj`` by the suffix):
    the float64 reference sampled near the surface, marching cubes, vertices bisected onto
    it; written whole or not at all. Returns its :class:`krsview.share.mesh.MeshStats`.
    Needs ``pip install 'krsview[mesh]'``."""
    from .share.mesh import build_mesh

    out = Path(path)
    m, stats = build_mesh(scene, resolution, box, lod, progress)
    tmp = out.with_name(f".{out.name}.tmp{out.suffix}")
    try:
        m.export(tmp)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    return stats


def frames(
    scene: Scene,
    camera_path: CameraPath | str | Path,
    folder: str | Path,
    size: tuple[int, int] = (640, 360),
    fps: float = DEFAULT_FPS,
    which: str | None = None,
    done: Callable[[int], None] | None = None,
) -> list[Path]:
    """The frames of a camera path (a ``NAME.path.json`` the viewer recorded) as PNGs in
    ``folder`` (``frame_00000.png`` …), each written atomically; frames already there are
    kept, so a run resumes. ``which``: ``"A-B"`` or ``"A"`` (default all). Returns the
    frames' files in order."""
    from .api import Renderer

    path = camera_path if isinstance(camera_path, CameraPath) else load_camera_path(camera_path)
    job = FrameJob(scene, path, fps, tuple(size), Path(folder))
    wanted = parse_frames(which, job.count, "which")
    job.folder.mkdir(parents=True, exist_ok=True)
    todo = job.missing(wanted)
    if todo:
        render_frames(job, todo, Renderer(*size).gpu_shared(), done)
    return [frame_file(job.folder, k) for k in wanted]


def video(
    folder: str | Path,
    video_path: str | Path,
    fps: float = DEFAULT_FPS,
    which: range | None = None,
    done: Callable[[int], None] | None = None,
) -> Path:
    """An H.264 MP4 of the frames in ``folder`` (all, or the range ``which``), written whole
    or not at all; ``done(k)`` after each frame."""
    folder = Path(folder)
    if which is None:
        count = 0
        while frame_file(folder, count).exists():
            count += 1
        which = range(count)
    write_video(folder, which, fps, Path(video_path), done)
    return Path(video_path)
