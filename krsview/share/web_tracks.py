"""The exported page's moving scene [issue 29]: keyframe tracks and sway are posed on the CPU
(``Scene.posed``), never in the shaders, so the page carries poses sampled over the scene's
loop. Each moment is compiled as the still page is; what is the same at every moment stays a
constant of the shader, and the rest is one row of values per moment that the page uploads
when its clock reaches it. Exact poses only: the page shows the row at or before its clock,
never a blend of two (a blend of two Möbius steps is no Möbius map, and blended mirrors and
balls are no longer the ones Alg. 1's distance bound was computed for)."""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from ..compile.camera import view_of
from ..compile.geometry import Compiled, compile_geometry
from ..gpu.uniforms import block_arrays, variant_defines, view_uniforms
from ..scene import Camera, Scene
from ..scene.camera_path import horizontal_axes

PAGE_RATE = 24.0  # poses a second of the scene's loop, at most
PAGE_MOMENTS = 480  # poses at most: each is posed and compiled at export (a few ms)
PAGE_DATA_CAP = 3 * 2**20  # bytes of the poses' text in the page (base64 float32 rows)
BLOCK_BYTES = 16384  # WebGL2's smallest MAX_UNIFORM_BLOCK_SIZE: the live KRSBlock's room
_INTEGERS = ("int", "ivec2", "ivec3", "ivec4", "bool")  # uploaded with uniform*iv


class Moment(NamedTuple):
    """One pose compiled for the page: the variant's defines, the uniform values the renderer
    would upload (relative to the eye O), the orbit's included, and the compiled geometry."""

    defines: dict
    values: dict
    compiled: Compiled


def moment(scene: Scene, origin: np.ndarray) -> Moment:
    """``scene`` posed at its time as the page's tracer draws it (one fragment pass, every
    level, no pre-pass; ``KRS_SLOTS`` the slots in use, no more), every position relative to
    ``origin``, the eye O every pose of the page shares; the posed camera is the orbit's
    start (its tracks followed) and its field of view."""
    scene = scene.posed()
    scene = replace(scene, render=replace(scene.render, prepass=0, path="fragment", lod=0.0))
    view = replace(view_of(scene.camera, 640, 360), origin=origin)  # the basis is live
    c = compile_geometry(scene.geometry(), scene.material.albedo).relative_to(origin)
    defines = variant_defines(scene, c)
    defines["KRS_SLOTS"] = len(c.records)
    values = {
        **view_uniforms(scene, view, c),
        **orbit_uniforms(scene.camera, origin),
        "u_epsilon_scale": scene.render.epsilon_scale,
    }
    return Moment(defines, values, c)


def orbit_uniforms(cam: Camera, origin: np.ndarray) -> dict[str, object]:
    """The orbit of web.frag's orbit_camera: around the camera's target, starting at its eye
    (positions relative to O)."""
    up = np.array(cam.up, dtype=np.float64)
    up /= np.linalg.norm(up)
    east, north = horizontal_axes(up)
    target = np.array(cam.target, dtype=np.float64) - origin
    away = np.array(cam.position, dtype=np.float64) - np.array(cam.target, dtype=np.float64)
    distance = float(np.linalg.norm(away))
    away /= distance
    return {
        "u_orbit_target": tuple(target),
        "u_orbit_east": tuple(east),
        "u_orbit_north": tuple(north),
        "u_orbit_up": tuple(up),
        "u_orbit_start": (
            math.atan2(away @ east, away @ north),
            math.asin(max(-1.0, min(1.0, away @ up))),
            distance,
        ),
    }


@dataclass(frozen=True)
class Poses:
    """The scene's loop as the page plays it: ``rate`` poses a second from t = 0, all of one
    variant (``defines``; ``KRS_SLOTS`` the largest any pose uses), each pose's uniform
    values and KRSBlock arrays (padded to those slots), relative to the exported eye."""

    rate: float
    defines: dict
    values: list[dict]
    blocks: list[dict]


def sample(scene: Scene) -> Poses | str:
    """The poses of the scene's loop at ``PAGE_RATE`` a second (fewer where the loop is longer
    than ``PAGE_MOMENTS`` of them), or why one variant cannot draw them all (a track that
    switches a define: a tracer, a kernel kind, an effect)."""
    rate = min(PAGE_RATE, PAGE_MOMENTS / scene.duration)
    count = max(1, math.ceil(scene.duration * rate - 1e-9))
    origin = np.array(scene.posed().camera.position, dtype=np.float64)  # the exported eye
    moments = [moment(scene.at(k / rate), origin) for k in range(count)]
    slots = max(m.defines["KRS_SLOTS"] for m in moments)
    defines = {**moments[0].defines, "KRS_SLOTS": slots}
    for k, m in enumerate(moments):
        other = {**m.defines, "KRS_SLOTS": slots}
        if other != defines:
            changed = min(name for name, _ in set(other.items()) ^ set(defines.items()))
            return f"the variant changes at t = {k / rate:g} s ({changed})"
    blocks = [block_arrays(m.compiled, "float", slots) for m in moments]
    return Poses(rate, defines, [m.values for m in moments], blocks)


def differs(rows: list) -> bool:
    """Whether a value is not the same at every moment (shape or any number)."""
    first = np.asarray(rows[0], dtype=np.float64)
    return any(
        (a := np.asarray(r, dtype=np.float64)).shape != first.shape or not np.array_equal(a, first)
        for r in rows[1:]
    )


def live_names(poses: Poses, declared: dict[str, str]) -> tuple[list[str], list[str]]:
    """The KRSBlock arrays and the ``declared`` uniforms (name → GLSL type, those the page
    would bake) whose values change over the loop: the page's live values."""
    block = [name for name in poses.blocks[0] if differs([b[name] for b in poses.blocks])]
    uniforms = [n for n in declared if differs([v[n] for v in poses.values])]
    return block, uniforms


def page_poses(poses: Poses, block: list[str], uniforms: dict[str, str]) -> dict | str:
    """The page's POSES: one float32 row per pose (the live block arrays in block order,
    then each live uniform, ``uniforms`` name → GLSL type), base64; every ``stride``-th pose
    where all of them would pass ``PAGE_DATA_CAP``. A live block over ``BLOCK_BYTES`` is the
    reason the page cannot carry the poses."""
    block_floats = sum(poses.blocks[0][n].size for n in block)
    if 4 * block_floats > BLOCK_BYTES:
        return (
            f"the changing mirrors and kernels fill {4 * block_floats} bytes, more than "
            f"WebGL2 promises a uniform block ({BLOCK_BYTES})"
        )
    layout, offset = [], block_floats
    for name, kind in uniforms.items():
        length = np.asarray(poses.values[0][name]).size
        width = int(kind[-1]) if kind[-1].isdigit() else 1
        layout.append([name, width, kind in _INTEGERS, offset, length])
        offset += length
    rows = np.array(
        [
            np.concatenate(
                [b[n].ravel() for n in block]
                + [np.asarray(v[n], dtype=np.float64).ravel() for n in uniforms]
            )
            for b, v in zip(poses.blocks, poses.values)
        ],
        dtype="<f4",
    )
    fit = max(1, PAGE_DATA_CAP // 4 * 3 // rows[0].nbytes)  # rows whose base64 fits the cap
    stride = math.ceil(len(rows) / fit)
    rows = rows[::stride]
    return {
        "rate": poses.rate / stride,
        "count": len(rows),
        "row": offset,
        "block": block_floats,
        "uniforms": layout,
        "data": base64.b64encode(rows.tobytes()).decode("ascii"),
    }
