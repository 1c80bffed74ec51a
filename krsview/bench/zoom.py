"""`krsview bench zoom`: a straight flight from the scene's view into the tip of its finest
kernel, twenty and more levels down a tree, with the frame time and the work per frame at
each stop [issue 27 §2; SVO12 flies a 10^11 zoom at a constant frame rate]. Detail below the
pixel should cost nothing; this bench shows where it still does (iterations per pixel and
levels walked per iteration, both deterministic), with the slowest frame against the
fastest."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..compile.balls import kernel_ball
from ..gpu.renderer import Renderer
from ..inputs import whole
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

END_RADII = 3.0  # the last stop is this many of the finest kernel's ball radii from its centre


def finest_kernel_ball(scene: Scene) -> np.ndarray:
    """(centre, radius) of the finest non-empty kernel K_i as the KRS holds it (one of its
    2^n instances: the branch every fold leaves in place), in world coordinates."""
    g = scene.single_krs("bench zoom flies into one KRS's finest kernel")
    for kernel in g.kernels:
        ball = kernel_ball(kernel)
        if ball is not None:
            return ball
    raise SceneError("PRESET", scene.name, "no bounded kernel to fly into")


def stops(scene: Scene, count: int) -> list[Scene]:
    """``count`` cameras on the line from the scene's eye to the finest kernel, looking at
    it, at distances in geometric progression (a constant zoom rate) down to END_RADII of
    its radius."""
    ball = finest_kernel_ball(scene)
    centre, radius = ball[:3], ball[3]
    eye = np.array(scene.camera.position, dtype=np.float64)
    far = float(np.linalg.norm(eye - centre))
    near = min(END_RADII * radius, far)
    out = []
    for d in np.geomspace(far, near, count):
        position = centre + (eye - centre) * (d / far)
        camera = replace(
            scene.camera, position=tuple(map(float, position)), target=tuple(map(float, centre))
        )
        out.append(replace(scene, camera=camera))
    return out


def bench_zoom(
    scene: Scene, size: tuple[int, int], rounds: int = 5, stops_count: int = 12, plot=None
) -> Measured:
    """One row per stop: distance to the kernel, ms per frame (interleaved rounds' fastest),
    iterations per pixel, levels walked per iteration, hit fraction, and beside them every
    level (lod 0) and the other walk (``[render] walk_restart`` switched); ``plot``: a PNG path
    for the plot of time and work along the flight."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    stops_count = whole(stops_count, "stops_count", 2, 1000)
    w, h = size
    views = stops(scene, stops_count)
    r = Renderer()
    centre = finest_kernel_ball(scene)[:3]
    names = [f"stop {k}" for k in range(len(views))]
    every = [replace(v, render=replace(v.render, lod=0.0)) for v in views]
    walk = "off" if scene.render.walk_restart == "on" else "on"  # the other walk, beside it
    other = [replace(v, render=replace(v.render, walk_restart=walk)) for v in views]
    variants = {n: Variant(v) for n, v in zip(names, views)}
    variants |= {f"{n}, every level": Variant(v) for n, v in zip(names, every)}
    variants |= {f"{n}, restart {walk}": Variant(v) for n, v in zip(names, other)}
    times = round_times(r, variants, size, rounds, f"bench zoom {scene.name}")
    best = fastest(times)
    rows = []
    for name, v, e, o in zip(names, views, every, other):
        frame = r.render(v, w, h)
        walked = r.levels(v, w, h)
        iterations = float(frame.iterations.mean())
        other_frame = r.render(o, w, h)
        rows.append(
            dict(
                stop=name,
                distance=float(np.linalg.norm(np.array(v.camera.position) - centre)),
                **time_columns(times[name]),
                ms_every_level=best[f"{name}, every level"] * 1e3,
                iterations=iterations,
                levels_per_iteration=float(walked.sum() / max(frame.iterations.sum(), 1)),
                levels_every_level=float(
                    r.levels(e, w, h).sum() / max(r.render(e, w, h).iterations.sum(), 1)
                ),
                hit=float(frame.hit.mean()),
                ms_other_walk=best[f"{name}, restart {walk}"] * 1e3,
                levels_other_walk=float(
                    r.levels(o, w, h).sum() / max(other_frame.iterations.sum(), 1)
                ),
            )
        )
    for column, suffix in (
        ("ms", ""),
        ("ms_every_level", ", every level"),
        ("ms_other_walk", f", restart {walk}"),
    ):
        to_fastest(rows, column, [times[name + suffix] for name in names])
    m = Measured(scene, size, rounds, rows)
    if plot is not None:
        write_plot(m, plot)
    return m


def to_fastest(rows: list[dict], column: str, stops: list[list[float]]) -> None:
    """Each stop's round-by-round ratio to the fastest stop's (``stops``: per-round seconds,
    one list per row), as the row's ``{column}_to_fastest_min`` and ``_max``: the spread of
    the zoom's slowest ÷ fastest frame."""
    quickest = min(stops, key=min)
    for row, t in zip(rows, stops, strict=True):
        lo, hi = ratio_range(t, quickest)
        row |= {f"{column}_to_fastest_min": lo, f"{column}_to_fastest_max": hi}


def spread(m: Measured, column: str = "ms") -> float:
    """The slowest frame's time over the fastest's along the flight (fastest rounds)."""
    return max(m.column(column)) / min(m.column(column))


def spread_text(m: Measured, column: str = "ms") -> str:
    """:func:`spread` with the [min–max] of the slowest stop's round-by-round ratio to the
    fastest's."""
    slowest = max(m.rows, key=lambda row: row[column])
    lo, hi = slowest[f"{column}_to_fastest_min"], slowest[f"{column}_to_fastest_max"]
    return with_range(spread(m, column), lo, hi)


def table(m: Measured) -> str:
    rs = m.scene.render
    path = (
        "persistent lanes"
        if rs.path == "compute" and rs.steps == 0
        else f"{rs.path or 'fragment'} path"
    )
    text = (
        f"\nA zoom into the finest kernel — {m.scene.name}, {m.size[0]}×{m.size[1]}, pre-pass "
        f"{rs.prepass or 'off'}, {path}, ms {TIME_SPREAD} of {m.rounds} interleaved rounds\n\n"
    )
    lod = rs.lod
    walk = "off" if rs.walk_restart == "on" else "on"
    text += markdown(
        (
            "stop",
            "distance",
            f"ms/frame (lod {lod:g})",
            "ms, every level (lod 0)",
            "iterations/px",
            "levels/iteration",
            "levels/iteration, every level",
            "hit",
            f"ms, walk restart {walk}",
            f"levels/iteration, walk restart {walk}",
        ),
        "lrrrrrrrrr",
        (
            (
                r["stop"],
                f"{r['distance']:.4g}",
                ms_spread(r),
                f"{r['ms_every_level']:.1f}",
                f"{r['iterations']:.1f}",
                f"{r['levels_per_iteration']:.1f}",
                f"{r['levels_every_level']:.1f}",
                f"{r['hit']:.0%}",
                f"{r['ms_other_walk']:.1f}",
                f"{r['levels_other_walk']:.1f}",
            )
            for r in m.rows
        ),
    )
    return (
        text + f"\n\nslowest frame / fastest (fastest rounds, with the [min–max] of the slowest "
        f"stop's round-by-round ratio to the fastest's): {spread_text(m)} (lod {lod:g}), "
        f"{spread_text(m, 'ms_every_level')} (every level), "
        f"{spread_text(m, 'ms_other_walk')} (walk restart {walk})"
    )


def write_plot(m: Measured, path) -> None:
    """Frame time, and iterations per pixel × levels per iteration, against the distance."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    d = m.column("distance")
    fig, (a, b) = plt.subplots(2, 1, figsize=(7, 6), sharex=True)
    ms = np.array(m.column("ms"))
    bars = [np.zeros_like(ms), np.array(m.column("ms_max")) - ms]
    lod = f"lod {m.scene.render.lod:g}"
    a.errorbar(d, ms, yerr=bars, fmt="o-", color="C0", capsize=3, label=lod)
    a.plot(d, m.column("ms_every_level"), "o--", color="C3", label="every level (lod 0)")
    walk = "off" if m.scene.render.walk_restart == "on" else "on"
    a.plot(d, m.column("ms_other_walk"), "s:", color="C4", label=f"walk restart {walk}")
    a.set_ylabel("ms/frame (fastest; bar: slowest)")
    a.legend()
    a.set_title(f"{m.scene.name}: zoom into the finest kernel, {m.size[0]}×{m.size[1]}")
    b.plot(d, m.column("iterations"), "o-", color="C1", label="iterations per pixel")
    b.plot(d, m.column("levels_per_iteration"), "s-", color="C2", label="levels per iteration")
    b.plot(d, m.column("levels_other_walk"), "s:", color="C4", label=f"… walk restart {walk}")
    b.set_xscale("log")
    b.invert_xaxis()
    b.set_xlabel("distance to the kernel (scene units; the flight goes right)")
    b.legend()
    for ax in (a, b):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
