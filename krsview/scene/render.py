"""How a scene is seen and drawn: its camera, light, material and the render knobs that the
benchmark sweeps against time (the geometry's dataclasses are in model.py)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from ..messages import SceneError
from .schema import COLOR, Vec3, param

TRACERS = ("sphere", "binary", "relaxed")
PRECISIONS = ("float", "double")
SWITCH = ("on", "off")
PATHS = ("fragment", "compute")  # the first is drawn where the file sets none (api.fast_settings)
PREPASS_RATIO = 4  # pre-pass: a coarse pass's tiles are this many times as wide as the next's
TARGET_DISTANCE = 1e-9  # below this the view direction is lost to rounding
# Defaults of the render knobs that the windows and the command line share.
VIEW_PREPASS = 4  # the viewer's pre-pass tile where the file has none (docs/speed.md)
# render.lod where the file has none: at most +0.2 % hit-mask error against the ground truth
# on every preset, no hole (docs/speed.md, docs/accuracy/); 0 draws every level
DEFAULT_LOD = 0.5
# render.shadow_block where the file has none: soft shadows within 1/255 of per-pixel ones in
# mean colour, for 14–26 % of a still frame on tree and grove (docs/speed.md); 1: per pixel
DEFAULT_SHADOW_BLOCK = 2
# A single KRS this deep traces its primary rays with persistent lanes where the file sets
# no path (the same image: inside tree's crown 0.82–0.84× the CPU, its whole views within
# noise; a MöKRS, a compound and shallow trees lose; docs/speed.md)
LANES_LEVELS = 20
# On a hardware GPU the fast settings trace by the compute path's rounds (render.steps, its
# shadow rays as tasks) from this pre-pass tile where the file sets no path: 2.4–7.3× the
# fragment path and 2.5× persistent lanes on an H100 at 1920×1080 (tree, grove, palm;
# docs/speed.md), where a warp waits for its slowest ray; on a CPU rasteriser they lose
HARDWARE_PREPASS = 8


@dataclass(frozen=True)
class Camera:
    """Pinhole camera; the renderer keeps it in float64 and gives the GPU camera-relative data."""

    position: Vec3 = param((0.0, 1.0, -5.0), help="eye position")
    target: Vec3 = param((0.0, 1.0, 0.0), help="point looked at")
    up: Vec3 = param((0.0, 1.0, 0.0), unit_vector="normalise", help="up direction")
    fov_y: float = param(45.0, lo=1.0, hi=170.0, unit="degrees", help="vertical field of view")

    def validate(self, path: str) -> None:
        length = math.dist(self.target, self.position)
        if length < TARGET_DISTANCE:
            raise SceneError(
                f"{path}.target",
                list(self.target),
                f"must be at least {TARGET_DISTANCE:g} from position (it is "
                f"{length:.3g} away): the view direction comes from the two",
            )
        f = tuple((t - p) / length for t, p in zip(self.target, self.position))
        cos = abs(sum(a * b for a, b in zip(f, self.up)))
        if cos > 1 - 1e-9:
            raise SceneError(f"{path}.up", list(self.up), "must not be parallel to the view")


@dataclass(frozen=True)
class Light:
    """Directional light arriving from ``direction`` (pointing towards the light)."""

    direction: Vec3 = param(
        (0.35777087639996635, 0.8944271909999159, -0.2683281572999748),
        unit_vector="normalise",
        help="towards the light",
    )
    color: Vec3 = param((1.0, 1.0, 1.0), lo=0.0, hi=100.0, help="linear RGB radiance")
    intensity: float = param(1.0, lo=0.0, hi=100.0, help="scale of color")


@dataclass(frozen=True)
class Material:
    """Lambert + ambient shading [KRS14 Alg. 2 without smoothing]."""

    albedo: Vec3 = param((0.7, 0.7, 0.7), **COLOR)
    ambient: Vec3 = param((0.15, 0.17, 0.2), lo=0.0, hi=10.0, help="ambient light, linear RGB")
    background: Vec3 = param((0.55, 0.7, 0.9), **COLOR)


@dataclass(frozen=True)
class Render:
    """Accuracy knobs; each is swept by the benchmark against time."""

    tracer: str = param(
        "sphere",
        choices=TRACERS,
        help="sphere: sphere tracing [Har96]; binary: binary sphere tracing "
        "with unbounding probes [KRS17 Alg. 2] (required by a MöKRS); "
        "relaxed: over-relaxed sphere tracing, steps of ω·d with a "
        "fallback [Keinert et al. 2014] (a single KRS)",
    )
    epsilon_scale: float = param(
        1.0, lo=1e-4, hi=100.0, unit="pixels", help="stop when distance < footprint × depth × scale"
    )
    max_iterations: int = param(256, lo=1, hi=10000, help="iteration cap per ray")
    max_distance: float = param(100.0, lo=0.0, lo_open=True, hi=1e9, help="far limit of rays")
    xi_bonus: float = param(
        2.0,
        lo=1.0,
        lo_open=True,
        hi=16.0,
        help="binary tracing: probe growth after a free probe [KRS17 §6.1]",
    )
    xi_penalty: float = param(
        0.3, lo=0.01, hi=0.95, help="binary tracing: probe shrink after a blocked probe"
    )
    relaxation: float = param(
        1.6,
        lo=1.0,
        hi=1.99,
        help="relaxed tracing: step ω·d; a step whose sphere does not "
        "meet the last one is taken back and ω drops to 1",
    )
    precision: str = param(
        "float",
        choices=PRECISIONS,
        help="float: the GPU's float32; double: distances, folds, Möbius "
        "maps and ray positions in float64 (GL 4 fp64), for deep "
        "zooms, at a cost in time",
    )
    culling: str = param(
        "on",
        choices=SWITCH,
        help="exact level culling: Alg. 1 stops at the first level whose "
        "bounding ball is no nearer than the distance found (the same "
        "value, fewer levels walked)",
    )
    lod: float = param(
        DEFAULT_LOD,
        lo=0.0,
        hi=8.0,
        unit="ε",
        help="level of detail: Alg. 1 stops at the first level whose top five levels look "
        "smaller than lod × ε at its distance from the eye, and draws the ball of "
        "everything below it there (0: off, every level; hit points move by at most that "
        "ball's diameter, 2K·lod·ε with K about 1.5 on a tree, never a hole)",
    )
    walk_restart: str = param(
        "off",
        choices=SWITCH,
        help="sphere tracer of one undistorted KRS: each step restarts Alg. 1 below the "
        "levels whose folds the ray cannot have changed since an earlier step (fewer levels "
        "walked inside a crown; a step whose value is only a bound takes no hit test, so "
        "grazing rays may converge a step apart)",
    )
    shadow_block: int = param(
        DEFAULT_SHADOW_BLOCK,
        lo=1,
        hi=4,
        unit="pixels",
        help="side of the pixel blocks that share a shadow ray: the nearest hit of each "
        "block traces one per light, and each pixel blends the blocks near its depth "
        "[KRS17 §8.5: soft shadows at ¼ resolution] (1: a shadow ray per pixel, as on the "
        "compute path's rounds and in double precision, which always trace per pixel)",
    )
    shadow_cone: str = param(
        "on",
        choices=SWITCH,
        help="a shadow ray steps each component only from where the component's ball (or "
        "a ground plane's half-space) meets its cone: the ray itself for hard shadows, the "
        "penumbra's radius t/k for soft ones, inside which nothing can darken it (off: every "
        "component from the surface on, as the reference's exact shadows)",
    )
    path: str | None = param(
        None,
        choices=PATHS,
        help="fragment: one full-screen pass traces and shades each pixel; "
        "compute: rays in a storage buffer traced in rounds of "
        "--steps iterations, finished rays leaving the queue (or by "
        "persistent lanes: --steps 0), then shaded in a deferred pass "
        "(the same image); not given: fragment, but `krsview render` and "
        f"the API trace a single KRS of {LANES_LEVELS} levels or more by persistent lanes",
    )
    steps: int = param(
        16,
        lo=0,
        hi=1024,
        help="compute path: iterations per ray per round (dispatch); 0: persistent lanes, "
        "each taking the next pixel as soon as its ray is done, so 8 lanes in lockstep wait "
        "for their slowest ray only at the end (one ray per pixel: no shadow or component "
        "tasks)",
    )
    shadow_tasks: str = param(
        "on",
        choices=SWITCH,
        help="compute path: shadow rays as tasks of their own, traced "
        "in rounds like the primary rays (on), or inline while "
        "shading (off); the same image",
    )
    component_tasks: str = param(
        "off",
        choices=SWITCH,
        help="compute path, compound: a task per pixel and "
        "component, each traced to its own hit, the nearest "
        "kept [KRS17 §5.1] (on); or one ray stepping its nearest "
        "component (off). The same hits except where a ray "
        "reaches the iteration cap, which counts per task",
    )
    prepass: int | None = param(
        None,
        lo=0,
        hi=64,
        unit="pixels",
        help="tile size of the low-resolution pre-pass: one cone per tile "
        "finds how far all its rays are free, and each ray starts there "
        "(0: off; not given: the viewer's and `krsview render`'s fast "
        f"default, {VIEW_PREPASS}, and off with --exact)",
    )
    prepass_levels: int = param(
        2,
        lo=1,
        hi=4,
        help=f"pre-pass: coarse passes, coarsest first, each with "
        f"tiles {PREPASS_RATIO}× as wide as the next; a cone "
        "starts where the coarser cone around it stopped (1: "
        "one coarse pass)",
    )


def ignored_by_tracer(knobs: dict[str, Any], tracer: str) -> tuple[str, str] | None:
    """The knob of ``knobs`` that ``tracer`` would ignore, and the tracer it needs: the
    over-relaxation belongs to the relaxed tracer, the walk restart to the sphere tracer."""
    if "relaxation" in knobs and tracer != "relaxed":
        return "relaxation", "relaxed"
    if knobs.get("walk_restart") == "on" and tracer != "sphere":
        return "walk_restart", "sphere"
    return None
