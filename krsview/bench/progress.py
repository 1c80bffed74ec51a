"""A one-line progress bar on stderr for long sweeps."""
from __future__ import annotations

import sys


class Progress:
    def __init__(self, total: int, label: str):
        self.total, self.label, self.done = total, label, 0

    def step(self, note: str = "") -> None:
        self.done += 1
        width = 24
        filled = width * self.done // self.total
        bar = "█" * filled + "·" * (width - filled)
        end = "\n" if self.done == self.total else ""
        print(f"\r{self.label} [{bar}] {self.done}/{self.total} {note:<24}", end=end,
              file=sys.stderr, flush=True)
