"""What the benchmarks and checks return, and its text: the :class:`Measured` rows of a bench,
Markdown tables, CSV files, the statistics of ``krsview check`` and the oracle's counts. The
CLI prints these; nothing here measures anything."""

from __future__ import annotations

import csv
import io
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from ..oracle.certify import Counts
from ..scene import Scene
from ..scene.info import SceneInfo


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


def scene_text(info: SceneInfo, source: str | Path) -> str:
    """``krsview check``'s report of a scene's statistics (``source``: the file read)."""
    lines = [f"{source}: ok — {info.name}"]
    if info.description:
        lines.append(f"  {info.description}")
    if info.geometry == "MöKRS":
        lines.append(
            f"  geometry        MöKRS: {info.mirrors} levels, {info.reflecting} reflecting"
        )
    elif info.geometry == "compound":
        lines.append(f"  geometry        compound of {len(info.parts)}: " + ", ".join(info.parts))
    else:
        lines.append(f"  geometry        {info.geometry}")
        lines.append(
            f"  levels          {info.levels} (kernels K_0..K_{info.mirrors}, "
            f"{info.mirrors} mirrors)"
        )
    lines.append(f"  kernel instances {info.instances:,}")
    lines.append("  kernels         " + ", ".join(f"{v}× {k}" for k, v in info.kernels.items()))
    lines.append(f"  effects         {', '.join(info.effects) or 'none'}")
    lines += [f"  warning         {w}" for w in info.warnings]
    binary = f" (ξ_bonus {info.xi[0]}, ξ_penalty {info.xi[1]})" if info.xi else ""
    lines.append(
        f"  render          {info.tracer} tracer{binary}, ε-scale {info.epsilon_scale}, "
        f"≤ {info.max_iterations} iterations, far {info.max_distance}"
    )
    return "\n".join(lines)


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
