"""The shading after the trace pass drawn by depth (gpu/passes.py ``_shade_by_depth``): the
hits go into the depth buffer, then the sky's pixels run the sky's code alone and the hits
the shading's (with shadow rays per block, or each pixel its own), so that llvmpipe skips
groups of pixels with nothing of a pass's kind. Each pixel is drawn by exactly one of the
two passes, and the image is the one a single shading pass over every pixel makes, bit for
bit."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu import passes
from krsview.gpu.context import behind_mark
from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers, read_plane

from .test_passes import SIZE, scene_of

PLANES = ("color", "depth", "normal", "iterations", "hit")


def one_pass(image: PassImage, outline, y0: int, rows: int, shading: str) -> None:
    """The shading as it was: one pass over every pixel of the rows, no depth test."""
    image._fill(image._programs[shading], image.output, image.size, y0, rows)


def drawn(renderer, targets, scene, ratio: int = 2, bands: int = 1) -> PassImage:
    with renderer.current():
        image = PassImage(renderer, targets, scene, SIZE, scene.geometry(), ratio)
        image.draw_all(bands)
        return image


@pytest.mark.parametrize("name, ratio", [("tree", 2), ("grove", 2), ("forest", 2), ("tree", 1)])
def test_the_image_is_the_one_pass_image(renderer, targets, monkeypatch, name, ratio):
    """Split by depth, in one band or in bands of rows, the image is the one-pass image;
    negative control: the sky's pass drawn again without the depth test replaces exactly
    the hits."""
    scene = scene_of(name)
    split = drawn(renderer, targets, scene, ratio)
    banded = drawn(renderer, targets, scene, ratio, bands=3)
    with renderer.current():
        got, bands = (read_buffers(i.output, *SIZE) for i in (split, banded))
        with monkeypatch.context() as m:
            m.setattr(PassImage, "_shade_by_depth", one_pass)
            want = read_buffers(drawn(renderer, targets, scene, ratio).output, *SIZE)
        for plane in PLANES:
            assert np.array_equal(getattr(got, plane), getattr(want, plane)), plane
            assert np.array_equal(getattr(bands, plane), getattr(want, plane)), plane
        split._fill(split._programs["sky"], split.output, SIZE, 0, SIZE[1])
        skied = read_buffers(split.output, *SIZE)
    off = np.abs(skied.color - want.color).max(-1) > 0
    assert 0.05 < want.hit.mean() < 0.95 and np.array_equal(off, want.hit)


@pytest.mark.parametrize("ratio, shading", [(2, "shade"), (1, "shadows+shade")])
def test_each_pixel_is_shaded_by_one_pass(renderer, targets, monkeypatch, ratio, shading):
    """Fragments each pass keeps (an occlusion query): the hits' depth every pixel, the sky's
    pass the pixels the trace pass found no hit for, the shading the others (counted from
    the trace pass's target, read back); negative control: with the two depth tests
    swapped, the sky's pass keeps the hits and the shading the sky."""
    tree = scene_of("tree")
    fill = PassImage._fill
    kept: dict[str, int] = {}

    def counted(image, prog, target, size, y0, rows, origin=(0, 0)):
        name = next(k for k, p in image._programs.items() if p is prog)
        query = renderer.ctx.query(samples=True)
        with query:
            fill(image, prog, target, size, y0, rows, origin)
        kept[name] = query.samples

    monkeypatch.setattr(PassImage, "_fill", counted)
    w, h = SIZE
    for swapped in (False, True):
        if swapped:
            monkeypatch.setattr(  # the sky's and the shading's depth tests swapped
                passes,
                "behind_mark",
                lambda ctx, mark, draw, marked: behind_mark(ctx, mark, marked, draw),
            )
        image = drawn(renderer, targets, tree, ratio)
        with renderer.current():
            hits = int((read_plane(image.traced, 0, *SIZE)[..., 3] > 0.5).sum())
        assert 0 < hits < w * h and kept["hits"] == w * h
        sky, shade = (hits, w * h - hits) if swapped else (w * h - hits, hits)
        assert (kept["sky"], kept[shading]) == (sky, shade), swapped
