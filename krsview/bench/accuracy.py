"""`krsview bench accuracy`: what accuracy costs in time. Each accuracy knob is swept on one
view, every setting is timed on the GPU (interleaved rounds; its fastest round, beside the
median and the slowest: a busy machine only adds time [Chen and Revels 2016]) and its image
is compared with the ground truth (the float64 reference at ε/8); the report says which
settings are worth it, and only where a time difference exceeds the run's noise floor (the
spread of settings doing the same work). Beside time, work (kernels evaluated per pixel)
shows each trade-off as no machine load changes it.

Knobs: ε-scale (LOD threshold [KRS17 §4]), iteration cap, tracer (sphere / over-relaxed
with ω [Keinert et al. 2014] / binary with ξ pairs [KRS17 Alg. 2]), precision (float32 or
float64 shader), exact level culling, the walk restart (render.walk_restart), the level of
detail in the walk (render.lod), the pixel blocks sharing a soft shadow ray
(render.shadow_block: colour only), the pre-pass tile, the path (fragment, compute rounds or
persistent lanes) and level count (LOD by truncation). One run writes a CSV, a Markdown
report, plots (error against time and against work per knob, the Pareto fronts over all
settings) and error images (holes red, false hits blue)."""

from __future__ import annotations

import contextlib
from dataclasses import asdict, dataclass, replace
from pathlib import Path

import numpy as np

from ..compile.camera import view_of
from ..compile.geometry import compile_geometry, walk_restarts
from ..frame import Frame
from ..gpu.passes import splits_shadows
from ..gpu.renderer import Renderer
from ..scene import Geometry, Scene, SceneError
from ..scene.render import PRECISIONS
from .harness import Variant, noise_floor, round_times, time_columns
from .metrics import compare, error_image
from .paths import TILES as PREPASS_TILES
from .report import Measured
from .truth import ground_truth

EPSILON_SCALES = (0.125, 0.25, 0.5, 1.0, 2.0, 4.0, 8.0)
CAPS = (16, 32, 64, 128, 256, 1024)
XI_PAIRS = ((2.0, 0.3), (1.5, 0.2), (3.0, 0.5))
RELAXATIONS = (1.2, 1.6, 1.9)  # ω of over-relaxed sphere tracing [Keinert et al. 2014]
LEVEL_CUTS = (12, 8, 4, 2)  # levels dropped from the finest end
LODS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)  # render.lod: subtrees below lod × ε drawn as a ball
SHADOW_BLOCKS = (1, 2, 3, 4)  # render.shadow_block: pixels sharing a shadow ray


@dataclass(frozen=True)
class Setting:
    knob: str
    value: str
    scene: Scene
    geometry: Geometry | None = None

    @property
    def name(self) -> str:
        return f"{self.knob} {self.value}"


def settings(scene: Scene) -> list[Setting]:
    """The scene's own setting first (the time reference), then one knob at a time."""
    r = scene.render
    out = [Setting("scene", "as saved", scene)]
    for e in EPSILON_SCALES:
        out.append(
            Setting("epsilon_scale", f"{e:g}", replace(scene, render=replace(r, epsilon_scale=e)))
        )
    for cap in CAPS:
        out.append(
            Setting(
                "max_iterations", f"{cap}", replace(scene, render=replace(r, max_iterations=cap))
            )
        )
    if scene.mokrs is None:
        out.append(Setting("tracer", "sphere", replace(scene, render=replace(r, tracer="sphere"))))
    if scene.mokrs is None and not scene.compound:
        for w in RELAXATIONS:
            out.append(
                Setting(
                    "tracer",
                    f"relaxed {w:g}",
                    replace(scene, render=replace(r, tracer="relaxed", relaxation=w)),
                )
            )
    for b, p in XI_PAIRS:
        out.append(
            Setting(
                "tracer",
                f"binary {b:g}/{p:g}",
                replace(scene, render=replace(r, tracer="binary", xi_bonus=b, xi_penalty=p)),
            )
        )
    for precision in PRECISIONS:
        if precision != r.precision:
            out.append(
                Setting(
                    "precision", precision, replace(scene, render=replace(r, precision=precision))
                )
            )
    if scene.mokrs is None:  # Alg. 1's culling; not in a MöKRS
        other = "off" if r.culling == "on" else "on"
        out.append(Setting("culling", other, replace(scene, render=replace(r, culling=other))))
    restarted = replace(scene, render=replace(r, walk_restart="on"))
    if walk_restarts(restarted, compile_geometry(scene.geometry(), scene.material.albedo)):
        other = "off" if r.walk_restart == "on" else "on"  # a single, undistorted KRS
        out.append(
            Setting("walk_restart", other, replace(scene, render=replace(r, walk_restart=other)))
        )
    for lod in LODS:  # Alg. 1's balls, or a MöKRS's levels' bounds
        if lod != r.lod:
            out.append(Setting("lod", f"{lod:g}", replace(scene, render=replace(r, lod=lod))))
    if splits_shadows(scene):  # soft shadows shared by pixel blocks [KRS17 §8.5]
        for block in SHADOW_BLOCKS:
            if block != r.shadow_block:
                out.append(
                    Setting(
                        "shadow_block",
                        f"{block}",
                        replace(scene, render=replace(r, shadow_block=block)),
                    )
                )
    if r.path != "compute":  # the compute path's rounds, and its persistent lanes
        out.append(Setting("path", "compute", replace(scene, render=replace(r, path="compute"))))
        lanes = replace(r, path="compute", steps=0)
        out.append(Setting("path", "lanes", replace(scene, render=lanes)))
    for tile in PREPASS_TILES:
        if tile != (r.prepass or 0):  # unset is off here (the bench draws the file's settings)
            out.append(
                Setting("prepass", f"{tile}", replace(scene, render=replace(r, prepass=tile)))
            )
    g = scene.geometry()
    for cut in LEVEL_CUTS:
        if g.depth - cut >= 1:
            # a MöKRS cut that cannot carry its kernel up is not a setting
            with contextlib.suppress(SceneError):
                out.append(Setting("levels", f"{g.depth - cut}", scene, g.truncated(g.depth - cut)))
    return out


@dataclass(frozen=True)
class Accuracy:
    """The accuracy bench's result: one row per setting (the CSV's columns: knob, value,
    size, time as the fastest round (ms), the median and slowest over rounds (ms_median,
    ms_max), the run's noise floor, work, the row doing the
    same work, every error of :class:`krsview.bench.metrics.Errors`) and the error images of
    the notable settings (file name → RGB array)."""

    measured: Measured
    errors: dict[str, np.ndarray]


CONTROL = "scene as saved (control)"  # the scene's own setting timed a second time per round


def bench_accuracy(
    scene: Scene, size: tuple[int, int], rounds: int = 3, cache: Path | None = None
) -> Accuracy:
    """Every setting of :func:`settings` timed on the GPU and compared with the ground truth
    (computed once, then read from ``cache``). Settings doing the same work share one time,
    pooled over their rounds; their spread is the run's noise floor."""
    w, h = size
    truth = ground_truth(scene, size, cache)
    footprint = view_of(scene.camera, w, h).footprint
    runs = settings(scene)
    r = Renderer()
    images = {s.name: r.render(s.scene, w, h, s.geometry) for s in runs}
    walked = {s.name: levels_walked(r, s, size) for s in runs}
    rep = same_work(r, runs, images, walked, size)
    variants = {s.name: Variant(s.scene, s.geometry) for s in runs}
    order = list(variants)  # the control half-way through each round, away from its twin
    order.insert(len(order) // 2, CONTROL)
    variants[CONTROL] = variants[runs[0].name]
    times = round_times(
        r, {n: variants[n] for n in order}, size, rounds, f"bench accuracy {scene.name}"
    )
    groups: dict[str, list[list[float]]] = {}
    for name in order:
        groups.setdefault(rep.get(name, runs[0].name), []).append(times[name])
    floor = noise_floor(list(groups.values()))
    pooled = {n: [t for ts in g for t in ts] for n, g in groups.items()}
    t0 = min(pooled[runs[0].name])
    index = {s.name: k for k, s in enumerate(runs)}
    rows = []
    for s in runs:
        t = pooled[rep[s.name]]
        e = compare(images[s.name], truth, footprint, s.scene.render.max_iterations)
        rows.append(
            dict(
                knob=s.knob,
                value=s.value,
                width=w,
                height=h,
                **time_columns(t),
                time_ratio=min(t) / t0,
                mask_error=e.mask_error,
                **asdict(e),
                noise_floor=floor,
                work=work(images[s.name], walked[s.name], s),
                same_as=index[rep[s.name]],
            )
        )
    errors = {
        image_name(row): error_image(images[f"{row['knob']} {row['value']}"], truth)
        for row in notable(rows)
    }
    return Accuracy(Measured(scene, size, rounds, rows), errors)


def levels_walked(r: Renderer, s: Setting, size: tuple[int, int]) -> np.ndarray:
    """Per pixel, the levels walked tracing the ray (Alg. 1's, or a MöKRS's ISUNBOUNDING
    walks: the KRS_COUNT_LEVELS probe of :meth:`Renderer.levels`), here with the setting's
    own geometry, as a truncation needs."""
    return r.levels(s.scene, *size, s.geometry)


def work(image: Frame, walked: np.ndarray, s: Setting) -> float:
    """Kernels evaluated per pixel while tracing, which no machine load changes: at each
    step the top kernel, then one per level walked."""
    return float(image.iterations.mean()) + float(walked.mean())


def same_work(
    r: Renderer,
    runs: list[Setting],
    images: dict[str, Frame],
    walked: dict[str, np.ndarray],
    size: tuple[int, int],
) -> dict[str, str]:
    """name → the first setting doing the same work: compiled to the same variant and
    pre-pass, the same colours, iterations and levels walked in every pixel."""
    w, h = size
    rep: dict[str, str] = {}
    seen: list[tuple[tuple, str]] = []
    for s in runs:
        rs = s.scene.render
        tile = rs.prepass or 0  # unset and 0 both draw no pre-pass
        key = (r.prepare(s.scene, w, h, s.geometry), rs.path, tile, rs.prepass_levels)
        key += (rs.shadow_block, rs.steps)
        a = images[s.name]
        rep[s.name] = next(
            (
                name
                for k, name in seen
                if k == key
                and np.array_equal(a.color, images[name].color)
                and np.array_equal(a.iterations, images[name].iterations)
                and np.array_equal(walked[s.name], walked[name])
            ),
            s.name,
        )
        if rep[s.name] == s.name:
            seen.append((key, s.name))
    return rep


def image_name(row: dict) -> str:
    return f"errors-{row['knob']}-{row['value'].replace('/', '-').replace(' ', '-')}.png"


def notable(rows: list[dict]) -> list[dict]:
    """The loosest ε, the smallest cap and the deepest truncation: where errors show."""
    pick = []
    for knob, which in (("epsilon_scale", -1), ("max_iterations", 0), ("levels", 0)):
        group = [r for r in rows if r["knob"] == knob]
        if group:
            pick.append(group[which])
    return pick
