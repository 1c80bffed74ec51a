"""`krsview bench levels`: frame time against the number of levels [KRS17 §11, Fig. 12].

The paper's claim: the expansion grows as 2^n while the time per ray grows linearly in n.
Level counts are interleaved round by round and medians compared, so machine noise hits
every variant alike.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..gpu.renderer import Renderer
from ..inputs import whole
from ..scene import Scene
from .harness import Variant, bench_inputs, median_times
from .report import Measured, markdown


def level_counts(total: int, step: int) -> list[int]:
    counts = list(range(step, total + 1, step))
    if not counts or counts[-1] != total:
        counts.append(total)
    return counts


def bench_levels(scene: Scene, size: tuple[int, int], step: int = 4, rounds: int = 5) -> Measured:
    """One row per level count (every ``step`` levels, and all): kernel instances, ms per
    frame, time ratio to the fewest levels, iterations per pixel, time per iteration ratio."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    step = whole(step, "step", 1)
    w, h = size
    krs = scene.geometry()
    counts = level_counts(krs.depth, step)
    variants = {m: krs.truncated(m) for m in counts}
    r = Renderer()
    iters = {m: float(r.render(scene, w, h, k).iterations.mean()) for m, k in variants.items()}
    every = replace(scene, render=replace(scene.render, lod=0.0))  # today's walk, beside it
    timed = {f"{m} levels": Variant(scene, variants[m]) for m in counts}
    timed |= {f"{m} levels, every level": Variant(every, variants[m]) for m in counts}
    med = median_times(r, timed, size, rounds, f"bench levels {scene.name}")
    base = counts[0]
    t_base = med[f"{base} levels"]
    rows = []
    for m in counts:
        t = med[f"{m} levels"]
        rows.append(
            dict(
                levels=m,
                instances=variants[m].instance_count(),
                ms=t * 1e3,
                time_ratio=t / t_base,
                iterations=iters[m],
                ratio_per_iteration=(t / iters[m]) / (t_base / iters[base]),
                ms_every_level=med[f"{m} levels, every level"] * 1e3,
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
        f"{m.scene.render.lod:g} beside every level, median of {m.rounds} interleaved rounds "
        f"(ratios to {rows[0]['levels']} levels)\n\n"
    )
    text += markdown(
        (
            "levels",
            "kernel instances",
            "ms/frame",
            "time ratio",
            "iterations/px",
            "time/iteration ratio",
            "ms/frame, every level (lod 0)",
        ),
        "rrrrrrr",
        (
            (
                r["levels"],
                f"{r['instances']:,}",
                f"{r['ms']:.2f}",
                f"{r['time_ratio']:.2f}",
                f"{r['iterations']:.1f}",
                f"{r['ratio_per_iteration']:.2f}",
                f"{r['ms_every_level']:.2f}",
            )
            for r in rows
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
