"""Shared output of the benchmarks: Markdown tables on stdout, CSV files."""

from __future__ import annotations

import csv
import io
from pathlib import Path


def write_csv(rows: list[dict], path: str) -> None:
    """The rows as CSV, fields quoted where they hold a comma (a part named "shadow rays,
    occlusion")."""
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    Path(path).write_text(text.getvalue())
    print(f"wrote {path}")
