"""Per-pixel outputs shared by the GPU renderer and the NumPy reference (rows top → bottom)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Buffers:
    color: np.ndarray  # (H, W, 3) display colour in [0, 1] (gamma-encoded)
    depth: np.ndarray  # (H, W) ray distance t to the hit; 0 where missed
    normal: np.ndarray  # (H, W, 3) unit world normal; 0 where missed
    iterations: np.ndarray  # (H, W) distance evaluations spent by the tracer
    hit: np.ndarray  # (H, W) bool

    def rgb8(self) -> np.ndarray:
        return np.round(np.clip(self.color, 0.0, 1.0) * 255.0).astype(np.uint8)

    def save_png(self, path: str | Path) -> None:
        from PIL import Image

        Image.fromarray(self.rgb8(), "RGB").save(path)

    def save_npz(self, path: str | Path) -> None:
        np.savez_compressed(
            path,
            color=self.color,
            depth=self.depth,
            normal=self.normal,
            iterations=self.iterations,
            hit=self.hit,
        )
