"""Every preset: the GLSL tracer agrees with the float64 NumPy reference pixel by pixel."""
from __future__ import annotations

import pytest

from krsview.reference import render_reference
from krsview.scene import load_scene

from .conftest import assert_finite, check_against_reference, preset_paths

W, H = 160, 120


@pytest.mark.parametrize("path", preset_paths(), ids=lambda p: p.stem)
def test_preset_matches_reference(renderer, path):
    scene = load_scene(path)
    gpu = renderer.render(scene, W, H)
    ref = render_reference(scene, W, H)
    assert_finite(gpu, scene.render.max_iterations)
    assert ref.hit.mean() > 0.02, "the preset's camera sees (almost) nothing"
    check_against_reference(path.stem, gpu, ref)
