"""What the benchmarks and checks return, and its text: the :class:`Measured` rows of a bench,
Markdown tables, CSV files, the accuracy report's plots, the statistics of ``krsview check``
and the oracle's counts. The CLI prints these; nothing here measures anything."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..oracle.certify import Counts
from ..scene import Scene


@dataclass(frozen=True)
class Measured:
    """A bench's result: one row per variant (a dict of the CSV's columns, in order) and
    what was measured (a table's caption)."""

    scene: Scene
    size: tuple[int, int]
    rounds: int
    rows: list[dict]

    def column(self, name: str) -> list:
        return [row[name] for row in self.rows]


def markdown(columns: Iterable[str], align: str, rows: Iterable[Iterable[object]]) -> str:
    """A Markdown table; ``align`` has one letter per column, ``l`` or ``r``."""
    lines = [
        "| " + " | ".join(columns) + " |",
        "|" + "|".join("---:" if a == "r" else "---" for a in align) + "|",
    ]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


def write_csv(rows: list[dict], path: str | Path) -> Path:
    """The rows as CSV, fields quoted where they hold a comma (a part named "shadow rays,
    occlusion"); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    path.write_text(text.getvalue())
    return path


AXES = (("ms", "ms per frame (median, bar: min–max)"), ("work", "kernels evaluated per pixel"))


def accuracy_plots(rows: list[dict], fronts: dict[str, list[dict]], out: Path, title: str) -> None:
    """time-vs-error.png: per knob, error against time (top) and against work (bottom);
    pareto.png: every setting and ``fronts`` (cost → the Pareto front of bench/accuracy.py),
    against time and against work."""
    import matplotlib

    matplotlib.use("Agg")
    knobs = [k for k in dict.fromkeys(r["knob"] for r in rows) if k != "scene"]
    _knob_plots(rows, knobs, out, title)
    _pareto_plots(rows, knobs, fronts, out, title)


def _knob_plots(rows: list[dict], knobs: list[str], out: Path, title: str) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(knobs), figsize=(4.2 * len(knobs), 7.0), squeeze=False)
    for (cost, label), line in zip(AXES, axes):
        for ax, knob in zip(line, knobs):
            group = [r for r in rows if r["knob"] == knob]
            x = [r[cost] for r in group]
            y = [100 * r["mask_error"] for r in group]
            ax.errorbar(x, y, xerr=_time_bars(group, cost), fmt="o-", color="tab:blue", ms=4)
            for r, xi, yi in zip(group, x, y):
                ax.annotate(
                    r["value"], (xi, yi), fontsize=7, xytext=(3, 3), textcoords="offset points"
                )
            base = rows[0]
            ax.plot(
                [base[cost]],
                [100 * base["mask_error"]],
                "*",
                color="tab:red",
                ms=10,
                label="as saved",
            )
            ax.set_title(knob.replace("_", " "))
            ax.set_xlabel(label)
            ax.set_ylabel("hit-mask error (% of pixels)")
            ax.set_yscale("symlog", linthresh=0.1)
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(
        f"{title}: error against time (noise floor {rows[0]['noise_floor']:.1%}) and against "
        "work, one knob at a time"
    )
    fig.tight_layout()
    fig.savefig(out / "time-vs-error.png", dpi=110)
    plt.close(fig)


def _pareto_plots(
    rows: list[dict], knobs: list[str], fronts: dict[str, list[dict]], out: Path, title: str
) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12.8, 4.6))
    colours = dict(zip(knobs + ["scene"], plt.get_cmap("tab20").colors))  # ≤ 20 knobs
    for ax, (cost, label) in zip(axes, AXES):
        for knob in knobs + ["scene"]:
            group = [r for r in rows if r["knob"] == knob]
            ax.errorbar(
                [r[cost] for r in group],
                [100 * r["mask_error"] for r in group],
                xerr=_time_bars(group, cost),
                fmt="o",
                label=knob.replace("_", " "),
                color=colours[knob],
                ms=4,
            )
        front = fronts[cost]
        ax.step(
            [r[cost] for r in front],
            [100 * r["mask_error"] for r in front],
            where="post",
            color="black",
            lw=1,
            label="Pareto front",
        )
        for r in front:
            ax.annotate(
                f"{r['knob'].split('_')[0]} {r['value']}",
                (r[cost], 100 * r["mask_error"]),
                fontsize=7,
                xytext=(3, 3),
                textcoords="offset points",
            )
        ax.set_yscale("symlog", linthresh=0.1)
        ax.set_xlabel(label)
        ax.set_ylabel("hit-mask error (% of pixels)")
        ax.grid(alpha=0.3)
    axes[0].set_title(f"time: medians' front (noise floor {rows[0]['noise_floor']:.1%})")
    axes[1].set_title("work (deterministic)")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{title}: every setting; below the line nothing is cheaper and better")
    fig.tight_layout()
    fig.savefig(out / "pareto.png", dpi=110)
    plt.close(fig)


def _time_bars(group: list[dict], cost: str) -> np.ndarray | None:
    """The min–max spread of the times as error bars; work has none."""
    if cost != "ms":
        return None
    return np.array(
        [[r["ms"] - r["ms_min"] for r in group], [r["ms_max"] - r["ms"] for r in group]]
    )


def oracle_header(name: str, size: tuple[int, int]) -> str:
    """The head of the oracle's table, printed before its slow rows."""
    return (
        f"| {name} {size[0]}×{size[1]} | rays | hits | holes | false hits beyond ε | "
        "below LOD | undecided | affine: segments, s | interval: segments, s |\n"
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    )


def oracle_row(tracer: str, c: Counts) -> str:
    """One tracer's certified counts and the oracle's work."""
    (sa, ta), (si, ti) = c.work["affine"], c.work["interval"]
    return (
        f"| {tracer} | {c.rays} | {c.hits} | {c.holes} | {c.false_hits} | "
        f"{c.below_lod} | {c.undecided} | {sa:,}, {ta:.1f} | {si:,}, {ti:.1f} |"
    )
