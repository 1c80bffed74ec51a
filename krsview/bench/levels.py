"""`krsview bench levels`: frame time against the number of levels [KRS17 §11, Fig. 12].

The paper's claim: the expansion grows as 2^n while the time per ray grows linearly in n.
Level counts are interleaved round by round and medians compared, so machine noise hits
every variant alike.
"""

from __future__ import annotations

import numpy as np

from ..gpu.renderer import Renderer
from ..scene import Scene
from .harness import Variant, median_times
from .report import write_csv


def level_counts(total: int, step: int) -> list[int]:
    counts = list(range(step, total + 1, step))
    if not counts or counts[-1] != total:
        counts.append(total)
    return counts


def bench_levels(
    scene: Scene, size: tuple[int, int], step: int = 4, rounds: int = 5, csv: str | None = None
) -> list[dict]:
    w, h = size
    krs = scene.geometry()
    counts = level_counts(krs.depth, step)
    variants = {m: krs.truncated(m) for m in counts}
    r = Renderer()
    iters = {m: float(r.render(scene, w, h, k).iterations.mean()) for m, k in variants.items()}
    med = median_times(
        r,
        {f"{m} levels": Variant(scene, variants[m]) for m in counts},
        size,
        rounds,
        f"bench levels {scene.name}",
    )
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
            )
        )
    print(
        f"\nFrame time against levels — {scene.name}, {w}×{h}, median of {rounds} "
        f"interleaved rounds (ratios to {base} levels)\n"
    )
    print(
        "| levels | kernel instances | ms/frame | time ratio | iterations/px | "
        "time/iteration ratio |"
    )
    print("|---:|---:|---:|---:|---:|---:|")
    for row in rows:
        print(
            f"| {row['levels']} | {row['instances']:,} | {row['ms']:.2f} | "
            f"{row['time_ratio']:.2f} | {row['iterations']:.1f} | "
            f"{row['ratio_per_iteration']:.2f} |"
        )
    if len(rows) >= 3:
        n = np.array([row["levels"] for row in rows], float)
        t = np.array([row["ms"] for row in rows])
        slope, icpt = np.polyfit(n, t, 1)
        resid = t - (slope * n + icpt)
        r2 = 1 - (resid @ resid) / max(((t - t.mean()) ** 2).sum(), 1e-30)
        grow = rows[-1]["instances"] / max(rows[0]["instances"], 1)
        print(
            f"\nlinear fit: {icpt:.2f} ms + {slope:.3f} ms/level (R² = {r2:.3f}); geometry grew "
            f"{grow:,.0f}× while time grew {rows[-1]['time_ratio']:.2f}×"
        )
    if csv:
        write_csv(rows, csv)
    return rows
