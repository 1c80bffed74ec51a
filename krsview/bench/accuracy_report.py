"""The report of `krsview bench accuracy` (:mod:`krsview.bench.accuracy` measures): the CSV,
the README with its table, the verdict (what is worth it, drawn only beyond the run's noise
floor), the Pareto fronts in time and in work, plots and error images."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

from ..scene import Scene
from .accuracy import EPSILON_SCALES, Accuracy, image_name, notable
from .harness import change, percent
from .report import accuracy_plots, ms_spread, write_csv
from .truth import TRUTH_EPSILON_SCALE, TRUTH_ITERATIONS

GOOD_ENOUGH = 0.01  # hit-mask error the summary asks for (1 % of the pixels)
ERROR_TOLERANCE = 0.001  # of the pixels: errors this close are alike (57 pixels at 320×180)
DEPTH_TOLERANCE = 0.5  # ε: depth p99s this close are alike


def write_report(acc: Accuracy, out: Path) -> str:
    """The report in folder ``out``: accuracy.csv, README.md (returned), plots of time
    against error and the Pareto front, and the error images."""
    from PIL import Image

    m = acc.measured
    out.mkdir(parents=True, exist_ok=True)
    write_csv(m.rows, out / "accuracy.csv")
    for name, image in acc.errors.items():
        Image.fromarray(image).save(out / name)
    fronts = {"ms": pareto(m.rows), "work": pareto(m.rows, cost="work")}
    accuracy_plots(m.rows, fronts, out, m.scene.name)
    report = _markdown(m.scene, m.size, m.rounds, m.rows, notable(m.rows))
    (out / "README.md").write_text(report)
    return report


def pareto(rows: list[dict], floor: float = 0.0, cost: str = "ms") -> list[dict]:
    """Settings no other beats in both ``cost`` ("ms" or "work") and hit-mask error, cheapest
    first; one setting per group doing the same work. With a noise ``floor``, only a cost
    lower beyond the noise beats: settings within noise of each other both stay. In work,
    the pre-pass's settings take no part: their cones are not counted (near free, else)."""
    own = [row for k, row in enumerate(rows) if row.get("same_as", k) == k]
    if cost == "work":
        own = [row for row in own if row["knob"] != "prepass"]

    def beats(a: dict, b: dict) -> bool:
        cheaper = a[cost] * (1 + floor)
        return (a["mask_error"] <= b["mask_error"] and cheaper < b[cost]) or (
            a["mask_error"] < b["mask_error"] and cheaper <= b[cost]
        )

    front = [b for b in own if not any(beats(a, b) for a in own if a is not b)]
    return sorted(front, key=lambda row: (row[cost], row["mask_error"]))


def _markdown(
    scene: Scene, size: tuple[int, int], rounds: int, rows: list[dict], notable: list[dict]
) -> str:
    w, h = size
    floor = rows[0]["noise_floor"]
    lines = [
        f"# What accuracy costs: {scene.name}",
        "",
        f"{w}×{h}, on the GL renderer (the scene's own path unless the row says), "
        f"{rounds} interleaved rounds: each time is the fastest round, with the median and "
        "the slowest beside it (a busy machine only adds time, so the fastest round is the "
        "estimate it disturbs least [Chen and Revels 2016]); errors against the ground "
        "truth: the "
        f"float64 reference at ε-scale {TRUTH_EPSILON_SCALE} with a cap of {TRUTH_ITERATIONS} "
        f"(so the ε-scale {TRUTH_EPSILON_SCALE} row's hit mask matches it by construction). "
        "Time ratios are to the scene **as saved**: the settings its file sets, and no "
        "pre-pass where it sets none (`krsview render` and the viewer add the pre-pass at 4 "
        "pixels: the 'prepass 4' row). **Noise floor "
        f"{floor:.1%}**: the largest spread between the times of settings doing the same "
        "work (the scene's own setting is timed a second time in each round as a control); "
        "a time difference under it is reported as within noise. Settings doing the same "
        "work (same compiled variant, same colours, iterations and levels walked in every "
        "pixel) share one time, pooled over their rounds, and read '= setting'. Work: kernels "
        "evaluated per pixel while tracing, the top one at each step and one per level "
        "walked (KRS_COUNT_LEVELS), which no machine load changes; the pre-pass's own cones "
        "are not counted (its rows' work is marked †, and left out of the work front). "
        "Hit-mask error: holes + false hits, the share of pixels whose hit differs from the "
        "truth's; holes: the truth hits, the image misses; false: the image hits empty "
        "space; 'off sil.' counts only pixels away from every outline. Depth error is in "
        "units of ε(t) = footprint × t, normal error in degrees, both over pixels both hit; "
        "PSNR and SSIM compare the colours with the truth's; it/px: iterations per pixel; "
        "capped: rays that reached the iteration cap.",
        "",
        "![time and work against error](time-vs-error.png)",
        "",
        "![Pareto front](pareto.png)",
        "",
        "| knob | value | ms, fastest [median–slowest] | time ratio | work | holes | false hits "
        "| holes off sil. | "
        "depth p50/p99 (ε) | normal p99 (°) | PSNR dB | SSIM | it/px | capped |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for k, r in enumerate(rows):
        same = rows[r["same_as"]]
        ms = ms_spread(r) if r["same_as"] == k else f"= {same['knob']} {same['value']}"
        dagger = "†" if r["knob"] == "prepass" else ""
        lines.append(
            f"| {r['knob']} | {r['value']} | {ms} | {r['time_ratio']:.2f} | "
            f"{r['work']:.1f}{dagger} | "
            f"{r['holes']:.2%} | {r['false_hits']:.2%} | {r['holes_off_silhouette']:.2%} | "
            f"{r['depth_eps_median']:.2f}/{r['depth_eps_p99']:.1f} | {r['normal_deg_p99']:.1f} | "
            f"{r['psnr']:.1f} | {r['ssim']:.3f} | {r['iterations']:.1f} | {r['capped']:.2%} |"
        )
    lines += ["", "## Verdict", ""] + [f"- {s}" for s in verdict(rows)]
    front = pareto(rows, floor)
    by_work = pareto(rows, cost="work")
    lines += [
        "",
        "Pareto front in time (settings within noise of each other both kept; fastest "
        "first): "
        + ", ".join(
            f"{r['knob']} {r['value']} ({r['ms']:.0f} ms, {r['mask_error']:.2%})" for r in front
        ),
        "",
        "Pareto front in work (least first): "
        + ", ".join(
            f"{r['knob']} {r['value']} ({r['work']:.0f} kernels/px, {r['mask_error']:.2%})"
            for r in by_work
        ),
        "",
        "Settings never worth it (another is faster beyond noise and no worse in hit-mask "
        f"error, holes or depth p99, within {ERROR_TOLERANCE:.2%} of the pixels and "
        f"{DEPTH_TOLERANCE:g} ε): " + _names(dominated(rows, floor)),
        "",
        "On the time front only within noise (a more accurate setting is no slower on these "
        "times, by less than the noise floor): "
        + _names(r for r in front if r not in pareto(rows)),
        "",
        "## Error images (holes red, false hits blue)",
        "",
    ]
    lines += [
        f"**{r['knob']} {r['value']}** ({r['mask_error']:.2%} of pixels): ![]({image_name(r)})  "
        for r in notable
    ]
    return "\n".join(lines) + "\n"


def dominated(rows: list[dict], floor: float) -> list[dict]:
    """The settings another beats outright: faster beyond the noise ``floor`` and no worse
    in hit-mask error, holes or depth p99 (within ERROR_TOLERANCE of the pixels and
    DEPTH_TOLERANCE ε: a few pixels' difference decides nothing). A setting that trades holes
    for false hits, or a sharper depth for a few pixels of mask, is not beaten."""

    def no_worse(a: dict, b: dict) -> bool:
        return (
            a["mask_error"] <= b["mask_error"] + ERROR_TOLERANCE
            and a["holes"] <= b["holes"] + ERROR_TOLERANCE
            and a["depth_eps_p99"] <= b["depth_eps_p99"] + DEPTH_TOLERANCE
        )

    own = [r for k, r in enumerate(rows) if r["same_as"] == k]
    return [
        b
        for b in own[1:]
        if any(a is not b and a["ms"] * (1 + floor) < b["ms"] and no_worse(a, b) for a in own)
    ]


def _names(rows: Iterable[dict]) -> str:
    return ", ".join(f"{r['knob']} {r['value']}" for r in rows) or "none"


def verdict(rows: list[dict]) -> list[str]:
    """Plain sentences: what halving ε buys, what precision costs, the cheapest
    good-enough setting; a time difference under the noise floor is said to be within
    noise, and work (deterministic) is given beside it."""
    out = []
    floor = rows[0]["noise_floor"]
    eps = {r["value"]: r for r in rows if r["knob"] == "epsilon_scale"}
    if "1" in eps and "0.5" in eps:
        a, b = eps["1"], eps["0.5"]
        removed = 1 - b["mask_error"] / a["mask_error"] if a["mask_error"] > 0 else 0.0
        out.append(
            f"Halving ε (ε-scale 1 → 0.5) costs {change(b['ms'], a['ms'], floor)} and "
            f"{percent(b['work'] / a['work'] - 1)} work; holes "
            f"go from {a['holes']:.2%} to {b['holes']:.2%} of the pixels and false hits "
            f"from {a['false_hits']:.2%} to {b['false_hits']:.2%}: {removed:.0%} of the "
            "hit-mask error removed."
        )
    base = rows[0]
    for r in rows:
        if r["knob"] == "precision":
            gain = base["mask_error"] - r["mask_error"]
            out.append(
                f"Precision {r['value']} costs {change(r['ms'], base['ms'], floor)} "
                f"and {percent(r['work'] / base['work'] - 1)} work; "
                f"hit-mask error {r['mask_error']:.2%} against {base['mask_error']:.2%} "
                f"as saved, depth p99 {r['depth_eps_p99']:.2f} against "
                f"{base['depth_eps_p99']:.2f} ε"
                + (
                    ": at this view the precision is not what limits accuracy (deep "
                    "zooms are where float64 pays: docs/stability.md)."
                    if abs(gain) < 0.001
                    else "."
                )
            )
    return out + _cheapest(rows, eps.get(f"{EPSILON_SCALES[0]:g}"), floor)


def _cheapest(rows: list[dict], tight: dict | None, floor: float) -> list[str]:
    """The cheapest setting within GOOD_ENOUGH against the tight one and the ≤ 0.5× goal:
    met or not met beyond the noise ``floor``, else within noise of it."""
    good = [r for r in rows if r["mask_error"] <= GOOD_ENOUGH and r is not tight]
    if not good:
        return [f"No setting comes within {GOOD_ENOUGH:.0%} hit-mask error."]
    if tight is None:
        return []
    best = min(good, key=lambda r: r["ms"])
    ratio = best["ms"] / tight["ms"]
    met = (
        "met"
        if ratio * (1 + floor) <= 0.5
        else "not met"
        if ratio >= 0.5 * (1 + floor)
        else "within noise of it"
    )
    return [
        f"Cheapest setting within {GOOD_ENOUGH:.0%} hit-mask error: {best['knob']} "
        f"{best['value']} at {best['ms']:.1f} ms, {ratio:.2f}× the tight setting "
        f"(ε-scale {EPSILON_SCALES[0]:g}: {tight['ms']:.1f} ms; work "
        f"{best['work'] / tight['work']:.2f}×, the pre-pass's own not counted); the goal, "
        f"half the tight setting's time within {GOOD_ENOUGH:.0%}, is ≤ 0.5×: {met}."
    ]
