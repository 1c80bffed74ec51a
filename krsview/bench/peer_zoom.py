"""`krsview bench peer-zoom`: bench zoom's flight with the peer beside it [issue 27 §2, §3].
The KRS is cut to ``levels`` levels (the peer's mesh holds every instance, so 16 by
default), expanded, tessellated for the scene's own view and built into an Embree BVH once
(bench/peer.py); then, at each stop of the flight into the finest kernel of the levels kept
(bench/zoom.py), the peer's frame and krsview's (its effects off) are drawn in interleaved
rounds. Along a zoom the share of the image that geometry covers changes many times over,
and a covered pixel costs in both renderers: the peer's slowest frame over its fastest says
how constant a rate the obvious alternative holds on the same flight. Nearer stops see the
mesh's facets (it is tessellated within ``tolerance`` pixels for the first view); a BVH's
time depends on its triangle count only logarithmically."""

from __future__ import annotations

import numpy as np

from ..compile.camera import view_of
from ..gpu.renderer import Renderer
from ..inputs import whole
from ..scene import Scene
from .expansion import TOLERANCE, expand, single_krs
from .harness import (
    Variant,
    bench_inputs,
    frame_timer,
    interleaved,
    ratio_range,
    time_columns,
    with_range,
)
from .peer import (
    PEER,
    build,
    camera_rays,
    check_levels,
    krsview_scene,
    load_peer,
    peer_hit,
    peer_timer,
)
from .report import TIME_SPREAD, Measured, markdown, ms_spread
from .zoom import finest_kernel_ball, spread_text, stops, to_fastest


def bench_peer_zoom(
    scene: Scene,
    size: tuple[int, int],
    rounds: int = 5,
    levels: int = 16,
    stops_count: int = 12,
    tolerance: float = TOLERANCE,
) -> Measured:
    """One row per stop: distance to the kernel, the peer's and krsview's ms per frame
    (:func:`harness.time_columns`, ``peer_`` for the peer's), krsview's ratio to the peer
    (fastest rounds, per-round spread), each one's hit fraction, and each one's round-by-round
    ratio to its own fastest stop."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    stops_count = whole(stops_count, "stops_count", 2, 1000)
    krs = single_krs(scene)
    check_levels(krs, (whole(levels, "levels", 1),), scene.name)
    o3d = load_peer()
    g = krs.truncated(levels)
    cut = scene.with_geometry(g)
    views = stops(cut, stops_count)
    w, h = size
    bvh, _ = build(o3d, expand(g, view_of(scene.camera, w, h), tolerance))
    r = Renderer()
    timers, hits = {}, {}
    for k, v in enumerate(views):
        rays = camera_rays(o3d, view_of(v.camera, w, h))
        drawn = krsview_scene(v, {})
        timers[f"{PEER} {k}"], timers[f"krsview {k}"] = (
            peer_timer(bvh, rays),
            frame_timer(r, Variant(drawn), size),
        )
        hits[k] = (float(peer_hit(bvh, rays).mean()), float(r.render(drawn, w, h).hit.mean()))
    times = interleaved(timers, rounds, f"bench peer-zoom {scene.name}, {levels} levels")
    centre = finest_kernel_ball(cut)[:3]
    rows = []
    for k, v in enumerate(views):
        peer, mine = times[f"{PEER} {k}"], times[f"krsview {k}"]
        lo, hi = ratio_range(mine, peer)
        rows.append(
            dict(
                stop=f"stop {k}",
                distance=float(np.linalg.norm(np.array(v.camera.position) - centre)),
                levels=levels,
                **{f"peer_{c}": x for c, x in time_columns(peer).items()},
                **time_columns(mine),
                ratio=min(mine) / min(peer),
                ratio_min=lo,
                ratio_max=hi,
                peer_hit=hits[k][0],
                hit=hits[k][1],
            )
        )
    for column, who in (("peer_ms", PEER), ("ms", "krsview")):
        to_fastest(rows, column, [times[f"{who} {k}"] for k in range(len(views))])
    return Measured(scene, size, rounds, rows)


def table(m: Measured) -> str:
    rs = m.scene.render
    text = (
        f"\nA zoom into the finest kernel, {PEER} beside krsview — {m.scene.name} cut to "
        f"{m.rows[0]['levels']} levels, {m.size[0]}×{m.size[1]}, the same primary rays; "
        f"krsview with pre-pass {rs.prepass or 'off'}, lod {rs.lod:g}, effects off; ms "
        f"{TIME_SPREAD} of {m.rounds} interleaved rounds\n\n"
    )
    text += markdown(
        ("stop", "distance", f"{PEER} ms", "krsview ms", "× peer", "hit (peer)", "hit"),
        "lrrrrrr",
        (
            (
                r["stop"],
                f"{r['distance']:.4g}",
                ms_spread({k[5:]: v for k, v in r.items() if k.startswith("peer_")}),
                ms_spread(r),
                with_range(r["ratio"], r["ratio_min"], r["ratio_max"]),
                f"{r['peer_hit']:.0%}",
                f"{r['hit']:.0%}",
            )
            for r in m.rows
        ),
    )
    return text + (
        "\n\nslowest frame / fastest along the flight (fastest rounds, with the [min–max] of "
        f"the slowest stop's round-by-round ratio to the fastest's): {PEER} "
        f"{spread_text(m, 'peer_ms')}, krsview {spread_text(m)}"
    )
