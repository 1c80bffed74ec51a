"""The one timing harness of the benchmarks: every variant is compiled and drawn once (warm-up),
then the variants are drawn round after round, interleaved, so machine noise hits them alike
(docs/architecture.md, Measure as ratios). A variant's time is its fastest round: load from
other work only ever adds time, so the fastest round is the estimate it disturbs least, and
on a shared machine, where up to half the rounds run slow, medians move while it holds [Chen
and Revels 2016, the estimator of Julia's BenchmarkTools]. The median and the slowest round
stay beside it, and a ratio carries the [min–max] of its round-by-round ratio. The noise
floor of a run is the spread between the times of variants that do the same work: a time
difference under it is not a measurement."""

from __future__ import annotations

import statistics
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..gpu.renderer import Renderer
from ..inputs import scene_of, size_of, whole
from ..progress import Progress
from ..scene import Geometry, Scene


@dataclass(frozen=True)
class Variant:
    scene: Scene
    geometry: Geometry | None = None  # None: the scene's own
    all_effects: bool = False  # the variant with every effect switched by uniforms
    prepass_only: bool = False  # time the pre-pass's coarse passes alone
    probes: tuple[str, ...] = ()  # a measuring variant's defines (Renderer.prepare)


MAX_ROUNDS = 1000  # interleaved rounds a benchmark takes


def bench_inputs(scene: Any, size: Any, rounds: Any) -> tuple[Scene, tuple[int, int], int]:
    """A benchmark's common arguments checked before any work, as the API checks its own
    (krsview/inputs.py): a scene, a preset's name or a file; (width, height); rounds ≥ 1."""
    return scene_of(scene), size_of(size), whole(rounds, "rounds", 1, MAX_ROUNDS)


def round_times(
    r: Renderer, variants: dict[str, Variant], size: tuple[int, int], rounds: int, label: str
) -> dict[str, list[float]]:
    """name → seconds per frame in each of ``rounds`` interleaved rounds (in order)."""
    timers = {name: frame_timer(r, v, size) for name, v in variants.items()}
    return interleaved(timers, rounds, f"{label} {size[0]}×{size[1]}")


def frame_timer(r: Renderer, v: Variant, size: tuple[int, int]) -> Callable[[], float]:
    """A timer of one frame of ``v``: seconds, GPU finished (Renderer.time_frame draws it
    once untimed first)."""
    return lambda: r.time_frame(
        v.scene,
        *size,
        v.geometry,
        all_effects=v.all_effects,
        prepass_only=v.prepass_only,
        probes=v.probes,
    )[0]


def interleaved(
    timers: dict[str, Callable[[], float]], rounds: int, label: str
) -> dict[str, list[float]]:
    """name → the seconds its timer returned in each of ``rounds`` rounds (in order): every
    timer is called once first (warm-up), then once per round, one after the other, so machine
    noise hits them alike. A timer times one frame of its own (a renderer's, or a peer's)."""
    for timer in timers.values():
        timer()
    times: dict[str, list[float]] = {name: [] for name in timers}
    bar = Progress(rounds * len(timers), label)
    for _ in range(rounds):
        for name, timer in timers.items():
            times[name].append(timer())
            bar.step(name)
    return times


def fastest(times: dict[str, list[float]]) -> dict[str, float]:
    """name → its fastest round: the time its work takes, least disturbed by load."""
    return {name: min(t) for name, t in times.items()}


def time_columns(t: list[float]) -> dict[str, float]:
    """A variant's time columns from its per-round seconds: ``ms`` (the fastest round),
    ``ms_median`` and ``ms_max`` (the slowest), milliseconds."""
    return dict(ms=min(t) * 1e3, ms_median=statistics.median(t) * 1e3, ms_max=max(t) * 1e3)


def ratio_range(num: list[float], den: list[float]) -> tuple[float, float]:
    """The [min, max] of the round-by-round ratio ``num[k] / den[k]`` of two variants timed
    in the same interleaved rounds: the spread their ratio carries (the ratio of their fastest
    rounds always lies inside it)."""
    per_round = [a / b for a, b in zip(num, den, strict=True)]
    return min(per_round), max(per_round)


def with_range(value: float, lo: float, hi: float) -> str:
    """``value`` with its round-by-round [lo–hi], said to be within noise where that range
    holds 1 (the rounds disagree on which side of 1 it lies)."""
    noise = " within noise" if lo <= 1 <= hi else ""
    return f"{value:.2f}× [{lo:.2f}–{hi:.2f}]{noise}"


def noise_floor(
    groups: list[list[list[float]]], estimate: Callable[[list[float]], float] = min
) -> float:
    """The largest relative spread (max/min − 1) between the ``estimate`` (the fastest
    round, or the median for comparison) of variants that do the same work; each group is a
    list of per-round times, one per variant. 0 where no group has two variants (nothing
    measured the noise)."""
    spreads = [
        max(est) / min(est) - 1 for est in ([estimate(t) for t in g] for g in groups if len(g) >= 2)
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
