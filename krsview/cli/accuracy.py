"""`krsview bench accuracy`: what accuracy costs, one report folder per preset
(bench/accuracy.py measures, bench/accuracy_report.py writes); here, or as Ray tasks."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..bench.report import MIN_ACCURACY_ROUNDS
from ..inputs import output_dir
from ..scene import SceneError
from ..scene.presets import DEFAULT_PRESET, resolve
from . import options


def add_accuracy(bsub) -> None:
    ba = bsub.add_parser(
        "accuracy",
        help="what accuracy costs: every knob against time and ground truth, as a report "
        "with plots",
        description="On one view: sweep ε-scale, the iteration cap, the tracer (sphere, "
        "over-relaxed with ω, binary with ξ pairs) and the level count; time each setting "
        "on the GPU (interleaved rounds: the fastest round, which a busy machine disturbs "
        "least, with the median and slowest beside it; settings doing the same work "
        "share one time, and their spread is the run's noise floor, under which a "
        "difference is 'within noise'), count its work (kernels evaluated per pixel, "
        "deterministic) and compare its image with the ground "
        "truth (the float64 reference at ε/8, computed once and cached): holes, false "
        "hits, depth error in ε, normal error, PSNR, SSIM, iterations, capped rays. Writes "
        "OUT/README.md, OUT/accuracy.csv, plots (error against time and against work per "
        "knob, the Pareto fronts) and error images. "
        "Example: krsview bench accuracy tree rock --out out/accuracy",
    )
    ba.add_argument(
        "preset",
        nargs="*",
        metavar="PRESET",
        help="one or more presets (default tree); several write OUT/PRESET each",
    )
    ba.add_argument("--size", type=options.size, default=(320, 180), help="default 320x180")
    ba.add_argument(
        "--workers",
        type=options.number_in("--workers", 1, 1024),
        default=1,
        help="run the presets as tasks on this many Ray workers (default 1: "
        "here, one after the other); needs 'krsview[cluster]'",
    )
    ba.add_argument(
        "--address",
        metavar="ADDRESS",
        help="run them on an existing Ray cluster (ray://HOST:10001 or 'auto')",
    )
    ba.add_argument(
        "--rounds",
        type=options.number_in("--rounds", MIN_ACCURACY_ROUNDS, 100),
        default=5,
        help=f"interleaved rounds, {MIN_ACCURACY_ROUNDS}..100; the fastest round with the "
        "median and slowest, and the run's noise floor, are reported (default 5; fewer rounds "
        "give no spread to draw a verdict on)",
    )
    ba.add_argument(
        "--out",
        metavar="DIR",
        help="report folder (default out/accuracy/PRESET; with several presets, DIR/PRESET)",
    )
    ba.add_argument(
        "--cache", metavar="DIR", help="ground-truth cache (default ~/.cache/krsview/truth)"
    )
    ba.set_defaults(func=run_accuracy)


def report_folder(out: str | None, name: str, several: bool) -> Path:
    """Where a preset's accuracy report goes: --out, --out/PRESET, or out/accuracy/PRESET."""
    if out is None:
        return Path("out") / "accuracy" / resolve(name).stem
    return Path(out) / resolve(name).stem if several else Path(out)


def run_accuracy(args: argparse.Namespace) -> int:
    from ..bench.accuracy import bench_accuracy
    from ..bench.accuracy_report import write_report
    from ..bench.truth import TRUTH_EPSILON_SCALE, TRUTH_ITERATIONS

    names = args.preset or [DEFAULT_PRESET]
    scenes = {n: options.scene_of(args, n) for n in names}
    if len(set(names)) != len(names):
        raise SceneError("PRESET", " ".join(names), "each preset once")
    outs = {n: report_folder(args.out, n, len(names) > 1) for n in names}
    for out in outs.values():
        output_dir(out, "--out")
    cache = output_dir(args.cache, "--cache") if args.cache else None  # writable, up front
    if args.workers > 1 or args.address is not None:
        return run_accuracy_on_ray(args, scenes, outs, cache)
    for n in names:  # here, one after the other
        print(
            f"ground truth: float64 reference, ε-scale {TRUTH_EPSILON_SCALE}, cap "
            f"{TRUTH_ITERATIONS} (cached) …",
            flush=True,
        )
        print(write_report(bench_accuracy(scenes[n], args.size, args.rounds, cache), outs[n]))
        print(f"wrote {outs[n].resolve()}/ (README.md, accuracy.csv, plots, error images)")
    return 0


def run_accuracy_on_ray(args: argparse.Namespace, scenes: dict, outs: dict, cache) -> int:
    """The presets' reports as Ray tasks, each printed as its task ends."""
    options.require("ray", extra="cluster", what="bench accuracy --workers/--address")
    from ..share.batch import check_address, run_accuracy_sweep

    check_address(args.address)
    print(
        f"krsview: accuracy of {len(scenes)} preset(s) on {args.workers} Ray worker(s) of "
        f"{args.address or 'a local cluster'}; each report when its task ends",
        flush=True,
    )

    def done(name: str, lines: list[str] | None, error: str) -> None:
        if lines is None:
            print(f"krsview: error: {name}: {error}", file=sys.stderr)
            return
        print(f"{name}: wrote {outs[name].resolve()}/")
        for line in lines:
            print(f"  {line}")

    failed = run_accuracy_sweep(
        scenes, args.size, args.rounds, outs, args.workers, args.address, done, cache
    )
    return 1 if failed else 0
