"""`krsview check`: a scene's statistics (:func:`krsview.check`), the numerical invariants
(:func:`krsview.stability`, over :func:`krsview.hard_cases` too) or the oracle's certified
errors (:func:`krsview.certify`), printed as the API returns them."""

from __future__ import annotations

import argparse

from .. import api
from ..bench.report import oracle_header, oracle_row
from ..oracle.certify import MAX_SEGMENTS
from ..progress import Progress
from ..scene import Scene, SceneError
from ..scene.presets import resolve
from . import options

SIZE = (48, 27)  # the image --stability and --oracle trace by default
TRACERS = ("sphere", "binary")  # what the oracle certifies (a MöKRS: binary only)


def add(sub) -> None:
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
        "'hard:NAME' (one case). Exit status 1 if one fails. "
        "Examples: krsview check grass; krsview check --stability hard; "
        "krsview check --oracle sierpinski --size 24x14",
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
        type=options.number_in("--segments", 1, 1_000_000),
        metavar="N",
        help=f"--oracle: segments per ray before it counts as undecided (default {MAX_SEGMENTS})",
    )
    c.add_argument(
        "--size",
        type=options.size,
        help=f"image size for --stability and --oracle (default {SIZE[0]}x{SIZE[1]})",
    )
    c.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    for name, needs in (("segments", args.oracle), ("size", args.oracle or args.stability)):
        if getattr(args, name) is not None and not needs:
            mode = "--oracle" if name == "segments" else "--stability or --oracle"
            given = getattr(args, name)
            shown = "x".join(map(str, given)) if name == "size" else given
            raise SceneError(f"--{name}", shown, f"needs {mode}")
    size = args.size or SIZE
    if args.stability:
        return stability(scenes_named(args.preset, catalogue=True), size)
    if args.oracle:
        return oracle(scenes_named(args.preset)[0], size, args.segments or MAX_SEGMENTS)
    if args.preset == "hard" or args.preset.startswith("hard:"):  # the cases' statistics
        for scene in scenes_named(args.preset, catalogue=True):
            print(api.check(scene).text(f"hard:{scene.name}"))
        return 0
    source = resolve(args.preset)
    print(api.check(source).text(source))
    return 0


def scenes_named(name: str, catalogue: bool = False) -> list[Scene]:
    """PRESET as scenes: a scene file or preset, ``hard:NAME`` (a hard case) or, with
    ``catalogue``, ``hard`` (every hard case)."""
    if catalogue and name == "hard":
        return list(api.hard_cases().values())
    if name.startswith("hard:"):
        cases = api.hard_cases()
        if name[5:] not in cases:
            raise SceneError("PRESET", name, "no such hard case; cases: " + ", ".join(cases))
        return [cases[name[5:]]]
    return [api.load(name)]


def stability(scenes: list[Scene], size: tuple[int, int]) -> int:
    """The invariants' table; exit status 1 when one fails."""
    bar = Progress(len(scenes), "  stability", options.SILENT_SECONDS)
    outcomes = []
    for scene in scenes:
        outcomes.append(api.stability(scene, size))
        bar.step(scene.name)
    from ..bench.stability import table

    print(table(outcomes))
    return 0 if all(o.ok for o in outcomes) else 1


def oracle(scene: Scene, size: tuple[int, int], segments: int) -> int:
    """The certified counts of each tracer, a row as each is done."""
    for k, tracer in enumerate(("binary",) if scene.mokrs is not None else TRACERS):
        counts = api.certify(scene, size, tracer, segments)
        if k == 0:
            print(oracle_header(scene.name, size))
        print(oracle_row(tracer, counts), flush=True)
    return 0
