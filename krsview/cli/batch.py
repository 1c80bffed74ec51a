"""`krsview batch`: a camera path's frames rendered on a pool of Ray actors
(:func:`krsview.share.batch.run_batch`), resumable, with the files `render --camera-path`
writes."""

from __future__ import annotations

import argparse
import math
import os
import sys

from ..progress import Progress
from ..scene import SceneError
from . import options
from .render import (
    camera_path_options,
    check_video,
    drawing_options,
    frame_job,
    settled,
    write_video,
)


def add(sub) -> None:
    bt = sub.add_parser(
        "batch",
        help="render a camera path's frames on a Ray cluster",
        description="Render the frames of a camera path on a pool of Ray "
        "actors, each holding one EGL context and the compiled shader, over "
        "chunks of frames. Frames already in the -o folder are skipped, so a "
        "batch resumes where it stopped; a failed chunk is retried; the files "
        "are those `krsview render --camera-path` writes. Needs pip install "
        "'krsview[cluster]'. Example: krsview batch tree --camera-path "
        "tree.path.json -o frames/ --workers 4 --video tree.mp4",
    )
    options.preset(bt)
    camera_path_options(bt, required=True)
    bt.add_argument("-o", "--output", help="folder for the frames (default out/frames)")
    bt.add_argument("--size", type=options.size, default=(640, 360), help="default 640x360")
    bt.add_argument(
        "--workers",
        type=options.number_in("--workers", 1, 1024),
        default=2,
        help="actors, one EGL context each (default 2; a local cluster: at most one per CPU, "
        "and never more than the chunks to render)",
    )
    bt.add_argument(
        "--chunk",
        type=options.number_in("--chunk", 1, 100000),
        default=8,
        help="frames per task (default 8): larger chunks amortise scheduling",
    )
    bt.add_argument(
        "--retries",
        type=options.number_in("--retries", 0, 100),
        default=2,
        help="times a failed chunk is tried again (default 2)",
    )
    bt.add_argument(
        "--address",
        metavar="ADDRESS",
        help="an existing Ray cluster (ray://HOST:10001, or 'auto'); default: start a local one",
    )
    drawing_options(bt)
    bt.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    options.require("ray", extra="cluster", what="batch")
    from ..share.batch import check_address, run_batch

    check_address(args.address)
    cpus = os.cpu_count() or 1
    if args.address is None and args.workers > cpus:  # a local cluster: one CPU each
        raise SceneError(
            "--workers",
            args.workers,
            f"a local cluster runs one worker per CPU, and this machine has {cpus}; "
            "give --address for a larger cluster",
        )
    scene = settled(args, options.scene_of(args))  # as render draws its frames
    video = check_video(args.video, args.size)  # before frame_job makes the folder
    job, frames = frame_job(args, scene)
    job.claim("-o")  # the last check: it writes the folder's frames.json
    todo = job.missing(frames)
    workers = max(1, min(args.workers, math.ceil(len(todo) / args.chunk)))  # idle ones: none
    print(
        f"krsview: {scene.name}: frames {frames.start}-{frames.stop - 1} of {job.count}, "
        f"{job.size[0]}×{job.size[1]} → {job.folder}/ on {workers} worker(s) of "
        f"{args.address or 'a local Ray cluster'}, {args.chunk} frames per chunk",
        flush=True,
    )
    bar = Progress(max(1, len(todo)), "  frames")
    report = run_batch(
        job,
        frames,
        workers,
        args.chunk,
        args.address,
        args.retries,
        lambda k: bar.step(f"frame {k}"),
    )
    print(
        f"  {report.skipped} already there, {report.frames} rendered; start-up "
        f"{report.startup:.1f} s, then {report.seconds:.1f} s ({report.fps:.2f} frames/s)"
        + (f"; {len(report.retried)} chunk(s) retried" if report.retried else "")
    )
    if report.failed:
        lost = ", ".join(f"{c[0]}-{c[-1]}" for c in report.failed)
        print(
            f"krsview: error: chunks {lost} failed {args.retries + 1} times; run the "
            "same command again to retry only those",
            file=sys.stderr,
        )
        return 1
    if video is not None:
        write_video(job, frames, video)
    return 0
