"""The effect registry and the effect settings: what a scene may switch on with
``effects = [...]`` and the ``[effect_settings]`` that tune it.

Each effect becomes one ``#define KRS_<NAME>`` in the scene's shader variant, so a scene pays
only for what it lists (docs/architecture.md, Specialise, don't branch). Some effects need the KRS
distance function or its mirror planes, which a MöKRS does not have [KRS17 §7].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..algebra.vectors import cross
from ..messages import SceneError
from .compound import Placement
from .schema import COLOR, Vec3, param


@dataclass(frozen=True)
class Effect:
    name: str
    help: str
    needs_distance: bool = False  # a KRS distance function and mirror planes (not a MöKRS)
    bit: int = 0  # its bit in u_effects when all effects are compiled in
    secondary: bool = False  # evaluates the geometry again per hit pixel (a shadow ray,
    # occlusion samples): bench split times the frame without it
    reads_time: bool = False  # moves with the scene's time, nothing keyed (Scene.animated)


_LIST = [
    Effect(
        "smooth_shading",
        "blend normals across mirror planes so no crease shows [KRS14 Alg. 2, KRS17 §8.1]",
        needs_distance=True,
    ),
    Effect(
        "triplanar_texture",
        "procedural texture projected along the three world axes, "
        "filtered by the pixel footprint [KRS17 §8.2]",
    ),
    Effect(
        "kernel_texture",
        "procedural bark-like texture in each kernel's own coordinates "
        "(along / around a capsule) [KRS17 §8.2]",
        needs_distance=True,
    ),
    Effect("shadows", "hard shadows: one shadow ray per light [KRS17 §8.5]", secondary=True),
    Effect(
        "soft_shadows",
        "soft shadows from the closest free distance along the shadow ray [KRS17 §8.5]",
        secondary=True,
    ),
    Effect(
        "ambient_occlusion",
        "darken creases by sampling the distance along the normal [KRS17 §8.5]",
        needs_distance=True,
        secondary=True,
    ),
    Effect(
        "twist",
        "twist the geometry around a vertical axis, steps kept safe by the "
        "twist's Lipschitz bound [KRS17 §5.2]",
        needs_distance=True,
    ),
    Effect(
        "wind",
        "bend the geometry along the wind about its foot, swaying with gusts in time; "
        "steps (a MöKRS's probes) kept safe by the bend's Lipschitz bound at that time "
        "[KRS17 §5.2, §10]",
        reads_time=True,
    ),
    Effect(
        "empty_zones", "remove the geometry inside given spheres [KRS17 §8.4]", needs_distance=True
    ),
    Effect("sky", "sky gradient and sun instead of a flat background"),
    Effect("fog", "exponential distance fog towards the sky colour"),
    Effect("tone_mapping", "exposure and filmic (ACES) tone curve before gamma"),
]
EFFECTS: dict[str, Effect] = {e.name: replace(e, bit=1 << k) for k, e in enumerate(_LIST)}
EXCLUSIVE = [("shadows", "soft_shadows"), ("twist", "wind")]  # pairs a scene may not list together
MAX_EMPTY_ZONES = 8
MIN_HORIZONTAL = 1e-3  # the least horizontal part of wind_direction (sine of its tilt)
# The shortest texture cell and wind height, and the slowest gust (Hz): the GPU divides by
# them in float32, so far below these 1/x overflows (from about 3e-39) and the image is
# wrong (a black texture, a sway of infinite phase) where the float64 reference is right.
SHORTEST = 1e-6
SLOWEST_GUST = 1e-6
# Gusts: n(t) = Σ w_k sin(2π r_k f t), |n| ≤ 1, at frequencies r_k f in irrational ratios so
# the sway never repeats; component c sways at t + c·WIND_PHASE/f (a golden-ratio fraction of
# the slowest period), so no two neighbours' sines keep in step (offsets .62, .38, .39 turns).
WIND_RATIOS = (1.0, math.sqrt(5.0), math.sqrt(15.0))
WIND_WEIGHTS = (0.5, 0.3, 0.2)
WIND_PHASE = (math.sqrt(5.0) - 1.0) / 2.0


@dataclass(frozen=True)
class EmptyZone:
    """A ball whose inside is skipped by the tracer: geometry there is removed [KRS17 §8.4]."""

    center: Vec3 = param((0.0, 0.0, 0.0), help="centre")
    radius: float = param(1.0, lo=0.0, lo_open=True, help="radius")


@dataclass(frozen=True)
class EffectSettings:
    """Tuning of the effects; a setting of an effect the scene does not list is ignored."""

    smooth_width: float = param(
        0.05,
        lo=0.0,
        hi=1e6,
        help="smooth_shading: width of the "
        "blend band across a mirror plane, scene units (never less "
        "than 2 pixel footprints)",
    )
    shadow_softness: float = param(
        12.0,
        lo=1.0,
        hi=1000.0,
        help="soft_shadows: penumbra sharpness k in visibility = min k·free/t (larger: harder)",
    )
    ao_step: float = param(
        0.06,
        lo=0.0,
        lo_open=True,
        hi=1e6,
        help="ambient_occlusion: spacing of the 5 samples along the normal",
    )
    ao_strength: float = param(1.0, lo=0.0, hi=4.0, help="ambient_occlusion: darkening scale")
    texture_scale: float = param(
        0.5, lo=SHORTEST, hi=1e6, help="textures: size of one noise cell, scene units"
    )
    texture_strength: float = param(
        0.5, lo=0.0, hi=1.0, help="textures: 0 = plain albedo, 1 = full contrast"
    )
    twist: float = param(
        0.0,
        lo=-720.0,
        hi=720.0,
        unit="degrees per unit height",
        help="twist: turn around the vertical axis per unit of height",
    )
    twist_center: Vec3 = param(
        (0.0, 0.0, 0.0), help="twist: a point on the vertical axis (no turn at its height)"
    )
    wind_direction: Vec3 = param(
        (1.0, 0.0, 0.0),
        unit_vector="normalise",
        help="wind: where it blows to; only its horizontal part is used",
    )
    wind_strength: float = param(
        4.0,
        lo=0.0,
        hi=30.0,
        unit="degrees",
        help="wind: mean lean at wind_height above the foot (the lean grows with height)",
    )
    wind_height: float = param(
        5.0,
        lo=SHORTEST,
        hi=1e6,
        unit="scene units",
        help="wind: the height above the foot that leans by wind_strength",
    )
    wind_gust: float = param(
        0.5, lo=0.0, hi=1.0, help="wind: the sway about the mean lean, as a fraction of it"
    )
    wind_frequency: float = param(
        0.3,
        lo=0.0,
        hi=10.0,
        unit="Hz",
        help=f"wind: of the slowest of the gusts' three sways (0: a steady lean; else at "
        f"least {SLOWEST_GUST:g})",
    )
    wind_base: Vec3 = param(
        (0.0, 0.0, 0.0),
        help="wind: the foot that stays put (in a compound, in each component's own frame)",
    )
    empty_zones: list[EmptyZone] = param([], help=f"empty_zones: at most {MAX_EMPTY_ZONES} balls")
    sky_zenith: Vec3 = param((0.22, 0.42, 0.82), **COLOR)
    fog_density: float = param(
        0.03,
        lo=0.0,
        hi=100.0,
        unit="per scene unit",
        help="fog: fraction of light lost is 1 − exp(−density·t)",
    )
    exposure: float = param(
        0.6,
        lo=0.0,
        lo_open=True,
        hi=64.0,
        help="tone_mapping: scale of linear radiance before the curve "
        "(0.6 maps mid-grey near where plain gamma puts it)",
    )

    def validate(self, path: str) -> None:
        if len(self.empty_zones) > MAX_EMPTY_ZONES:
            raise SceneError(
                f"{path}.empty_zones",
                f"<{len(self.empty_zones)} zones>",
                f"allowed: at most {MAX_EMPTY_ZONES}",
            )
        if 0.0 < self.wind_frequency < SLOWEST_GUST:
            raise SceneError(
                f"{path}.wind_frequency",
                self.wind_frequency,
                f"allowed: 0 (a steady lean) or value ≥ {SLOWEST_GUST:g} Hz",
            )
        if math.hypot(self.wind_direction[0], self.wind_direction[2]) < MIN_HORIZONTAL:
            raise SceneError(
                f"{path}.wind_direction",
                self.wind_direction,
                "a direction with a horizontal part (the wind blows along the ground)",
            )


def allowed_effects(mokrs: bool) -> list[str]:
    """The effects a geometry can draw: a MöKRS lacks Alg. 1's distance and mirror planes."""
    return [n for n, e in EFFECTS.items() if not (mokrs and e.needs_distance)]


def check_effects(effects: list[str], mokrs: bool, path: str = "effects") -> None:
    """Known names, no pair that excludes each other, nothing a MöKRS cannot draw."""
    if not isinstance(effects, (list, tuple)):  # a string would be read letter by letter
        if effects in ("none", "", None):
            said = "expected a list of effect names; none is []"
        else:
            one = effects if isinstance(effects, str) else "sky"
            said = f"expected a list of effect names, e.g. [{one!r}]"
        raise SceneError(path, effects, said)
    for i, e in enumerate(effects):
        if e not in EFFECTS:
            raise SceneError(f"{path}[{i}]", e, "unknown effect; allowed: " + ", ".join(EFFECTS))
        if e not in allowed_effects(mokrs):
            raise SceneError(
                f"{path}[{i}]",
                e,
                "needs a KRS distance function and mirror "
                "planes, which a MöKRS does not have; allowed on a MöKRS: "
                + ", ".join(allowed_effects(True)),
            )
    if len(set(effects)) != len(effects):
        raise SceneError(path, effects, "each effect at most once")
    for a, b in EXCLUSIVE:
        if a in effects and b in effects:
            raise SceneError(path, effects, f"'{a}' and '{b}' exclude each other; choose one")


def wind_feet(scene, balls: list) -> list[tuple[Vec3, float]]:
    """Per component of ``scene`` (a Scene with a KRS, a compound or a MöKRS), given the ball
    around it (``CompiledKRS.ball`` or a MöKRS's outermost bound, world; radius < 0:
    unbounded): its foot, ``wind_base`` moved by the component's placement, and its reach,
    the farthest its geometry gets from the foot (a turn about the foot keeps it), or 0 where
    it stands: an unbounded KRS (a ground plane) would make the bend and its Lipschitz bound
    unbounded too."""
    base = scene.effect_settings.wind_base
    feet = (
        [Placement(c.position, c.axis, c.angle, c.scale).point(base) for c in scene.compound]
        if scene.compound
        else [base]
    )
    return [
        (foot, float(np.linalg.norm(np.array(ball[:3]) - foot) + ball[3]) if ball[3] >= 0 else 0.0)
        for foot, ball in zip(feet, balls)
    ]


def swept_ball(foot, reach: float, ball, axis, most: float) -> tuple[float, ...]:
    """A ball (centre, radius) holding a component bent by the wind at any time, given its
    foot and reach (wind_feet), its rest ball, the wind's axis A and the largest rate: a bent
    point lies within reach of the foot, so its rest point turned about the axis line through
    the foot by an angle in [0, most·reach]; the rest ball turned by half of that and grown by
    the chord its centre sweeps holds them all. The foot's own ball where that is smaller;
    radius −1 where the component stands (reach 0)."""
    if reach <= 0.0:
        return (0.0, 0.0, 0.0, -1.0)
    foot, axis, v = np.array(foot), np.array(axis), np.array(ball[:3]) - foot
    half = 0.5 * most * reach
    axial = axis * (axis @ v)
    turned = axial + (v - axial) * math.cos(half) + cross(axis, v) * math.sin(half)
    chord = 2.0 * np.linalg.norm(cross(axis, v)) * math.sin(min(half / 2, math.pi / 2))
    radius = ball[3] + chord
    if radius >= reach:
        return (*(float(x) for x in foot), float(reach))
    return (*(float(x) for x in foot + turned), float(radius))
