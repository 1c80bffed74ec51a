"""Where a pass lies on llvmpipe's bins: llvmpipe gives each BIN × BIN pixels of a pass (a bin)
to one of its threads and runs a group of 4 × 2 pixels in lockstep, so a small image placed on
one bin, or a list of work spread over a full-width image, keeps a thread idle
(docs/speed.md). The coarse passes' quarters (coarse.py) follow the same bins."""

from __future__ import annotations

BIN = 64  # llvmpipe gives each BIN × BIN pixels of a pass (a bin) to one of its threads


def bin_origin(size: tuple[int, int]) -> tuple[int, int]:
    """Where a coarse image of ``size`` starts in its target: one within 2 × 2 of llvmpipe's
    bins with its middle on a bin corner, so that its work lies in four even quarters, not
    in one bin or a bin and a sliver (the visibility pass of a 269 × 151 frame on llvmpipe's
    two threads: 0.84-0.91× the wall time); a larger one at 0, where more, smaller bins
    measured slower (480 × 270: 1.05×)."""
    if max(size) > 2 * BIN:
        return (0, 0)
    return ((-(size[0] // 2)) % BIN, (-(size[1] // 2)) % BIN)


def packed(size: tuple[int, int], listed: int) -> tuple[int, int]:
    """The image of a pass over ``listed`` entries of a list of an image of ``size``'s pixels
    or blocks (the outline pixels, the blocks' rays), drawn into ``Targets.lanes``: the
    fewest whole pairs of llvmpipe's bins across that hold them in the image's rows, so that
    its two threads get as many bins (tree's and grove's outline passes: 0.79-0.93× the
    wall time of a full-width pass), or the image's width where that is narrower; filled by
    4 × 2 groups of lanes, eight consecutive entries each (shadows.glsl, packed_index: a
    group's rays are neighbours; tree's outline pass 0.82× the CPU of rows filled in turn)."""
    w, h = -(-size[0] // 4) * 4, -(-size[1] // 2) * 2
    pairs = max(1, -(-listed // (2 * BIN * h)))
    width = min(2 * BIN * pairs, w)
    rows = 2 * -(-listed // (2 * width))
    if rows > h:
        raise ValueError(f"{listed} entries in groups of lanes: more than the {size} image's")
    return width, rows
