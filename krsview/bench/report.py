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

MIN_ACCURACY_ROUNDS = 3  # the accuracy verdict needs each setting's spread: 1 or 2 rounds have none


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


TIME_SPREAD = "fastest round [median–slowest]"  # how ms_spread reads, for captions


def ms_spread(row: dict, digits: int = 1) -> str:
    """A row's time as "fastest [median–slowest]" milliseconds (its ms, ms_median and
    ms_max: :func:`harness.time_columns`)."""
    return f"{row['ms']:.{digits}f} [{row['ms_median']:.{digits}f}–{row['ms_max']:.{digits}f}]"


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


AXES = (
    ("ms", "ms per frame (fastest round; bar: to the slowest)"),
    ("work", "kernels evaluated per pixel"),
)


def accuracy_plots(rows: list[dict], fronts: dict[str, list[dict]], out: Path, title: str) -> None:
    """time-vs-error.png: per knob, error against time (top) and against work (bottom);
    pareto.png: every setting and ``fronts`` (cost → the Pareto front of bench/accuracy.py),
    against time and against work."""
    import matplotlib

    matplotlib.use("Agg")
    knobs = [k for k in dict.fromkeys(r["knob"] for r in rows) if k != "scene"]
    _knob_plots(rows, knobs, out, title)
    _pareto_plots(rows, knobs, fronts, out, title)


SWEPT = ("epsilon_scale", "max_iterations", "lod", "levels")  # knobs with an order: a line
PLOT_COLUMNS = 4  # knobs side by side in time-vs-error.png (a row of 11 was 5,000 px wide)


def _knob_plots(rows: list[dict], knobs: list[str], out: Path, title: str) -> None:
    """Per knob, hit-mask error against time and, under it, against work; four knobs a row,
    a knob swept in order drawn as a line, one of choices as points; the y axis linear
    where the errors span little (numbers on every panel)."""
    import matplotlib.pyplot as plt

    cols = min(PLOT_COLUMNS, len(knobs))
    grid = -(-len(knobs) // cols)
    fig, axes = plt.subplots(2 * grid, cols, figsize=(4.2 * cols, 3.4 * 2 * grid), squeeze=False)
    base = rows[0]
    for k, knob in enumerate(knobs):
        group = [r for r in rows if r["knob"] == knob]
        y = [100 * r["mask_error"] for r in group]
        for line, (cost, label) in enumerate(AXES):
            ax = axes[2 * (k // cols) + line][k % cols]
            x = [r[cost] for r in group]
            fmt = "o-" if knob in SWEPT else "o"
            ax.errorbar(x, y, xerr=_time_bars(group, cost), fmt=fmt, color="tab:blue", ms=4)
            for j, (r, xi, yi) in enumerate(zip(group, x, y)):  # alternate sides: no overlap
                ax.annotate(
                    r["value"],
                    (xi, yi),
                    fontsize=7,
                    xytext=(4, 4 if j % 2 == 0 else -10),
                    textcoords="offset points",
                )
            ax.plot([base[cost]], [100 * base["mask_error"]], "*", color="tab:red", ms=10,
                    label="as saved")  # fmt: skip
            uncounted = " (its cones not counted)" if knob == "prepass" and cost == "work" else ""
            ax.set_title(
                f"{knob.replace('_', ' ')}: against {'time' if cost == 'ms' else cost}{uncounted}"
            )
            ax.set_xlabel(label)
            ax.set_ylabel("hit-mask error (% of pixels)")
            every = y + [100 * base["mask_error"]]
            if max(every) > 10 * max(min(every), 0.1):  # errors over decades: a log scale
                ax.set_yscale("symlog", linthresh=0.1)
            ax.ticklabel_format(axis="x", useOffset=False, style="plain")
            ax.grid(alpha=0.3)
    for k in range(len(knobs), grid * cols):  # the last row's empty places
        for line in range(2):
            axes[2 * (k // cols) + line][k % cols].set_visible(False)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(
        f"{title}: error against time (noise floor {rows[0]['noise_floor']:.1%}) and against "
        "work, one knob at a time"
    )
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.3 / fig.get_figheight()))  # room for the title
    fig.savefig(out / "time-vs-error.png", dpi=100)
    plt.close(fig)


def _pareto_plots(
    rows: list[dict], knobs: list[str], fronts: dict[str, list[dict]], out: Path, title: str
) -> None:
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(14.4, 4.6))
    palette = plt.get_cmap("tab10").colors + plt.get_cmap("Dark2").colors  # distinct hues
    colours = dict(zip(knobs + ["scene"], palette))  # ≤ 18 knobs
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
    axes[0].set_title(f"time: fastest rounds' front (noise floor {rows[0]['noise_floor']:.1%})")
    axes[1].set_title("work (deterministic; the pre-pass's cones not counted: off the front)")
    fig.legend(*axes[0].get_legend_handles_labels(), fontsize=7, loc="center right")
    fig.suptitle(f"{title}: every setting; below the line nothing is cheaper and better")
    fig.tight_layout(rect=(0, 0, 0.9, 1))  # the legend to the right, off the points
    fig.savefig(out / "pareto.png", dpi=110)
    plt.close(fig)


def _time_bars(group: list[dict], cost: str) -> np.ndarray | None:
    """The spread of the times over rounds as error bars (from the fastest, the time shown,
    to the slowest); work has none."""
    if cost != "ms":
        return None
    return np.array([[0.0] * len(group), [r["ms_max"] - r["ms"] for r in group]])


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
