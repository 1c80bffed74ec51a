"""A KRS flattened to arrays, shared by the NumPy reference and the GPU uniform packer.

Each kernel becomes a record of ``RECORD_VEC4`` vec4s (layout below, mirrored in
``shaders/kernels.glsl``); positions are relative to ``origin`` so the GPU can work in
camera-relative coordinates while the CPU keeps the camera in float64 (DESIGN.md, Precision).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..scene import KRS, Capsule, Empty, Plane, Sphere, ToroidalCapsule, arc_of

# Kernel type codes, equal to the KERNEL_* defines in kernels.glsl.
KERNEL_CODES = {"empty": 0, "sphere": 1, "capsule": 2, "toroidal_capsule": 3, "plane": 4}
RECORD_VEC4 = 6
# record[0] = (colour rgb, type code)
# record[1] = sphere (centre, r) | capsule/arc (start A, r) | plane (normal u, offset w)
# record[2] = capsule/arc (end B, 0)
# record[3] = arc (centre O, major radius R)
# record[4] = arc (e1: unit O→A, cos phi)     phi: arc angle from A to B, in (0, 2π)
# record[5] = arc (e2: unit, in-plane ⟂ e1, sin phi)


@dataclass(frozen=True)
class CompiledKRS:
    mirrors: np.ndarray   # (n, 4): u.xyz, w  (plane u·x = w, relative to origin)
    records: np.ndarray   # (n+1, RECORD_VEC4, 4) float64
    types: tuple[str, ...]  # kernel type per level (after arc → capsule degeneration)

    @property
    def n(self) -> int:
        return len(self.mirrors)


def compile_krs(krs: KRS, albedo: tuple[float, float, float],
                origin: np.ndarray | tuple = (0.0, 0.0, 0.0)) -> CompiledKRS:
    """Flatten ``krs`` with all positions taken relative to ``origin`` (float64)."""
    o = np.asarray(origin, dtype=np.float64)
    mirrors = np.array([[*m.normal, m.offset - np.dot(m.normal, o)] for m in krs.mirrors],
                       dtype=np.float64).reshape(-1, 4)
    records = np.zeros((len(krs.levels), RECORD_VEC4, 4))
    types = []
    for i, k in enumerate(krs.kernels):
        kind = k.kind
        r = records[i]
        color = getattr(k, "color", None) or albedo
        if isinstance(k, Sphere):
            r[1] = [*(np.array(k.center) - o), k.radius]
        elif isinstance(k, Capsule):
            r[1] = [*(np.array(k.a) - o), k.radius]
            r[2, :3] = np.array(k.b) - o
        elif isinstance(k, ToroidalCapsule):
            r[1] = [*(np.array(k.start) - o), k.radius]
            r[2, :3] = np.array(k.end) - o
            arc = arc_of(k)
            if arc is None:
                kind = "capsule"
            else:
                r[3] = [*(np.array(arc.center) - o), arc.R]
                r[4] = [*arc.e1, np.cos(arc.phi)]
                r[5] = [*arc.e2, np.sin(arc.phi)]
        elif isinstance(k, Plane):
            r[1] = [*k.normal, k.offset - np.dot(k.normal, o)]
        else:
            assert isinstance(k, Empty), k
        r[0] = [*color, KERNEL_CODES[kind]]
        types.append(kind)
    return CompiledKRS(mirrors, records, tuple(types))
