"""`krsview bench paths`: what each speed lever of issue 17 buys, measured side by side —
exact level culling on and off and the low-resolution pre-pass off and at several tile sizes
(with the default coarse passes, and with one) on the fragment path, the compute path at
several iterations per round (shadow rays as tasks and inline, where the scene has shadows)
and with persistent lanes (steps 0, at the viewer's pre-pass), at two resolutions;
frame-time ratios against the plain frame (fragment path, no culling, no pre-pass),
iterations and levels of Alg. 1 walked per pixel in the full pass (a KRS), and the coarse
passes' share of the frame. Variants are interleaved round by round (bench/harness.py)."""

from __future__ import annotations

from dataclasses import replace

from ..gpu.renderer import Renderer
from ..scene import Scene
from ..scene.render import VIEW_PREPASS
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

TILES = (0, 4, 8, 16)  # pre-pass tile sizes compared (0: off)
ONE_PASS_TILES = (4, 8)  # also timed with a single coarse pass (prepass_levels = 1)
STEPS = (4, 8, 16, 32)  # compute path: iterations per ray per round
COMPUTE_TILE = 8  # the compute path is timed with culling and this pre-pass


def lever(
    scene: Scene,
    path: str,
    culling: str,
    tile: int,
    steps: int,
    shadow_tasks: str = "on",
    passes: int | None = None,
) -> Scene:
    r = scene.render
    return replace(
        scene,
        render=replace(
            r,
            path=path,
            culling=culling,
            prepass=tile,
            steps=steps,
            shadow_tasks=shadow_tasks,
            prepass_levels=passes or r.prepass_levels,
        ),
    )


def levers(scene: Scene) -> dict[tuple, Scene]:
    """(path, culling, tile, coarse passes, steps, shadow rays) → the scene drawn so; coarse
    passes 0 without a pre-pass; steps 0 on the fragment path, and on the compute path its
    persistent lanes; shadow rays "tasks" or "inline" on the compute path's rounds of a scene
    with shadows, else ""."""
    shadowed = bool({"shadows", "soft_shadows"} & set(scene.effects))
    passes = scene.render.prepass_levels
    out = {
        ("fragment", c, t, passes if t else 0, 0, ""): lever(
            scene, "fragment", c, t, scene.render.steps
        )
        for c in ("off", "on")
        for t in TILES
    }
    out.update(
        {
            ("fragment", "on", t, 1, 0, ""): lever(
                scene, "fragment", "on", t, scene.render.steps, passes=1
            )
            for t in ONE_PASS_TILES
            if passes != 1
        }
    )
    out.update(
        {
            ("compute", "on", COMPUTE_TILE, passes, s, "tasks" if shadowed else ""): lever(
                scene, "compute", "on", COMPUTE_TILE, s
            )
            for s in STEPS
        }
    )
    out[("compute", "on", VIEW_PREPASS, passes, 0, "")] = lever(  # persistent lanes
        scene, "compute", "on", VIEW_PREPASS, 0
    )
    if shadowed:
        out.update(
            {
                ("compute", "on", COMPUTE_TILE, passes, s, "inline"): lever(
                    scene, "compute", "on", COMPUTE_TILE, s, "off"
                )
                for s in STEPS
            }
        )
    return out


def lever_name(k: tuple) -> str:
    """A lever's key as words: "compute, culling on, pre-pass 8 × 2, 16 per round"."""
    return (
        f"{k[0]}, culling {k[1]}, pre-pass {k[2] or 'off'}"
        + (f" × {k[3]}" if k[3] else "")
        + (f", {k[4]} per round" if k[4] else ", persistent lanes" if k[0] == "compute" else "")
        + (f", shadow rays {k[5]}" if k[5] else "")
    )


def bench_paths(scene: Scene, size: tuple[int, int], rounds: int = 5) -> Measured:
    """One row per lever (:func:`levers`) at ``size`` and twice it: ms per frame, speed-up
    against the plain frame, iterations and levels walked per pixel, coarse passes' share."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    r = Renderer()
    rows = []
    for w, h in (size, (2 * size[0], 2 * size[1])):
        variants = levers(scene)
        tiles = {k[1:4]: s for k, s in variants.items() if k[2]}
        alone = {f"pre-pass alone {k}": Variant(s, prepass_only=True) for k, s in tiles.items()}
        times = round_times(  # the coarse passes alone in the same rounds as the frames
            r,
            {lever_name(k): Variant(s) for k, s in variants.items()} | alone,
            (w, h),
            rounds,
            f"bench paths {scene.name}",
        )
        best = fastest(times)
        coarse = {k: best[f"pre-pass alone {k}"] for k in tiles}
        plain = lever_name(("fragment", "off", 0, 0, 0, ""))
        base = best[plain]
        for k, s in variants.items():
            t = best[lever_name(k)]
            lo, hi = ratio_range(times[plain], times[lever_name(k)])
            rows.append(
                dict(
                    size=f"{w}x{h}",
                    path=k[0],
                    culling=k[1],
                    prepass=k[2],
                    coarse_passes=k[3],
                    steps=k[4],
                    shadow_rays=k[5],
                    **time_columns(times[lever_name(k)]),
                    speedup=base / t,
                    speedup_min=lo,  # the round-by-round ratio's spread
                    speedup_max=hi,
                    iterations=float(r.render(s, w, h).iterations.mean()),
                    levels=float(r.levels(s, w, h).mean()),
                    coarse_share=coarse.get(k[1:4], 0.0) / t,
                )
            )
    return Measured(scene, size, rounds, rows)


def share(x: float) -> str:
    """A coarse pass share; above the whole frame it is timing noise (a frame of a
    millisecond or less, where the passes alone read slower than the frame holding them)."""
    return f"{x:.0%}" if x <= 1.0 else "— (noise)"


def table(m: Measured) -> str:
    caption = (
        f"\nSpeed levers — {m.scene.name}, ms {TIME_SPREAD} of {m.rounds} interleaved rounds; "
        "speed-up "
        "against the fragment path without culling or pre-pass at the same size, with the "
        "[min–max] of its round-by-round ratio: where that range holds 1×, the difference is "
        "within noise\n\n"
    )
    return caption + markdown(
        (
            "size",
            "path",
            "culling",
            "pre-pass tile",
            "coarse passes",
            "iterations per round",
            "shadow rays",
            "ms/frame",
            "speed-up",
            "iterations/px (full pass)",
            "levels walked/px",
            "coarse pass share",
        ),
        "lllrrrlrrrrr",
        (
            (
                r["size"],
                r["path"],
                r["culling"],
                r["prepass"] or "off",
                r["coarse_passes"] or "—",
                r["steps"] or "—",
                r["shadow_rays"] or "—",
                ms_spread(r),
                with_range(r["speedup"], r["speedup_min"], r["speedup_max"]),
                f"{r['iterations']:.1f}",
                f"{r['levels']:.1f}",
                share(r["coarse_share"]),
            )
            for r in m.rows
        ),
    )
