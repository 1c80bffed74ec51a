"""Moving frames at least 240 pixels wide share a shadow ray per 3 × 3 pixels
(viewer/adaptive.py ``moving_ratio``): they light as an image with a shadow ray per pixel
does, to 1/255 of the mean colour over the hits, at the preset's view and inside tree's crown
(where the blocks' rays cost most); and the viewer draws its moving frames so."""

from __future__ import annotations

import shutil
from dataclasses import replace

import numpy as np
import pytest

from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers
from krsview.scene.presets import resolve

from .test_passes import scene_of

CROWN = ((-0.27, 3.02, -1.06), (-0.30, 3.10, -0.06))  # tree after 100 turns of W from the preset


def lit(renderer, targets, scene, size, ratio: int) -> tuple[np.ndarray, np.ndarray]:
    """``scene``'s image at ``size`` in passes of ``ratio``: the colour and the hits."""
    with renderer.current():
        image = PassImage(renderer, targets, scene, size, scene.geometry(), ratio)
        frame = read_buffers(image.draw_all(), *size)
    return frame.color, frame.hit


@pytest.mark.parametrize(
    "name, camera, size",
    [("tree", None, (240, 135)), ("grove", None, (240, 135)), ("tree", CROWN, (320, 180))],
)
def test_blocks_of_3_light_as_a_ray_per_pixel(renderer, targets, name, camera, size):
    """Over the hits, the mean colour with 3 × 3 blocks is within 1/255 of the image with a
    shadow ray per pixel; negative control: the image without shadows is not."""
    scene = scene_of(name)
    if camera:
        scene = replace(scene, camera=replace(scene.camera, position=camera[0], target=camera[1]))
    exact, hit = lit(renderer, targets, scene, size, 1)
    blocks, hit3 = lit(renderer, targets, scene, size, 3)
    plain = replace(scene, effects=[e for e in scene.effects if e != "soft_shadows"])
    unshadowed, _ = lit(renderer, targets, plain, size, 0)
    assert np.array_equal(hit, hit3) and hit.mean() > 0.1  # the same tracing
    want = exact[hit].mean(0)
    assert np.abs(blocks[hit].mean(0) - want).max() < 1 / 255
    assert np.abs(unshadowed[hit].mean(0) - want).max() > 4 / 255


def test_the_viewer_moves_with_blocks_of_3_where_wide_enough(display, tmp_path):
    """In a 320 × 180 window, moving frames of 240 pixels share a shadow ray per 3 × 3 pixels,
    and those of 160 per 2 × 2 (the negative control: too few blocks across); the still
    image keeps the scene's 2 × 2."""
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(320, 180), hud=False)
    try:
        a = v.frames.adaptive
        a.target_fps = 1000.0  # every frame over budget: the scale stays at the floor
        for scale, side in ((0.75, 3), (0.5, 2)):
            a.min_scale = a.scale = scale
            v.input.key("W", True)
            v.step(0.05)
            v.input.key("W", False)
            state = v.frames.frame_state()
            assert (state.state, state.size, state.shadows) == ("moving", a.moving_size(), side)
            assert state.size[0] == 320 * scale
        a.target_fps = 30.0
        for _ in range(400):
            v.step(0.02)
            if v.frames.refined:
                break
        still = v.frames.frame_state()
        assert (still.state, still.size, still.shadows) == ("still", (320, 180), 2)
    finally:
        v.close()
