"""The shadow blocks' coarse image lies on a corner of llvmpipe's bins (gpu/passes.py,
bin_origin), so that its pass spreads over both threads: the images are the same bit for bit
as with the image at its target's corner, and the shading finds the blocks where the
visibility pass wrote them."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu import passes
from krsview.gpu.bins import BIN, bin_origin
from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers

from .test_passes import scene_of

MOVING = (269, 151)  # the flight's moving frame: 3 × 3 blocks, a coarse image of 90 × 51
FULL = (320, 180)


def bins_across(origin: int, n: int) -> list[int]:
    """Pixels of each bin that an image of ``n`` pixels from ``origin`` covers, along one
    axis."""
    cover: dict[int, int] = {}
    for x in range(origin, origin + n):
        cover[x // BIN] = cover.get(x // BIN, 0) + 1
    return list(cover.values())


@pytest.mark.parametrize("n", [2, 26, 45, 51, 64, 90, 127, 128, 129, 160, 480])
def test_an_image_within_two_bins_is_split_evenly_across_a_bin_corner(n):
    """Within 2 × 2 bins, each axis lies in two bins holding as many of its pixels (within
    one), so both threads get work; larger, the image starts at 0 (its bins full but the
    last); at 0 (the control) a 90-pixel axis lies 64 and 26 in two bins, 45 in one."""
    origin = bin_origin((n, 45))
    assert min(origin) >= 0 and max(origin) < BIN
    if n <= 2 * BIN:
        for start, length in zip(origin, (n, 45)):
            cover = bins_across(start, length)
            assert len(cover) == 2 and abs(cover[0] - cover[1]) <= 1, cover
    else:
        assert origin == (0, 0)
    assert bins_across(0, 90) == [64, 26] and bins_across(0, 45) == [45]


def images(renderer, targets, scene, moved: bool):
    """The moving frame at MOVING, then a window-size primary image shaded with its blocks:
    each image's planes (``moved``: the coarse images at bin_origin, else at the corner)."""
    geometry = scene.geometry()
    with renderer.current():
        moving = PassImage(renderer, targets, scene, MOVING, geometry, 3)
        first = read_buffers(moving.draw_all(), *MOVING)
        assert (moving.origin != (0, 0)) == moved
        primary = PassImage(renderer, targets, scene, FULL, geometry, 2, blocks=moving)
        return first, read_buffers(primary.draw_all(), *FULL)


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_the_images_are_those_of_the_coarse_image_at_the_corner(
    renderer, targets, monkeypatch, name
):
    """Moved to a bin corner or not, the moving frame and the primary image that takes its
    blocks are the same bit for bit; negative control: the shading reading the blocks at
    the target's corner while they lie at bin_origin is off over the hits."""
    scene = scene_of(name)
    moved = images(renderer, targets, scene, True)
    with monkeypatch.context() as m:
        m.setattr(passes, "bin_origin", lambda size: (0, 0))
        still = images(renderer, targets, scene, False)
    for got, want in zip(moved, still):
        for plane in ("color", "depth", "normal", "iterations", "hit"):
            assert np.array_equal(getattr(got, plane), getattr(want, plane)), plane
    with renderer.current():  # the negative control
        image = PassImage(renderer, targets, scene, MOVING, scene.geometry(), 3)
        image.prepare()
        for shade in ("shade", "outline"):
            image._programs[shade]["u_coarse_origin"].value = (0, 0)
        for name_, _, rows in image.passes:
            image.draw(name_, 0, rows)
        off = read_buffers(image.output, *MOVING)
    want = moved[0]
    diff = np.abs(off.color - want.color).max(-1)[want.hit]
    assert (diff > 1e-3).mean() > 0.05
