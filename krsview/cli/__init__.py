"""`krsview render|check|bench`: argument parsing only; the work lives in the packages."""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
import typing
from dataclasses import fields, replace
from pathlib import Path

import numpy as np

from ..oracle.certify import MAX_SEGMENTS
from ..progress import Progress
from ..scene import EFFECTS, MAX_LEVELS, Render, Scene, SceneError, load_scene
from ..scene.effects import check_effects
from ..scene.model import VIEW_PREPASS
from ..scene.presets import DEFAULT_PRESET, preset_names, resolve
from ..scene.schema import check_value, describe_range
from ..share.frames import DEFAULT_FPS
from ..share.mesh import BRICK as MESH_BRICK
from ..share.mesh import FORMATS as MESH_FORMATS
from ..version import __version__

EXIT_USAGE, EXIT_SCENE, EXIT_GL = 2, 2, 3

SILENT_SECONDS = 1.0  # work quicker than this shows no progress bar


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"--size {text!r}: expected WIDTHxHEIGHT, e.g. 640x360"
        ) from None
    if not (1 <= w <= 8192 and 1 <= h <= 8192):
        raise argparse.ArgumentTypeError(f"--size {text!r}: each side must be 1..8192 pixels")
    return w, h


def _positive_float(name: str, lo: float, hi: float):
    def parse(text: str) -> float:
        try:
            v = float(text)
        except ValueError:
            v = float("nan")
        if not (lo <= v <= hi):
            raise argparse.ArgumentTypeError(f"{name} {text!r}: allowed {lo} ≤ value ≤ {hi}")
        return v

    return parse


def _int_in(name: str, lo: int, hi: int):
    def parse(text: str) -> int:
        try:
            v = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} {text!r}: expected a whole number") from None
        if not (lo <= v <= hi):
            raise argparse.ArgumentTypeError(f"{name} {text!r}: allowed {lo} ≤ value ≤ {hi}")
        return v

    return parse


def _box(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 6 or not all(np.isfinite(values)):
        raise argparse.ArgumentTypeError(
            f"--box {text!r}: expected six numbers XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX"
        )
    if not all(values[k + 3] > values[k] for k in range(3)):
        raise argparse.ArgumentTypeError(f"--box {text!r}: each max must exceed its min")
    return values


RENDER_FIELDS = {f.name: f for f in fields(Render)}


def render_option(sp: argparse.ArgumentParser, name: str) -> None:
    """``--NAME`` overriding ``[render] NAME``: type, range and help come from the scene
    schema, and the value is checked by the schema's own rule (one schema, DESIGN.md)."""
    f, flag = RENDER_FIELDS[name], "--" + name.replace("_", "-")
    meta = dict(f.metadata)
    hint = typing.get_type_hints(Render)[name]

    def parse(text: str):
        try:
            value = hint(text) if hint in (int, float) else text
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{flag} {text!r}: expected a {'whole ' if hint is int else ''}number"
            ) from None
        try:
            return check_value(hint, value, flag, meta)
        except SceneError as e:
            raise argparse.ArgumentTypeError(str(e)) from None

    allowed = (
        describe_range(meta, hint)
        if not meta.get("choices")
        else "one of " + ", ".join(meta["choices"])
    )
    sp.add_argument(
        flag,
        type=parse,
        metavar=name.split("_")[-1].upper(),
        help=f"{meta['help']} ({allowed}; overrides the scene's [render])",
    )


def _load(args: argparse.Namespace) -> Scene:
    scene = load_scene(resolve(args.preset))
    given = {
        name: getattr(args, name) for name in RENDER_FIELDS if getattr(args, name, None) is not None
    }  # the render_option()s used
    if "tracer" in given:
        scene.check_tracer(given["tracer"], "--tracer")
    scene = replace(scene, render=replace(scene.render, **given))
    effects = getattr(args, "effects", None)
    if effects is not None:
        names = [] if effects.strip() == "none" else [e.strip() for e in effects.split(",")]
        check_effects(names, scene.mokrs is not None, "--effects")
        scene = replace(scene, effects=names)
    levels = getattr(args, "levels", None)
    if levels is not None:
        krs = scene.geometry()
        if levels > krs.depth:
            raise SceneError(
                "--levels", levels, f"this scene has {krs.depth} levels; allowed 1..{krs.depth}"
            )
        scene = scene.with_geometry(krs.truncated(levels))
    return scene


def cmd_render(args: argparse.Namespace) -> int:
    scene = _load(args)
    if args.camera_path is not None:
        for flag, given in (
            ("--buffers", args.buffers),
            ("--reference", args.reference),
            ("--view", args.view != "shaded"),
        ):
            if given:
                raise SceneError(
                    flag,
                    getattr(args, flag[2:]),
                    "cannot be combined with --camera-path (it writes shaded frames)",
                )
        return render_camera_path(args, scene)
    for flag in ("frames", "video"):
        if getattr(args, flag) is not None:
            raise SceneError(f"--{flag}", getattr(args, flag), "needs --camera-path FILE")
    out = check_output_file(args.output or "out/render.png", "-o", ".png")
    if args.buffers:
        check_output_file(args.buffers, "--buffers", ".npz")
    w, h = args.size
    krs = scene.geometry()
    print(
        f"krsview: {scene.name}: {krs.depth} levels, {krs.instance_count():,} kernel "
        f"instances, {w}×{h}, {'NumPy reference' if args.reference else 'GPU'}",
        flush=True,
    )
    t0 = time.perf_counter()
    if args.reference:
        from ..reference import render_reference

        buffers = render_reference(scene, w, h, progress=Progress(1, "  rays", SILENT_SECONDS))
        frame = time.perf_counter() - t0
        print(f"  traced in {frame * 1e3:.0f} ms (float64 reference)")
    else:
        from ..gpu.renderer import Renderer

        r = Renderer()
        print("  compiling shader variant …", flush=True)
        buffers = r.render(scene, w, h, progress=Progress(1, "  first frame, rows", SILENT_SECONDS))
        print(
            f"  first frame {(time.perf_counter() - t0) * 1e3:.0f} ms (with compiling)", flush=True
        )
        bar = Progress(args.repeats, "  timing frames", SILENT_SECONDS)
        times = []
        for _ in range(args.repeats):
            times += r.time_frame(scene, w, h, repeats=1)
            bar.step()
        frame = sorted(times)[len(times) // 2]
        print(
            f"  frame time {frame * 1e3:.1f} ms (median of {args.repeats}), "
            f"{buffers.iterations.mean():.1f} iterations/pixel, "
            f"{buffers.hit.mean() * 100:.0f}% of pixels hit"
        )
    if args.view == "iterations":
        from ..heatmap import save_heatmap

        it = buffers.iterations
        vmax = save_heatmap(
            it, out, args.legend_max, f"{scene.render.tracer} tracing: iterations per pixel"
        )
        print(
            f"  iterations per pixel: median {np.median(it):.0f}, mean {it.mean():.1f}, "
            f"max {it.max()} (colour scale 0..{vmax})"
        )
    else:
        buffers.save(out)
    print(f"  wrote {out.resolve()}")
    if args.buffers:
        buffers.save(args.buffers)
        print(f"  wrote {args.buffers} (color, depth, normal, iterations, hit)")
    return 0


def frame_job(args: argparse.Namespace, scene: Scene):
    """The frames ``--camera-path``, ``--frames``, ``--fps``, ``--size`` and ``-o`` ask for,
    checked before any frame is drawn."""
    from ..scene.camera_path import load_camera_path
    from ..share.frames import FrameJob, parse_frames

    path = load_camera_path(args.camera_path)
    folder = Path(args.output or "out/frames")
    if folder.suffix.lower() == ".png":
        raise SceneError("-o", str(folder), "with --camera-path, give a folder for the frames")
    check_output_dir(folder, "-o")
    job = FrameJob(scene, path, args.fps, args.size, folder)
    return job, parse_frames(args.frames, job.count)


def render_camera_path(args: argparse.Namespace, scene: Scene) -> int:
    from ..share.frames import render_frames, write_video

    job, frames = frame_job(args, scene)
    video = check_video(args.video, job.size)
    todo = job.missing(frames)
    print(
        f"krsview: {scene.name}: frames {frames.start}-{frames.stop - 1} of "
        f"{job.count} ({job.path.duration:.2f} s at {job.fps:g} fps), "
        f"{job.size[0]}×{job.size[1]} → {job.folder}/; "
        f"{len(frames) - len(todo)} already there, {len(todo)} to render",
        flush=True,
    )
    if todo:
        from ..gpu.renderer import Renderer

        bar = Progress(len(todo), "  frames")
        render_frames(job, todo, Renderer(), lambda k: bar.step(f"frame {k}"))
    if video is not None:
        bar = Progress(len(frames), "  video")
        write_video(job.folder, frames, job.fps, video, lambda k: bar.step())
        print(f"  wrote {video.resolve()}")
    return 0


def cmd_export_web(args: argparse.Namespace) -> int:
    from ..scene.scene import write_atomic
    from ..share.web import export_notes, html_page, shadertoy_source

    scene = _load(args)
    out = check_output_file(args.output, "-o", args.suffix)
    notes = export_notes(scene)
    text = html_page(scene) if args.format == "html" else shadertoy_source(scene)
    write_atomic(out, text)
    for note in notes:
        print(f"  note: {note}")
    print(f"krsview: {scene.name}: wrote {out.resolve()} ({len(text) / 1024:.0f} KiB)")
    return 0


def cmd_export_mesh(args: argparse.Namespace) -> int:
    import resource

    from ..share.mesh import build_mesh

    require("skimage", "trimesh", extra="mesh", what="export mesh")
    scene = _load(args)
    suffix = Path(args.output).suffix.lower()
    if suffix not in MESH_FORMATS:
        raise SceneError("-o", args.output, "the file must end in " + ", ".join(MESH_FORMATS))
    out = check_output_file(args.output, "-o", suffix)
    print(
        f"krsview: {scene.name}: meshing at {args.resolution} voxels a side, level set "
        f"{args.lod:g} voxel out …",
        flush=True,
    )
    bar = Progress(1, "  bricks", SILENT_SECONDS)
    mesh, st = build_mesh(scene, args.resolution, args.box, args.lod, bar)
    tmp = out.with_name(f".{out.name}.tmp{out.suffix}")  # whole file or none
    try:
        mesh.export(tmp)
        os.replace(tmp, out)
    finally:
        tmp.unlink(missing_ok=True)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(
        f"  {st.triangles:,} triangles, {'watertight' if st.watertight else 'open'}; "
        f"{st.bricks} bricks of {(st.resolution // MESH_BRICK) ** 3} sampled, "
        f"{st.samples:,} reference samples ({st.samples / (st.resolution + 1) ** 3:.1%} of "
        f"a dense grid); {st.seconds:.1f} s, peak memory {peak:.0f} MiB"
    )
    print(f"  wrote {out.resolve()}")
    return 0


def require(*modules: str, extra: str, what: str) -> None:
    """An optional extra's packages are there, or one line says how to get them."""
    import importlib.util

    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise MissingExtra(f"{what} needs {', '.join(missing)}: pip install 'krsview[{extra}]'")


class MissingExtra(RuntimeError):
    """An optional dependency is not installed (exit status 3, as for GL problems)."""


def cmd_batch(args: argparse.Namespace) -> int:
    require("ray", extra="cluster", what="batch")
    from ..share.batch import check_address, run_batch
    from ..share.frames import write_video

    check_address(args.address)
    scene = _load(args)
    job, frames = frame_job(args, scene)
    video = check_video(args.video, job.size)
    where = args.address or "a local Ray cluster"
    print(
        f"krsview: {scene.name}: frames {frames.start}-{frames.stop - 1} of {job.count}, "
        f"{job.size[0]}×{job.size[1]} → {job.folder}/ on {args.workers} worker(s) of "
        f"{where}, {args.chunk} frames per chunk",
        flush=True,
    )
    bar = Progress(max(1, len(job.missing(frames))), "  frames")
    report = run_batch(
        job,
        frames,
        args.workers,
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
        vbar = Progress(len(frames), "  video")
        write_video(job.folder, frames, job.fps, video, lambda k: vbar.step())
        print(f"  wrote {video.resolve()}")
    return 0


def check_video(text: str | None, size: tuple[int, int]) -> Path | None:
    """``--video``: an .mp4 that can be written, of a size H.264 4:2:0 takes."""
    if text is None:
        return None
    video = check_output_file(text, "--video", ".mp4")
    if size[0] % 2 or size[1] % 2:
        raise SceneError(
            "--size",
            f"{size[0]}x{size[1]}",
            "--video needs an even width and height (H.264, 4:2:0 colour)",
        )
    return video


def cmd_view(args: argparse.Namespace) -> int:
    from .. import app

    app.view(
        resolve(args.preset),
        size=args.size,
        hud=not args.no_hud,
        target_fps=args.fps,
        prepass=args.prepass,
        moving_effects=args.moving_effects,
    )
    return 0


def cmd_edit(args: argparse.Namespace) -> int:
    from .. import app

    app.edit(resolve(args.preset), size=args.size, target_fps=args.fps)
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    if args.stability:
        return check_stability(args.preset, args.size)
    if args.oracle:
        return check_oracle(args.preset, args.size, args.segments)
    path = resolve(args.preset)
    scene = load_scene(path)
    krs = scene.geometry()
    kinds: dict[str, int] = {}
    for k in krs.kernels:
        kinds[k.kind] = kinds.get(k.kind, 0) + 1
    print(f"{path}: ok — {scene.name}")
    if scene.description:
        print(f"  {scene.description}")
    if scene.mokrs is not None:
        print(
            f"  geometry        MöKRS: {krs.n} levels, "
            f"{sum(lv.reflect for lv in scene.mokrs.levels)} reflecting"
        )
    elif scene.compound:
        print(
            f"  geometry        compound of {len(scene.compound)}: "
            + ", ".join(
                f"{'tree' if c.tree else 'route' if c.route else 'KRS'} of {p.depth} levels"
                for c, p in zip(scene.compound, krs.parts)
            )
        )
    else:
        kind = "tree (grown)" if scene.tree else "tree (route)" if scene.route else "explicit KRS"
        print(f"  geometry        {kind}")
        print(f"  levels          {krs.depth} (kernels K_0..K_{krs.n}, {krs.n} mirrors)")
    print(f"  kernel instances {krs.instance_count():,}")
    print("  kernels         " + ", ".join(f"{v}× {k}" for k, v in sorted(kinds.items())))
    print(f"  effects         {', '.join(scene.effects) or 'none'}")
    for w in scene.route.warnings() if scene.route else []:
        print(f"  warning         route.{w}")
    r = scene.render
    binary = f" (ξ_bonus {r.xi_bonus}, ξ_penalty {r.xi_penalty})" if r.tracer == "binary" else ""
    print(
        f"  render          {r.tracer} tracer{binary}, ε-scale {r.epsilon_scale}, "
        f"≤ {r.max_iterations} iterations, far {r.max_distance}"
    )
    return 0


def check_bench_csv(args: argparse.Namespace) -> None:
    """--csv is checked before the bench runs (the check_output_file rules)."""
    if args.csv:
        check_output_file(args.csv, "--csv", ".csv")


def check_stability(name: str, size: tuple[int, int]) -> int:
    """The invariants of bench/stability.py on a scene, a hard case (hard:NAME) or the whole
    catalogue (hard); exit status 1 when one fails."""
    from ..bench import stability
    from ..bench.hard_cases import CASES, HardCase
    from ..gpu.renderer import Renderer

    if name == "hard":
        cases = list(CASES.values())
    elif name.startswith("hard:"):
        if name[5:] not in CASES:
            raise SceneError("PRESET", name, "no such hard case; cases: " + ", ".join(CASES))
        cases = [CASES[name[5:]]]
    else:
        scene = load_scene(resolve(name))
        cases = [HardCase(scene.name, lambda: scene, "")]
    r = Renderer()
    bar = Progress(len(cases), "  stability", SILENT_SECONDS)
    outcomes = []
    for case in cases:
        outcomes.append(stability.check(replace(case.build(), name=case.name), r, size))
        bar.step(case.name)
    print(stability.table(outcomes))
    return 0 if all(o.ok for o in outcomes) else 1


def check_oracle(name: str, size: tuple[int, int], segments: int) -> int:
    """Certified holes and false hits of the tracers on a scene (or a hard case, hard:NAME),
    with the oracle's work in interval and affine arithmetic."""
    from ..bench.hard_cases import CASES
    from ..gpu.renderer import Renderer
    from ..oracle.certify import count_errors

    if name.startswith("hard:"):
        if name[5:] not in CASES:
            raise SceneError("PRESET", name, "no such hard case; cases: " + ", ".join(CASES))
        scene = replace(CASES[name[5:]].build(), name=name[5:])
    else:
        scene = load_scene(resolve(name))
    if {"twist", "empty_zones"} & set(scene.effects):
        raise SceneError(
            "PRESET",
            name,
            "the oracle covers scenes without twist or empty "
            "zones (their distortions are not in it)",
        )
    r = Renderer()
    print(
        f"| {scene.name} {size[0]}×{size[1]} | rays | hits | holes | false hits beyond ε | "
        "below LOD | undecided | affine: segments, s | interval: segments, s |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for tracer in ("binary",) if scene.mokrs is not None else ("sphere", "binary"):
        traced = replace(scene, render=replace(scene.render, tracer=tracer))
        c = count_errors(traced, r.render(traced, *size), max_segments=segments)
        (sa, ta), (si, ti) = c.work["affine"], c.work["interval"]
        print(
            f"| {tracer} | {c.rays} | {c.hits} | {c.holes} | {c.false_hits} | "
            f"{c.below_lod} | {c.undecided} | {sa:,}, {ta:.1f} | {si:,}, {ti:.1f} |",
            flush=True,
        )
    return 0


def cmd_bench_levels(args: argparse.Namespace) -> int:
    from ..bench.levels import bench_levels

    scene = _load(args)
    check_bench_csv(args)
    bench_levels(scene, args.size, step=args.step, rounds=args.rounds, csv=args.csv)
    return 0


def cmd_bench_paths(args: argparse.Namespace) -> int:
    from ..bench.paths import bench_paths

    scene = _load(args)
    check_bench_csv(args)
    bench_paths(scene, args.size, rounds=args.rounds, csv=args.csv)
    return 0


def cmd_bench_split(args: argparse.Namespace) -> int:
    from ..bench.split import bench_split

    scene = _load(args)
    check_bench_csv(args)
    bench_split(scene, args.size, rounds=args.rounds, csv=args.csv)
    return 0


def cmd_bench_tracers(args: argparse.Namespace) -> int:
    from ..bench.tracers import bench_tracers

    scene = _load(args)
    check_bench_csv(args)
    bench_tracers(scene, args.size, rounds=args.rounds, sweep=not args.no_sweep, csv=args.csv)
    return 0


def cmd_bench_effects(args: argparse.Namespace) -> int:
    from ..bench.effects import bench_effects

    scene = _load(args)
    check_bench_csv(args)
    bench_effects(scene, args.size, rounds=args.rounds, csv=args.csv)
    return 0


def cmd_bench_accuracy(args: argparse.Namespace) -> int:
    from ..bench.accuracy import bench_accuracy

    names = args.preset or [DEFAULT_PRESET]
    scenes = {n: _load(argparse.Namespace(**{**vars(args), "preset": n})) for n in names}
    if len(set(names)) != len(names):
        raise SceneError("PRESET", " ".join(names), "each preset once")
    outs = {
        n: (
            Path(args.out) / resolve(n).stem
            if args.out and len(names) > 1
            else Path(args.out)
            if args.out
            else Path("out") / "accuracy" / resolve(n).stem
        )
        for n in names
    }
    for out in outs.values():
        check_output_dir(out, "--out")
    if args.workers == 1 and args.address is None:  # here, one after the other
        for n in names:
            bench_accuracy(
                scenes[n],
                args.size,
                outs[n],
                rounds=args.rounds,
                cache=Path(args.cache) if args.cache else None,
            )
        return 0
    require("ray", extra="cluster", what="bench accuracy --workers/--address")
    from ..share.batch import check_address, run_accuracy_sweep

    check_address(args.address)
    print(
        f"krsview: accuracy of {len(names)} preset(s) on {args.workers} Ray worker(s) of "
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
        scenes,
        args.size,
        args.rounds,
        outs,
        args.workers,
        args.address,
        done,
        Path(args.cache) if args.cache else None,
    )
    return 1 if failed else 0


def check_output_file(path: str, flag: str, suffix: str) -> Path:
    """Before any work: the file has the format's extension, is not a folder, and its folder
    exists or can be made and is writable (a render must not fail after it ran)."""
    p = Path(path)
    if p.suffix.lower() != suffix:
        raise SceneError(
            flag, path, f"the file must end in {suffix} (it is written as {suffix[1:].upper()})"
        )
    if p.is_dir():
        raise SceneError(flag, path, "is a folder; give a file name ending in " + suffix)
    try:
        p.parent.mkdir(parents=True, exist_ok=True)
        probe = p.parent / f".{p.name}.write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise SceneError(flag, path, f"cannot write there: {e.strerror}") from None
    return p


def check_output_dir(path: Path, flag: str) -> None:
    """Before any work: the folder exists or can be made, and is writable."""
    if path.exists() and not path.is_dir():
        raise SceneError(flag, str(path), "is a file; give a folder for the report")
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise SceneError(flag, str(path), f"cannot write there: {e.strerror}") from None


def build_parser() -> argparse.ArgumentParser:
    presets = ", ".join(preset_names()) or "none found"
    p = argparse.ArgumentParser(
        prog="krsview",
        description="Render, check and benchmark Kernel–Reflection Sequence scenes [KRS17]. "
        "A PRESET is a scene file (.toml) or the name of a shipped preset: "
        f"{presets}.",
        epilog="examples:\n  krsview render tree -o tree.png --size 640x360\n"
        "  krsview check grass\n  krsview bench levels tree\n"
        "  krsview render palm --view iterations -o palm-iterations.png\n"
        "  krsview bench tracers tree",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"krsview {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def accuracy(sp: argparse.ArgumentParser) -> None:
        render_option(sp, "epsilon_scale")
        render_option(sp, "max_iterations")
        sp.add_argument(
            "--levels",
            type=_int_in("--levels", 1, MAX_LEVELS),
            help="keep only the coarsest N levels (drops the finest detail)",
        )
        sp.add_argument(
            "--effects",
            metavar="LIST",
            help="comma-separated effects replacing the scene's, or 'none'; one of: "
            + ", ".join(EFFECTS),
        )

    def window_arguments(sp: argparse.ArgumentParser, size: tuple[int, int]) -> None:
        sp.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
        sp.add_argument(
            "--size", type=_size, default=size, help=f"window size (default {size[0]}x{size[1]})"
        )
        sp.add_argument(
            "--fps",
            type=_positive_float("--fps", 1.0, 240.0),
            default=30.0,
            help="frame rate held while moving or dragging, by lowering the "
            "internal resolution (default 30)",
        )

    def camera_path_arguments(sp, required: bool) -> None:
        sp.add_argument(
            "--camera-path",
            required=required,
            metavar="FILE",
            help="a NAME.path.json camera path (recorded in the viewer with F5)",
        )
        sp.add_argument(
            "--frames",
            metavar="A-B",
            help="only frames A to B, inclusive (default: all the path's)",
        )
        sp.add_argument(
            "--fps",
            type=_positive_float("--fps", 1.0, 240.0),
            default=DEFAULT_FPS,
            help=f"frames per second of path time (default {DEFAULT_FPS:g})",
        )
        sp.add_argument(
            "--video",
            metavar="MP4",
            help="also write the frames as an H.264 "
            "video, ending in .mp4 (needs an even width and height)",
        )

    def bench_arguments(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
        sp.add_argument("--size", type=_size, default=(320, 180), help="default 320x180")
        sp.add_argument(
            "--rounds",
            type=_int_in("--rounds", 1, 100),
            default=5,
            help="interleaved rounds; medians are reported (default 5)",
        )
        sp.add_argument(
            "--csv", metavar="PATH", help="also write the table to this file, ending in .csv"
        )

    r = sub.add_parser(
        "render",
        help="render a scene headless to PNG (and raw buffers)",
        description="Render PRESET headless through EGL and write a PNG; prints "
        "the measured frame time.",
    )
    r.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
    r.add_argument(
        "-o",
        "--output",
        help="PNG file to write, ending in .png (default out/render.png); with "
        "--camera-path, the folder for the frames (default out/frames)",
    )
    r.add_argument("--size", type=_size, default=(640, 360), help="WIDTHxHEIGHT (default 640x360)")
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
        type=_int_in("--repeats", 1, 1000),
        default=5,
        help="frames timed; the median is printed (default 5)",
    )
    r.add_argument(
        "--view",
        choices=("shaded", "iterations"),
        default="shaded",
        help="shaded image, or the per-pixel iteration count as a heat map with a "
        "legend (black = 0, white = the maximum) [KRS17 Fig. 13]",
    )
    r.add_argument(
        "--legend-max",
        type=_int_in("--legend-max", 1, 100000),
        metavar="N",
        help="iterations shown as white in --view iterations (default: the image's "
        "maximum); fix it to compare tracers on one scale",
    )
    render_option(r, "tracer")
    render_option(r, "relaxation")
    render_option(r, "precision")
    render_option(r, "culling")
    render_option(r, "prepass")
    render_option(r, "prepass_levels")
    render_option(r, "path")
    render_option(r, "steps")
    render_option(r, "shadow_tasks")
    render_option(r, "component_tasks")
    accuracy(r)
    cp = r.add_argument_group(
        "camera paths",
        "Render the frames of a path recorded in the viewer (F5; saved as "
        "NAME.path.json beside the preset) to frame_00000.png, … in the -o folder. Frames "
        "already there are skipped, so an interrupted run resumes where it stopped.",
    )
    camera_path_arguments(cp, required=False)
    r.set_defaults(func=cmd_render)

    v = sub.add_parser(
        "view",
        help="fly through a scene in a window",
        description="Open PRESET in a window. WASD/QE fly (speed follows the "
        "distance to the nearest surface; scroll scales it), right-drag "
        "looks, O orbits the point at the centre, R resets, B saves a "
        "bookmark in the preset, N cycles bookmarks, F5 records and F6 "
        "replays a camera path, F12 saves a screenshot, F1 hides the "
        "HUD. Editing the preset or a shader reloads it.",
    )
    window_arguments(v, (960, 540))
    v.add_argument("--no-hud", action="store_true", help="start with the HUD hidden")
    v.add_argument(
        "--prepass",
        type=_int_in("--prepass", 0, 64),
        metavar="TILE",
        help="tile size of the low-resolution pre-pass while viewing (default: "
        f"the scene's [render] prepass, else {VIEW_PREPASS}; 0: off)",
    )
    v.add_argument(
        "--moving-effects",
        action="store_true",
        help="keep shadows and ambient occlusion in moving frames too (default: "
        "they appear when the view stops, so moving frames stay sharp)",
    )
    v.set_defaults(func=cmd_view)

    e = sub.add_parser(
        "edit",
        help="shape a tree: drag forks, control points and mirror normals; undo, save",
        description="Open PRESET in the editor. Click a handle (forks orange, "
        "control points cyan, mirror normals pink), an outline entry "
        "or the geometry to select; drag the gizmo to move it (Shift "
        "snaps). A grown [tree] is baked into an editable route with "
        "one click. Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo, "
        "Ctrl+S saves atomically, Ctrl+Shift+S saves as; unsaved "
        "edits are autosaved to PRESET.recovery and offered back "
        "after a crash. The viewer's keys fly the camera.",
    )
    window_arguments(e, (1280, 720))
    e.set_defaults(func=cmd_edit)

    c = sub.add_parser(
        "check",
        help="validate a scene file and print its statistics",
        description="Validate PRESET; print levels, kernel instances, effects. "
        "With --stability, run the numerical invariants on it "
        "instead: finite pixels, rays within the iteration cap "
        "(capped rays counted), continuity under a 1/100-pixel "
        "nudge of the eye, and GPU = float64 reference (trying "
        "precision = double where float32 falls short). PRESET "
        "may also be 'hard' (the whole hard-case catalogue) or "
        "'hard:NAME' (one case). Exit status 1 if one fails.",
    )
    c.add_argument("preset", metavar="PRESET")
    mode = c.add_mutually_exclusive_group()
    mode.add_argument(
        "--stability",
        action="store_true",
        help="run the stability invariants and print their table",
    )
    mode.add_argument(
        "--oracle",
        action="store_true",
        help="count the sphere and binary tracers' certified holes and false "
        "hits with the interval / affine arithmetic oracle [RAA09] (a deep "
        "tree takes about a minute)",
    )
    c.add_argument(
        "--segments",
        type=_int_in("--segments", 1, 1_000_000),
        default=MAX_SEGMENTS,
        metavar="N",
        help=f"--oracle: segments per ray before it counts as undecided (default {MAX_SEGMENTS})",
    )
    c.add_argument(
        "--size",
        type=_size,
        default=(48, 27),
        help="image size for --stability and --oracle (default 48x27)",
    )
    c.set_defaults(func=cmd_check)

    x = sub.add_parser(
        "export",
        help="a web page, a Shadertoy shader or a mesh of a scene",
        description="Take a scene out of krsview.",
    )
    xsub = x.add_subparsers(dest="format", required=True, metavar="FORMAT")
    for fmt, suffix, text in (
        (
            "html",
            ".html",
            "one self-contained page (no server, no network) that runs the "
            "scene's own specialised tracer in WebGL2: drag to orbit, wheel to zoom, "
            "double-click to reset. Open it in any current browser.",
        ),
        (
            "shadertoy",
            ".glsl",
            "the same shader as one Shadertoy mainImage (scene baked "
            "in as constants; iResolution, iTime and iMouse drive the camera). Paste it into "
            "a new shader on shadertoy.com.",
        ),
    ):
        xp = xsub.add_parser(
            fmt,
            help=text.split(" (")[0].split(":")[0],
            description=text + " Double precision cannot be exported "
            "(GLSL ES 3.00 has no fp64); the pre-pass and the compute path "
            "are left out (the same surfaces, one fragment pass).",
        )
        xp.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
        xp.add_argument("-o", "--output", required=True, help=f"file to write, ending in {suffix}")
        accuracy(xp)
        xp.set_defaults(func=cmd_export_web, suffix=suffix)

    xm = xsub.add_parser(
        "mesh",
        help="a triangle mesh (.glb, .ply, .stl, .obj)",
        description="Sample the float64 reference near the surface only (an "
        "octree drops every box certified empty), extract it with marching "
        "cubes, place each vertex on the surface by bisection along its grid "
        "edge, and write it with vertex colours (not in .stl). A scene with a "
        "ground plane is unbounded: give --box.",
    )
    xm.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
    xm.add_argument(
        "-o", "--output", required=True, help="file to write, ending in " + ", ".join(MESH_FORMATS)
    )
    xm.add_argument(
        "--resolution",
        type=_int_in("--resolution", 16, 2048),
        default=256,
        metavar="N",
        help="voxels along the side of the cube sampled, rounded up to 16·2^k (default 256)",
    )
    xm.add_argument(
        "--lod",
        type=_positive_float("--lod", 0.0, 4.0),
        default=0.5,
        metavar="VOXELS",
        help="mesh the level set this many voxels out, the "
        "renderer's level of detail: leaves thinner than a voxel thicken instead of "
        "vanishing (default 0.5; 0: the surface itself)",
    )
    xm.add_argument(
        "--box",
        type=_box,
        metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
        help="the region to mesh (default: the scene's bounding ball)",
    )
    xm.add_argument(
        "--levels", type=_int_in("--levels", 1, MAX_LEVELS), help="keep only the coarsest N levels"
    )
    xm.set_defaults(func=cmd_export_mesh)

    bt = sub.add_parser(
        "batch",
        help="render a camera path's frames on a Ray cluster",
        description="Render the frames of a camera path on a pool of Ray "
        "actors, each holding one EGL context and the compiled shader, over "
        "chunks of frames. Frames already in the -o folder are skipped, so a "
        "batch resumes where it stopped; a failed chunk is retried; the files "
        "are those `krsview render --camera-path` writes. Needs pip install "
        "'krsview[cluster]'.",
    )
    bt.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")
    camera_path_arguments(bt, required=True)
    bt.add_argument("-o", "--output", help="folder for the frames (default out/frames)")
    bt.add_argument("--size", type=_size, default=(640, 360), help="default 640x360")
    bt.add_argument(
        "--workers",
        type=_int_in("--workers", 1, 1024),
        default=2,
        help="actors, one EGL context each (default 2)",
    )
    bt.add_argument(
        "--chunk",
        type=_int_in("--chunk", 1, 100000),
        default=8,
        help="frames per task (default 8): larger chunks amortise scheduling",
    )
    bt.add_argument(
        "--retries",
        type=_int_in("--retries", 0, 100),
        default=2,
        help="times a failed chunk is tried again (default 2)",
    )
    bt.add_argument(
        "--address",
        metavar="ADDRESS",
        help="an existing Ray cluster (ray://HOST:10001, or 'auto'); default: start a local one",
    )
    accuracy(bt)
    bt.set_defaults(func=cmd_batch)

    b = sub.add_parser(
        "bench",
        help="benchmarks (levels, tracers, effects, accuracy)",
        description="Benchmarks that report ratios measured side by side.",
    )
    bsub = b.add_subparsers(dest="bench", required=True, metavar="BENCH")
    bl = bsub.add_parser(
        "levels",
        help="frame time against level count (O(n) vs 2^n)",
        description="Render the same view with the coarsest 4, 8, … levels, "
        "interleaved, median of several frames; print time relative "
        "to the smallest level count beside the kernel instances.",
    )
    bench_arguments(bl)
    bl.add_argument(
        "--step",
        type=_int_in("--step", 1, MAX_LEVELS),
        default=4,
        help="level increment (default 4)",
    )
    render_option(bl, "epsilon_scale")
    render_option(bl, "max_iterations")
    bl.set_defaults(func=cmd_bench_levels)
    bp = bsub.add_parser(
        "paths",
        help="what culling, the pre-pass and the compute path buy",
        description="Exact level culling off/on × the low-resolution pre-pass "
        "off and at tiles 4, 8, 16 (tiles 4 and 8 also with one "
        "coarse pass) on the fragment path, and the "
        "compute path at 4, 8, 16, 32 iterations per round, at "
        "--size and twice it, interleaved: frame time and "
        "speed-up against the plain frame, iterations per pixel, "
        "the coarse pass's share.",
    )
    bench_arguments(bp)
    render_option(bp, "tracer")
    bp.set_defaults(func=cmd_bench_paths)
    bs = bsub.add_parser(
        "split",
        help="where a frame's time goes: coarse passes, tracing, shading, shadow rays",
        description="On one scene and view, the fragment path: the frame, "
        "the frame without secondary effects (shadow rays, "
        "occlusion; what the viewer's moving frames leave out), "
        "the tracing alone and the coarse passes alone, "
        "interleaved; each part of the frame is the difference "
        "of two of them. Example: krsview bench split tree "
        f"--prepass {VIEW_PREPASS} (the viewer's pre-pass).",
    )
    bench_arguments(bs)
    for name in ("culling", "prepass", "prepass_levels"):
        render_option(bs, name)
    bs.set_defaults(func=cmd_bench_split)
    bt = bsub.add_parser(
        "tracers",
        help="sphere vs binary sphere tracing, and a ξ sweep",
        description="On one scene and view: sphere tracing, binary tracing at "
        "the paper's ξ_bonus/ξ_penalty = 2.0/0.3, and a sweep over "
        "ξ_bonus ∈ {1.5, 2, 3} × ξ_penalty ∈ {0.2, 0.3, 0.5}; "
        "iterations per pixel, frame time and hit agreement, as "
        "ratios to sphere tracing (to binary 2.0/0.3 for a MöKRS).",
    )
    bench_arguments(bt)
    bt.add_argument("--no-sweep", action="store_true", help="only sphere vs binary 2.0/0.3")
    accuracy(bt)
    bt.set_defaults(func=cmd_bench_tracers)
    be = bsub.add_parser(
        "effects",
        help="cost of each effect; specialised vs all compiled",
        description="On one scene and view: the plain render (no effect), "
        "each effect alone, and the scene's effect set both "
        "specialised (#define) and in the variant that compiles "
        "every effect and switches them by uniforms; frame times "
        "as ratios to the plain render. An idle twist (0°) or "
        "an empty zone list gets a stand-in so its cost shows. "
        "A KRS is also drawn as a compound of one; a compound "
        "against its components drawn alone, and their sum.",
    )
    bench_arguments(be)
    accuracy(be)
    be.set_defaults(func=cmd_bench_effects)
    ba = bsub.add_parser(
        "accuracy",
        help="what accuracy costs: every knob against time and "
        "ground truth, as a report with plots",
        description="On one view: sweep ε-scale, the iteration cap, the "
        "tracer (sphere, over-relaxed with ω, binary with ξ pairs) "
        "and the level count; "
        "time each setting on the GPU (interleaved rounds, "
        "medians) and compare its image with the ground truth "
        "(the float64 reference at ε/8, computed once and cached): "
        "holes, false hits, depth error in ε, normal error, PSNR, "
        "SSIM, iterations, capped rays. Writes OUT/README.md, "
        "OUT/accuracy.csv, plots (time vs error per knob, the "
        "Pareto front) and error images.",
    )
    ba.add_argument(
        "preset",
        nargs="*",
        metavar="PRESET",
        help="one or more presets (default tree); several write OUT/PRESET each",
    )
    ba.add_argument("--size", type=_size, default=(320, 180), help="default 320x180")
    ba.add_argument(
        "--workers",
        type=_int_in("--workers", 1, 1024),
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
        type=_int_in("--rounds", 1, 100),
        default=3,
        help="interleaved rounds; medians are reported (default 3)",
    )
    ba.add_argument(
        "--out",
        metavar="DIR",
        help="report folder (default out/accuracy/PRESET; with several presets, DIR/PRESET)",
    )
    ba.add_argument(
        "--cache", metavar="DIR", help="ground-truth cache (default ~/.cache/krsview/truth)"
    )
    ba.set_defaults(func=cmd_bench_accuracy)
    return p


_NEGATIVE = re.compile(r"^-(\d|\.\d|inf|nan)", re.IGNORECASE)


def join_negative_values(argv: list[str]) -> list[str]:
    """``--size -5x3`` → ``--size=-5x3``: argparse takes a value that starts with '-' for an
    option ("expected one argument"); joined, the option's own check says what is wrong."""
    out: list[str] = []
    for token in argv:
        if out and out[-1].startswith("--") and "=" not in out[-1] and _NEGATIVE.match(token):
            out[-1] += "=" + token
        else:
            out.append(token)
    return out


def main(argv: list[str] | None = None) -> int:
    argv = join_negative_values(sys.argv[1:] if argv is None else list(argv))
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except SceneError as e:
        print(f"krsview: error: {e}", file=sys.stderr)
        return EXIT_SCENE
    except RuntimeError as e:  # ContextError, ShaderError: environment or build problems
        print(f"krsview: error: {e}", file=sys.stderr)
        return EXIT_GL


if __name__ == "__main__":
    sys.exit(main())
