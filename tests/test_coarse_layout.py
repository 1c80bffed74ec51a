"""A coarse pass stores its tiles as four quarter images, each on a corner of llvmpipe's bins
(prepass.glsl's coarse_texel, gpu/coarse.py), so that the
threads, which take a bin each, share the cones. Checked against brute force: every tile gets
a texel of its own inside its quarter's rectangle, a band of tiles is drawn by the rectangles
that hold exactly its texels, and an image drawn in bands equals the one drawn whole.
Negative controls: quarters laid over each other put two tiles on one texel; bands that leave
out a quarter change the image. The GPU reads the layout as Python writes it:
tests/test_prepass.py compares each finer tile's start with its coarser tile's free distance,
read through the layout."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.constants import PREPASS_BLOCK
from krsview.gpu import renderer as renderer_module
from krsview.gpu.bins import BIN
from krsview.gpu.coarse import coarse_layout, coarse_quarter, quarters
from krsview.gpu.renderer import Renderer
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders

SIZES = [(1, 1), (2, 1), (3, 5), (9, 3), (20, 12), (80, 45), (121, 67), (480, 270)]


def texels(columns: int, rows: int, stride: tuple[int, int]) -> dict[tuple[int, int], tuple]:
    """Tile (x, y) → its texel, from coarse_quarter and the quarters' stride."""
    out = {}
    for y in range(rows):
        for x in range(columns):
            (qx, cx), (qy, cy) = coarse_quarter(x), coarse_quarter(y)
            out[x, y] = (qx * stride[0] + cx, qy * stride[1] + cy)
    return out


def inside(rects) -> set[tuple[int, int]]:
    return {(x, y) for rx, ry, w, h in rects for x in range(rx, rx + w) for y in range(ry, ry + h)}


def distinct_and_inside(where: dict, size: tuple[int, int]) -> bool:
    cells = list(where.values())
    return len(set(cells)) == len(cells) and all(
        0 <= x < size[0] and 0 <= y < size[1] for x, y in cells
    )


@pytest.mark.parametrize("columns, rows", SIZES)
def test_each_tile_has_a_texel_of_its_own_and_the_quarters_start_on_bins(columns, rows):
    stride, size = coarse_layout(columns, rows)
    where = texels(columns, rows, stride)
    assert distinct_and_inside(where, size)
    rects = list(quarters(columns, rows, None))
    assert inside(rects) == set(where.values())  # the draws cover the tiles and nothing else
    assert all(x % BIN == 0 for x, _, _, _ in rects if x >= stride[0])
    assert all(y % BIN == 0 for _, y, _, _ in rects if y >= stride[1])
    if min(columns, rows) > PREPASS_BLOCK:  # two blocks each way: four quarters, four bins
        assert len({(x // BIN, y // BIN) for x, y, _, _ in rects}) == 4
    # negative control: with the quarters laid over each other (no stride), tiles collide
    overlaid = {k: (v[0] % stride[0], v[1] % stride[1]) for k, v in where.items()}
    assert max(columns, rows) <= PREPASS_BLOCK or not distinct_and_inside(overlaid, size)


@pytest.mark.parametrize("columns, rows", [(80, 45), (121, 67), (9, 3)])
def test_a_band_of_tiles_is_drawn_by_exactly_its_texels(columns, rows):
    stride, _ = coarse_layout(columns, rows)
    where = texels(columns, rows, stride)
    rng = np.random.default_rng(7)
    for _ in range(20):
        x0, x1 = sorted(rng.integers(0, columns + 1, 2))
        y0, y1 = sorted(rng.integers(0, rows + 1, 2))
        band = {where[x, y] for x in range(x0, x1) for y in range(y0, y1)}
        assert inside(quarters(columns, rows, (x0, y0, x1, y1))) == band


def test_the_prepass_drawn_in_bands_draws_every_tile(renderer, monkeypatch):
    """Bands of rows that start off the coarse grids (progress): each coarse pass draws the
    quarters' parts of the band's tiles, and the image equals the one drawn whole, after a
    view of the sky has left other distances in the targets. Negative control: bands that
    leave out a quarter's part keep those distances, and the image differs."""
    scene = load_scene(resolve("tree"))
    scene = replace(scene, render=replace(scene.render, prepass=4, prepass_levels=2))
    sky = replace(scene, camera=replace(scene.camera, target=(0.0, 2.4, -20.0)))
    w, h = 150, 83
    whole = renderer.render(scene, w, h)

    def banded():
        assert not renderer.render(sky, w, h).hit.any()  # the targets now hold the sky's
        return renderer.render(scene, w, h, progress=lambda done, total: None)

    fields = ("color", "depth", "normal", "iterations", "hit")
    assert all(np.array_equal(getattr(whole, f), getattr(banded(), f)) for f in fields)
    assert whole.hit.any()
    monkeypatch.setattr(renderer_module, "quarters", lambda *a: quarters(*a)[:-1])
    assert not np.array_equal(whole.iterations, banded().iterations)


@pytest.mark.parametrize("tile, size", [(3, (61, 35)), (5, (77, 44)), (4, (150, 83))])
def test_each_pixel_starts_from_its_own_tile(renderer, tmp_path, tile, size):
    """Each pixel reads its tile's free distance through the layout (ray_start): the pixels
    the free tiles' pass wrote alone (the tracing variant counts 1000 more iterations) are
    exactly those whose tile, pixel // tile in NumPy, is free past the far limit, for tiles
    that are no power of two and sizes that are no multiple of them."""
    scene = load_scene(resolve("tree")).edit(("tree", "levels"), 3)
    scene = scene.edit(("render", "prepass"), tile).edit(("render", "shadow_block"), 1)
    traced = "bool hit = trace_ray(vec3r(0.0), dir, start, t, iterations, slots);"
    marked = Renderer(
        shader_dir=broken_shaders(
            tmp_path, "render.frag", traced, traced + "\n iterations += 1000;"
        )
    )
    w, h = size
    skipped = marked.render(scene, w, h).iterations < 1000
    free = renderer.free_distances(scene, w, h)[..., 0] > scene.render.max_distance
    rows = np.arange(h) // tile  # tiles count from the top row, as the image's rows
    assert np.array_equal(skipped, free[rows][:, np.arange(w) // tile])
    assert 0.3 < skipped.mean() < 1.0
    # negative controls: tiles counted from the bottom row (these heights are no multiple of
    # the tile), and the pixel's tile one column off, are other masks
    assert not np.array_equal(
        skipped, free[len(free) - 1 - (h - 1 - np.arange(h)) // tile][:, np.arange(w) // tile]
    )
    assert not np.array_equal(skipped, free[rows][:, (np.arange(w) + tile) // tile % free.shape[1]])
