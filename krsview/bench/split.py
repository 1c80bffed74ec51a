"""`krsview bench split`: where a frame's time goes — the pre-pass's coarse passes, the
tracing of the primary rays, the nearest kernel and shading, and the secondary effects
(shadow rays and occlusion samples). Each part
is the difference of two variants timed side by side, interleaved (bench/harness.py), each
to the GPU's finish. GPU timer queries would split one frame instead, but llvmpipe's time
only its command thread (a 138 ms draw read 29 ms), so each part is a variant of its own.
Drawn on the fragment path, as the viewer draws."""

from __future__ import annotations

from dataclasses import replace

from ..gpu.passes import still_ratio
from ..gpu.renderer import Renderer
from ..scene import EFFECTS, Scene
from .harness import Variant, median_times
from .report import Measured, markdown


def split_variants(scene: Scene) -> dict[str, Variant]:
    """The variants whose differences are the parts: the frame, the frame without secondary
    effects, the tracing alone, and the coarse passes alone."""
    scene = replace(scene, render=replace(scene.render, path="fragment"))
    moving = replace(scene, effects=tuple(e for e in scene.effects if not EFFECTS[e].secondary))
    out = {
        "frame": Variant(scene),
        "moving": Variant(moving),
        "trace": Variant(moving, probes=("KRS_TRACE_ONLY",)),
    }
    if scene.render.prepass:
        out["coarse"] = Variant(scene, prepass_only=True)
    if still_ratio(scene):  # shadow rays shared by pixel blocks: and one per pixel beside
        out["per pixel"] = Variant(scene.edit(("render", "shadow_block"), 1))
    return out


def bench_split(scene: Scene, size: tuple[int, int], rounds: int = 5) -> Measured:
    """One row per part of the frame (coarse passes, tracing, nearest kernel and shading,
    secondary effects) and the frame and the moving frame whole: ms and share of the frame;
    where the frame shares shadow rays among pixel blocks, the secondary effects and the
    frame with a shadow ray per pixel too (shares of that frame)."""
    med = median_times(Renderer(), split_variants(scene), size, rounds, f"bench split {scene.name}")
    coarse = med.get("coarse", 0.0)
    parts = [
        ("coarse passes", coarse),
        ("tracing", med["trace"] - coarse),
        ("nearest kernel and shading", med["moving"] - med["trace"]),
        ("secondary effects (shadow rays, occlusion)", med["frame"] - med["moving"]),
        ("frame", med["frame"]),
        ("frame without secondary effects", med["moving"]),
    ]
    rows = [dict(part=name, ms=t * 1e3, share=t / med["frame"]) for name, t in parts]
    if "per pixel" in med:  # shares of that frame
        whole = med["per pixel"]
        rows += [
            dict(part=name, ms=t * 1e3, share=t / whole)
            for name, t in (
                ("secondary effects, a shadow ray per pixel", whole - med["moving"]),
                ("frame, a shadow ray per pixel", whole),
            )
        ]
    return Measured(scene, size, rounds, rows)


def table(m: Measured) -> str:
    r = m.scene.render
    block = still_ratio(m.scene)
    shared = f", shadow rays per {block}×{block} px" if block else ""
    return (
        f"\nWhere the time goes — {m.scene.name} at {m.size[0]}×{m.size[1]}, pre-pass "
        f"{f'{r.prepass} × {r.prepass_levels}' if r.prepass else 'off'}, culling "
        f"{r.culling}, lod {r.lod:g}{shared}; median of {m.rounds} interleaved rounds, each "
        "part the difference of two variants\n\n"
    ) + markdown(
        ("part", "ms", "share of the frame"),
        "lrr",
        ((row["part"], f"{row['ms']:.1f}", f"{row['share']:.0%}") for row in m.rows),
    )
