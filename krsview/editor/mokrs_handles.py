"""Handles of a MöKRS [KRS17 §7]: its kernels' points and every transform step, each placed in
the world through the Möbius maps above it, and the edit a drag makes (the dragged world point
mapped back through their inverse). Pure NumPy: the editor window draws and drags them.

Level i's space reaches the world through G_i, G_{i+1}, …, G_last. Inside level i the steps
s_0 … s_k apply in order, so the frame after step j reaches the world through
M_j = G_last ∘ … ∘ G_{i+1} ∘ s_k ∘ … ∘ s_{j+1}; a step's handle is a point of that frame:
translate its vector ``by``, scale the image s·ρ·u of a point at the level's size ρ along u,
rotate a dial point turned by the angle about the axis (and the axis' tip), invert the
sphere's centre and a point on it (an inversion maps its sphere onto itself)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..algebra import mobius
from ..algebra.vectors import cross
from ..scene import MoKRS, Scene
from ..scene.edits import Path, get_at
from ..scene.model import Empty
from ..scene.mokrs import (
    Invert,
    MobiusLevel,
    Rotate,
    Scale,
    Translate,
    from_real,
    linked_edit,
)

KERNEL_POINTS = ("center", "a", "b", "start", "control", "end")  # the kernels' point fields
SCALE_DIRECTION = np.array([1.0, 0.0, 0.0])  # u: where a scale step's handle sits
RADIUS_DIRECTION = np.array([1.0, 0.0, 0.0])  # an inversion sphere's point handle
SHARED = 1e-9  # a kernel point this close (× its size) to a step's handle is that handle
GUIDE_SEGMENTS = 48  # a circle of a guide (a dial, a sphere's great circle) in segments
DIAL_DECIMALS = 2  # a dragged angle lands on 0.01°, a hundredth of a pixel on the dial's ring
FACTOR_DECIMALS = 4  # a dragged scale factor lands on 0.0001: under 1/50 px while ρ < 200 px
AXIS_STEP = 1e-6  # × ρ: the step along a dial's axis whose image gives its world direction


@dataclass(frozen=True, eq=False)
class MobiusHandle:
    """A handle of a MöKRS, with the fields the editor reads of every handle (``path``,
    ``kind``, ``position``, ``level``, ``label``, ``owner``, ``pivot``) and the map
    ``to_world`` of the frame its point lives in."""

    path: Path  # the field it edits
    kind: str  # "point"; "axis": a rotation axis' tip; "dial": turned about ``axis``
    position: np.ndarray  # world, float64
    level: int
    label: str
    owner: Path  # the step or level the panel shows
    to_world: np.ndarray  # Möbius matrix: the handle's frame → world
    role: str  # "point", "by", "factor", "degrees", "axis", "center", "radius", "origin"
    size: float = 1.0  # ρ: the dial's radius, the unit a scale handle measures in
    pivot: np.ndarray | None = None
    guides: tuple[np.ndarray, ...] = field(default=(), repr=False)  # world polylines
    axis: np.ndarray | None = None  # "dial": the world direction it turns about, at pivot

    @property
    def carries(self) -> bool:
        """A MöKRS has no subtree to carry: the finer levels follow a level's maps anyway
        (its steps' links are ``carry`` for the step handles: dragging.drag_edits)."""
        return False

    def edit_to(self, scene: Scene, p: np.ndarray, carry: bool = True) -> tuple[Path, Any]:
        """The edit (field path, new value) that puts the handle at world point ``p``; with
        ``carry``, a step's change goes to the finer levels with the same steps too
        (``linked_levels``: palm's leaflets bend alike)."""
        value = self.value_at(scene, p)
        if self.role == "origin":  # an identity level gains the translate its handle is
            return (*self.owner, "transform"), [Translate(value)]
        if carry and self.role != "point":
            return linked_edit(scene.mokrs, self.path, value)
        return self.path, value

    def value_at(self, scene: Scene, p: np.ndarray) -> Any:
        """The field's new value: ``p`` mapped into the handle's frame, then read as the
        step reads it. A point on a pole maps to infinity: the schema refuses it."""
        with np.errstate(all="ignore"):
            q = mobius.apply(mobius.inverse(self.to_world), np.asarray(p, dtype=np.float64)[None])
        q = q[0]
        step = get_at(scene, self.owner)
        if self.role == "factor":  # no float noise in the saved file, as the dial
            return round(float(q @ SCALE_DIRECTION) / self.size, FACTOR_DECIMALS)
        if self.role == "radius":
            return float(np.linalg.norm(q - np.array(step.center)))
        if self.role == "degrees":
            return _dial_degrees(step, q)
        if self.role == "axis":
            n = float(np.linalg.norm(q))
            return tuple(float(c) for c in (q / n if n > 0 else q))  # zero: the schema says why
        return tuple(float(c) for c in q)

    def same(self, other: Any) -> bool:
        return other is not None and (self.path, self.kind) == (other.path, other.kind)


def _dial_vector(axis) -> np.ndarray:
    """A unit vector ⊥ ``axis``: where a rotation's dial reads 0°."""
    a = np.asarray(axis, dtype=np.float64)
    e = np.eye(3)[int(np.argmin(np.abs(a)))]
    v = e - (e @ a) * a
    return v / np.linalg.norm(v)


def _dial_degrees(step: Rotate, q: np.ndarray) -> float:
    """The angle about the step's axis that turns the dial's 0° vector towards ``q``: the
    representative nearest the step's present angle, so a dial dragged past ±180° keeps
    turning (within the schema's ±360°), written as the shortest decimal of DIAL_DECIMALS
    places (as the gizmo writes a moved point: no float noise in the saved file)."""
    a = np.asarray(step.axis, dtype=np.float64)
    v = _dial_vector(a)
    w = q - (q @ a) * a
    angle = math.degrees(math.atan2(float(cross(v, w) @ a), float(v @ w)))
    new = step.degrees + (angle - step.degrees + 180.0) % 360.0 - 180.0
    new = new - 360.0 if new > 360.0 else new + 360.0 if new < -360.0 else new
    return round(new, DIAL_DECIMALS)


def level_size(lv: MobiusLevel) -> float:
    """ρ: the reach of the level's kernel from its origin (1 for an empty or plane kernel),
    so a level's handles sit at its own scale."""
    k = lv.kernel
    pts = [np.array(getattr(k, f)) for f in KERNEL_POINTS if hasattr(k, f)]
    if isinstance(k, Empty) or not pts:
        return 1.0
    return max(float(np.linalg.norm(p)) for p in pts) + float(getattr(k, "radius", 0.0)) or 1.0


@dataclass(frozen=True)
class _Local:
    """A handle before it is mapped: its point, pivot and guides in its own frame."""

    path: Path
    kind: str
    level: int
    label: str
    owner: Path
    to_world: np.ndarray
    role: str
    size: float
    point: np.ndarray
    guides: tuple[np.ndarray, ...] = ()
    pivot: np.ndarray | None = None
    axis: np.ndarray | None = None


def mokrs_handles(m: MoKRS, at: Path) -> list[MobiusHandle]:
    """Every level's kernel points and step handles, in world space, from the coarsest level
    inwards: the map of level i's space is the frame before its first step."""
    out: list[_Local] = []
    outside = np.eye(8)  # level i+1's space → world, as a real 8×8 matrix
    for i in range(len(m.levels) - 1, -1, -1):
        lv, lev = m.levels[i], (*at, "levels", i)
        frames = []  # frames[j]: the frame after step j → world
        for s in reversed(lv.transform):
            frames.append(from_real(outside))
            outside = outside @ mobius.real_matrix(s.matrix())
        frames.reverse()
        rho = level_size(lv)  # ρ before each step
        for j, (s, M) in enumerate(zip(lv.transform, frames)):
            out += _one_step(s, (*lev, "transform", j), i, f"L{i} step {j} {s.kind}", M, rho)
            rho *= s.factor if isinstance(s, Scale) else 1.0
        k, M = lv.kernel, from_real(outside)
        out += [
            _Local((*lev, "kernel", f), "point", i, f"K{i} {f}", lev, M, "point", 1.0,
                   np.array(getattr(k, f), dtype=np.float64))
            for f in KERNEL_POINTS if hasattr(k, f)
        ]  # fmt: skip
        if not lv.transform and not any(hasattr(k, f) for f in KERNEL_POINTS):
            out.append(_origin(i, lev, M))
    return _steps_first(_mapped_all(out))


def _origin(i: int, lev: Path, M) -> _Local:
    """A level with nothing to grab (no steps, no kernel point: an inserted identity level)
    shows its origin, so it can be selected; a drag gives it a translate step, whose
    handle this becomes (the same path), so the drag goes on."""
    by = (*lev, "transform", 0, "by")
    return _Local(by, "point", i, f"L{i} origin", lev, M, "origin", 1.0, np.zeros(3))


def _mapped_all(local: list[_Local]) -> list[MobiusHandle]:
    """Map every handle's points into the world in one vectorised Möbius application (the
    per-point matrices stacked as (2, 2, N, 4)); a handle sent to infinity is left out, and
    a dial whose pivot is (it cannot turn there)."""
    if not local:
        return []
    parts = [[h.point[None], *([h.pivot[None]] if h.pivot is not None else []), *h.guides,
              *([(h.pivot + AXIS_STEP * h.size * h.axis)[None]] if h.axis is not None else [])]
             for h in local]  # fmt: skip
    pts = np.concatenate([x for p in parts for x in p])
    maps = np.stack([h.to_world for h in local])
    owner = np.repeat(np.arange(len(local)), [sum(len(x) for x in p) for p in parts])
    world = _world(np.moveaxis(maps[owner], 0, 2), pts)
    out, k = [], 0
    for h, p in zip(local, parts):
        mine = []
        for x in p:
            mine.append(world[k : k + len(x)])
            k += len(x)
        if not np.isfinite(mine[0]).all():
            continue
        pivot = mine[1][0] if h.pivot is not None else None
        axis = None
        if h.axis is not None:  # the dial's axis in the world, at the pivot: a short step
            step = mine.pop()[0] - pivot  # along it, mapped (a Möbius map is conformal)
            axis = step / np.linalg.norm(step)
            if not np.isfinite(axis).all():
                continue
        guides = tuple(g[np.isfinite(g).all(axis=1)] for g in mine[1 + (pivot is not None) :])
        out.append(
            MobiusHandle(h.path, h.kind, mine[0][0], h.level, h.label, h.owner, h.to_world,
                         h.role, h.size, pivot, guides, axis)
        )  # fmt: skip
    return out


def _steps_first(hs: list[MobiusHandle]) -> list[MobiusHandle]:
    """Step handles first, and a kernel point that lies on one (palm: a segment's start is
    where the translate puts it) given exactly its position: a click there, nearest-first,
    grabs the step, which moves the point along; the outline and panel still reach the
    point itself."""
    steps = [h for h in hs if h.role != "point"]
    at = np.array([h.position for h in steps]).reshape(-1, 3)
    out = list(steps)
    for h in hs:
        if h.role != "point":
            continue
        if len(at):
            gaps = np.linalg.norm(at - h.position, axis=1)
            k = int(np.argmin(gaps))
            if gaps[k] <= SHARED * max(1.0, float(np.abs(h.position).max())):
                h = replace(h, position=steps[k].position)
        out.append(h)
    return out


def _one_step(s, sp: Path, i: int, name: str, M, rho: float) -> list[_Local]:
    """The handles of one step ``s`` at path ``sp``, in the frame after it (mapped by M)."""

    def handle(role, kind, point, label, guides=(), pivot=None, axis=None):
        return _Local((*sp, role), kind, i, f"{name} {label}", sp, M, role, rho,
                      np.asarray(point, dtype=np.float64), guides, pivot, axis)  # fmt: skip

    zero = np.zeros(3)
    if isinstance(s, Translate):
        by = np.array(s.by)
        return [handle("by", "point", by, "by", (_segment(zero, by),))]
    if isinstance(s, Scale):
        tip = s.factor * rho * SCALE_DIRECTION
        return [handle("factor", "point", tip, "factor", (_segment(zero, tip),))]
    if isinstance(s, Rotate):
        a = np.array(s.axis)
        v = _dial_vector(a)
        dial = mobius.apply(s.matrix(), rho * v[None])[0]
        ring = _circle(zero, rho * v, rho * cross(a, v))
        return [
            handle(
                "degrees", "dial", dial, f"{s.degrees:g} deg", (ring, _segment(zero, dial)), zero, a
            ),
            handle("axis", "axis", rho * a, "axis", (_segment(-rho * a, rho * a),), zero),
        ]
    if isinstance(s, Invert):
        c, r = np.array(s.center), s.radius
        e = np.eye(3) * r
        rings = tuple(_circle(c, e[k], e[(k + 1) % 3]) for k in range(3))
        rim = c + r * RADIUS_DIRECTION
        return [
            handle("center", "point", c, "centre", rings),
            handle("radius", "point", rim, f"radius {r:g}", (*rings, _segment(c, rim))),
        ]
    raise TypeError(f"no handles for a {type(s).__name__} step")  # every step kind has them


def _world(M, x: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        return mobius.apply(M, x)


def _circle(centre, a, b) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * math.pi, GUIDE_SEGMENTS + 1)[:, None]
    return centre + np.cos(t) * a + np.sin(t) * b


def _segment(a, b) -> np.ndarray:
    """Points along a→b (its image is a circular arc under a map with a pole)."""
    t = np.linspace(0.0, 1.0, 9)[:, None]
    return a + t * (np.asarray(b) - a)


def guide_lines(h: MobiusHandle, rgba: tuple) -> list[tuple[np.ndarray, np.ndarray, tuple]]:
    """The selected handle's guides as overlay line segments."""
    return [(a, b, rgba) for g in h.guides for a, b in zip(g[:-1], g[1:])]


def mokrs_outline(m: MoKRS) -> list[str]:
    """One line per level: its kernel, its steps, and R where it reflects."""
    return [
        f"L{i} {lv.kernel.kind}: "
        + (" · ".join(s.kind for s in lv.transform) or "identity")
        + (" · R" if lv.reflect else "")
        for i, lv in enumerate(m.levels)
    ]
