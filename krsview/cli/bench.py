"""`krsview bench NAME`: one table of benchmarks, each a function of :mod:`krsview.bench`
returning its rows and a ``table`` making them Markdown; this module only parses, calls and
prints (and writes ``--csv``). `bench accuracy` writes a report folder per preset."""

from __future__ import annotations

import argparse
import importlib
import sys
from dataclasses import dataclass, field
from pathlib import Path

from .. import app
from ..bench.expansion import TOLERANCE
from ..bench.report import MIN_ACCURACY_ROUNDS, markdown, write_csv
from ..inputs import output_dir, output_file
from ..scene import MAX_LEVELS, SceneError
from ..scene.presets import DEFAULT_PRESET, resolve
from ..scene.render import VIEW_PREPASS
from . import options
from .options import render_option


@dataclass(frozen=True)
class Bench:
    """A bench of ``krsview.bench.NAME``: ``bench_NAME(scene, size, rounds=, **own)`` →
    :class:`krsview.bench.report.Measured`, printed by its ``table``."""

    help: str
    description: str
    knobs: tuple[str, ...] = ()  # [render] fields it takes as options
    scene_options: bool = False  # --epsilon-scale, --max-iterations, --levels, --effects
    own: tuple[tuple[str, dict], ...] = field(default=())  # its own options: flag, argparse
    needs: tuple[str, str] | None = None  # (module, extra) of an optional library it runs on
    fast: bool = False  # draws with `render`'s fast settings where no file or option sets them


def level_list(text: str) -> tuple[int, ...]:
    """``--levels 16,18`` → (16, 18), each a level count in 1..MAX_LEVELS."""
    parse = options.number_in("--levels", 1, MAX_LEVELS)
    return tuple(parse(item) for item in text.split(","))


BENCHES = {
    "levels": Bench(
        "frame time against level count (O(n) vs 2^n)",
        "Render the same view with the coarsest 4, 8, … levels, interleaved rounds, and "
        "every level (lod 0) beside; print the time per frame (fastest round [median–slowest]), "
        "its ratio "
        "to the smallest level count and to the row before (each with the [min–max] of its "
        "round-by-round ratio, 'within noise' where that holds 1×) beside the kernel "
        "instances. Example: krsview bench levels tree --step 4",
        knobs=("epsilon_scale", "max_iterations", "lod", "prepass", "walk_restart"),
        own=(
            (
                "--step",
                dict(
                    type=options.number_in("--step", 1, MAX_LEVELS),
                    default=4,
                    help="level increment (default 4)",
                ),
            ),
        ),
    ),
    "paths": Bench(
        "what culling, the pre-pass and the compute path buy",
        "Exact level culling off/on × the low-resolution pre-pass off and at tiles 4, 8, 16 "
        "(tiles 4 and 8 also with one coarse pass) on the fragment path, and the compute "
        "path at 4, 8, 16, 32 iterations per round, at --size and twice it, interleaved: "
        "frame time and speed-up against the plain frame, iterations per pixel, the coarse "
        "pass's share. Example: krsview bench paths forest --size 160x90 --csv paths.csv",
        knobs=("tracer",),
    ),
    "split": Bench(
        "where a frame's time goes: coarse passes, tracing, shading, shadow rays",
        "On one scene and view, the fragment path: the frame, the frame without secondary "
        "effects (shadow rays, occlusion), the "
        "tracing alone and the coarse passes alone, interleaved; each part of the frame is "
        "the difference of two of them. Where pixel blocks share shadow rays (the "
        "still frame's [render] shadow_block), the frame with a shadow ray per pixel beside "
        "it. Where the scene's shadow rays meet its components through the shadow cone "
        "([render] shadow_cone), the frame without it beside it; the frames' rows carry the "
        "shadow rays' steps and levels per pixel (a counting variant, which no machine load "
        "changes). Example: krsview bench split tree "
        f"--prepass {VIEW_PREPASS} (the viewer's pre-pass).",
        knobs=("culling", "lod", "prepass", "prepass_levels", "shadow_block", "shadow_cone"),
    ),
    "tracers": Bench(
        "sphere vs binary sphere tracing, and a ξ sweep",
        "On one scene and view: sphere tracing, binary tracing at the paper's "
        "ξ_bonus/ξ_penalty = 2.0/0.3, and a sweep over ξ_bonus ∈ {1.5, 2, 3} × ξ_penalty ∈ "
        "{0.2, 0.3, 0.5}; iterations per pixel, frame time (fastest round [median–slowest] "
        "of interleaved rounds) and hit agreement, as ratios to sphere tracing (to binary "
        "2.0/0.3 for a MöKRS), time ratios with their round-by-round [min–max]. Example: "
        "krsview bench tracers palm --epsilon-scale 0.5",
        scene_options=True,
        own=(
            (
                "--no-sweep",
                dict(dest="sweep", action="store_false", help="only sphere vs binary 2.0/0.3"),
            ),
        ),
    ),
    "effects": Bench(
        "cost of each effect; specialised vs all compiled",
        "On one scene and view: the plain render (no effect), each effect alone, and the "
        "scene's effect set both specialised (#define) and in the variant that compiles "
        "every effect and switches them by uniforms; frame times as ratios to the plain "
        "render. An idle twist (0°) or an empty zone list gets a stand-in so its cost "
        "shows. A KRS is also drawn as a compound of one; a compound against its "
        "components drawn alone, and their sum. Example: krsview bench effects grove",
        scene_options=True,
    ),
    "zoom": Bench(
        "a flight into the finest twig: frame time and work at each stop",
        "From the scene's eye straight into its finest kernel (the tip of a tree's twig, "
        "20 and more levels down), at distances shrinking geometrically: frame time "
        "(interleaved rounds), iterations per pixel and levels walked per iteration at each "
        "stop, and the slowest frame against the fastest with the [min–max] of its "
        "round-by-round ratio. It draws with `render`'s fast "
        "settings where the scene and the options set none. Example: krsview bench zoom "
        "tree --stops 12 --plot out/zoom.png",
        knobs=("prepass", "culling", "lod", "walk_restart", "path", "steps"),
        fast=True,
        own=(
            (
                "--stops",
                dict(
                    dest="stops_count",
                    type=options.number_in("--stops", 2, 100),
                    default=12,
                    help="cameras along the flight (default 12)",
                ),
            ),
            (
                "--plot",
                dict(
                    metavar="PATH",
                    help="also draw time and work along the flight into this PNG",
                ),
            ),
        ),
    ),
    "peer": Bench(
        "krsview against an Embree BVH over the expanded, tessellated tree (same rays)",
        "The obvious CPU alternative [issue 27 §3]: the KRS expanded into all its kernel "
        "instances, each tessellated within --tolerance pixels of its surface, in an Embree BVH "
        "(Open3D's RaycastingScene, on every core), cast with krsview's own primary rays. "
        "Per level count: ms per frame of the peer and of krsview (exact, the level of "
        f"detail, the pre-pass {VIEW_PREPASS}, and both: render's default; effects off) in "
        "interleaved rounds (fastest round [median–slowest]), their ratio (fastest to "
        "fastest, with its round-by-round [min–max]), the BVH's build, the first frame and "
        "peak memory of each in a fresh process, and where the hit masks differ. Needs "
        "'krsview[peer]'. Example: krsview bench peer tree --levels 16,18 --csv out/peer.csv",
        own=(
            (
                "--levels",
                dict(
                    dest="level_counts",
                    metavar="N[,N…]",
                    type=level_list,
                    default=(16,),
                    help="level counts to expand, comma-separated (default 16; each level "
                    "doubles the peer's mesh)",
                ),
            ),
            (
                "--tolerance",
                dict(
                    type=options.number_in("--tolerance", 0.01, 8.0, float),
                    metavar="PIXELS",
                    default=TOLERANCE,
                    help="pixels the peer's mesh may lie from the surface, at the nearest "
                    f"instance of each level (default {TOLERANCE}; finer: more triangles)",
                ),
            ),
        ),
        needs=("open3d", "peer"),
    ),
}


def add(sub) -> None:
    b = sub.add_parser(
        "bench",
        help="benchmarks (levels, paths, split, tracers, effects, zoom, peer, accuracy, latency)",
        description="Benchmarks that report ratios measured side by side. "
        "Example: krsview bench tracers tree --csv out/tracers.csv",
    )
    bsub = b.add_subparsers(dest="bench", required=True, metavar="BENCH")
    for name, bench in BENCHES.items():
        sp = bsub.add_parser(name, help=bench.help, description=bench.description)
        options.preset(sp)
        sp.add_argument("--size", type=options.size, default=(320, 180), help="default 320x180")
        sp.add_argument(
            "--rounds",
            type=options.number_in("--rounds", 1, 100),
            default=5,
            help="interleaved rounds; each time is its fastest round, with the median and "
            "slowest beside it: load only adds time (default 5)",
        )
        sp.add_argument(
            "--csv", metavar="PATH", help="also write the table to this file, ending in .csv"
        )
        own = [sp.add_argument(flag, **spec).dest for flag, spec in bench.own]
        for knob in bench.knobs:
            render_option(sp, knob)
        if bench.scene_options:
            options.scene_options(sp)
        sp.set_defaults(func=run, own=own)
    add_accuracy(bsub)
    add_latency(bsub)


def run(args: argparse.Namespace) -> int:
    needs = BENCHES[args.bench].needs
    if needs is not None:
        options.require(needs[0], extra=needs[1], what=f"bench {args.bench}")
    scene = options.scene_of(args)
    if BENCHES[args.bench].fast:
        scene = options.fast_scene_of(args, scene)
    if args.csv:
        output_file(args.csv, "--csv", (".csv",))
    own = {dest: getattr(args, dest) for dest in args.own}
    if own.get("plot"):  # checked here, where its error is one line (argparse hid it)
        own["plot"] = output_file(own["plot"], "--plot", (".png",))
    module = importlib.import_module(f"krsview.bench.{args.bench}")
    measured = getattr(module, f"bench_{args.bench}")(scene, args.size, rounds=args.rounds, **own)
    print(module.table(measured))
    if args.csv:
        print(f"wrote {write_csv(measured.rows, args.csv).resolve()}")
    if own.get("plot"):
        print(f"wrote {own['plot'].resolve()}")
    return 0


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


def add_latency(bsub) -> None:
    bl = bsub.add_parser(
        "latency",
        help="how fast the editor answers a drag, in a real window",
        description="Open PRESET in the editor (a grown tree baked into its route), let the "
        "view settle, then drag the fork halfway down the route (in a compound, one of its "
        "trees) in small steps, one per "
        "turn of the event loop, through the gizmo's own path; each frame is time-stamped "
        "once on screen. Prints the latency from a drag step to the first frame traced "
        "from it and the frame rate while dragging (median and p90), the internal size "
        "while dragging, and after the release the first full-resolution image and the "
        "still one. Needs a display (DISPLAY; Xvfb will do). "
        "Example: krsview bench latency grove --size 1280x720",
    )
    options.preset(bl)
    bl.add_argument("--size", type=options.size, default=(1280, 720), help="default 1280x720")
    bl.add_argument(
        "--steps",
        type=options.number_in("--steps", 2, 10000),
        default=40,
        help="drag steps, one per turn (default 40)",
    )
    bl.add_argument("--csv", metavar="PATH", help="also write the row to this file, ending in .csv")
    bl.set_defaults(func=run_latency)


def run_latency(args: argparse.Namespace) -> int:
    if args.csv:
        output_file(args.csv, "--csv", (".csv",))
    rows = app.drag_latency(resolve(args.preset), args.size, args.steps)
    print(
        markdown(
            (
                "scene",
                "window",
                "latency ms (median, p90)",
                "FPS dragging (median, p10)",
                "internal size",
                "first full resolution",
                "still",
            ),
            "llrrlrr",
            (
                (
                    r["scene"],
                    r["window"],
                    f"{r['latency_ms_median']:.0f}, {r['latency_ms_p90']:.0f}",
                    f"{r['fps_median']:.1f}, {r['fps_p10']:.1f}",
                    r["drag_size"],
                    f"{r['first_full_s']:.2f} s",
                    f"{r['still_s']:.2f} s",
                )
                for r in rows
            ),
        )
    )
    if args.csv:
        print(f"wrote {write_csv(rows, args.csv).resolve()}")
    return 0
