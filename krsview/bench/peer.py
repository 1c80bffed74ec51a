"""`krsview bench peer`: krsview against the obvious CPU alternative [issue 27 §3]: the KRS
expanded into the 2^(n−i) instances of every kernel K_i, each tessellated finely enough that
the mesh stays within TOLERANCE pixels of the surface (bench/expansion.py), in an Embree BVH
(Open3D's RaycastingScene, which traces on every core as llvmpipe does), cast with krsview's
own primary rays. Per frame time side by side in interleaved rounds, the BVH's build, the
first frame and the peak memory of each in a fresh process, and where the hit masks differ."""

from __future__ import annotations

import math
import os
import pickle
import subprocess
import sys
import time

import numpy as np

from ..compile.camera import View, primary_rays, view_of
from ..compile.geometry import compile_geometry
from ..gpu.renderer import Renderer
from ..oracle.certify import lod_reach
from ..scene import KRS, Scene, SceneError
from ..scene.render import DEFAULT_LOD, VIEW_PREPASS
from .expansion import TOLERANCE, Mesh, expand, single_krs
from .harness import (
    Variant,
    bench_inputs,
    frame_timer,
    interleaved,
    ratio_range,
    time_columns,
)
from .report import TIME_SPREAD, Measured, markdown, ms_spread

PEER = "Embree (Open3D)"
# krsview's rows, each with the effects off (primary rays only, as the peer casts): every
# level without the pre-pass (`render --exact`), the level of detail alone, the pre-pass
# alone, and both (what `render` and the API draw where the file sets neither).
VARIANTS = {
    "krsview, exact": {"prepass": 0, "lod": 0.0},
    f"krsview, lod {DEFAULT_LOD}": {"prepass": 0, "lod": DEFAULT_LOD},
    f"krsview, pre-pass {VIEW_PREPASS}": {"prepass": VIEW_PREPASS, "lod": 0.0},
    f"krsview, pre-pass {VIEW_PREPASS} + lod {DEFAULT_LOD} (render's default)": {
        "prepass": VIEW_PREPASS,
        "lod": DEFAULT_LOD,
    },
}
INSTALL = "pip install 'krsview[peer]' (Linux also needs libusb-1.0: apt-get install libusb-1.0-0)"


def load_peer():
    """The peer library (open3d), or one line saying how to get it."""
    try:
        import open3d
    except ImportError as e:
        raise RuntimeError(f"bench peer needs open3d ({e}): {INSTALL}") from None
    return open3d


# ------------------------------------------------------------------------------- the peer
def build(o3d, mesh: Mesh):
    """(the Embree scene, seconds to build its BVH: Open3D builds it on the first query)."""
    t0 = time.perf_counter()
    bvh = o3d.t.geometry.RaycastingScene()
    bvh.add_triangles(o3d.core.Tensor(mesh.vertices), o3d.core.Tensor(mesh.faces))
    bvh.cast_rays(o3d.core.Tensor(np.array([[0, 0, 0, 0, 0, 1]], dtype=np.float32)))
    return bvh, time.perf_counter() - t0


def camera_rays(o3d, view: View):
    """krsview's primary rays (compile/camera.py), rows top → bottom, as Open3D's tensor."""
    d = primary_rays(view)
    rays = np.concatenate([np.broadcast_to(view.origin, d.shape), d], axis=1)
    return o3d.core.Tensor(rays.astype(np.float32).reshape(view.height, view.width, 6))


def peer_hit(bvh, rays) -> np.ndarray:
    """Per pixel, whether the ray hits a triangle."""
    return np.isfinite(bvh.cast_rays(rays)["t_hit"].numpy())


def peer_timer(bvh, rays):
    """A timer of one peer frame, cast once untimed first as Renderer.time_frame draws."""

    def timer() -> float:
        bvh.cast_rays(rays)
        t0 = time.perf_counter()
        bvh.cast_rays(rays)
        return time.perf_counter() - t0

    return timer


def krsview_scene(scene: Scene, knobs: dict) -> Scene:
    """The scene as krsview's row draws it: its effects off, ``knobs`` set in [render]."""
    out = scene.edit("effects", [])
    for name, value in knobs.items():
        out = out.edit(f"render.{name}", value)
    return out


def fresh_process(job: str, scene: Scene, levels: int, size: tuple[int, int], knobs: dict):
    """(seconds to the first frame, peak RSS in MiB) of a process of its own doing one
    ``job`` after its imports: "peer" (expand within ``knobs["tolerance"]`` pixels,
    tessellate, build, cast), "krsview" (compile and draw with ``knobs``; Mesa's shader cache
    off, so it compiles from scratch), or "idle" (nothing: the imports' share). The job
    travels pickled through stdin, so no script is imported again (as multiprocessing's
    spawn does)."""
    done = subprocess.run(
        [sys.executable, "-c", "from krsview.bench.peer import child; child()"],
        input=pickle.dumps((job, scene, levels, size, knobs)),
        capture_output=True,
        check=False,
        env=os.environ | {"MESA_SHADER_CACHE_DISABLE": "true"},
    )
    if done.returncode:
        raise RuntimeError(f"bench peer: the {job} process failed: {done.stderr.decode()[-500:]}")
    return pickle.loads(done.stdout)


def child() -> None:
    """A fresh process's side of :func:`fresh_process`."""
    sys.stdout.buffer.write(pickle.dumps(_first_frame(*pickle.loads(sys.stdin.buffer.read()))))


def _first_frame(job: str, scene: Scene, levels: int, size: tuple[int, int], knobs: dict):
    """The job of :func:`fresh_process`, timed from after the imports."""
    krs = single_krs(scene).truncated(levels)
    o3d = load_peer() if job == "peer" else None
    t0 = time.perf_counter()
    if job == "peer":
        view = view_of(scene.camera, *size)
        peer_hit(build(o3d, expand(krs, view, knobs["tolerance"]))[0], camera_rays(o3d, view))
    elif job == "krsview":
        Renderer().render(krsview_scene(scene, knobs), *size, krs)
    return time.perf_counter() - t0, peak_rss_mib()


def peak_rss_mib() -> float:
    """This process's peak resident memory (Linux's VmHWM; ru_maxrss would also count the
    parent's memory at fork); NaN where /proc does not say."""
    try:
        with open("/proc/self/status") as f:
            line = next(x for x in f if x.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return math.nan
    return int(line.split()[1]) / 1024


# ------------------------------------------------------------------------------- the bench
def check_levels(krs: KRS, levels: tuple[int, ...], name: str) -> None:
    """Each level count within the scene's, or a one-line error naming --levels."""
    for n in levels:
        if not 1 <= n <= krs.depth:
            raise SceneError("--levels", n, f"allowed: 1..{krs.depth} (the levels of {name})")


def bench_peer(
    scene: Scene,
    size: tuple[int, int],
    rounds: int = 5,
    level_counts: tuple[int, ...] = (16,),
    tolerance: float = TOLERANCE,
) -> Measured:
    """Per level count (the coarsest ``level_counts`` levels of the scene's KRS), a row for
    the peer and one per krsview variant (VARIANTS): ms per frame over interleaved rounds
    (:func:`row`), the ratio to the peer (fastest rounds, per-round spread), the first frame
    and peak RSS of a fresh process, the pixels whose hit differs from the peer's, and
    krsview's hits farther from the mesh than its ε(t) and ``tolerance`` (pixels) allow."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    o3d = load_peer()
    krs = single_krs(scene)
    check_levels(krs, level_counts, scene.name)
    idle = fresh_process("idle", scene, 1, size, {})[1]
    r = Renderer()
    rows = []
    for n in level_counts:
        rows += [
            x | dict(idle_rss_mb=idle)
            for x in measure_level(o3d, r, scene, krs.truncated(n), size, rounds, tolerance)
        ]
    return Measured(scene, size, rounds, rows)


def measure_level(
    o3d, r: Renderer, scene: Scene, g: KRS, size, rounds: int, tolerance: float
) -> list[dict]:
    """The rows of one level count: the peer's, then each of VARIANTS'."""
    view = view_of(scene.camera, *size)
    rays = camera_rays(o3d, view)
    scenes = {name: krsview_scene(scene, knobs) for name, knobs in VARIANTS.items()}
    t0 = time.perf_counter()
    mesh = expand(g, view, tolerance)
    setup = dict(tolerance_px=tolerance, instances=mesh.instances, triangles=len(mesh.faces))
    setup |= dict(mesh_s=time.perf_counter() - t0)
    bvh, setup["bvh_s"] = build(o3d, mesh)
    hit = {PEER: peer_hit(bvh, rays)}
    timers = {PEER: peer_timer(bvh, rays)}
    timers |= {name: frame_timer(r, Variant(s, g), size) for name, s in scenes.items()}
    times = interleaved(timers, rounds, f"bench peer {scene.name}, {g.depth} levels")
    far = {PEER: 0.0}
    for name, s in scenes.items():
        frame = r.render(s, *size, g)
        hit[name], far[name] = frame.hit, beyond_epsilon(o3d, bvh, frame, view, s, tolerance)
    del bvh  # freed before the fresh processes build their own
    jobs = {PEER: ("peer", {"tolerance": tolerance})} | {
        name: ("krsview", knobs) for name, knobs in VARIANTS.items()
    }
    rows = []
    for name, (job, knobs) in jobs.items():
        first, peak = fresh_process(job, scene, g.depth, size, knobs)
        rows.append(row(g.depth, name, times, first, peak, hit[name], hit[PEER], far[name]) | setup)
    return rows


def beyond_epsilon(o3d, bvh, frame, view: View, scene: Scene, tolerance: float) -> float:
    """Fraction of pixels where krsview hits farther from the mesh than (1 + 2K·lod)·ε(t) +
    ``tolerance`` pixels at its depth t: a hit the mesh does not explain (the mesh lies within
    ``tolerance`` pixels of the surface, the tracer stops within ε(t) of it [KRS17 §4], and
    the level of detail moves a hit by at most its cut ball's diameter, 2K·lod·ε:
    compile/lod.py)."""
    t = frame.depth[frame.hit]
    d = primary_rays(view).reshape(*frame.hit.shape, 3)[frame.hit]
    points = (view.origin + t[:, None] * d).astype(np.float32)
    gap = bvh.compute_distance(o3d.core.Tensor(points)).numpy()
    reach = lod_reach(compile_geometry(scene.geometry(), scene.material.albedo))
    eps = scene.render.epsilon_scale * (1.0 + reach * scene.render.lod)
    allowed = (eps + tolerance) * view.footprint * t
    return float((gap > allowed).sum() / frame.hit.size)


def row(n: int, name: str, times: dict, first: float, peak: float, hit, peer_hit, far: float):
    """One renderer's columns: its time (:func:`harness.time_columns`) and its ratio to the
    peer's, fastest round to fastest round, with the [min–max] of the ratio per round, between
    frames drawn side by side."""
    t, peer = times[name], times[PEER]
    lo, hi = ratio_range(t, peer)
    return dict(
        levels=n,
        renderer=name,
        **time_columns(t),
        ratio=min(t) / min(peer),
        ratio_min=lo,
        ratio_max=hi,
        first_frame_s=first,
        peak_rss_mb=peak,
        hit_differs=float((hit != peer_hit).mean()),
        only_krsview=float((hit & ~peer_hit).mean()),
        only_peer=float((peer_hit & ~hit).mean()),
        beyond_epsilon=far,
    )


def table(m: Measured) -> str:
    text = (
        f"\nkrsview against {PEER} over the expanded, tessellated KRS — {m.scene.name}, "
        f"{m.size[0]}×{m.size[1]}, the same primary rays, {m.rounds} interleaved rounds "
        "(krsview with its effects off)\n\n"
    )
    text += markdown(
        (
            "levels",
            "renderer",
            f"ms/frame, {TIME_SPREAD}",
            "× peer [min–max]",
            "first frame",
            "peak RSS",
            "hit differs (krsview only / peer only)",
            "hits beyond ε",
        ),
        "rlrrrrrr",
        (
            (
                r["levels"],
                r["renderer"],
                ms_spread(r),
                f"{r['ratio']:.2f} [{r['ratio_min']:.2f}–{r['ratio_max']:.2f}]",
                f"{r['first_frame_s']:.2f} s",
                f"{r['peak_rss_mb']:,.0f} MiB",
                f"{r['hit_differs']:.2%} ({r['only_krsview']:.2%} / {r['only_peer']:.2%})",
                f"{r['beyond_epsilon']:.2%}",
            )
            for r in m.rows
        ),
    )
    notes = [
        f"{r['levels']} levels: {r['instances']:,} kernel instances, {r['triangles']:,} "
        f"triangles (within {r['tolerance_px']} px of the surface): expansion and tessellation "
        f"{r['mesh_s']:.2f} s, BVH build {r['bvh_s']:.2f} s"
        for r in m.rows
        if r["renderer"] == PEER
    ]
    notes += [
        "hits beyond ε: pixels where krsview hits farther from the mesh than its ε(t) "
        "(1 + 2K·lod of them with the level of detail, K about 1.5) and the "
        f"mesh's {m.rows[0]['tolerance_px']} px allow (the tracer stops within ε(t) of the "
        "surface, so it draws sub-pixel twigs about a pixel wide, where the mesh's rays pass "
        "by: krsview only)",
        "first frame (scene to image; krsview compiles its shaders, Mesa's disk cache off) and "
        "peak RSS: each in a fresh process, after its imports (one that only imports krsview "
        f"peaks at {m.rows[0]['idle_rss_mb']:,.0f} MiB)",
    ]
    return text + "\n\n" + "\n\n".join(notes)
