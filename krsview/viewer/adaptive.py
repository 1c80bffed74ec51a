"""Adaptive internal resolution: while the view moves, scale the image so a frame fits the
target frame time; when it is still, refine to full resolution in tiles within a per-turn
time budget, so input is never blocked by a slow frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass
class AdaptiveResolution:
    full: tuple[int, int]  # window size in pixels
    target_fps: float = 30.0
    min_scale: float = 0.1
    scale: float = 0.5  # start near 320×180 for a 640×360 window (DESIGN.md)
    supersample: int = 1  # still images: 1, or 2 for 2×2 supersampling
    history: list[float] = field(default_factory=list)

    @property
    def budget(self) -> float:
        return 1.0 / self.target_fps

    def moving_size(self) -> tuple[int, int]:
        return (max(1, round(self.full[0] * self.scale)), max(1, round(self.full[1] * self.scale)))

    def still_size(self) -> tuple[int, int]:
        return (self.full[0] * self.supersample, self.full[1] * self.supersample)

    def frame_done(self, seconds: float) -> None:
        """After a moving frame: cost ∝ pixels ∝ scale², so aim scale at the budget, damped."""
        self.history = (self.history + [seconds])[-120:]
        if seconds <= 0:
            return
        factor = math.sqrt(self.budget / seconds)
        factor = min(1.25, max(0.7, factor))  # damped: a noisy frame moves scale a little
        self.scale = min(1.0, max(self.min_scale, self.scale * factor))


@dataclass
class Refinement:
    """Full-resolution image traced in horizontal bands, a few per event-loop turn."""

    size: tuple[int, int]
    band: int = 16  # rows per tile
    next_row: int = 0
    seconds_per_row: float = 0.0

    @property
    def done(self) -> bool:
        return self.next_row >= self.size[1]

    def next_tile(self, budget: float) -> tuple[int, int, int, int]:
        """The next band, sized so it should fit ``budget`` seconds by the measured row cost."""
        rows = self.band
        if self.seconds_per_row > 0:
            rows = max(1, min(self.size[1], int(budget / self.seconds_per_row)))
        rows = min(rows, self.size[1] - self.next_row)
        tile = (0, self.next_row, self.size[0], rows)
        self.next_row += rows
        return tile

    def tile_done(self, tile: tuple[int, int, int, int], seconds: float) -> None:
        per_row = seconds / max(tile[3], 1)
        self.seconds_per_row = (
            per_row if self.seconds_per_row == 0 else (0.5 * self.seconds_per_row + 0.5 * per_row)
        )
