"""Sphere tracing [Har96] of the KRS distance with LOD ε = footprint × t × ε-scale [KRS17 §4].

Mirrors ``shaders/trace.glsl`` step for step: evaluate, count, stop when d ≤ ε(t), else advance
by d; a ray that passes max_distance or spends the iteration cap is a miss.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .compiled import CompiledKRS
from .krs import distance


@dataclass
class Trace:
    hit: np.ndarray         # bool (N,)
    t: np.ndarray           # ray distance at termination (N,)
    iterations: np.ndarray  # distance evaluations (N,)


def sphere_trace(c: CompiledKRS, origin: np.ndarray, dirs: np.ndarray, eps_per_t: float,
                 max_iterations: int, max_distance: float) -> Trace:
    N = len(dirs)
    t = np.zeros(N)
    hit = np.zeros(N, dtype=bool)
    iters = np.zeros(N, dtype=np.int64)
    active = np.arange(N)
    for _ in range(max_iterations):
        if active.size == 0:
            break
        ta = t[active]
        d = distance(c, origin + ta[:, None] * dirs[active])
        iters[active] += 1
        converged = d <= eps_per_t * ta
        hit[active[converged]] = True
        ta = ta + d
        t[active[~converged]] = ta[~converged]
        active = active[~converged & (ta <= max_distance)]
    return Trace(hit, t, iters)
