"""`krsview bench levels`: frame time against the number of levels [KRS17 §11, Fig. 12].

The paper's claim: the expansion grows as 2^n while the time per ray grows linearly in n.
Level counts are interleaved round by round and their fastest rounds compared, so machine
noise hits every variant alike.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..gpu.renderer import Renderer
from ..inputs import whole
from ..scene import Scene
from .harness import (
    Variant,
    bench_inputs,
    fastest,
    ratio_range,
    round_times,
    time_columns,
    with_range,
)
from .report import TIME_SPREAD, Measured, markdown, ms_spread


def level_counts(total: int, step: int) -> list[int]:
    counts = list(range(step, total + 1, step))
    if not counts or counts[-1] != total:
        counts.append(total)
    return counts


def bench_levels(scene: Scene, size: tuple[int, int], step: int = 4, rounds: int = 5) -> Measured:
    """One row per level count (every ``step`` levels, and all): kernel instances, ms per
    frame (fastest round, median, slowest), time ratio to the fewest levels and to the row
    before (each with its round-by-round [min, max]), iterations per pixel, time per
    iteration ratio, and every level walked (lod 0) beside it."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    step = whole(step, "step", 1)
    w, h = size
    krs = scene.geometry()
    counts = level_counts(krs.depth, step)
    variants = {m: krs.truncated(m) for m in counts}
    r = Renderer()
    iters = {m: float(r.render(scene, w, h, k).iterations.mean()) for m, k in variants.items()}
    all_levels = replace(scene, render=replace(scene.render, lod=0.0))  # every level, beside
    timed = {f"{m} levels": Variant(scene, variants[m]) for m in counts}
    timed |= {f"{m} levels, every level": Variant(all_levels, variants[m]) for m in counts}
    times = round_times(r, timed, size, rounds, f"bench levels {scene.name}")
    best = fastest(times)
    base = counts[0]
    t_base = best[f"{base} levels"]
    rows = []
    for before, m in zip([base, *counts], counts):
        name, t = f"{m} levels", best[f"{m} levels"]
        every = times[f"{name}, every level"]
        lo, hi = ratio_range(times[name], times[f"{base} levels"])
        prev_lo, prev_hi = ratio_range(times[name], times[f"{before} levels"])
        gain_lo, gain_hi = ratio_range(every, times[name])
        rows.append(
            dict(
                levels=m,
                instances=variants[m].instance_count(),
                **time_columns(times[name]),
                time_ratio=t / t_base,
                time_ratio_min=lo,
                time_ratio_max=hi,
                to_previous=t / best[f"{before} levels"],  # 1 in the first row
                to_previous_min=prev_lo,
                to_previous_max=prev_hi,
                iterations=iters[m],
                ratio_per_iteration=(t / iters[m]) / (t_base / iters[base]),
                ms_every_level=min(every) * 1e3,
                lod_speedup=min(every) / t,
                lod_speedup_min=gain_lo,
                lod_speedup_max=gain_hi,
            )
        )
    return Measured(scene, size, rounds, rows)


def linear_fit(m: Measured) -> tuple[float, float, float]:
    """Frame time against levels as a line: (intercept ms, slope ms/level, R²)."""
    n = np.array(m.column("levels"), float)
    t = np.array(m.column("ms"))
    slope, icpt = np.polyfit(n, t, 1)
    resid = t - (slope * n + icpt)
    return icpt, slope, 1 - (resid @ resid) / max(((t - t.mean()) ** 2).sum(), 1e-30)


def table(m: Measured) -> str:
    rows = m.rows
    text = (
        f"\nFrame time against levels — {m.scene.name}, {m.size[0]}×{m.size[1]}, lod "
        f"{m.scene.render.lod:g} beside every level, ms {TIME_SPREAD} of {m.rounds} "
        f"interleaved rounds; ratios to {rows[0]['levels']} levels and to the row before, "
        "each with the [min–max] of its round-by-round ratio (within noise where that holds "
        "1×)\n\n"
    )
    text += markdown(
        (
            "levels",
            "kernel instances",
            "ms/frame",
            "time ratio",
            "× row before",
            "iterations/px",
            "time/iteration ratio",
            "ms/frame, every level (lod 0)",
            "lod's speed-up",
        ),
        "rrrrrrrrr",
        (
            (
                r["levels"],
                f"{r['instances']:,}",
                ms_spread(r, 2),
                "1.00×"  # the base row: a ratio to itself
                if k == 0
                else with_range(r["time_ratio"], r["time_ratio_min"], r["time_ratio_max"]),
                "—"
                if k == 0
                else with_range(r["to_previous"], r["to_previous_min"], r["to_previous_max"]),
                f"{r['iterations']:.1f}",
                f"{r['ratio_per_iteration']:.2f}",
                f"{r['ms_every_level']:.2f}",
                with_range(r["lod_speedup"], r["lod_speedup_min"], r["lod_speedup_max"]),
            )
            for k, r in enumerate(rows)
        ),
    )
    if len(rows) >= 3:
        icpt, slope, r2 = linear_fit(m)
        grow = rows[-1]["instances"] / max(rows[0]["instances"], 1)
        text += (
            f"\n\nlinear fit: {icpt:.2f} ms + {slope:.3f} ms/level (R² = {r2:.3f}); geometry "
            f"grew {grow:,.0f}× while time grew {rows[-1]['time_ratio']:.2f}×"
        )
    return text
