"""Shared output of the benchmarks: Markdown tables on stdout, CSV files."""
from __future__ import annotations

from pathlib import Path


def write_csv(rows: list[dict], path: str) -> None:
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    keys = list(rows[0])
    Path(path).write_text(",".join(keys) + "\n" + "\n".join(
        ",".join(f"{row[k]}" for k in keys) for row in rows) + "\n")
    print(f"wrote {path}")
