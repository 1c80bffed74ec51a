"""MöKRS compiled for the tracers [KRS17 §6–7]: each level's inverse map H_i = G_i⁻¹, its
mirror flag, kernel records, pole records and bounding balls (in each level's space and
mapped out). Shared by the GPU packer, the NumPy reference and the oracle."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..algebra import mobius
from ..scene import MoKRS, SceneError
from ..scene.model import Empty
from ..scene.mokrs import check_view
from .balls import CULL_MARGIN, UNBOUNDED, kernel_ball, union_ball
from .krs import kernel_records

FLOAT32_REACH = 1e18  # a bound's reach in its level's space: its square stays in float32


def level_bounds(m: MoKRS) -> np.ndarray:
    """(n, 4): per level i, a ball in level i's space holding everything the tracer still
    tests at level i and below: K_i ∪ L_{i−1}, doubled by R when the level reflects; radius −1
    where unbounded (a plane kernel, or a ball carried through a pole)."""
    return bounds_in_and_out(m)[0]


def bounds_in_and_out(m: MoKRS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`level_bounds`, and each mapped out by G_i into the space before H_i (level
    i+1's; the world for the outermost), widened by CULL_MARGIN against the float64 map's
    rounding (the oracle tests them before H_i, away from its pole); radius −1 where
    unbounded or where the bound holds G_i's pole (its image is no ball). Third, each mapped
    ball's radius in world lengths: scaled by the maps above it while they are similarities,
    ∞ below a map with a pole (its scale varies) or where unbounded."""
    out, outer, below = [], [], None  # below: bound of L_{i−1} in level i's space
    unbounded = False
    for lv in m.levels:
        if not unbounded:
            k = kernel_ball(lv.kernel)
            unbounded = k is None and not isinstance(lv.kernel, Empty)
            ball = union_ball(below, k)
            if ball is not None and lv.reflect:
                ball = union_ball(ball, ball * [-1.0, 1.0, 1.0, 1.0])
        out.append(UNBOUNDED if unbounded or ball is None else ball)
        if not unbounded and ball is not None:
            c, r, ok = mobius.map_ball(lv.matrix(), ball[None, :3], ball[3:])
            unbounded = not ok[0] or not np.isfinite(r[0]) or not np.isfinite(c).all()
            below = np.array([*c[0], r[0]])
        margin = CULL_MARGIN * float(np.abs(below[:3]).max()) if below is not None else 0.0
        outer.append(
            UNBOUNDED
            if unbounded or ball is None
            else np.array([*below[:3], below[3] * (1 + CULL_MARGIN) + margin])
        )
    outer = np.array(outer)
    size, scale = np.full(len(outer), np.inf), 1.0  # world length per unit of level i+1
    for i in range(len(outer) - 1, -1, -1):
        if outer[i, 3] >= 0:
            size[i] = outer[i, 3] * scale
        G = m.levels[i].matrix()
        scale = np.inf if mobius.pole(G) is not None else scale * mobius.affine_scale(G)
    return np.array(out), outer, size


@dataclass(frozen=True)
class CompiledMoKRS:
    inverse: np.ndarray  # (n, 2, 2, 4): H_i = G_i⁻¹, level i+1's space → level i's
    reflect: np.ndarray  # (n,) bool
    records: np.ndarray  # (n, RECORD_VEC4, 4), in each level's own space
    types: tuple[str, ...]
    poles: np.ndarray  # (n, 4): (pole.xyz | (|a|/|d|, 0, 0), has_pole + 2·reflects)
    bounds: np.ndarray  # (n, 4): level_bounds, in each level's own space
    outer: np.ndarray  # (n, 4): each mapped out by G_i (bounds_in_and_out)
    outer_size: np.ndarray  # (n,): their radii in world lengths (∞: the scale varies)

    @property
    def n(self) -> int:
        return len(self.reflect)

    def relative_to(self, origin) -> CompiledMoKRS:
        """World positions taken relative to ``origin``: only the outermost H changes,
        H_{n−1} ← H_{n−1} · T(origin) (the world point is origin + the relative point)."""
        inverse, poles = self.inverse.copy(), self.poles.copy()
        inverse[-1] = mobius.tidy(mobius.compose(inverse[-1], mobius.translation(origin)))
        poles[-1] = pole_record(inverse[-1], self.reflect[-1])
        outer = self.outer.copy()  # the outermost lives in the world
        if outer[-1, 3] >= 0:
            outer[-1, :3] -= np.asarray(origin, dtype=np.float64)
        return CompiledMoKRS(
            inverse,
            self.reflect,
            self.records,
            self.types,
            poles,
            self.bounds,
            outer,
            self.outer_size,
        )  # level spaces stay


def pole_record(H: np.ndarray, reflect: bool) -> np.ndarray:
    """What ``map_ball`` in mobius.glsl needs besides H: the pole, or for a similarity its
    scale, and the flags; computed per scene (the top level's per frame), not per pixel."""
    p = mobius.pole(H)
    slot = p if p is not None else (mobius.affine_scale(H), 0.0, 0.0)
    return np.array([*slot, (p is not None) + 2 * bool(reflect)], dtype=np.float64)


def compile_mokrs(m: MoKRS, albedo: tuple[float, float, float]) -> CompiledMoKRS:
    """The tracer's arrays; a SceneError where its bounding balls outgrow float32."""
    inverse = np.array([lv.inverse() for lv in m.levels])
    reflect = np.array([lv.reflect for lv in m.levels])
    records, types = kernel_records(m.kernels, albedo)
    poles = np.array([pole_record(H, r) for H, r in zip(inverse, reflect)])
    bounds = bounds_in_and_out(m)
    check_float32(bounds[0])
    return CompiledMoKRS(inverse, reflect, records, types, poles, *bounds)


def check_drawable(m: MoKRS, eye: tuple[float, float, float], where: str) -> None:
    """A SceneError unless the tracer can draw ``m`` from ``eye`` (``where`` names it): the
    viewpoint off every pole [KRS17 §7], and every bounding ball within float32 (refused,
    not drawn as a solid colour)."""
    check_view(m, eye, where)
    check_float32(bounds_in_and_out(m)[0])


def check_float32(bounds: np.ndarray, path: str = "mokrs.levels") -> None:
    """Each level's bounding ball fits float32 with room for its square (the tracer compares
    squared lengths): a scale factor that grows every level by itself, repeated over linked
    levels, multiplies past it (palm's 29 linked levels at a factor of 50: 1.9e51, drawn as
    a solid colour). A SceneError names the first level too far."""
    reach = np.abs(bounds[:, :3]).max(axis=1) + np.maximum(bounds[:, 3], 0.0)
    for i in np.flatnonzero(~(reach <= FLOAT32_REACH)):
        raise SceneError(
            f"{path}[{int(i)}]",
            f"<a bound reaching {reach[i]:.3g}>",
            f"its levels' maps scale it past what float32 holds (allowed: {FLOAT32_REACH:g} "
            "in its level's space); a smaller scale factor, or fewer levels sharing it",
        )
