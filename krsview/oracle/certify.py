"""Certify what a ray meets, by recursive subdivision of its segments [RAA09 §4]: a segment
whose enclosure of the distance is > 0 holds no surface; one of at most δ whose ends are
certified on either side of 0 holds one (the distance is continuous). With those, count the
rays a tracer got wrong:

- **hole**: a surface certified on [0, T], T = ε(t_hit) before the tracer's hit (or the far
  limit on a miss): the tracer went past geometry that exists;
- **false hit beyond ε**: the box of half-size ε(t_hit) around the tracer's hit point is
  certified free of the surface (boxes subdivided up to BOX_DEPTH times): the tracer stopped
  where nothing lies within ε (within the reach the scene's level of detail allows,
  ``hit_reach``);
- **below the level of detail**: no surface on [0, T] except, perhaps, inside balls of
  radius ≤ δ (a quarter pixel) that hold whole subtrees the walk left out: the ray passes
  sub-pixel detail, which a tracer whose ε grows with the pixel may hit or pass;
- **undecided**: the budget ran out, or a segment of size δ touches 0 without a certified
  crossing (tangent rays): counted, never guessed.

A segment is walked with the levels' balls (``distance.bounds``): a ball it clears ends the
walk (culling), and a ball no larger than LOD_BALL × the segment stands for its levels, so a
long segment costs a few levels and only short ones near the geometry walk deep — the
level-of-detail oracle that decides trees at full depth.

In the wind each bent component is walked from the enclosure of its world→rest map over the
segment or box (``oracle/wind.py``), at the scene's time; a hit's reach widens by the map's
stretch there (``wind.hit_stretch``).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..compile.camera import primary_rays, view_of
from ..compile.geometry import compile_geometry
from ..compile.mokrs import CompiledMoKRS
from ..frame import Frame
from ..reference.wind import Wind
from ..scene import Scene
from .distance import Bounds, bounds, in_box, on_segments, placed
from .wind import hit_stretch, wind_moved

DELTA_PIXELS = 0.25  # a crossing is certified within a quarter pixel footprint
REFINE = 1024  # a segment δ/REFINE long that touches 0 without a crossing: undecided
MAX_SEGMENTS = 500  # per ray: past this the ray is undecided
BOX_DEPTH = 3  # octree subdivisions of an ε-box (up to 8³ boxes)
LOD_BALL = 1.0  # a segment walks no level whose ball is ≤ this × its length
SURFACE, NONE, UNDECIDED, BELOW_LOD = 1, 0, -1, 2  # per-ray outcomes
DECIDED = np.array([0, 2, 3, 1])  # at outcome + 1: undecided < below LOD < none < surface
ARITHMETICS = ("affine", "interval")


@dataclass
class Certified:
    """Per ray: SURFACE certified on [0, T], NONE certified there, BELOW_LOD (none but
    perhaps sub-pixel detail), UNDECIDED; and the work it took."""

    surface: np.ndarray
    segments: int = 0  # enclosures evaluated (subdivisions + 1 per ray)
    seconds: float = 0.0


def enclosure(c, origin, dirs, a, b, arithmetic: str, lod: bool = False) -> Bounds:
    """Bounds of the value over the segments (with ``lod``, detail below LOD_BALL × their
    length left out); NaN (∞ · 0 near a pole) means unknown."""
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        return bounds(
            c, on_segments(origin, dirs, a, b, arithmetic), LOD_BALL * (b - a) if lod else None
        )


def surfaces_before(
    c,
    origin: np.ndarray,
    dirs: np.ndarray,
    T: np.ndarray,
    footprint: float,
    arithmetic: str,
    max_segments: int = MAX_SEGMENTS,
    lod: bool = True,
) -> Certified:
    """For each ray (dirs (N, 3)), whether a surface is certified on [0, T]. ``footprint``
    is a pixel's angle: a segment ending at t is small at δ = DELTA_PIXELS × footprint × t,
    where a crossing is looked for and left-out detail is accepted as below the level of
    detail. Rays found below it are then walked without leaving detail out (``lod`` False),
    within the same budget, which may still certify a surface or none."""
    t0 = time.perf_counter()
    N = len(dirs)
    surface = np.full(N, NONE)
    below_lod = np.zeros(N, dtype=bool)
    budget = np.full(N, max_segments)
    ray, a, b = np.arange(N), np.zeros(N), np.asarray(T, dtype=np.float64).copy()
    total = 0
    while ray.size:
        e = enclosure(c, origin, dirs[ray], a, b, arithmetic, lod)
        total += ray.size
        np.subtract.at(budget, ray, 1)
        live = ~(e.lower > 0) & (surface[ray] == NONE)  # may hold a surface (NaN: unknown)
        delta = DELTA_PIXELS * footprint * b  # a quarter pixel where the segment ends
        small = live & (b - a <= delta)
        detail = small & (e.lo > 0)  # only a left-out ball reaches 0: sub-pixel detail
        below_lod[ray[detail]] = True
        small &= ~detail
        live &= ~detail
        if small.any():
            r, sa, sb = ray[small], a[small], b[small]
            pa = enclosure(c, origin, dirs[r], sa, sa, "interval")
            pb = enclosure(c, origin, dirs[r], sb, sb, "interval")
            crossing = ((pa.lower > 0) & (pb.hi < 0)) | (pa.hi < 0)  # or already inside
            surface[r[crossing]] = SURFACE
            tiny = ~crossing & (sb - sa <= delta[small] / REFINE)  # touches 0: give up
            surface[r[tiny]] = np.where(surface[r[tiny]] == NONE, UNDECIDED, surface[r[tiny]])
        split = live & (surface[ray] == NONE)
        out = budget[ray] <= 0
        surface[ray[split & out & (surface[ray] == NONE)]] = UNDECIDED
        split &= ~out
        mid = 0.5 * (a[split] + b[split])
        ray = np.concatenate([ray[split], ray[split]])
        a, b = np.concatenate([a[split], mid]), np.concatenate([mid, b[split]])
    surface[(surface == NONE) & below_lod] = BELOW_LOD
    again = np.nonzero(surface == BELOW_LOD)[0]
    if lod and again.size:
        exact = surfaces_before(
            c, origin, dirs[again], T[again], footprint, arithmetic, max_segments, lod=False
        )
        surface[again] = np.where(exact.surface == UNDECIDED, BELOW_LOD, exact.surface)
        total += exact.segments
    return Certified(surface, total, time.perf_counter() - t0)


def free_boxes(c, centers: np.ndarray, half: np.ndarray) -> np.ndarray:
    """Whether each box centre ± half holds no surface (interval enclosures > 0 after up to
    BOX_DEPTH octree subdivisions)."""
    N = len(centers)
    free = np.ones(N, dtype=bool)
    idx, ctr, h = np.arange(N), centers, np.asarray(half, dtype=np.float64)
    for depth in range(BOX_DEPTH + 1):
        with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
            lower = bounds(c, in_box(ctr, h)).lower
        open_ = ~(lower > 0)  # NaN (through a pole): unknown
        if depth == BOX_DEPTH:
            free[idx[open_]] = False
            break
        if not open_.any():
            break
        idx, ctr, h = idx[open_], ctr[open_], h[open_] / 2
        offsets = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        idx = np.repeat(idx, 8)
        ctr = (ctr[:, None, :] + offsets[None] * h[:, None, None]).reshape(-1, 3)
        h = np.repeat(h, 8)
    return free


# How near a hit is to a surface, in ε(t): a sphere-traced hit stops where the distance bound
# is below ε; a binary one at a free point t whose blocked probe (centre t + s, radius s ≤ ε)
# holds a surface, so within 2ε (reference/trace.py, binary_trace). A hit whose box of this
# half-size is certified empty is a false hit.
HIT_REACH = {"sphere": 1.0, "relaxed": 1.0, "binary": 2.0}


def hit_reach(scene: Scene, c, eps_per_t: float) -> float:
    """How near a hit is to a surface, in ε(t): HIT_REACH, and with the level of detail
    (render.lod) the diameter of a ball standing for the levels below it, 2K·lod·ε at most
    for the compiled geometry ``c`` (2·lod·ε for a MöKRS's; reference/krs.py, distance; a
    binary probe takes lod·ε at its far side, 2ε further)."""
    r = scene.render
    return HIT_REACH[r.tracer] + lod_reach(c) * r.lod * (1.0 + 2.0 * eps_per_t)


def lod_reach(c) -> float:
    """The most a ball cut at the level of detail ρ reaches beyond what it holds, per ρ: the
    largest of the KRS components' 2K (compile/lod.py), 2 for a MöKRS's level bounds."""
    return max(2.0 if isinstance(p, CompiledMoKRS) else float(p.lod_cut[2]) for p, _ in placed(c))


@dataclass
class Counts:
    rays: int
    hits: int
    holes: int
    false_hits: int
    below_lod: int
    undecided: int
    work: dict = field(default_factory=dict)  # arithmetic → (segments, seconds)


UNCOVERED = frozenset({"twist", "empty_zones"})  # distortions not in the oracle


def count_errors(
    scene: Scene, image: Frame, arithmetics=ARITHMETICS, max_segments: int = MAX_SEGMENTS
) -> Counts:
    """Certified holes and false hits of a traced image (GPU or reference) of ``scene``: a
    KRS, compound or MöKRS, in the wind at the scene's time too (the twist and empty zones
    are not in the oracle)."""
    if UNCOVERED & set(scene.effects):
        raise ValueError(f"{scene.name}: the oracle covers scenes without twist or empty zones")
    scene = scene.posed()  # the static scene drawn at its time (tracks, sway)
    h, w = image.hit.shape
    view = view_of(scene.camera, w, h)
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    wind = Wind.of(scene) if "wind" in scene.effects else None
    if wind is not None:
        c = wind_moved(wind, c)
    dirs = primary_rays(view)
    hit, t = image.hit.ravel(), image.depth.ravel()
    eps = view.footprint * scene.render.epsilon_scale * t
    capped = (image.iterations.ravel() >= scene.render.max_iterations) & ~hit
    T = np.where(hit, t - eps, scene.render.max_distance)
    check = ~capped & (T > 0)
    work, surface = {}, None
    for arithmetic in arithmetics:  # both are sound: the more decided answer counts
        cert = surfaces_before(
            c, view.origin, dirs[check], T[check], view.footprint, arithmetic, max_segments
        )
        work[arithmetic] = (cert.segments, cert.seconds)
        surface = (
            cert.surface
            if surface is None
            else np.where(DECIDED[cert.surface + 1] > DECIDED[surface + 1], cert.surface, surface)
        )
    centres = view.origin + t[hit, None] * dirs[hit]
    reach = hit_reach(scene, c, view.footprint * scene.render.epsilon_scale) * eps[hit]
    if wind is not None:
        reach = reach * hit_stretch(scene, wind, centres, reach)
    false_hits = int(free_boxes(c, centres, reach).sum())
    return Counts(
        len(hit),
        int(hit.sum()),
        int((surface == SURFACE).sum()),
        false_hits,
        int((surface == BELOW_LOD).sum()),
        int((surface == UNDECIDED).sum()),
        work,
    )
