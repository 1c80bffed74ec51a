"""`krsview bench tracers`: sphere tracing against binary sphere tracing [KRS17 §6.1, §11].

The paper reports about twice the iterations for binary tracing and leaves ξ_bonus/ξ_penalty
unexplored (§12). On one KRS scene and view, in one run: sphere tracing, binary tracing at
the paper's (2.0, 0.3), and a small ξ sweep; frames interleaved round by round, fastest rounds
and ratios to sphere tracing. "Hit agreement" compares each hit mask with sphere tracing's.
"""

from __future__ import annotations

import itertools
from dataclasses import replace

import numpy as np

from ..gpu.renderer import Renderer
from ..scene import Scene, SceneError
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

BONUS = (1.5, 2.0, 3.0)
PENALTY = (0.2, 0.3, 0.5)


def variants(scene: Scene, sweep: bool) -> dict[str, Scene]:
    """name → scene: sphere (KRS only), binary at the paper's ξ, then the ξ sweep."""
    out = {}
    if scene.mokrs is None:
        out["sphere"] = replace(scene, render=replace(scene.render, tracer="sphere"))
    pairs = [(2.0, 0.3)] + (
        [p for p in itertools.product(BONUS, PENALTY) if p != (2.0, 0.3)] if sweep else []
    )
    for b, p in pairs:
        out[f"binary {b:g}/{p:g}"] = replace(
            scene, render=replace(scene.render, tracer="binary", xi_bonus=b, xi_penalty=p)
        )
    return out


def bench_tracers(
    scene: Scene, size: tuple[int, int], rounds: int = 5, sweep: bool = True
) -> Measured:
    """One row per tracer setting: iterations per pixel (median, mean, ratio to the first),
    ms per frame, time ratio, hit fraction and agreement with the first's hit mask."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    if scene.mokrs is not None and not sweep:
        raise SceneError(
            "--no-sweep",
            True,
            "a MöKRS has only the binary tracer; keep the ξ sweep to have something to compare",
        )
    w, h = size
    runs = variants(scene, sweep)
    r = Renderer()
    buffers = {name: r.render(s, w, h) for name, s in runs.items()}
    times = round_times(
        r,
        {name: Variant(s) for name, s in runs.items()},
        size,
        rounds,
        f"bench tracers {scene.name}",
    )
    best = fastest(times)
    base = next(iter(runs))
    t0 = best[base]
    it0 = float(np.mean(buffers[base].iterations))
    rows = []
    for name, s in runs.items():
        b, t = buffers[name], best[name]
        lo, hi = ratio_range(times[name], times[base])
        binary = s.render.tracer == "binary"
        rows.append(
            dict(
                tracer=s.render.tracer,
                xi_bonus=s.render.xi_bonus if binary else "",
                xi_penalty=s.render.xi_penalty if binary else "",
                median_iterations=float(np.median(b.iterations)),
                mean_iterations=float(np.mean(b.iterations)),
                iteration_ratio=float(np.mean(b.iterations)) / it0,
                **time_columns(times[name]),
                time_ratio=t / t0,
                time_ratio_min=lo,
                time_ratio_max=hi,
                hit_fraction=float(b.hit.mean()),
                hit_agreement=float((b.hit == buffers[base].hit).mean()),
            )
        )
    return Measured(scene, size, rounds, rows)


def table(m: Measured) -> str:
    first = m.rows[0]
    base = (
        "sphere"
        if first["tracer"] == "sphere"
        else f"binary {first['xi_bonus']:g}/{first['xi_penalty']:g}"
    )
    text = (
        f"\nSphere vs binary tracing — {m.scene.name}, {m.size[0]}×{m.size[1]}, ε-scale "
        f"{m.scene.render.epsilon_scale}, ms {TIME_SPREAD} of {m.rounds} interleaved rounds "
        f"(ratios to {base}; time ratios with the [min–max] of their round-by-round ratio, "
        "within noise where that holds 1×)\n\n"
    )
    text += markdown(
        (
            "tracer",
            "ξ_bonus",
            "ξ_penalty",
            "median it/px",
            "mean it/px",
            "iteration ratio",
            "ms/frame",
            "time ratio",
            "hit agreement",
        ),
        "lrrrrrrrr",
        (
            (
                r["tracer"],
                r["xi_bonus"],
                r["xi_penalty"],
                f"{r['median_iterations']:.0f}",
                f"{r['mean_iterations']:.1f}",
                f"{r['iteration_ratio']:.2f}",
                ms_spread(r),
                "1.00×"  # the base row: a ratio to itself
                if k == 0
                else with_range(r["time_ratio"], r["time_ratio_min"], r["time_ratio_max"]),
                f"{r['hit_agreement']:.2%}",
            )
            for k, r in enumerate(m.rows)
        ),
    )
    binaries = [row for row in m.rows if row["tracer"] == "binary"]
    if len(binaries) > 1:
        fast = min(binaries, key=lambda row: row["ms"])
        few = min(binaries, key=lambda row: row["mean_iterations"])
        text += (
            f"\n\nfastest ξ pair: {fast['xi_bonus']}/{fast['xi_penalty']} "
            f"({with_range(fast['time_ratio'], fast['time_ratio_min'], fast['time_ratio_max'])} "
            f"{base}); fewest iterations: "
            f"{few['xi_bonus']}/{few['xi_penalty']} ({few['mean_iterations']:.1f} it/px)"
        )
    return text
