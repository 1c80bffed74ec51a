"""The one timing harness of the benchmarks: every variant is compiled and drawn once
(warm-up), then the variants are drawn round after round, interleaved, so machine noise hits
them alike, and each variant's median frame time is kept (DESIGN.md, Measure as ratios)."""

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


def median_times(
    r: Renderer, variants: dict[str, Variant], size: tuple[int, int], rounds: int, label: str
) -> dict[str, float]:
    """name → median seconds per frame over ``rounds`` interleaved rounds."""
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
    return {name: statistics.median(t) for name, t in times.items()}
