"""The one timing harness of the benchmarks: every variant is compiled and drawn once
(warm-up), then the variants are drawn round after round, interleaved, so machine noise hits
them alike, and each variant's median frame time is kept (DESIGN.md, Measure as ratios).
The noise floor of a run is the spread between the medians of variants that do the same
work: a time difference under it is not a measurement."""

from __future__ import annotations

import statistics
from dataclasses import dataclass

from ..gpu.renderer import Renderer
from ..progress import Progress
from ..scene import Geometry, Scene


@dataclass(frozen=True)
class Variant:
    scene: Scene
    geometry: Geometry | None = None  # None: the scene's own
    all_effects: bool = False  # the variant with every effect switched by uniforms
    prepass_only: bool = False  # time the pre-pass's coarse passes alone
    probes: tuple[str, ...] = ()  # a measuring variant's defines (Renderer.prepare)


def round_times(
    r: Renderer, variants: dict[str, Variant], size: tuple[int, int], rounds: int, label: str
) -> dict[str, list[float]]:
    """name → seconds per frame in each of ``rounds`` interleaved rounds (in order)."""
    w, h = size
    for v in variants.values():
        r.time_frame(
            v.scene,
            w,
            h,
            v.geometry,
            all_effects=v.all_effects,
            prepass_only=v.prepass_only,
            probes=v.probes,
        )
    times: dict[str, list[float]] = {name: [] for name in variants}
    bar = Progress(rounds * len(variants), f"{label} {w}×{h}")
    for _ in range(rounds):
        for name, v in variants.items():
            times[name] += r.time_frame(
                v.scene,
                w,
                h,
                v.geometry,
                repeats=1,
                all_effects=v.all_effects,
                prepass_only=v.prepass_only,
                probes=v.probes,
            )
            bar.step(name)
    return times


def median_times(
    r: Renderer, variants: dict[str, Variant], size: tuple[int, int], rounds: int, label: str
) -> dict[str, float]:
    """name → median seconds per frame over ``rounds`` interleaved rounds."""
    times = round_times(r, variants, size, rounds, label)
    return {name: statistics.median(t) for name, t in times.items()}


def noise_floor(groups: list[list[list[float]]]) -> float:
    """The largest relative spread (max/min − 1) between the medians of variants that do the
    same work; each group is a list of per-round times, one per variant. 0 where no group has
    two variants (nothing measured the noise)."""
    spreads = [
        max(meds) / min(meds) - 1
        for meds in ([statistics.median(t) for t in g] for g in groups if len(g) >= 2)
    ]
    return max(spreads, default=0.0)


def change(new: float, old: float, floor: float) -> str:
    """``new`` against ``old`` as a relative time change, said to be within noise where the
    ratio differs from 1 by no more than the noise ``floor``."""
    ratio = new / old - 1
    if abs(ratio) <= floor:
        return f"{percent(ratio)} time (within noise: floor {floor:.1%})"
    return f"{percent(ratio)} time"


def percent(ratio: float) -> str:
    """A relative change as a signed whole percentage, 0 unsigned (no "-0%")."""
    text = f"{ratio:+.0%}"
    return "0%" if text in ("+0%", "-0%") else text
