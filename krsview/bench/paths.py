"""`krsview bench paths`: what each speed lever of issue 17 buys, measured side by side —
exact level culling on and off, the low-resolution pre-pass off and at several tile sizes,
at two resolutions; frame-time ratios against the plain frame (no culling, no pre-pass),
iterations per pixel of the full pass, and the coarse pass's share of the frame.
Variants are interleaved round by round (bench/harness.py)."""
from __future__ import annotations

from dataclasses import replace

from ..gpu.renderer import Renderer
from ..scene import Scene
from .harness import Variant, median_times
from .report import write_csv

TILES = (0, 4, 8, 16)    # pre-pass tile sizes compared (0: off)


def lever(scene: Scene, culling: str, tile: int) -> Scene:
    return replace(scene, render=replace(scene.render, culling=culling, prepass=tile))


def bench_paths(scene: Scene, size: tuple[int, int], rounds: int = 5,
                csv: str | None = None) -> list[dict]:
    r = Renderer()
    sizes = [size, (2 * size[0], 2 * size[1])]
    rows = []
    for w, h in sizes:
        levers = {(c, t): lever(scene, c, t) for c in ("off", "on") for t in TILES}
        names = {k: f"culling {k[0]}, pre-pass {k[1] or 'off'}" for k in levers}
        med = median_times(r, {names[k]: Variant(s) for k, s in levers.items()}, (w, h),
                           rounds, f"bench paths {scene.name}")
        coarse = {k: median_times(r, {names[k]: Variant(s, prepass_only=True)}, (w, h),
                                  rounds, "pre-pass alone")[names[k]]
                  for k, s in levers.items() if k[1]}
        base = med[names[("off", 0)]]
        for k, s in levers.items():
            t = med[names[k]]
            rows.append(dict(size=f"{w}x{h}", culling=k[0], prepass=k[1], ms=t * 1e3,
                             speedup=base / t,
                             iterations=float(r.render(s, w, h).iterations.mean()),
                             coarse_share=coarse.get(k, 0.0) / t))
    print(f"\nSpeed levers — {scene.name}, median of {rounds} interleaved rounds; speed-up "
          "against culling off, pre-pass off at the same size\n")
    print("| size | culling | pre-pass tile | ms/frame | speed-up | iterations/px (full pass) "
          "| coarse pass share |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for row in rows:
        print(f"| {row['size']} | {row['culling']} | {row['prepass'] or 'off'} | "
              f"{row['ms']:.1f} | {row['speedup']:.2f}× | {row['iterations']:.1f} | "
              f"{row['coarse_share']:.0%} |")
    if csv:
        write_csv(rows, csv)
    return rows
