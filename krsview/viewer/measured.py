"""The viewer's view of a preset's measured accuracy report (`krsview bench accuracy`): which
measured setting the view uses now, and the most accurate one that fits the frame budget."""

from __future__ import annotations

import csv
from dataclasses import replace
from pathlib import Path

from ..scene import Scene
from ..scene.presets import PRESET_DIR
from ..scene.render import Render
from .commands import Command, Edit, SetLevels, SetPrepass

# A report made here by `krsview bench accuracy` (OUT/PRESET/accuracy.csv) wins over the
# measurements shipped beside the presets (PRESET.accuracy.csv, in the wheel too).
REPORT_DIRS = (Path("out") / "accuracy",)
SWITCHES = ("precision", "culling", "path", "walk_restart")  # knobs whose value is a word


def report_files(stem: str) -> list[Path]:
    """Where the measurements of the preset ``stem`` may be, in order."""
    return [d / stem / "accuracy.csv" for d in REPORT_DIRS] + [PRESET_DIR / f"{stem}.accuracy.csv"]


def load_measured(stem: str) -> list[dict] | None:
    """The rows of ``accuracy.csv`` for the preset ``stem``, numbers as floats; None if no
    report exists or it cannot be read."""
    for f in report_files(stem):
        try:
            with f.open() as fh:
                rows = list(csv.DictReader(fh))
        except OSError:
            continue
        try:
            for r in rows:
                for k, v in r.items():
                    if k not in ("knob", "value"):
                        r[k] = float(v)
        except (TypeError, ValueError):
            return None
        return rows or None
    return None


def matches(
    row: dict, scene: Scene, saved: Scene, levels: int, depth: int, prepass: int = 0
) -> bool:
    """Whether the view draws with the setting this row measured; ``levels`` is the view's
    level count (0: all ``depth`` levels of the geometry, which the caller already has),
    ``prepass`` the viewer's pre-pass tile. The bench draws every row but the pre-pass's with
    the file's own pre-pass, none where the file sets none (bench/accuracy.py), while the
    viewer draws VIEW_PREPASS there: such a view is the ``prepass`` row's, not the scene's."""
    r, s = scene.render, saved.render
    knob, value = row["knob"], row["value"]
    row_levels = int(value) if knob == "levels" else depth

    def same_but(**kw) -> bool:
        drawn = replace(s, prepass=r.prepass, **kw) == r and (levels or depth) == row_levels
        return drawn and prepass == row_prepass(row, s)

    if knob in ("scene", "prepass", "levels"):
        return same_but()
    if knob == "epsilon_scale":
        return same_but(epsilon_scale=float(value))
    if knob == "max_iterations":
        return same_but(max_iterations=int(value))
    if knob == "lod":
        return same_but(lod=float(value))
    if knob == "tracer":
        return same_but(**_tracer(value))
    if knob in SWITCHES:
        return same_but(**{knob: value})
    return False


def row_prepass(row: dict, saved: Render) -> int:
    """The pre-pass tile the bench drew a row with: a pre-pass row's own, else the file's,
    none where the file sets none (bench/accuracy.py)."""
    return int(row["value"]) if row["knob"] == "prepass" else (saved.prepass or 0)


def _tracer(value: str) -> dict:
    if value == "sphere":
        return dict(tracer="sphere")
    if value.startswith("relaxed"):
        return dict(tracer="relaxed", relaxation=float(value.split()[1]))
    b, p = value.split()[1].split("/")
    return dict(tracer="binary", xi_bonus=float(b), xi_penalty=float(p))


def best_within(rows: list[dict], budget_ms: float, pixels: int) -> dict | None:
    """The measured setting with the least hit-mask error whose time, scaled from the
    report's resolution to ``pixels``, fits ``budget_ms``; None if none fits."""
    fits = [r for r in rows if r["ms"] * pixels / (r["width"] * r["height"]) <= budget_ms]
    return min(fits, key=lambda r: (r["mask_error"], r["ms"])) if fits else None


def apply_row(row: dict, saved: Scene) -> list[Command]:
    """Commands that put the view on a measured setting (the others as saved), its pre-pass
    (:func:`row_prepass`) included."""
    knob, value = row["knob"], row["value"]
    base = saved.render
    render = {
        "epsilon_scale": lambda: replace(base, epsilon_scale=float(value)),
        "max_iterations": lambda: replace(base, max_iterations=int(value)),
        "lod": lambda: replace(base, lod=float(value)),
        "tracer": lambda: replace(base, **_tracer(value)),
        **{k: lambda k=k: replace(base, **{k: value}) for k in SWITCHES},
    }.get(knob, lambda: base)()
    levels = int(value) if knob == "levels" else 0
    return [Edit(("render",), render), SetLevels(levels), SetPrepass(row_prepass(row, base))]
