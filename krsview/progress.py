"""Progress of long work (sweeps, slow renders, frames) on stderr, drawn by tqdm: a bar that
redraws in place on a terminal, and nothing at all when stderr is a file or a pipe, so logs
hold no carriage-return redraws."""

from __future__ import annotations

import sys

from tqdm import tqdm


class Progress:
    """``step()`` once per unit of work, or call it as a renderer's ``progress(done, total)``.
    With ``delay`` seconds the bar stays silent until the work has taken that long, so quick
    work prints nothing."""

    def __init__(self, total: int, label: str, delay: float = 0.0):
        self.bar = tqdm(
            total=total,
            desc=label,
            delay=delay,
            file=sys.stderr,
            disable=None,  # off unless stderr is a terminal
            bar_format="{desc} [{bar:24}] {n_fmt}/{total_fmt}{postfix}",
            ascii="·█",
        )

    def step(self, note: str = "") -> None:
        self.show(self.bar.n + 1, note)

    def show(self, done: int, note: str = "") -> None:
        if note:
            self.bar.set_postfix_str(note, refresh=False)
        self.bar.update(done - self.bar.n)
        if self.bar.total is not None and done >= self.bar.total:
            self.bar.close()

    def __call__(self, done: int, total: int) -> None:
        """As a ``progress(done, total)`` callback of the renderers."""
        self.bar.total = total
        self.show(done)
