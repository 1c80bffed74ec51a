"""The blocks' shadow rays in two passes (gpu/passes.py, coarse_visibility.frag): a pass over
the blocks writes each one's depth and lists those whose nearest hit faces a light, a list
per llvmpipe bin; only the listed blocks run the rays pass, packed two bins (128 pixels)
wide in whole 4 × 2 groups, and each gets a visibility for exactly the lights its hit
faces."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers

from .test_passes import SIZE, scene_of


def coarse_planes(image: PassImage) -> tuple[np.ndarray, np.ndarray]:
    """The blocks' visibilities and depths (coarse rows in GL order)."""
    cw, ch = image.coarse
    target = image.coarse_target()
    return tuple(
        np.frombuffer(
            target.read((*image.origin, cw, ch), attachment=k, components=4, dtype="f4"),
            np.float32,
        ).reshape(ch, cw, 4)
        for k in (0, 1)
    )


def blocks_rule(image: PassImage) -> tuple[np.ndarray, np.ndarray]:
    """NumPy's blocks from the trace pass's targets: each 2 × 2 block's nearest hit's depth
    (−1: none) and, per light, whether that hit faces it (coarse rows in GL order)."""
    (w, h), (cw, ch) = image.size, image.coarse
    hit = np.frombuffer(image.traced.read(components=4, dtype="f4"), np.float32)
    nt = np.frombuffer(image.traced.read(attachment=1, components=4, dtype="f4"), np.float32)
    hit, nt = hit.reshape(h, w, 4)[..., 3] > 0.5, nt.reshape(h, w, 4)
    prog = image._programs["visibility"]
    k = prog["u_light_count"].value
    light_dir = np.asarray(prog["u_light_dir"].value, np.float32)[:k]
    depth = np.full((ch, cw), -1.0, np.float32)
    facing = np.zeros((ch, cw, 4), bool)
    for by in range(ch):
        for bx in range(cw):
            q = [(y, x) for y in (2 * by, 2 * by + 1) for x in (2 * bx, 2 * bx + 1)]
            q = [(y, x) for y, x in q if y < h and x < w and hit[y, x]]
            if q:
                y, x = min(q, key=lambda yx: nt[yx][3])  # the first of equals, as the pass
                depth[by, bx] = nt[y, x, 3]
                facing[by, bx, :k] = nt[y, x, :3] @ light_dir.T > 0.0
    return depth, facing


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_only_blocks_facing_a_light_trace_rays(renderer, targets, monkeypatch, name):
    scene = scene_of(name)
    drawn: dict[str, tuple[int, int]] = {}
    fill = PassImage._fill

    def counted(image, prog, target, size, y0, rows, origin=(0, 0)):
        query = renderer.ctx.query(samples=True)
        with query:
            fill(image, prog, target, size, y0, rows, origin)
        drawn[next(k for k, p in image._programs.items() if p is prog)] = rows, query.samples

    monkeypatch.setattr(PassImage, "_fill", counted)
    with renderer.current():
        image = PassImage(renderer, targets, scene, SIZE, scene.geometry(), 2)
        whole = read_buffers(image.draw_all(), *SIZE)
        vis, depth = coarse_planes(image)
        want_depth, facing = blocks_rule(image)
        listed = int(facing.any(-1).sum())
        assert 0 < listed < facing.shape[0] * facing.shape[1]
        rows = 2 * -(-listed // 256)  # two bins across in 4 × 2 groups
        assert drawn["rays"] == (rows, listed)  # a fragment per listed block
        assert np.array_equal(depth[..., 0], want_depth)
        assert np.array_equal(vis >= 0.0, facing) and (vis[facing] <= 1.0).all()
        # negative control: the list pass alone leaves no block a visibility, so every hit
        # facing a light is an outline pixel, lit by its own ray: another image
        across, bins = image.coarse_bins()
        lists = np.frombuffer(targets.block_list(bins).read(), np.uint32)
        targets.block_list(bins).write(bytes(4 * bins))
        prog, size = image._programs["visibility"], image.coarse
        image._fill(prog, image.coarse_target(), size, 0, size[1], image.origin)
        assert (coarse_planes(image)[0] < 0.0).all()
        image.draw("shade", 0, SIZE[1])
        alone = read_buffers(image.output, *SIZE)
    assert not np.array_equal(alone.color, whole.color)
    # each bin listed its own blocks' nearest hits, each once: together, the blocks facing
    # a light (coarse target coordinates: the blocks at the coarse image's origin)
    (w, _), (ox, oy), side = SIZE, image.origin, 64
    got = []
    for b in range(bins):
        hits = lists[bins + b * side * side :][: lists[b]]
        bx, by = hits % w // 2 + ox, hits // w // 2 + oy
        assert ((by // side * across + bx // side) == b).all(), b
        got += zip((by - oy).tolist(), (bx - ox).tolist())
    assert len(got) == len(set(got)) and set(got) == set(zip(*np.nonzero(facing.any(-1))))
