"""The shadow blocks' visibility pass drawn only on the blocks with a hit (gpu/passes.py,
``_visibility``): their rows cleared to none, then the pass behind a mark of the blocks with a
hit, so that llvmpipe, which skips a group of pixels only where an early depth test fails for
all of it, never runs shadow-ray code over groups of sky blocks. The blocks and the images
are those of the pass drawn over every block, bit for bit, and only the blocks with a hit run
it."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu import passes
from krsview.gpu.context import behind_mark
from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers, read_plane

from .test_passes import SIZE, scene_of

PLANES = ("color", "depth", "normal", "iterations", "hit")


def every_block(image: PassImage, prog, y0: int, rows: int) -> None:
    """The visibility pass as it was: every block of the rows, no clear, no depth test."""
    image._fill(prog, image.coarse_target(), image.coarse, y0, rows, image.origin)


def drawn(renderer, targets, scene, size, ratio, bands=1):
    """``scene``'s image in passes: its planes and its blocks' (visibilities, depths)."""
    with renderer.current():
        image = PassImage(renderer, targets, scene, size, scene.geometry(), ratio)
        out = read_buffers(image.draw_all(bands), *size)
        return out, blocks_of(image)


def blocks_of(image: PassImage) -> np.ndarray:
    """The coarse image's visibilities and depths, (rows, columns, 8)."""
    (w, h), target = image.coarse, image.coarse_target()
    return np.concatenate(
        [
            np.frombuffer(
                target.read((*image.origin, w, h), attachment=k, components=4, dtype="f4"),
                np.float32,
            ).reshape(h, w, 4)
            for k in (0, 1)
        ],
        axis=-1,
    )


@pytest.mark.parametrize(
    "name, size, ratio",
    [("grove", SIZE, 2), ("tree", SIZE, 2), ("forest", SIZE, 2), ("tree", (269, 151), 3)],
)
def test_the_images_are_those_of_every_block_drawn(
    renderer, targets, monkeypatch, name, size, ratio
):
    """In one band or in bands, the blocks and the image are those of the pass over every
    block (drawn after another scene's image in the same targets: no block keeps it);
    negative control: the pass drawn on the sky blocks alone leaves every block with a hit
    without a visibility."""
    scene = scene_of(name)
    got = [drawn(renderer, targets, scene, size, ratio, bands) for bands in (1, 3)]
    with monkeypatch.context() as m:
        m.setattr(PassImage, "_visibility", every_block)
        want, want_blocks = drawn(renderer, targets, scene, size, ratio)
    for image, blocks in got:
        assert np.array_equal(blocks, want_blocks)
        for plane in PLANES:
            assert np.array_equal(getattr(image, plane), getattr(want, plane)), plane
    with monkeypatch.context() as m:  # the negative control
        m.setattr(
            passes,
            "behind_mark",
            lambda ctx, mark, draw, marked: behind_mark(ctx, mark, marked, draw),
        )
        _, swapped = drawn(renderer, targets, scene, size, ratio)
    hit = want_blocks[..., 4] >= 0
    assert 0.05 < hit.mean() < 0.95
    assert (swapped[hit][:, 4] == -1).all() and np.array_equal(swapped[~hit], want_blocks[~hit])


def test_only_the_blocks_with_a_hit_run_the_visibility_pass(renderer, targets, monkeypatch):
    """Fragments each pass keeps (an occlusion query): the blocks' mark every block, the
    visibility pass the blocks with a hit in the trace pass's target (read back, counted
    2 × 2 by NumPy), fewer than all."""
    tree = scene_of("tree")
    kept: list[tuple[str, int]] = []
    fill = PassImage._fill

    def counted(image, prog, target, size, y0, rows, origin=(0, 0)):
        name = next(k for k, p in image._programs.items() if p is prog)
        query = renderer.ctx.query(samples=True)
        with query:
            fill(image, prog, target, size, y0, rows, origin)
        kept.append((name, query.samples))

    monkeypatch.setattr(PassImage, "_fill", counted)
    with renderer.current():
        image = PassImage(renderer, targets, tree, SIZE, tree.geometry(), 2)
        image.draw_all()
        hit = read_plane(image.traced, 0, *SIZE)[..., 3] > 0.5
    (w, h), blocks = image.coarse, hit.reshape(SIZE[1] // 2, 2, SIZE[0] // 2, 2).any((1, 3))
    assert kept[:2] == [("hits", w * h), ("visibility", int(blocks.sum()))]
    assert 0 < blocks.sum() < w * h
