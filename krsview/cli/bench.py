"""`krsview bench NAME`: one table of benchmarks, each a function of :mod:`krsview.bench`
returning its rows and a ``table`` making them Markdown; this module only parses, calls and
prints (and writes ``--csv``). `bench accuracy` (accuracy.py) writes a report folder per
preset."""

from __future__ import annotations

import argparse
import importlib
from dataclasses import dataclass, field

from .. import app
from ..bench.expansion import TOLERANCE
from ..bench.report import markdown, write_csv
from ..inputs import output_file
from ..scene import MAX_LEVELS
from ..scene.presets import resolve
from ..scene.render import VIEW_PREPASS
from ..scene.settings import ViewerSettings
from . import options
from .accuracy import add_accuracy
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


STOPS = (  # bench zoom's and peer-zoom's cameras
    "--stops",
    dict(
        dest="stops_count",
        type=options.number_in("--stops", 2, 100),
        default=12,
        help="cameras along the flight (default 12)",
    ),
)
PEER_TOLERANCE = (
    "--tolerance",
    dict(
        type=options.number_in("--tolerance", 0.01, 8.0, float),
        metavar="PIXELS",
        default=TOLERANCE,
        help="pixels the peer's mesh may lie from the surface, at the nearest "
        f"instance of each level (default {TOLERANCE}; finer: more triangles)",
    ),
)

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
        "path at 4, 8, 16, 32 iterations per round (shadow rays as tasks of their own and "
        "inline, where the scene has shadows) and by persistent lanes (steps 0, at the "
        "viewer's pre-pass), at --size and twice it, interleaved: "
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
            STOPS,
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
            PEER_TOLERANCE,
        ),
        needs=("open3d", "peer"),
    ),
    "peer-zoom": Bench(
        "bench zoom's flight with the Embree BVH beside krsview",
        "The scene's KRS cut to --levels levels, expanded and tessellated into an Embree BVH as "
        "bench peer does, then drawn by both along bench zoom's flight into its finest "
        "kernel, krsview with `render`'s fast settings and its effects off: per stop the "
        "frame time of each (fastest round [median–slowest] of interleaved rounds), "
        "krsview's ratio to the peer, the share of pixels each hits, and each one's slowest "
        "frame against its fastest: how constant a rate the obvious alternative holds on "
        "the same flight. Needs 'krsview[peer]'. Example: krsview bench peer-zoom tree "
        "--levels 16 --rounds 7",
        knobs=("prepass", "lod"),
        fast=True,
        own=(
            (
                "--levels",
                dict(
                    type=options.number_in("--levels", 1, MAX_LEVELS),
                    default=16,
                    help="the coarsest levels kept and expanded (default 16; each level "
                    "doubles the peer's mesh)",
                ),
            ),
            STOPS,
            PEER_TOLERANCE,
        ),
        needs=("open3d", "peer"),
    ),
}


def add(sub) -> None:
    b = sub.add_parser(
        "bench",
        help="benchmarks (levels, paths, split, tracers, effects, zoom, peer, peer-zoom, accuracy, "
        "latency)",
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
            help="interleaved rounds; each time is its fastest round (load only adds time), "
            "the median and slowest printed beside it where the table has room (default 5)",
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
    name = args.bench.replace("-", "_")  # peer-zoom: krsview.bench.peer_zoom
    module = importlib.import_module(f"krsview.bench.{name}")
    measured = getattr(module, f"bench_{name}")(scene, args.size, rounds=args.rounds, **own)
    print(module.table(measured))
    if args.csv:
        print(f"wrote {write_csv(measured.rows, args.csv).resolve()}")
    if own.get("plot"):
        print(f"wrote {own['plot'].resolve()}")
    return 0


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
    options.field_option(bl, ViewerSettings, "size", default=(1280, 720))  # the window's range
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
