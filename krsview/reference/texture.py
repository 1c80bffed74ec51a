"""Procedural textures [KRS17 §8.2]: fractal value noise on an integer-hashed lattice, with
octaves faded out as they approach the pixel footprint (LOD filtering); triplanar projection
[Gei07] and kernel-space coordinates along / around each kernel. Twin of
``shaders/texture.glsl``: the hash is exact uint32 arithmetic in both, so only the float
interpolation differs."""

from __future__ import annotations

import numpy as np

from ..algebra.vectors import cross
from ..compile.constants import (
    BARK_STRETCH,
    GROUND_STRETCH,
    TEXTURE_OCTAVE_SHIFT,
    TEXTURE_OCTAVES,
)
from ..scene.tree import perpendicular
from .kernels import arc_local


def lattice(cx: np.ndarray, cy: np.ndarray) -> np.ndarray:
    """Hash of integer lattice points to [0, 1], in uint32 arithmetic as the shader."""
    x = (cx.astype(np.int64) & 0xFFFFFFFF).astype(np.uint32)
    y = (cy.astype(np.int64) & 0xFFFFFFFF).astype(np.uint32)
    with np.errstate(over="ignore"):
        h = (x * np.uint32(0x8DA6B343)) ^ (y * np.uint32(0xD8163841))
        h ^= h >> np.uint32(13)
        h *= np.uint32(0x85EBCA6B)
        h ^= h >> np.uint32(16)
    return (h & np.uint32(0xFFFF)).astype(np.float64) / 65535.0


def value_noise(x: np.ndarray) -> np.ndarray:
    """Smoothly interpolated lattice values at points x (N, 2)."""
    i = np.floor(x)
    f = x - i
    u = f * f * (3.0 - 2.0 * f)
    cx, cy = i[:, 0], i[:, 1]
    a, b = lattice(cx, cy), lattice(cx + 1, cy)
    c, d = lattice(cx, cy + 1), lattice(cx + 1, cy + 1)
    return (a + (b - a) * u[:, 0]) * (1 - u[:, 1]) + (c + (d - c) * u[:, 0]) * u[:, 1]


def fbm(x: np.ndarray, footprint: np.ndarray) -> np.ndarray:
    """Octaves of 1, 2, 4, … cells per unit of x; an octave is kept fully while its cell is
    ≥ 4 footprints wide and replaced by its mean 0.5 once it is ≤ 2 footprints."""
    total = np.zeros(len(x))
    norm, amp, freq, shift = 0.0, 1.0, 1.0, np.array(TEXTURE_OCTAVE_SHIFT)
    for o in range(TEXTURE_OCTAVES):
        keep = np.clip(2.0 - 4.0 * footprint * freq, 0.0, 1.0)
        total += amp * (0.5 + (value_noise(freq * x + o * shift) - 0.5) * keep)
        norm += amp
        amp *= 0.5
        freq *= 2.0
    return total / norm


def modulation(pattern: np.ndarray, strength: float) -> np.ndarray:
    """Albedo factor with mean 1: 1 + strength·(2·pattern − 1)."""
    return 1.0 + strength * (2.0 * pattern - 1.0)


def triplanar(p: np.ndarray, n: np.ndarray, footprint: np.ndarray, scale: float) -> np.ndarray:
    """The texture projected along x, y, z, blended by |n|⁴ [Gei07]; world points p."""
    w = np.abs(n) ** 4
    w /= w.sum(axis=1, keepdims=True)
    x, f = p / scale, footprint / scale
    return (
        w[:, 0] * fbm(x[:, [1, 2]], f)
        + w[:, 1] * fbm(x[:, [2, 0]], f)
        + w[:, 2] * fbm(x[:, [0, 1]], f)
    )


def kernel_uv(kind: str, rec: np.ndarray, xk: np.ndarray) -> np.ndarray:
    """(along, around) in scene units at kernel-space points xk (N, 3) of one kernel; world
    coordinates (the shader adds the eye back for planes, whose records are camera-relative)."""
    r = rec[1, 3]
    if kind == "sphere":
        q = xk - rec[1, :3]
        cos = np.clip(q[:, 1] / np.maximum(np.linalg.norm(q, axis=1), 1e-30), -1.0, 1.0)
        return r * np.stack([np.arctan2(q[:, 2], q[:, 0]), np.arccos(cos)], axis=1)
    if kind == "capsule":
        a = rec[1, :3]
        d = (rec[2, :3] - a) / np.linalg.norm(rec[2, :3] - a)
        e1 = perpendicular(d)
        e2 = cross(d, e1)
        q = xk - a
        return np.stack([q @ d, r * np.arctan2(q @ e2, q @ e1)], axis=1)
    if kind == "toroidal_capsule":  # the arc's frame in units of R: angles from its bisector
        a = arc_local(rec[2], xk - rec[1, :3])  # along, from its plane around the tube
        along = np.arctan2(a[:, 1], a[:, 0]) / float(rec[2] @ rec[2])
        return np.stack([along, r * np.arctan2(a[:, 2], np.hypot(a[:, 0], a[:, 1]) - 1.0)], axis=1)
    u = rec[1, :3]  # plane
    e1 = perpendicular(u)
    return np.stack([xk @ e1, xk @ cross(u, e1)], axis=1)


def kernel_texture(
    kind: str, rec: np.ndarray, xk: np.ndarray, footprint: np.ndarray, scale: float
) -> np.ndarray:
    stretch = np.array(GROUND_STRETCH if kind == "plane" else BARK_STRETCH)
    x = stretch * kernel_uv(kind, rec, xk) / scale
    return fbm(x, stretch.max() * footprint / scale)
