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

from collections.abc import Callable
from pathlib import Path

from .files import write_atomic
from .inputs import output_dir, output_file, real, region, scene_of, size_of, switch, whole
from .scene import Scene, SceneError
from .scene.camera_path import CameraPath, load_camera_path
from .share.frames import (
    DEFAULT_FPS,
    FrameJob,
    frame_file,
    frames_in,
    parse_frames,
    render_frames,
    write_video,
)


def html(scene: Scene | str | Path, path: str | Path) -> list[str]:
    """One page (no server, no network) running the scene's own specialised tracer in
    WebGL2, written atomically to ``path`` (``.html``); returns notes on what the web
    cannot carry (double precision, the pre-pass, the compute path)."""
    from .share.web import export_notes, html_page

    scene, path = scene_of(scene), output_file(path, "path", (".html", ".htm"))
    write_atomic(path, html_page(scene))
    return export_notes(scene)


def shadertoy(scene: Scene | str | Path, path: str | Path) -> list[str]:
    """The same tracer as one Shadertoy ``mainImage`` (scene baked in as constants), written
    atomically to ``path`` (``.glsl``)."""
    from .share.web import export_notes, shadertoy_source

    scene, path = scene_of(scene), output_file(path, "path", (".glsl", ".txt"))
    write_atomic(path, shadertoy_source(scene))
    return export_notes(scene, shadertoy=True)


def mesh(
    scene: Scene | str | Path,
    path: str | Path,
    resolution: int = 256,
    lod: float = 0.5,
    box: tuple[float, ...] | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """A triangle mesh of the surface (``.glb``, ``.ply``, ``.stl``, ``.obj`` by the suffix):
    the float64 reference sampled near the surface, marching cubes, vertices bisected onto
    it; written whole or not at all. ``resolution``: voxels along the sampled cube's side,
    16..2048, rounded up to a power of two times the brick's side; ``lod``: mesh the level
    set this many voxels out, 0..4 (what is thinner than a voxel then stays); ``box``: the
    region (XMIN, YMIN, ZMIN, XMAX, YMAX, ZMAX), by default the scene's bounding ball (a
    ground plane has none). Returns its :class:`krsview.share.mesh.MeshStats`. Needs
    ``pip install 'krsview[mesh]'``."""
    from .share.mesh import FORMATS, build_mesh

    scene, out = scene_of(scene), output_file(path, "path", FORMATS)
    resolution = whole(resolution, "resolution", 16, 2048)
    lod = real(lod, "lod", 0.0, 4.0)
    box = None if box is None else region(box, "box")
    m, stats = build_mesh(scene, resolution, box, lod, progress)
    write_atomic(out, m.export(file_type=out.suffix[1:].lower()))
    return stats


def frames(
    scene: Scene,
    camera_path: CameraPath | str | Path,
    folder: str | Path,
    size: tuple[int, int] = (640, 360),
    fps: float = DEFAULT_FPS,
    which: str | None = None,
    done: Callable[[int], None] | None = None,
    exact: bool = False,
) -> list[Path]:
    """The frames of a camera path (a ``NAME.path.json`` the viewer recorded) as PNGs in
    ``folder`` (``frame_00000.png`` …), each written atomically; frames already there are
    kept, so a run resumes. ``which``: ``"A-B"``, ``"A"``, a frame number or a range
    (default all). Drawn as :func:`krsview.render` draws: the fast settings where the scene
    sets none, or with ``exact`` every level and no pre-pass; so they are the frames of
    `krsview render --camera-path` (and ``--exact``), and either resumes the other's folder.
    Returns the frames' files in order."""
    from .api import Renderer, exact_settings, fast_settings, on_hardware

    scene, size = scene_of(scene), size_of(size)
    exact = switch(exact, "exact")
    scene = exact_settings(scene) if exact else fast_settings(scene, on_hardware())
    path = camera_path if isinstance(camera_path, CameraPath) else load_camera_path(camera_path)
    fps = real(fps, "fps", 1.0, 240.0)
    wanted = parse_frames(which, path.frame_count(fps), "which")  # before the folder is made
    job = FrameJob(scene, path, fps, size, output_dir(folder, "folder"))
    job.claim()
    todo = job.missing(wanted)
    if todo:
        render_frames(job, todo, Renderer(*size).gpu_shared(), done)
    return [frame_file(job.folder, k) for k in wanted]


def video(
    folder: str | Path,
    video_path: str | Path,
    fps: float = DEFAULT_FPS,
    which: str | int | range | None = None,
    done: Callable[[int], None] | None = None,
) -> Path:
    """An H.264 MP4 of the frames in ``folder`` (all, or ``which``: ``"A-B"``, ``"A"``, a
    frame number or a range, as :func:`frames` takes), written whole or not at all;
    ``done(k)`` after each frame. The frames need an even width and height."""
    folder, video = Path(folder), output_file(video_path, "video_path", (".mp4",))
    fps = real(fps, "fps", 1.0, 240.0)
    count = max(frames_in(folder), 1)  # which=None: from 0 to the last (each must be there)
    which = parse_frames(which, count, "which", "the folder has frames {}")
    missing = next((k for k in which if not frame_file(folder, k).exists()), None)
    if not which or missing is not None:
        name = frame_file(folder, 0 if missing is None else missing).name
        raise SceneError("folder", str(folder), f"has no {name} (export.frames writes frames)")
    write_video(folder, which, fps, video, done)
    return video
