"""The pre-pass cone stops at a blocked probe PREPASS_STOP times its own width, not at its
width (prepass.glsl): in one coarse pass the same probes as before, continued, so every tile's
free distance is at least what it was and most tiles with geometry get closer to it; with two
passes the rays start nearer the surface and take fewer steps, and the oracle still certifies
the image hole-free. Negative control: the cone that stops at its width (the shader before) is
not closer than itself."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.constants import PREPASS_STOP
from krsview.gpu.renderer import Renderer
from krsview.oracle.certify import count_errors
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import broken_shaders

W, H = 96, 54
STOP = "if (s <= PREPASS_STOP * t * sigma) break;"


def closer(new: np.ndarray, old: np.ndarray, far: float) -> bool:
    """Whether ``new`` free distances continue ``old``'s cones: none nearer (float32 rounding
    of the stored value aside) and most tiles that see geometry further."""
    seen = old <= far
    return bool((new >= old * (1 - 2e-6)).all() and (new[seen] > old[seen]).mean() > 0.5)


@pytest.fixture(scope="module")
def at_width(tmp_path_factory):
    """A renderer whose cones stop at their width, as before PREPASS_STOP."""
    shaders = broken_shaders(
        tmp_path_factory.mktemp("stop"), "prepass.glsl", STOP, "if (s <= t * sigma) break;"
    )
    return Renderer(shader_dir=shaders)


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_cones_get_closer_than_their_width_and_skip_no_surface(renderer, at_width, name):
    assert 0 < PREPASS_STOP < 1
    scene = load_scene(resolve(name))
    scene = replace(scene, render=replace(scene.render, prepass=4))
    one = replace(scene, render=replace(scene.render, prepass_levels=1))
    used = len(getattr(scene.geometry(), "parts", [None]))  # components: the rest are 0
    new = renderer.free_distances(one, W, H)[..., :used]
    old = at_width.free_distances(one, W, H)[..., :used]
    far = scene.render.max_distance
    assert closer(new, old, far)
    assert not closer(old, old, far)  # negative control: the cone at its width
    img, before = renderer.render(scene, W, H), at_width.render(scene, W, H)
    assert img.iterations.mean() < 0.9 * before.iterations.mean()
    assert (img.hit != before.hit).mean() < 0.01  # grazing rays on outlines alone
    counts = count_errors(scene, renderer.render(scene, 48, 27), arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
