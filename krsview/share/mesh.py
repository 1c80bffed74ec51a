"""`krsview export mesh`: a triangle mesh of a scene [issue 18 §2]. The float64 reference
field (the KRS distance bound of Alg. 1, or a MöKRS's first-order distance estimate) is
sampled near the surface only: an octree over the scene's bounding box drops every box whose
ball the reference certifies free of the surface (outside, or inside one kernel instance),
down to bricks of BRICK³ voxels; each remaining brick's corners are sampled densely and
marching cubes (scikit-image) extracts its piece. Pieces meet on shared brick faces with the
same corner values, so merging their vertices closes the mesh. trimesh writes the file."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..compile.balls import union_ball
from ..compile.geometry import compile_geometry, scene_ball
from ..compile.mokrs import CompiledMoKRS
from ..reference import mokrs
from ..reference.distortion import Distortion
from ..reference.geometry import nearest, surface_field
from ..scene import Scene, SceneError

BRICK = 16  # voxels per brick side: one marching-cubes call each
FORMATS = (".glb", ".ply", ".stl", ".obj")  # what trimesh writes
BATCH = 1 << 18  # points per reference call (memory stays flat)
PROGRESS_STEPS = 20  # the bricks are sampled in at least this many calls, each reported
REFINE_STEPS = 8  # bisections per vertex along its grid edge: within h / 256
REFINE_SHARE = 0.2  # the bisections and colours against the bricks (tree 8 %, palm 32 %)


@dataclass
class MeshStats:
    resolution: int  # voxels along the box's side
    lod: float  # the level set meshed, in voxels (0: the surface)
    voxel: float  # their size, scene units
    bricks: int  # bricks sampled (of resolution³ / BRICK³)
    samples: int  # reference evaluations, octree tests included
    triangles: int
    seconds: float
    watertight: bool


def box_of(
    scene: Scene, c, box: tuple[float, ...] | None, dist: Distortion | None = None
) -> tuple[np.ndarray, float]:
    """(lowest corner, side) of the cube sampled: around the given box (XMIN, YMIN, ZMIN,
    XMAX, YMAX, ZMAX), or the scene's bounding ball, grown in the wind to hold each bent
    component's swept ball (the bend carries geometry out of its rest ball)."""
    if box is not None:
        lo, hi = np.array(box[:3], dtype=float), np.array(box[3:], dtype=float)
        side = float((hi - lo).max())
        return (lo + hi) / 2 - side / 2, side
    ball = scene_ball(c)
    if ball is not None and dist is not None and dist.wind is not None:
        for swept in dist.wind.balls:
            ball = ball if swept[3] < 0 else union_ball(ball, swept)
    if ball is None:
        raise SceneError(
            "geometry",
            scene.name,
            "is unbounded (a ground plane, or a MöKRS whose outer bound is not a ball): "
            "give the region to mesh, its box XMIN, YMIN, ZMIN, XMAX, YMAX, ZMAX",
        )
    pad = 1.02 * ball[3]  # a margin, so the surface never touches the cube's faces
    return ball[:3] - pad, 2 * pad


def sampled_resolution(resolution: int) -> int:
    """The voxels along the sampled cube's side for ``resolution``: rounded up to BRICK·2^k
    (the octree halves the cube down to bricks)."""
    return BRICK << max(0, math.ceil(math.log2(max(resolution, BRICK) / BRICK)))


def build_mesh(
    scene: Scene,
    resolution: int,
    box: tuple[float, ...] | None = None,
    lod: float = 0.0,
    progress: Callable[[int, int], None] | None = None,
):
    """The mesh (a trimesh.Trimesh with vertex colours from the nearest kernel's albedo) and
    its MeshStats. ``resolution`` voxels along the sampled cube's side, rounded up to a
    multiple of BRICK. ``lod`` > 0 meshes the level set at lod voxels instead of the surface
    (the renderer's level of detail [KRS17 §4]: what is thinner than a voxel is thickened to
    about one instead of vanishing between samples). ``progress(done, total)`` counts the
    bricks' samples, then the vertices' bisections and colours; their total is known once
    the bricks are done (until then it is guessed at REFINE_SHARE more than the bricks')."""
    import trimesh
    from skimage.measure import marching_cubes

    t0 = time.perf_counter()
    scene = scene.posed()  # the surface at the scene's time (tracks, sway)
    geometry = scene.geometry()
    c = compile_geometry(geometry, scene.material.albedo)
    dist = Distortion.of(scene)
    value, is_empty = mesh_field(c, dist)
    lo, side = box_of(scene, c, box, dist)
    n = sampled_resolution(resolution)
    bricks_per_side = n // BRICK
    h = side / n
    iso = lod * h
    boxes, samples = occupied_bricks(is_empty, lo, h, iso, bricks_per_side)
    verts, faces, count = [], [], 0
    grid = np.stack(np.meshgrid(*[np.arange(BRICK + 1)] * 3, indexing="ij"), -1).reshape(-1, 3)
    sampled = len(boxes) * len(grid)  # the bricks' corners: the first part of the work
    per_call = max(1, min(BATCH // len(grid), math.ceil(len(boxes) / PROGRESS_STEPS)))
    for k0 in range(0, len(boxes), per_call):
        chunk = boxes[k0 : k0 + per_call]
        corners = (chunk[:, None, :] * BRICK + grid[None]).reshape(-1, 3)
        field = value(lo + corners * h).reshape(len(chunk), BRICK + 1, BRICK + 1, BRICK + 1) - iso
        samples += len(corners)
        for b, vol in zip(chunk, field):
            if not (vol.min() < 0.0 < vol.max()):
                continue
            v, f, _, _ = marching_cubes(
                vol, 0.0, gradient_direction="descent", allow_degenerate=False
            )
            verts.append(b * BRICK + v)  # grid units: shared faces agree exactly
            faces.append(f + count)
            count += len(v)
        if progress is not None:
            progress(min(k0 + per_call, len(boxes)) * len(grid), int(sampled * (1 + REFINE_SHARE)))
    if not faces:
        raise SceneError("geometry", scene.name, "no surface inside the region sampled")
    grid_verts, index = np.unique(np.concatenate(verts), axis=0, return_inverse=True)
    faces = index.reshape(-1)[np.concatenate(faces)]
    faces = faces[
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 2] != faces[:, 0])
    ]
    total = sampled + (REFINE_STEPS + 2) * len(grid_verts)  # + the bisections, the colours

    def bisected(k: int) -> None:
        if progress is not None:
            progress(sampled + k * len(grid_verts), total)

    positions = lo + refine(grid_verts, lambda g: value(lo + g * h) - iso, bisected) * h
    samples += REFINE_STEPS * len(grid_verts)
    mesh = trimesh.Trimesh(positions, faces, process=False)
    level, _, _ = nearest(c, np.asarray(mesh.vertices), None, dist)
    if progress is not None:
        progress(total, total)
    albedo = np.clip(c.records[level, 0, :3], 0.0, 1.0) ** (1 / 2.2)
    mesh.visual.vertex_colors = np.concatenate(
        [np.round(albedo * 255), np.full((len(albedo), 1), 255)], axis=1
    ).astype(np.uint8)
    stats = MeshStats(
        n,
        lod,
        h,
        len(boxes),
        samples,
        len(mesh.faces),
        time.perf_counter() - t0,
        bool(mesh.is_watertight),
    )
    return mesh, stats


def mesh_field(c, dist: Distortion | None):
    """(value, is_empty) of the surface sampled (reference/geometry.py, surface_field). A
    MöKRS in the wind is bent as the tracer bends it: its estimate is looked up at the rest
    point g(x) (zero exactly on the bent surface, same sign), and balls are certified free
    through the bend (mokrs.is_unbounding with the wind); the twist is refused for a MöKRS."""
    if not isinstance(c, CompiledMoKRS) or dist is None or dist.wind is None:
        return surface_field(c, dist)
    wind = dist.wind
    return (
        lambda x: mokrs.distance_estimate(c, wind.unwind(0, x)),
        lambda x, r: mokrs.is_unbounding(c, x, r, wind=wind),
    )


def occupied_bricks(
    is_empty: Callable, lo: np.ndarray, h: float, iso: float, bricks_per_side: int
) -> tuple[np.ndarray, int]:
    """The bricks (integer corners, in bricks) that may hold surface, by an octree: boxes
    whose ball is certified empty are dropped, the rest split, down to single bricks; and
    the tests it took."""
    samples = 0
    boxes, size = np.zeros((1, 3), dtype=np.int64), bricks_per_side
    while True:
        centers = lo + (boxes + size / 2) * BRICK * h
        radius = np.full(len(boxes), math.sqrt(3) / 2 * size * BRICK * h + h + iso)
        keep = ~_batched(is_empty, centers, radius)
        samples += len(boxes)
        boxes = boxes[keep]
        if size == 1 or len(boxes) == 0:
            return boxes, samples
        size //= 2
        offsets = np.array([(i, j, k) for i in (0, 1) for j in (0, 1) for k in (0, 1)]) * size
        boxes = (boxes[:, None, :] + offsets[None]).reshape(-1, 3)


def _batched(f: Callable, *xs: np.ndarray) -> np.ndarray:
    """f over the rows of ``xs`` (at least one) in slices of BATCH rows: memory stays flat."""
    return np.concatenate([f(*(x[k : k + BATCH] for x in xs)) for k in range(0, len(xs[0]), BATCH)])


def refine(
    g: np.ndarray,
    f: Callable[[np.ndarray], np.ndarray],
    passes: Callable[[int], None] = lambda k: None,
) -> np.ndarray:
    """Marching cubes places a vertex on a grid edge whose corners f has opposite signs, by
    linear interpolation: up to half a voxel off where f is not a true distance (Alg. 1
    gives a bound). Bisect f along that edge instead, REFINE_STEPS times: each vertex ends
    within 2^-REFINE_STEPS voxel of a sign change of f. ``g``: vertices in grid units
    (exactly one coordinate fractional; others, such as marching cubes 33's cell-interior
    vertices, are left where they are). ``passes(k)`` is told after each of the
    REFINE_STEPS + 1 passes of f over the vertices."""
    frac = np.abs(g - np.round(g)) > 1e-9
    on_edge = frac.sum(1) == 1
    out = g.copy()
    idx = np.flatnonzero(on_edge)
    if len(idx) == 0:
        return out
    axis = np.argmax(frac[idx], 1)
    a, b = g[idx].copy(), g[idx].copy()
    rows = np.arange(len(idx))
    a[rows, axis] = np.floor(g[idx, axis])
    b[rows, axis] = np.ceil(g[idx, axis])
    fa = _batched(f, a)
    passes(1)
    for k in range(REFINE_STEPS):
        m = (a + b) / 2
        fm = _batched(f, m)
        same = (fm < 0) == (fa < 0)  # the sign change lies in [m, b]
        a = np.where(same[:, None], m, a)
        fa = np.where(same, fm, fa)
        b = np.where(same[:, None], b, m)
        passes(k + 2)
    out[idx] = (a + b) / 2
    return out
