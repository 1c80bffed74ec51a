"""A one-line progress bar on stderr for long work (sweeps, slow renders)."""

from __future__ import annotations

import sys
import time


class Progress:
    """``step()`` once per unit of work. With ``delay`` seconds the bar stays silent until
    the work has taken that long, so quick work prints nothing (tqdm's habit)."""

    def __init__(self, total: int, label: str, delay: float = 0.0):
        self.total, self.label, self.done, self.delay = total, label, 0, delay
        self.start, self.shown = time.perf_counter(), False

    def step(self, note: str = "") -> None:
        self.done += 1
        self.show(self.done, note)

    def show(self, done: int, note: str = "") -> None:
        self.done = done
        if not self.shown and time.perf_counter() - self.start < self.delay:
            return
        self.shown = True
        width = 24
        filled = width * self.done // self.total
        bar = "█" * filled + "·" * (width - filled)
        end = "\n" if self.done == self.total else ""
        print(
            f"\r{self.label} [{bar}] {self.done}/{self.total} {note:<24}",
            end=end,
            file=sys.stderr,
            flush=True,
        )

    def __call__(self, done: int, total: int) -> None:
        """As a ``progress(done, total)`` callback of the renderers."""
        self.total = total
        self.show(done)
