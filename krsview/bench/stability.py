"""The invariants every hard case (and any scene, `krsview check --stability`) must keep, on
the GPU and on the float64 reference [issue 16]:

- finite pixels, and every ray within the iteration cap; capped rays are counted and
  reported (a capped ray is drawn as sky, so silence would hide a hole);
- continuity: nudging the eye by a hundredth of a pixel changes few pixels;
- the GPU agrees with the reference at the pixel tests' tolerances — or, for a documented
  precision limit, the double-precision shader does.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..compile.camera import view_of
from ..frame import Frame
from ..gpu.renderer import Renderer
from ..reference.render import render_reference
from ..scene import Scene
from .metrics import gpu_reference_agreement, tolerance_failures

SIZE = (48, 27)
NUDGE_PIXELS = 0.01  # the eye moves sideways by this many pixels at the target's distance
CONTINUITY = 0.01  # at most this fraction of pixels may change hit state under the nudge


@dataclass(frozen=True)
class Outcome:
    name: str
    hit: float  # fraction of pixels the reference hits
    finite: bool  # GPU and reference
    within_cap: bool
    capped_gpu: int  # rays that reached the cap without a hit
    capped_reference: int
    changed: float  # fraction of pixels whose hit state a tiny nudge changes
    agreement: str  # "ok", or what disagrees
    precision: str  # the shader precision that agreed ("float", "double", "-")

    @property
    def ok(self) -> bool:
        return (
            self.finite
            and self.within_cap
            and self.changed <= CONTINUITY
            and self.agreement == "ok"
        )


def capped(b: Frame, cap: int) -> int:
    return int(((b.iterations >= cap) & ~b.hit).sum())


def disagreement(gpu: Frame, ref: Frame) -> str:
    return "; ".join(tolerance_failures(gpu_reference_agreement(gpu, ref))) or "ok"


def nudged(scene: Scene, size: tuple[int, int]) -> Scene:
    """The eye and target moved sideways by NUDGE_PIXELS pixels at the target's distance."""
    v = view_of(scene.camera, *size)
    shift = (
        NUDGE_PIXELS
        * v.footprint
        * np.linalg.norm(np.array(scene.camera.target) - v.origin)
        * v.right
    )
    cam = scene.camera
    return replace(
        scene,
        camera=replace(
            cam,
            position=tuple(np.array(cam.position) + shift),
            target=tuple(np.array(cam.target) + shift),
        ),
    )


def check(
    scene: Scene, renderer: Renderer, size: tuple[int, int] = SIZE, double_if_needed: bool = True
) -> Outcome:
    w, h = size
    cap = scene.render.max_iterations
    scene = scene.edit(("render", "shadow_block"), 1)  # as the reference: a ray per pixel
    ref = render_reference(scene, w, h)
    gpu = renderer.render(scene, w, h)
    precision = scene.render.precision
    verdict = disagreement(gpu, ref)
    if verdict != "ok" and double_if_needed and precision == "float":
        double = replace(scene, render=replace(scene.render, precision="double"))
        g2 = renderer.render(double, w, h)
        if disagreement(g2, ref) == "ok":
            scene, gpu, precision, verdict = double, g2, "double", "ok"
    moved = renderer.render(nudged(scene, size), w, h)
    finite = all(
        np.isfinite(getattr(b, k)).all() for b in (gpu, ref) for k in ("color", "depth", "normal")
    )
    within = all(b.iterations.min() >= 1 and b.iterations.max() <= cap for b in (gpu, ref))
    return Outcome(
        scene.name,
        float(ref.hit.mean()),
        finite,
        within,
        capped(gpu, cap),
        capped(ref, cap),
        float((moved.hit != gpu.hit).mean()),
        verdict,
        precision if verdict == "ok" else "-",
    )


def table(outcomes: list[Outcome]) -> str:
    """Markdown: one row per scene."""
    lines = [
        "| scene | hit | finite | within cap | capped GPU / ref | changed by a nudge | "
        "GPU = reference | precision | verdict |",
        "|---|---:|---|---|---:|---:|---|---|---|",
    ]
    for o in outcomes:
        lines.append(
            f"| {o.name} | {o.hit:.0%} | {'yes' if o.finite else 'NO'} | "
            f"{'yes' if o.within_cap else 'NO'} | {o.capped_gpu} / "
            f"{o.capped_reference} | {o.changed:.2%} | {o.agreement} | "
            f"{o.precision} | {'ok' if o.ok else 'FAILS'} |"
        )
    return "\n".join(lines)
