"""`krsview render`: one frame headless to PNG (and its arrays), or a camera path's frames and
their video, through :class:`krsview.Renderer` and :mod:`krsview.export`."""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from .. import api, export
from ..frame import Frame
from ..inputs import output_dir, output_file
from ..progress import Progress
from ..scene import Scene, SceneError
from ..scene.presets import resolve
from ..scene.render import (
    DEFAULT_LOD,
    DEFAULT_SHADOW_BLOCK,
    HARDWARE_PREPASS,
    LANES_LEVELS,
    VIEW_PREPASS,
)
from ..share.frames import DEFAULT_FPS
from . import options
from .options import SILENT_SECONDS, render_option

REPEATS = 5  # frames timed by default
KNOBS = (
    "tracer",
    "relaxation",
    "precision",
    "culling",
    "lod",
    "walk_restart",
    "shadow_block",
    "shadow_cone",
    "prepass",
    "prepass_levels",
    "path",
    "steps",
    "shadow_tasks",
    "component_tasks",
)  # the [render] fields `render` overrides, beside the scene options


def add(sub) -> None:
    r = sub.add_parser(
        "render",
        help="render a scene headless to PNG (and raw buffers)",
        description="Render PRESET headless through EGL and write a PNG; prints the measured "
        "frame time. Draws with the viewer's fast settings (the pre-pass, the level of "
        f"detail; persistent lanes for a single KRS of {LANES_LEVELS} levels or more; on a "
        f"GPU, not a CPU rasteriser, the compute path's rounds from pre-pass tiles of "
        f"{HARDWARE_PREPASS}) unless the scene or an option sets them; --exact draws every "
        "level without the pre-pass. "
        "Example: krsview render tree -o tree.png --size 640x360 --prepass 8",
    )
    options.preset(r)
    r.add_argument(
        "-o",
        "--output",
        help="PNG file to write, ending in .png (default out/render.png); with "
        "--camera-path, the folder for the frames (default out/frames)",
    )
    r.add_argument(
        "--size", type=options.size, default=(640, 360), help="WIDTHxHEIGHT (default 640x360)"
    )
    r.add_argument(
        "--buffers",
        metavar="NPZ",
        help="also write color, depth, normal, iterations and hit arrays to this "
        "NumPy file, ending in .npz",
    )
    r.add_argument(
        "--reference",
        action="store_true",
        help="render with the float64 NumPy reference instead of the GPU (slow)",
    )
    r.add_argument(
        "--repeats",
        type=options.number_in("--repeats", 1, 1000),
        help=f"frames timed; the median is printed (default {REPEATS})",
    )
    r.add_argument(
        "--view",
        choices=("shaded", "iterations"),
        default="shaded",
        help="shaded image, or the per-pixel iteration count as a heat map with a "
        "legend (black = 0, white = the maximum) [KRS17 Fig. 13]: the full pass's steps, "
        "after the pre-pass's cones (per tile, not counted) moved each ray's start; "
        "--exact counts every step from the eye; the legend adds rows below the image",
    )
    r.add_argument(
        "--legend-max",
        type=options.number_in("--legend-max", 1, 100000),
        metavar="N",
        help="iterations shown as white in --view iterations (default: the image's "
        "maximum); fix it to compare tracers on one scale",
    )
    drawing_options(r)
    cp = r.add_argument_group(
        "camera paths",
        "Render the frames of a path recorded in the viewer (F5; saved as "
        "NAME.path.json beside the preset) to frame_00000.png, … in the -o folder. Frames "
        "already there are skipped, so an interrupted run resumes where it stopped.",
    )
    camera_path_options(cp, required=False)
    r.set_defaults(func=run)


def drawing_options(sp) -> None:
    """How a frame is drawn, the same for `render` and `batch` (whose frames are those
    `render --camera-path` writes): --exact, the [render] knobs and the scene options."""
    sp.add_argument(
        "--exact",
        action="store_true",
        help="every level, no pre-pass and a shadow ray per pixel: the image the float64 "
        "reference matches, for tests (default: the viewer's fast settings where the scene "
        f"sets none: the pre-pass at {VIEW_PREPASS} pixels and the level of detail lod = "
        f"{DEFAULT_LOD:g}, both certified hole-free, and soft shadows shared by "
        f"{DEFAULT_SHADOW_BLOCK}×{DEFAULT_SHADOW_BLOCK} pixels)",
    )
    for name in KNOBS:
        render_option(sp, name)
    options.scene_options(sp)


def camera_path_options(sp, required: bool) -> None:
    """--camera-path, --frames, --fps and --video (`render` and `batch`)."""
    sp.add_argument(
        "--camera-path",
        required=required,
        metavar="FILE",
        help="a NAME.path.json camera path (recorded in the viewer with F5)",
    )
    sp.add_argument(
        "--frames", metavar="A-B", help="only frames A to B, inclusive (default: all the path's)"
    )
    sp.add_argument(
        "--fps",
        type=options.number_in("--fps", 1.0, 240.0, float),
        help=f"frames per second of path time (default {DEFAULT_FPS:g})",
    )
    sp.add_argument(
        "--video",
        metavar="MP4",
        help="also write the frames as an H.264 "
        "video, ending in .mp4 (needs an even width and height)",
    )


def run(args: argparse.Namespace) -> int:
    scene = settled(args, options.scene_of(args))
    refuse_unused(args, scene)
    if args.camera_path is not None:
        return render_camera_path(args, scene)
    out = output_file("out/render.png" if args.output is None else args.output, "-o", (".png",))
    if args.buffers:
        output_file(args.buffers, "--buffers", (".npz",))
    info = api.check(scene)
    print(
        f"krsview: {scene.name}: {info.levels} levels, {info.instances:,} kernel "
        f"instances, {args.size[0]}×{args.size[1]}, "
        f"{'NumPy reference' if args.reference else 'GPU'}",
        flush=True,
    )
    if args.reference:
        frame = reference_frame(scene, args.size)
    else:
        frame = timed_frame(scene, args.size, args.repeats or REPEATS, args.exact)
    if args.view == "iterations":
        from ..heatmap import save_heatmap

        it = frame.iterations
        vmax = save_heatmap(
            it, out, args.legend_max, f"{scene.render.tracer} tracing: iterations per pixel"
        )
        print(
            f"  iterations per pixel: median {np.median(it):.0f}, mean {it.mean():.1f}, "
            f"max {it.max()} (colour scale 0..{vmax})"
        )
    else:
        frame.save(out)
    print(f"  wrote {out.resolve()}")
    if args.buffers:
        frame.save(args.buffers)
        print(f"  wrote {Path(args.buffers).resolve()} (color, depth, normal, iterations, hit)")
    return 0


GPU_ONLY = (  # the GPU's settings, which the float64 reference never reads
    "repeats",
    "path",
    "steps",
    "shadow_tasks",
    "component_tasks",
    "precision",
    "culling",
    "prepass",
    "prepass_levels",
    "shadow_block",
)


def refuse_unused(args: argparse.Namespace, scene: Scene) -> None:
    """Before any work: an option that this run would ignore is refused, naming what it
    needs (a person who gives one believes it took effect)."""

    def refuse(name: str, why: str) -> None:
        raise SceneError("--" + name.replace("_", "-"), getattr(args, name), why)

    if args.camera_path is not None:
        shaded = {"buffers": args.buffers, "reference": args.reference}
        shaded |= {"view": args.view != "shaded", "legend_max": args.legend_max is not None}
        for name, given in shaded.items():
            if given:
                refuse(name, "cannot be combined with --camera-path (it writes shaded frames)")
        if args.repeats is not None:
            refuse("repeats", "cannot be combined with --camera-path (it times no frame)")
    for name in ("frames", "video", "fps"):
        if args.camera_path is None and getattr(args, name) is not None:
            refuse(name, "needs --camera-path FILE")
    if args.legend_max is not None and args.view != "iterations":
        refuse("legend_max", "needs --view iterations (it sets the heat map's white)")
    for name in GPU_ONLY if args.reference else ():
        if getattr(args, name) is not None:
            refuse(name, "has no effect with --reference (a setting of the GPU's)")
    if scene.render.path != "compute" and not args.reference:
        for name in ("steps", "shadow_tasks", "component_tasks"):
            if getattr(args, name) is not None:
                refuse(name, "applies to --path compute (this run traces by the fragment path)")


def settled(args: argparse.Namespace, scene: Scene) -> Scene:
    """The viewer's fast settings where neither the file nor an option sets them, or with
    --exact every level and no pre-pass (the reference's image)."""
    if args.exact:
        for knob in ("prepass", "lod", "shadow_block", "shadow_cone", "walk_restart"):
            if getattr(args, knob) is not None:
                flag = "--" + knob.replace("_", "-")
                raise SceneError(flag, getattr(args, knob), "cannot be combined with --exact")
        return api.exact_settings(scene)
    return options.fast_scene_of(args, scene)


def reference_frame(scene: Scene, size: tuple[int, int]) -> Frame:
    """The float64 reference's frame, its time printed."""
    t0 = time.perf_counter()
    frame = api.Renderer(*size).render(
        scene,
        reference=True,
        prepass=scene.render.prepass,  # as run() settled it
        progress=Progress(1, "  rays", SILENT_SECONDS),
    )
    print(f"  traced in {(time.perf_counter() - t0) * 1e3:.0f} ms (float64 reference)")
    return frame


def timed_frame(scene: Scene, size: tuple[int, int], repeats: int, exact: bool) -> Frame:
    """The GPU's frame, and the median of ``repeats`` more frames' times, printed (``exact``:
    as run() settled it, without the fast settings' persistent lanes)."""
    r = api.Renderer(*size)
    t0 = time.perf_counter()
    print("  compiling shader variant …", flush=True)
    frame = r.render(
        scene,
        exact=exact,
        prepass=scene.render.prepass,  # as run() settled it
        progress=Progress(1, "  first frame, rows", SILENT_SECONDS),
    )
    print(f"  first frame {(time.perf_counter() - t0) * 1e3:.0f} ms (with compiling)", flush=True)
    bar = Progress(repeats, "  timing frames", SILENT_SECONDS)
    times = []
    for _ in range(repeats):
        times += r.time(scene, repeats=1, exact=exact, prepass=scene.render.prepass)
        bar.step()
    print(
        f"  frame time {sorted(times)[len(times) // 2] * 1e3:.1f} ms (median of {repeats}), "
        f"{frame.iterations.mean():.1f} iterations/pixel, "
        f"{frame.hit.mean() * 100:.0f}% of pixels hit"
    )
    return frame


def frame_job(args: argparse.Namespace, scene: Scene):
    """The frames ``--camera-path``, ``--frames``, ``--fps``, ``--size`` and ``-o`` ask for,
    checked before any frame is drawn: the job and the range of frames."""
    from ..scene.camera_path import load_camera_path
    from ..share.frames import FrameJob, parse_frames

    path = load_camera_path(args.camera_path)
    given = "out/frames" if args.output is None else args.output
    if Path(given).suffix.lower() == ".png":
        raise SceneError("-o", given, "with --camera-path, give a folder for the frames")
    fps = DEFAULT_FPS if args.fps is None else args.fps
    frames = parse_frames(args.frames, path.frame_count(fps))  # before the folder is made
    job = FrameJob(scene, path, fps, args.size, Path(given))
    if scene.animation is not None and scene.animation.tracks:  # a track between its keys
        bar = Progress(len(frames), "  posing the frames", SILENT_SECONDS)
        try:
            for k in frames:
                job.frame_scene(k).posed()
                bar.step()
        except SceneError as e:
            raise e.in_file(str(resolve(args.preset))) if e.file is None else e from None
    return replace(job, folder=output_dir(given, "-o")), frames


def check_video(text: str | None, size: tuple[int, int]) -> Path | None:
    """``--video``: an .mp4 that can be written, of a size H.264 4:2:0 takes."""
    if text is None:
        return None
    video = output_file(text, "--video", (".mp4",))
    if size[0] % 2 or size[1] % 2:
        raise SceneError(
            "--size",
            f"{size[0]}x{size[1]}",
            "--video needs an even width and height (H.264, 4:2:0 colour)",
        )
    return video


def write_video(job, frames: range, video: Path) -> None:
    """The frames as an MP4, with a progress bar."""
    bar = Progress(len(frames), "  video")
    export.video(job.folder, video, job.fps, frames, lambda k: bar.step())
    print(f"  wrote {video.resolve()}")


def render_camera_path(args: argparse.Namespace, scene: Scene) -> int:
    video = check_video(args.video, args.size)  # before frame_job makes the folder
    job, frames = frame_job(args, scene)
    job.claim("-o")  # the last check: it writes the folder's frames.json
    todo = job.missing(frames)
    print(
        f"krsview: {scene.name}: frames {frames.start}-{frames.stop - 1} of "
        f"{job.count} ({job.path.duration:.2f} s at {job.fps:g} fps), "
        f"{job.size[0]}×{job.size[1]} → {job.folder}/; "
        f"{len(frames) - len(todo)} already there, {len(todo)} to render",
        flush=True,
    )
    if todo:
        bar = Progress(len(todo), "  frames")
        export.frames(
            scene,
            job.path,
            job.folder,
            job.size,
            job.fps,
            args.frames,
            lambda k: bar.step(f"frame {k}"),
            exact=args.exact,
        )
    if video is not None:
        write_video(job, frames, video)
    return 0
