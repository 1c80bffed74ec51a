"""What a scene is, in numbers: its geometry, levels, kernel instances, kernels, effects and
render settings (`krsview check`, :func:`krsview.check`)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from ..messages import counted
from .effects import EFFECTS
from .motion import near_misses
from .scene import Scene


@dataclass(frozen=True)
class SceneInfo:
    name: str
    description: str
    geometry: str  # "explicit KRS", "tree (grown)", "tree (route)", "compound", "MöKRS"
    levels: int  # kernels K_0..K_{levels-1}
    mirrors: int
    instances: int  # kernel instances drawn (up to 2^levels - 1 per KRS)
    kernels: dict[str, int]  # kernel kind → how many levels carry one
    effects: tuple[str, ...]
    warnings: tuple[str, ...]  # e.g. a route's branch clipped by its fork's mirror
    parts: tuple[str, ...]  # a compound's components, one line each
    reflecting: int  # a MöKRS's reflecting levels
    tracer: str
    epsilon_scale: float
    max_iterations: int
    max_distance: float
    xi: tuple[float, float] | None  # binary tracing's (ξ_bonus, ξ_penalty)
    moves: str  # what changes with time ("" for a still scene), e.g. "wind; 2 keyframe tracks"

    def text(self, source: str | Path | None = None) -> str:
        """The statistics as `krsview check` prints them (``source``: the file read, said
        first); ``str(info)`` is this without a source."""
        lines = [f"{source}: ok — {self.name}" if source is not None else self.name]
        if self.description:
            lines.append(f"  {self.description}")
        if self.geometry == "MöKRS":
            levels = counted(self.mirrors, "level")
            lines.append(f"  geometry        MöKRS: {levels}, {self.reflecting} reflecting")
        elif self.geometry == "compound":
            parts = ", ".join(self.parts)
            lines.append(f"  geometry        compound of {len(self.parts)}: {parts}")
        else:
            lines.append(f"  geometry        {self.geometry}")
            grown = self.geometry == "tree (grown)"
            forks = f"; [tree] levels counts its {self.mirrors} forks" if grown else ""
            lines.append(
                f"  levels          {self.levels} (kernels K_0..K_{self.mirrors}, "
                f"{counted(self.mirrors, 'mirror')}{forks})"
            )
        lines.append(f"  kernel instances {self.instances:,}")
        lines.append("  kernels         " + ", ".join(f"{v}× {k}" for k, v in self.kernels.items()))
        lines.append(f"  effects         {', '.join(self.effects) or 'none'}")
        if self.moves:
            lines.append(f"  moves           {self.moves}")
        lines += [f"  warning         {w}" for w in self.warnings]
        binary = f" (ξ_bonus {self.xi[0]}, ξ_penalty {self.xi[1]})" if self.xi else ""
        lines.append(
            f"  render          {self.tracer} tracer{binary}, ε-scale {self.epsilon_scale}, "
            f"≤ {self.max_iterations} iterations, far {self.max_distance}"
        )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.text()


def describe(scene: Scene, posed: int = 0) -> SceneInfo:
    """The statistics of a (validated) scene; ``posed``: at how many moments its motion
    was checked (animation.check_motion)."""
    g = scene.geometry()
    if scene.mokrs is not None:
        kind = "MöKRS"
    elif scene.compound:
        kind = "compound"
    else:
        kind = "tree (grown)" if scene.tree else "tree (route)" if scene.route else "explicit KRS"
    parts = tuple(
        f"{'tree' if c.tree else 'route' if c.route else 'KRS'} of {counted(p.depth, 'level')}"
        for c, p in zip(scene.compound, getattr(g, "parts", ()))
    )
    r = scene.render
    return SceneInfo(
        name=scene.name,
        description=scene.description,
        geometry=kind,
        levels=g.depth,
        mirrors=g.n if kind != "compound" else sum(p.n for p in g.parts),
        instances=g.instance_count(),
        kernels=dict(sorted(Counter(k.kind for k in g.kernels).items())),
        effects=tuple(scene.effects),
        warnings=tuple(f"route.{w}" for w in (scene.route.warnings() if scene.route else ()))
        + tuple(near_misses(scene)),
        parts=parts,
        reflecting=sum(lv.reflect for lv in scene.mokrs.levels) if scene.mokrs else 0,
        tracer=r.tracer,
        epsilon_scale=r.epsilon_scale,
        max_iterations=r.max_iterations,
        max_distance=r.max_distance,
        xi=(r.xi_bonus, r.xi_penalty) if r.tracer == "binary" else None,
        moves=motion(scene, posed),
    )


def motion(scene: Scene, posed: int = 0) -> str:
    """What moves the scene with time, in a line ("" when nothing does); ``posed``: at
    how many moments its tracks were checked."""
    a = scene.animation
    parts = [e for e in scene.effects if EFFECTS[e].reads_time]
    if a is not None and a.tracks:
        parts.append(f"{len(a.tracks)} keyframe track{'s' * (len(a.tracks) != 1)}")
    if a is not None and a.sway is not None:
        w = a.sway
        levels = counted(w.levels, "level")
        parts.append(f"sway of {levels}, {w.amplitude:g}° at {w.frequency:g} Hz")
    if not parts:
        return ""
    checked = f", posed at {counted(posed, 'moment')}" if posed else ""
    return "; ".join(parts) + f" — loop {scene.duration:g} s{checked}"
