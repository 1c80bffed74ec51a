"""A KRS as triangles, for the peer of `krsview bench peer` [issue 27 §3]: the expansion into
the 2^(n−i) instances of every kernel K_i (the maps of the reflection paths [KRS17 §3]), each
kernel tessellated as its core swept by a ball, finely enough that the mesh stays within a
given number of pixels of the surface as a view sees the level's nearest instance."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..algebra.vectors import cross
from ..compile.balls import kernel_ball
from ..compile.camera import View
from ..compile.krs import CompiledKRS, compile_krs
from ..reference.kernels import arc_world
from ..scene import KRS, Scene, SceneError
from ..scene.model import Empty

TOLERANCE = 0.5  # pixels: how far the mesh may lie from the surface, at the nearest instance
MAX_PIECES = 256  # sides of a ring, bands of a cap, segments of an arc, at most (eye in a kernel)


@dataclass(frozen=True)
class Mesh:
    """Every kernel instance as triangles, in world coordinates (float32, as Embree takes them)."""

    vertices: np.ndarray  # (V, 3) float32, world
    faces: np.ndarray  # (F, 3) uint32
    instances: int  # kernel instances expanded


def single_krs(scene: Scene) -> KRS:
    """The scene's one KRS, every kernel bounded, or a one-line error."""
    g = scene.single_krs("bench peer expands one KRS into triangles")
    for i, k in enumerate(g.kernels):
        if kernel_ball(k) is None and not isinstance(k, Empty):
            raise SceneError(f"levels[{i}].kernel", k.kind, "bench peer meshes bounded kernels")
    return g


def instance_maps(c: CompiledKRS) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per level j, the 2^(n−j) maps x ↦ M x + t taking K_j to its instances
    R_{n−1}^{b_{n−1}} ∘ … ∘ R_j^{b_j} K_j (L_i = K_i ∪ L_{i−1} ∪ R_{i−1} L_{i−1} [KRS17 §3]);
    unclipped: Alg. 1 clips a kernel that crosses a mirror, a tree's do not."""
    M, t = np.eye(3)[None], np.zeros((1, 3))
    out = [(M, t)]
    for u, w in zip(c.mirrors[::-1, :3], c.mirrors[::-1, 3]):
        H = np.eye(3) - 2.0 * np.outer(u, u)  # x ↦ H x + 2 w u, applied before the maps above
        M, t = np.concatenate([M, M @ H]), np.concatenate([t, t + 2.0 * w * (M @ u)])
        out.append((M, t))
    return out[::-1]


def pieces(angle: float, radius: float, tol: float, least: int) -> int:
    """Equal chords that follow a circular arc of ``angle`` at ``radius`` within ``tol``."""
    if tol >= radius:
        return least
    if tol <= 0.0:
        return MAX_PIECES
    return min(MAX_PIECES, max(least, math.ceil(angle / (2.0 * math.acos(1.0 - tol / radius)))))


def kernel_mesh(kind: str, rec: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """A closed mesh of one kernel (its core — point, segment or arc — swept by a ball, caps
    as half spheres), every vertex on the surface and every triangle within ``tol`` of it
    (half for the rings, half for the arc or the caps): inside, except on a torus's inner
    side, where chords along the arc pass outside by less than tol/2."""
    r = rec[1, 3]
    if kind == "sphere":
        core, tangent = rec[1:2, :3], np.array([[0.0, 0.0, 1.0]])
        n1, n2 = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]])
    elif kind == "capsule":
        a, b = rec[1, :3], rec[2, :3]
        axis = (b - a) / np.linalg.norm(b - a)
        side = cross(axis, np.eye(3)[np.argmin(np.abs(axis))])
        side /= np.linalg.norm(side)
        core, tangent = np.stack([a, b]), np.stack([axis, axis])
        n1, n2 = np.stack([side, side]), np.stack([cross(axis, side)] * 2)
    elif kind == "toroidal_capsule":
        R = 1.0 / float(rec[2] @ rec[2])
        e1, e2, n = arc_world(rec[2], np.eye(3)) / R  # the arc's frame (compile/krs.py)
        half = 2.0 * math.atan(rec[3, 0])  # half the arc's angle: t = tan(phi/4)
        a = np.linspace(-half, half, pieces(2.0 * half, R + r, tol / 2, 1) + 1)[:, None]
        n1 = np.cos(a) * e1 + np.sin(a) * e2
        core, tangent = rec[1, :3] + R * n1, -np.sin(a) * e1 + np.cos(a) * e2
        n2 = np.broadcast_to(n, n1.shape)
    else:
        raise ValueError(f"kernel_mesh: a {kind} kernel has no closed surface")
    sides = pieces(2.0 * math.pi, r, tol / 2, 3)
    bands = pieces(math.pi / 2, r, tol / 2, 1)
    beta = np.arange(bands - 1, 0, -1) * (math.pi / 2 / bands)  # cap latitudes, pole side first
    last = len(core) - 1
    centres = np.concatenate(
        [
            core[0] - r * np.sin(beta)[:, None] * tangent[0],
            core,
            core[last] + r * np.sin(beta[::-1])[:, None] * tangent[last],
        ]
    )
    radii = np.concatenate([r * np.cos(beta), np.full(len(core), r), r * np.cos(beta[::-1])])
    ends = [0] * len(beta) + list(range(len(core))) + [last] * len(beta)
    theta = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
    around = (
        np.cos(theta)[None, :, None] * n1[ends][:, None]
        + np.sin(theta)[None, :, None] * n2[ends][:, None]
    )
    rings = centres[:, None] + radii[:, None, None] * around
    poles = np.stack([core[0] - r * tangent[0], core[last] + r * tangent[last]])
    vertices = np.concatenate([rings.reshape(-1, 3), poles])
    return vertices, ring_faces(len(centres), sides)


def ring_faces(count: int, sides: int) -> np.ndarray:
    """Triangles joining ``count`` rings of ``sides`` vertices, each ring to the next, and
    fans to the two poles stored after them (first pole before ring 0, second after the last)."""
    s = np.arange(sides)
    ring = np.arange(count - 1)[:, None] * sides
    a, b = ring + s, ring + (s + 1) % sides
    c, d = a + sides, b + sides
    bands = np.stack([np.stack([a, b, d], -1), np.stack([a, d, c], -1)], 2).reshape(-1, 3)
    first, second = count * sides, count * sides + 1
    top = np.stack([np.full(sides, first), (s + 1) % sides, s], -1)
    end = (count - 1) * sides
    bottom = np.stack([np.full(sides, second), end + s, end + (s + 1) % sides], -1)
    return np.concatenate([top, bands, bottom])


def level_tolerances(krs: KRS, maps, view: View, tol_px: float) -> list[float]:
    """Per level, ``tol_px`` pixels in world units at the nearest of its instances (0 where
    the eye is inside one: the finest tessellation)."""
    out = []
    for k, (M, t) in zip(krs.kernels, maps):
        ball = kernel_ball(k)
        if ball is None:
            out.append(0.0)
            continue
        centres = M @ ball[:3] + t
        near = float(np.linalg.norm(centres - view.origin, axis=1).min()) - ball[3]
        out.append(tol_px * view.footprint * max(near, 0.0))
    return out


def expand(krs: KRS, view: View, tol_px: float = TOLERANCE) -> Mesh:
    """Every kernel instance of ``krs`` as triangles, within ``tol_px`` pixels of the surface
    as ``view`` sees its nearest instance of each level."""
    c = compile_krs(krs, (1.0, 1.0, 1.0))
    maps = instance_maps(c)
    tols = level_tolerances(krs, maps, view, tol_px)
    vertices, faces, count, instances = [], [], 0, 0
    for kind, rec, (M, t), tol in zip(c.types, c.records, maps, tols):
        if kind == "empty":
            continue
        v, f = kernel_mesh(kind, rec, tol)
        vertices.append((np.einsum("kij,vj->kvi", M, v) + t[:, None]).reshape(-1, 3))
        faces.append((f[None] + count + len(v) * np.arange(len(M))[:, None, None]).reshape(-1, 3))
        count += len(M) * len(v)
        instances += len(M)
    return Mesh(
        np.concatenate(vertices).astype(np.float32),
        np.concatenate(faces).astype(np.uint32),
        instances,
    )
