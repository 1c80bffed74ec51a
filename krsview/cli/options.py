"""The options the commands share: value parsers, options generated from a schema dataclass's
field metadata (range, default and help in one place, docs/architecture.md), the scene a command's
arguments ask for, and the checks of output paths made before any work."""

from __future__ import annotations

import argparse
import importlib.util
import math
import types
import typing
from dataclasses import MISSING, fields
from typing import Any

from .. import api
from ..inputs import region
from ..scene import EFFECTS, MAX_LEVELS, Render, Scene, SceneError
from ..scene.presets import DEFAULT_PRESET
from ..scene.render import ignored_by_tracer
from ..scene.schema import check_value, describe_range
from ..scene.settings import MAX_SIDE

SILENT_SECONDS = 1.0  # work quicker than this shows no progress bar


def size(text: str, lo: int = 1, flag: str = "--size") -> tuple[int, int]:
    """``WIDTHxHEIGHT`` (or ``WIDTH×HEIGHT``, as krsview prints sizes) → (width, height),
    each side ``lo``..MAX_SIDE pixels."""
    try:
        w, h = (int(v) for v in text.lower().replace("×", "x").split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{flag} {text!r}: expected WIDTHxHEIGHT, e.g. 640x360"
        ) from None
    if not (lo <= w <= MAX_SIDE and lo <= h <= MAX_SIDE):
        raise argparse.ArgumentTypeError(
            f"{flag} {text!r}: each side must be {lo}..{MAX_SIDE} pixels"
        )
    return w, h


def number_in(flag: str, lo: float, hi: float, kind: type = int):
    """A parser of a whole (``kind=int``) or real number in lo..hi for the CLI's own
    options (rounds, workers, …: settings of a run, not of a scene)."""

    def parse(text: str):
        try:
            v = kind(text)
        except ValueError:
            if kind is int:
                raise argparse.ArgumentTypeError(
                    f"{flag} {text!r}: expected a whole number"
                ) from None
            v = math.nan
        if not (lo <= v <= hi):
            raise argparse.ArgumentTypeError(f"{flag} {text!r}: allowed {lo} ≤ value ≤ {hi}")
        return v

    return parse


def box(text: str) -> tuple[float, ...]:
    """``XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX`` → six finite numbers, each max above its min."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    try:
        return region(values, "--box")
    except SceneError as e:
        raise argparse.ArgumentTypeError(f"--box {text!r}: {e.allowed}") from None


def field_option(
    sp: argparse.ArgumentParser,
    cls: type,
    name: str,
    flag: str | None = None,
    default: Any = MISSING,
    note: str | None = None,
) -> None:
    """``--NAME`` for field NAME of a schema dataclass (``scene.schema.param``): its type,
    range, default and help come from the field, and a value is checked by the schema's own
    rule. ``default``: the option's default when not the field's (None: not given);
    ``note``: what the help says instead of the default. A bool field is a switch
    (``--no-NAME`` when it is on by default); a (width, height) field takes WIDTHxHEIGHT."""
    f = {f.name: f for f in fields(cls)}[name]
    meta, hint = dict(f.metadata), typing.get_type_hints(cls)[name]
    default = f.default if default is MISSING else default
    flag = flag or "--" + name.replace("_", "-")
    if hint is bool:
        on = not default
        sp.add_argument(
            flag if on else "--no-" + flag[2:],
            dest=name,
            action="store_true" if on else "store_false",
            help=meta["help"] if on else f"do not {meta['help']} (without this flag, it does)",
        )
        return
    if typing.get_origin(hint) is tuple:
        shown, lo = "x".join(map(str, default)), meta.get("lo", 1)
        sp.add_argument(
            flag,
            dest=name,
            type=lambda text: size(text, lo, flag),
            default=default,
            help=f"{meta['help']} (default {shown}; each side {lo}..{MAX_SIDE} {meta['unit']})",
        )
        return
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        (hint,) = [a for a in typing.get_args(hint) if a is not type(None)]

    def parse(text: str):
        try:
            value = hint(text) if hint in (int, float) else text
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{flag} {text!r}: expected a {'whole ' if hint is int else ''}number"
            ) from None
        try:
            return check_value(hint, value, flag, meta)
        except SceneError as e:  # a number said as typed: 0, not 0.0
            shown = text if hint in (int, float) else repr(text)
            raise argparse.ArgumentTypeError(f"{flag} = {shown}: {e.allowed}") from None

    allowed = (
        "one of " + ", ".join(meta["choices"])
        if meta.get("choices")
        else describe_range(meta, hint)
    )
    sp.add_argument(
        flag,
        dest=name,
        type=parse,
        default=default,
        metavar=name.split("_")[-1].upper(),
        help=f"{meta['help']} ({allowed}; {note or f'default {default:g}'})",
    )


def render_option(sp: argparse.ArgumentParser, name: str) -> None:
    """``--NAME`` overriding the scene's ``[render] NAME`` (:class:`krsview.scene.Render`)."""
    field_option(sp, Render, name, default=None, note="overrides the scene's [render]")


def scene_options(sp: argparse.ArgumentParser) -> None:
    """The options every scene-drawing command takes: ε-scale, iteration cap, level count,
    effect set and the moment drawn."""
    render_option(sp, "epsilon_scale")
    render_option(sp, "max_iterations")
    sp.add_argument(
        "--levels",
        type=number_in("--levels", 1, MAX_LEVELS),
        help=f"keep only the coarsest N levels (drops the finest detail; at most the "
        f"scene's own, and ≤ {MAX_LEVELS})",
    )
    sp.add_argument(
        "--effects",
        metavar="LIST",
        help="comma-separated effects replacing the scene's, or 'none'; one of: "
        + ", ".join(EFFECTS),
    )
    time_option(sp)


def time_option(sp: argparse.ArgumentParser) -> None:
    """``--time``: the moment a moving scene is drawn or exported at."""
    sp.add_argument(
        "--time",
        type=float,
        metavar="SECONDS",
        help="the moment drawn, for scenes that move (wind, keyframe tracks, sway; "
        "default: the scene's [animation] time, else 0)",
    )


def preset(sp: argparse.ArgumentParser) -> None:
    """The optional PRESET argument (a scene file or a shipped preset's name)."""
    sp.add_argument("preset", nargs="?", default=DEFAULT_PRESET, metavar="PRESET")


def scene_of(args: argparse.Namespace, name: str | None = None) -> Scene:
    """The scene PRESET (or ``name``) names, with the render options, ``--effects`` and
    ``--levels`` given applied; errors name the option."""
    scene = api.load(name or args.preset)
    knobs = {k: v for k in api.RENDER_KNOBS if (v := getattr(args, k, None)) is not None}
    if "tracer" in knobs:
        scene.check_tracer(knobs["tracer"], "--tracer")
    tracer = knobs.get("tracer", scene.render.tracer)  # what configure refuses, said of flags
    if ignored := ignored_by_tracer(knobs, tracer):
        name, needs = ignored
        said = f"applies to --tracer {needs} (this run traces {tracer})"
        raise SceneError("--" + name.replace("_", "-"), knobs[name], said)
    scene = api.configure(scene, **knobs)
    effects = getattr(args, "effects", None)
    if effects is not None:
        if not effects.strip():
            raise SceneError("--effects", effects, "give effects by name, or 'none' for no effects")
        names = [] if effects.strip() == "none" else [e.strip() for e in effects.split(",")]
        scene = scene.with_effects(names, "--effects")
    levels = getattr(args, "levels", None)
    if levels is not None:
        scene = scene.with_levels(levels, "--levels")
    t = getattr(args, "time", None)
    return scene if t is None else scene.at(t, "--time")


FAST_KNOBS = ("prepass", "path", "steps")  # the [render] fields api.fast_settings may set


def fast_scene_of(args: argparse.Namespace, scene: Scene) -> Scene:
    """``scene`` (``scene_of(args)``) with the viewer's fast settings (api.fast_settings)
    where neither its file nor an option given sets them: an option given stands. Those of
    the device the GPU renderer draws on; --reference draws without GL, so with a CPU's."""
    given = {k: getattr(scene.render, k) for k in FAST_KNOBS if getattr(args, k, None) is not None}
    hardware = not getattr(args, "reference", False) and api.on_hardware()
    return api.configure(api.fast_settings(scene, hardware), **given)


class MissingExtra(RuntimeError):
    """An optional dependency is not installed (exit status 3, as for GL problems)."""


def require(*modules: str, extra: str, what: str) -> None:
    """An optional extra's packages are there, or one line says how to get them."""
    missing = [m for m in modules if importlib.util.find_spec(m) is None]
    if missing:
        raise MissingExtra(f"{what} needs {', '.join(missing)}: pip install 'krsview[{extra}]'")
