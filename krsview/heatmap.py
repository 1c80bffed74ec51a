"""Iteration heat maps with a legend, as in [KRS17 Fig. 13]: where the tracer spends its work.

``heat`` is the twin of ``heat()`` in shaders/display.frag, so the viewer's iterations view
and the PNG written by ``krsview render --view iterations`` use the same colours."""

from __future__ import annotations

from pathlib import Path

import numpy as np

LEGEND_HEIGHT = 42  # pixels below the image: colour bar, tick labels, caption
LEGEND_BACKGROUND = (32, 32, 36)  # dark, so the white end of the bar shows


VIEW_WHITE = 32  # iterations: the viewer's heat map is white here until the HUD says more


def heat(x: np.ndarray) -> np.ndarray:
    """Black → purple → orange → white for x in [0, 1]; returns (..., 3) in [0, 1]."""
    x = np.clip(x, 0.0, 1.0)
    rgb = np.stack([1.6 * x, 1.15 * x * x - 0.15, 0.9 * np.sin(np.pi * x) + x**3], axis=-1)
    return np.clip(rgb, 0.0, 1.0)


def heatmap_image(iterations: np.ndarray, vmax: int, label: str):
    """The heat map of ``iterations`` (H, W) scaled to ``vmax``, above a legend bar with
    ticks at 0, vmax/2 and vmax and ``label``; a PIL image."""
    from PIL import Image, ImageDraw

    H, W = iterations.shape
    top = np.round(heat(iterations / max(vmax, 1)) * 255).astype(np.uint8)
    canvas = Image.new("RGB", (W, H + LEGEND_HEIGHT), LEGEND_BACKGROUND)
    canvas.paste(Image.fromarray(top, "RGB"), (0, 0))
    margin, bar_h = 4, 8
    x0, x1 = margin, max(W - margin, margin + 2)
    ramp = heat(np.linspace(0.0, 1.0, x1 - x0))
    bar = np.round(np.broadcast_to(ramp, (bar_h, x1 - x0, 3)) * 255).astype(np.uint8)
    canvas.paste(Image.fromarray(np.ascontiguousarray(bar), "RGB"), (x0, H + 3))
    draw = ImageDraw.Draw(canvas)
    y = H + 3 + bar_h + 2
    for frac, anchor in ((0.0, "la"), (0.5, "ma"), (1.0, "ra")):
        draw.text(
            (x0 + frac * (x1 - x0), y), f"{round(frac * vmax)}", fill=(255, 255, 255), anchor=anchor
        )
    draw.text((W / 2, y + 13), label, fill=(200, 200, 200), anchor="ma")
    return canvas


def save_heatmap(iterations: np.ndarray, path: str | Path, vmax: int | None, label: str) -> int:
    """Write the heat map PNG; ``vmax`` None uses the image's own maximum. Returns vmax."""
    vmax = int(iterations.max()) if vmax is None else vmax
    heatmap_image(iterations, vmax, label).save(path)
    return vmax
