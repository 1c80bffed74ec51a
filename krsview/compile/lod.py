"""Where the level of detail cuts a KRS's walk, in closed form [issue 27, KRS14 LOD].

A walk at a point with level of detail ρ (lod.glsl) stops descending at its *cut slot* and
draws that slot's culling ball C_i for everything below it (krs.glsl, reference/krs.py). The
cut asks how large the slot looks, not how deep the tree below it goes: a slot's *cut
radius* is the ball around its top EXACT_LEVELS + 1 levels alone (balls.top_balls), so a
30-level tree cuts where the 23-level one does, where the radius of C_i, which grows with
every level below, would cut one level deeper. On a tree the cut radii fall geometrically
with the depth k = top − i, so one envelope r̂_k = A·q^k above them serves the whole KRS and
a step finds its cut depth from ρ alone, k* = ⌊ln(ρ/A) / ln q⌋ + 1, the first depth with
r̂ < ρ: three numbers read per step, not one more per level (the per-level alternative,
searched, cost llvmpipe what it saved: docs/speed.md).

The walk cuts at the first slot with a ball at or below depth k*. Its ball holds everything
below, so the LOD geometry still holds the KRS (no ray passes it), and R_i ≤ K·r̂_i < K·ρ with
K = max_i R_i / r̂_i: a ball drawn below a slot reaches at most its diameter, under 2Kρ,
beyond that slot's ball, which is culling's reach (read once a step, :func:`krs_lod`), and
every point of it lies within that diameter of what it stands for."""

from __future__ import annotations

import math

import numpy as np

from ..scene import KRS
from .balls import EXACT_LEVELS, top_balls

STEEPEST = math.log(0.05)  # ln q kept in [STEEPEST, FLATTEST]: radii that do not fall, or
FLATTEST = math.log(0.999)  # fall faster than any tree, still get a finite cut depth
REACH_MARGIN = 1e-3  # against a float log that cuts one slot early at r̂ ≈ ρ
NO_CUT = np.array([0.0, 1.0, 0.0, 0.0])  # "never cuts" (1/ln q ≥ 0): no slot has a ball
DEEPEST = 1 << 20  # a cut depth past every level (ρ = 0)


def lod_cut(krs: KRS, bounds: np.ndarray) -> np.ndarray:
    """The KRS's cut record (ln A, 1/ln q, 2K, 0) from its slots' culling balls ``bounds``
    (balls.krs_bounds; radius < 0: none), twin of lod.glsl's u_lod_cut."""
    n = len(bounds)
    has = np.flatnonzero(bounds[:, 3] >= 0)
    if not has.size:
        return NO_CUT.copy()
    tops = top_balls(krs)
    r = np.array([tops[i][3] if tops[i] is not None else bounds[i, 3] for i in has])
    r = np.maximum(r, 1e-300)
    k = (n - 1 - has).astype(np.float64)
    full = has >= EXACT_LEVELS  # slots with all their top levels below them: the trend
    fit = full if full.sum() >= 2 else np.ones_like(full)
    slope = np.polyfit(k[fit], np.log(r[fit]), 1)[0] if fit.sum() >= 2 else FLATTEST
    ln_q = float(np.clip(slope, STEEPEST, FLATTEST))
    ln_a = float(np.max(np.log(r) - k * ln_q))  # the envelope: r̂_k ≥ r_k at every slot
    K = float(np.max(bounds[has, 3] / np.exp(ln_a + k * ln_q)))
    return np.array([ln_a, 1.0 / ln_q, 2.0 * K * (1.0 + REACH_MARGIN), 0.0])


def cut_depth(cut: np.ndarray, rho: np.ndarray | float) -> np.ndarray:
    """k*(ρ): the first depth below the top slot whose envelope radius is below ρ, 0 where the
    top's is; DEEPEST where ρ = 0 or nothing cuts. In float32, as lod.glsl computes it (GLSL
    has no double log), so the twins cut at the same slot."""
    rho = np.asarray(rho, dtype=np.float32)
    if cut[1] >= 0:  # NO_CUT: no slot has a ball
        return np.full(rho.shape, DEEPEST)
    with np.errstate(divide="ignore"):
        x = (np.log(np.maximum(rho, np.float32(1e-30))) - np.float32(cut[0])) * np.float32(cut[1])
    return np.clip(np.floor(np.minimum(x, np.float32(DEEPEST))) + 1, 0, DEEPEST).astype(np.int64)


def krs_lod(c, rho: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
    """A walk's level of detail at ρ in the compiled KRS ``c`` (its ``lod_cut`` and
    ``bounds``): the cut depth (:func:`cut_depth`), and how far a ball cut there reaches
    beyond the ball of any slot above it, culling's reach: the diameter of the slot's ball at
    that depth, 2Kρ where that slot has none and the cut falls to a ball below it, 0 where
    the depth is past the last level. Twin of lod.glsl's krs_lod."""
    rho = np.asarray(rho, dtype=np.float64)
    depth = cut_depth(c.lod_cut, rho)
    radii = c.bounds[:, 3]
    slot = c.n - 1 - np.minimum(depth, c.n)
    r = radii[np.maximum(slot, 0)] if c.n else np.zeros(np.shape(slot))
    return depth, np.where(slot < 0, 0.0, np.where(r >= 0, 2.0 * r, c.lod_cut[2] * rho))
