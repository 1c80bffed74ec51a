"""The refinement's full-resolution primary image (issue 28 §5, issue 27 §4): traced alone and
shaded with the shadow blocks of the image before it, it lights as the still image that
follows (no jump from lit to shadowed); the still image adds its shadow rays to that
tracing without a second trace pass; a scene without shared shadow rays has no such step."""

from __future__ import annotations

import numpy as np
import pytest

import krsview
from krsview.frame import Frame
from krsview.gpu.passes import PassImage
from krsview.gpu.renderer import read_buffers
from krsview.viewer.adaptive import AdaptiveResolution
from krsview.viewer.frames import Frames

FULL = (320, 180)
MOVING = (96, 54)  # the last moving frame's size (0.3 of the window's side)


def scene_of(name: str) -> krsview.Scene:
    return krsview.configure(krsview.load(name), prepass=4)


def luminance(frame: Frame) -> np.ndarray:
    return frame.color.mean(-1)


def first_and_final(renderer, targets, scene, visibility: float | None = None):
    """The moving frame, then the window-size primary image shaded with its blocks (their
    visibilities all set to ``visibility`` where given), then the still image reusing that
    tracing: (primary, final, the still image traced anew) as Frames."""
    geometry = scene.geometry()
    with renderer.current():
        moving = PassImage(renderer, targets, scene, MOVING, geometry, 2)
        moving.draw_all()
        if visibility is not None:
            vis = moving.coarse_target().color_attachments[0]
            vis.write(
                np.full((*moving.coarse[::-1], 4), visibility, np.float32).tobytes(),
                viewport=(*moving.origin, *moving.coarse),
            )
        primary = PassImage(renderer, targets, scene, FULL, geometry, 2, blocks=moving)
        assert [p[0] for p in primary.passes] == ["trace", "shade"]
        first = read_buffers(primary.draw_all(), *FULL)
        final = PassImage(renderer, targets, scene, FULL, geometry, 2, traced=primary)
        assert [p[0] for p in final.passes] == ["visibility", "shade"]  # no second trace
        last = read_buffers(final.draw_all(), *FULL)
        anew = PassImage(renderer, targets, scene, FULL, geometry, 2)
        return first, last, read_buffers(anew.draw_all(), *FULL)


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_the_primary_image_lights_as_the_still_image_after_it(renderer, targets, name):
    """Over the hits, the mean colour within 3/255 of the still image's, and under 3.5 % of
    them (block edges, at a coarser image's blocks) lit (+0.1 in luminance) where the still
    image is in shadow; with the blocks' visibility set to 1 (the moving frames' shading
    before they had shadows: 5.8–13/255 off, 9–17 % lit) neither holds."""
    scene = scene_of(name)
    first, final, anew = first_and_final(renderer, targets, scene)
    hit = final.hit
    assert hit.mean() > 0.1 and np.array_equal(first.hit, hit)
    # the still image reusing the primary image's tracing is the one traced anew, bit for bit
    assert np.array_equal(final.color, anew.color) and np.array_equal(final.depth, anew.depth)

    def jumps(f: Frame) -> tuple[float, float]:
        mean = np.abs(f.color[hit].mean(0) - final.color[hit].mean(0)).max()
        lit = ((luminance(f) - luminance(final)) > 0.1)[hit].mean()
        return mean, lit

    mean, lit = jumps(first)
    assert mean < 3 / 255 and lit < 0.035, (mean, lit)
    unshadowed, _, _ = first_and_final(renderer, targets, scene, visibility=1.0)
    mean, lit = jumps(unshadowed)  # negative control: no shadows from the blocks
    assert mean > 5 / 255 and lit > 0.07, (mean, lit)


def refine(renderer, scene) -> tuple[list, list[tuple[int, str]]]:
    """Frames after a stop: a moving frame at 0.3 of the window's side, then the refinement to
    the still image; its steps and the passes drawn, (step, pass name)."""
    drawn: list[tuple[int, str]] = []
    draw = PassImage.draw

    def recording(image, name, y0, rows):
        if y0 == 0:
            drawn.append((frames.refinement.k if frames.refinement else -1, name))
        draw(image, name, y0, rows)

    geometry = scene.geometry()
    with renderer.current(), pytest.MonkeyPatch.context() as mp:
        frames = Frames(renderer.ctx, renderer, AdaptiveResolution(FULL, scale=0.3))
        mp.setattr(PassImage, "draw", recording)
        frames.trace(scene, geometry)  # the moving frame
        drawn.clear()
        for _ in range(500):
            if frames.refined:
                break
            frames.trace(scene, geometry)
    assert frames.refined and frames.shown.size == FULL
    return frames.refinement.steps, drawn


def test_the_window_size_primary_step_is_followed_by_its_shadows_without_a_trace(renderer):
    steps, drawn = refine(renderer, scene_of("tree"))
    k = next(i for i, s in enumerate(steps) if s.primary)
    assert steps[k].scale == 1.0 and k == len(steps) - 2  # the still image comes next
    assert [name for j, name in drawn if j == k] == ["trace", "shade"]
    assert [name for j, name in drawn if j == k + 1] == ["visibility", "shade"]
    assert sum(name == "trace" for _, name in drawn) == k + 1  # one per traced size
    # negative control: a scene without shadows has no primary step, one pass per image
    plain = scene_of("tree").with_effects(["sky"])
    steps, drawn = refine(renderer, plain)
    assert not any(s.primary for s in steps) and steps[-1].scale == 1.0
    assert {name for _, name in drawn} == {"render"} and len(drawn) == len(steps)


def test_the_hud_says_the_primary_images_shadows_come_next(renderer):
    from krsview.viewer.frames import FrameState

    state = FrameState("refining", FULL, FULL, 0.1, (2, 3), 2, blocks_of=(160, 90))
    assert state.text() == "refining 2/3, shadows next: 320×180 (100% of the window's width)"
    assert state.timing() == "traced in 100.0 ms, shadows per 2×2 px of the 160×90 image"
    plain = FrameState("refining", FULL, FULL, 0.1, (2, 3), 2)  # control: its own blocks
    assert plain.text() == "refining 2/3: 320×180 (100% of the window's width)"
    assert plain.timing() == "traced in 100.0 ms, shadows per 2×2 px"
