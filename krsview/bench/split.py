"""`krsview bench split`: where a frame's time goes — the pre-pass's coarse passes, the
tracing of the primary rays, the nearest kernel and shading, and the secondary effects
(shadow rays and occlusion samples). Each part
is the difference of two variants timed side by side, interleaved (bench/harness.py), each
to the GPU's finish. GPU timer queries would split one frame instead, but llvmpipe's time
only its command thread (a 138 ms draw read 29 ms), so each part is a variant of its own.
Drawn on the fragment path, as the viewer draws. Beside the times, the shadow rays' work,
which no machine load changes: steps and levels walked per pixel (a counting variant with a
shadow ray per pixel); where the scene has the shadow cone, both again without it."""

from __future__ import annotations

from dataclasses import replace

from ..compile.geometry import compile_geometry
from ..gpu.passes import still_ratio
from ..gpu.readback import read_plane
from ..gpu.renderer import Renderer
from ..gpu.uniforms import variant_defines
from ..scene import EFFECTS, Scene
from .harness import Variant, bench_inputs, fastest, round_times
from .report import Measured, markdown

WORK = ("shadow steps/px", "shadow levels/px")  # the frames' rows' work (shadow_work)


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
    if has_cone(scene):  # and the exact shadow rays beside (render.shadow_cone)
        out["cone off"] = Variant(scene.edit(("render", "shadow_cone"), "off"))
    return out


def has_cone(scene: Scene) -> bool:
    """Whether ``scene``'s shadow rays meet its components through the shadow cone."""
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    return "KRS_SHADOW_CONE" in variant_defines(scene, c)


def shadow_work(r: Renderer, scene: Scene, size: tuple[int, int]) -> tuple[float, float]:
    """Shadow rays' steps and levels walked per pixel, a shadow ray per pixel (the counting
    variant, render.frag); a measure of work that no machine load changes."""
    with r.current():
        prog = r.prepare(scene, *size, probes=("KRS_COUNT_LEVELS",))
        counts = read_plane(r.draw(prog, *size), 2, *size)
    return float(counts[..., 2].mean()), float(counts[..., 3].mean())


def bench_split(scene: Scene, size: tuple[int, int], rounds: int = 5) -> Measured:
    """One row per part of the frame (coarse passes, tracing, nearest kernel and shading,
    secondary effects) and the frame and the moving frame whole: ms and share of the frame;
    where the frame shares shadow rays among pixel blocks, the secondary effects and the
    frame with a shadow ray per pixel too (shares of that frame); where it has the shadow
    cone, the frame without it too. The frames' rows carry the shadow rays' work
    (:func:`shadow_work`), the others none."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    r = Renderer()
    variants = split_variants(scene)
    times = round_times(r, variants, size, rounds, f"bench split {scene.name}")
    best = fastest(times)
    parts = [  # (name, the part in a round's times)
        ("coarse passes", lambda t: t.get("coarse", 0.0)),
        ("tracing", lambda t: t["trace"] - t.get("coarse", 0.0)),
        ("nearest kernel and shading", lambda t: t["moving"] - t["trace"]),
        ("secondary effects (shadow rays, occlusion)", lambda t: t["frame"] - t["moving"]),
        ("frame", lambda t: t["frame"]),
        ("frame without secondary effects", lambda t: t["moving"]),
    ]
    for key, label in (("per pixel", "a shadow ray per pixel"), ("cone off", "shadow cone off")):
        if key in best:  # shares of that frame
            parts += [
                (f"secondary effects, {label}", lambda t, k=key: t[k] - t["moving"]),
                (f"frame, {label}", lambda t, k=key: t[k]),
            ]
    rows = []
    for name, part in parts:
        ms = part(best) * 1e3
        whole = best.get(_frame_of(name), best["frame"])
        each = [part({k: v[i] for k, v in times.items()}) * 1e3 for i in range(rounds)]
        rows.append(dict(part=name, ms=ms, share=ms / 1e3 / whole, low=min(each), high=max(each)))
    work = {"frame": variants["frame"], "frame, shadow cone off": variants.get("cone off")}
    for row in rows:
        v = work.get(row["part"])
        steps, levels = shadow_work(r, v.scene, size) if v else ("", "")
        row.update({"shadow steps/px": steps, "shadow levels/px": levels})
    return Measured(scene, size, rounds, rows)


def _frame_of(part: str) -> str:
    """The frame a part is a share of: an alternative frame's own, else the frame."""
    return {"a shadow ray per pixel": "per pixel", "shadow cone off": "cone off"}.get(
        part.rpartition(", ")[2], "frame"
    )


def noted(row: dict) -> str:
    """A part's name, said to be within noise where its rounds disagree on its sign (a part
    measured as a difference of two variants' times: their noise can make it negative)."""
    within = row["low"] <= 0.0 <= row["high"] and not row["part"].startswith("frame")
    return row["part"] + (" (within noise)" if within else "")


def table(m: Measured) -> str:
    r = m.scene.render
    block = still_ratio(m.scene)
    shared = f", shadow rays per {block}×{block} px" if block else ""
    return (
        f"\nWhere the time goes — {m.scene.name} at {m.size[0]}×{m.size[1]}, pre-pass "
        f"{f'{r.prepass} × {r.prepass_levels}' if r.prepass else 'off'}, culling "
        f"{r.culling}, lod {r.lod:g}{shared}; fastest of {m.rounds} interleaved rounds, each "
        "part the difference of two variants (within noise where its rounds disagree on "
        "its sign)\n\n"
    ) + markdown(
        (
            "part",
            "ms",
            "rounds [min–max]",
            "share of the frame",
            "shadow steps/px",
            "shadow levels/px",
        ),
        "lrrrrr",
        (
            (
                noted(row),
                f"{row['ms']:.1f}",
                f"{row['low']:.1f}–{row['high']:.1f}",
                f"{row['share']:.0%}",
                *(f"{row[k]:.2f}" if row[k] != "" else "" for k in WORK),
            )
            for row in m.rows
        ),
    )
