"""What a scene is, in numbers: its geometry, levels, kernel instances, kernels, effects and
render settings (`krsview check`, :func:`krsview.check`)."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from pathlib import Path

from .effects import EFFECTS
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
        info = self
        lines = [f"{source}: ok — {info.name}" if source is not None else info.name]
        if info.description:
            lines.append(f"  {info.description}")
        if info.geometry == "MöKRS":
            lines.append(
                f"  geometry        MöKRS: {info.mirrors} levels, {info.reflecting} reflecting"
            )
        elif info.geometry == "compound":
            parts = ", ".join(info.parts)
            lines.append(f"  geometry        compound of {len(info.parts)}: {parts}")
        else:
            lines.append(f"  geometry        {info.geometry}")
            lines.append(
                f"  levels          {info.levels} (kernels K_0..K_{info.mirrors}, "
                f"{info.mirrors} mirrors)"
            )
        lines.append(f"  kernel instances {info.instances:,}")
        lines.append("  kernels         " + ", ".join(f"{v}× {k}" for k, v in info.kernels.items()))
        lines.append(f"  effects         {', '.join(info.effects) or 'none'}")
        if info.moves:
            lines.append(f"  moves           {info.moves}")
        lines += [f"  warning         {w}" for w in info.warnings]
        binary = f" (ξ_bonus {info.xi[0]}, ξ_penalty {info.xi[1]})" if info.xi else ""
        lines.append(
            f"  render          {info.tracer} tracer{binary}, ε-scale {info.epsilon_scale}, "
            f"≤ {info.max_iterations} iterations, far {info.max_distance}"
        )
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.text()


def describe(scene: Scene) -> SceneInfo:
    """The statistics of a (validated) scene."""
    g = scene.geometry()
    if scene.mokrs is not None:
        kind = "MöKRS"
    elif scene.compound:
        kind = "compound"
    else:
        kind = "tree (grown)" if scene.tree else "tree (route)" if scene.route else "explicit KRS"
    parts = tuple(
        f"{'tree' if c.tree else 'route' if c.route else 'KRS'} of {p.depth} levels"
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
        warnings=tuple(f"route.{w}" for w in (scene.route.warnings() if scene.route else ())),
        parts=parts,
        reflecting=sum(lv.reflect for lv in scene.mokrs.levels) if scene.mokrs else 0,
        tracer=r.tracer,
        epsilon_scale=r.epsilon_scale,
        max_iterations=r.max_iterations,
        max_distance=r.max_distance,
        xi=(r.xi_bonus, r.xi_penalty) if r.tracer == "binary" else None,
        moves=motion(scene),
    )


def motion(scene: Scene) -> str:
    """What moves the scene with time, in a line ("" when nothing does)."""
    a = scene.animation
    parts = [e for e in scene.effects if EFFECTS[e].reads_time]
    if a is not None and a.tracks:
        parts.append(f"{len(a.tracks)} keyframe track{'s' * (len(a.tracks) != 1)}")
    if a is not None and a.sway is not None:
        w = a.sway
        parts.append(f"sway of {w.levels} levels, {w.amplitude:g}° at {w.frequency:g} Hz")
    if not parts:
        return ""
    return "; ".join(parts) + f" — loop {scene.duration:g} s"
