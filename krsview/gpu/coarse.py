"""Where a coarse pass of the pre-pass stores its tiles: four quarter images, blocks of
PREPASS_BLOCK × PREPASS_BLOCK tiles alternating between them, each quarter on a corner of
llvmpipe's bins (prepass.glsl, coarse_texel). llvmpipe gives each 64-pixel bin of a pass to one
thread, and a coarse image of up to 64 × 64 tiles lies in one or two bins, a view's cones
mostly in one; the quarters spread them over four (docs/speed.md)."""

from __future__ import annotations

import functools

from ..compile.camera import View
from ..compile.constants import PREPASS_BLOCK
from .bins import BIN


def coarse_quarter(x: int) -> tuple[int, int]:
    """Tile column (or row) ``x`` of a coarse pass: its quarter, 0 or 1, and its column (row)
    in that quarter's image: blocks of PREPASS_BLOCK tiles alternate between the quarters
    (prepass.glsl, coarse_texel)."""
    block = x // PREPASS_BLOCK
    return block % 2, block // 2 * PREPASS_BLOCK + x % PREPASS_BLOCK


@functools.cache
def coarse_layout(columns: int, rows: int) -> tuple[tuple[int, int], tuple[int, int]]:
    """The quarter images' stride and the target's size of a coarse pass of ``columns`` ×
    ``rows`` tiles (prepass.glsl, coarse_texel): each quarter starts on a corner of
    BIN-pixel bins, the bins llvmpipe gives one thread each (cached: every frame
    asks)."""
    stride, size = [], []
    for n in (columns, rows):
        ends = [0, 0]  # each quarter's width
        for x in range(n):
            q, local = coarse_quarter(x)
            ends[q] = max(ends[q], local + 1)
        stride.append(-(-ends[0] // BIN) * BIN)
        size.append(stride[-1] + ends[1] if ends[1] else ends[0])
    return (stride[0], stride[1]), (size[0], size[1])


def free_stride(view: View, tile: int) -> tuple[int, int]:
    """The quarter stride of the finest coarse pass (tiles of ``tile`` pixels) over ``view``,
    which the full pass reads its rays' starts from (prepass.glsl, ray_start)."""
    tile = max(tile, 1)
    return coarse_layout(-(-view.width // tile), -(-view.height // tile))[0]


@functools.cache
def quarters(
    columns: int, rows: int, tiles: tuple[int, int, int, int] | None
) -> tuple[tuple[int, int, int, int], ...]:
    """The texel rectangles (x, y, w, h) of a coarse pass's quarter images (coarse_layout) that
    hold the tiles ``tiles`` = (x0, y0, x1, y1) (None: all), in GL coordinates; empty ones
    left out. A quarter's tiles in a range of columns lie in a range of its columns (cached:
    every frame asks)."""
    x0, y0, x1, y1 = tiles or (0, 0, columns, rows)
    stride, _ = coarse_layout(columns, rows)
    spans = []  # per axis and quarter: its columns (rows) that hold the range's tiles
    for a, b in ((x0, x1), (y0, y1)):
        cells = [coarse_quarter(x) for x in range(a, b)]
        spans.append([[c for q, c in cells if q == k] for k in (0, 1)])
    rects = []
    for qy in (0, 1):
        for qx in (0, 1):
            xs, ys = spans[0][qx], spans[1][qy]
            if xs and ys:
                origin = (qx * stride[0] + xs[0], qy * stride[1] + ys[0])
                rects.append((*origin, xs[-1] + 1 - xs[0], ys[-1] + 1 - ys[0]))
    return tuple(rects)
