"""Every preset: the GLSL tracer agrees with the float64 NumPy reference pixel by pixel
(`make test` runs a slice, a preset of each kind; KRSVIEW_SWEEP=full every preset)."""

from __future__ import annotations

from dataclasses import replace

import pytest

from krsview.bench.metrics import gpu_reference_agreement
from krsview.compile.camera import view_of
from krsview.reference import render_reference
from krsview.scene import load_scene

from .conftest import (
    assert_finite,
    check_against_reference,
    fold_ties,
    per_pixel,
    preset_paths,
    sweep,
)

W, H = 160, 120


# CI's slice: a scene of each kind (module doc); KRSVIEW_SWEEP=full adds the rest
SLICE = {"tree", "grove", "grass", "rock", "sierpinski", "palm", "shell", "palm-curl", "tree-wind"}


@pytest.mark.parametrize(
    "path", sweep(preset_paths(), SLICE, name=lambda p: p.stem), ids=lambda p: p.stem
)
def test_preset_matches_reference(renderer, path):
    """The fragment tracer against the reference, and the same with the low-resolution
    pre-pass [issue 17 §2]. Without it both take the same steps, so every tolerance holds.
    With it a ray starts from its tile's free distance and steps elsewhere: it stops at
    another point within ε of the surface (binary tracing: 2 ε), on sub-pixel detail often
    of another kernel, so normals and colours are not compared; away from outlines every
    hit state must still agree, and on outlines grazing rays may flip (≤ 1.5 %). Every
    level is drawn: the level of detail's cut, a float comparison, may fall differently in
    float32 and float64 (its own agreement is tests/test_lod.py's)."""
    scene = load_scene(path)
    scene = per_pixel(replace(scene, render=replace(scene.render, lod=0.0)))
    ref = render_reference(scene, W, H)
    assert ref.hit.mean() > 0.02, "the preset's camera sees (almost) nothing"
    gpu = renderer.render(scene, W, H)
    assert_finite(gpu, scene.render.max_iterations)
    ties = fold_ties(scene, ref)  # tree at 160×120: one pixel within an ulp of a mirror
    assert ties.sum() <= 0.002 * ties.size
    check_against_reference(path.stem, gpu, ref, ties)
    fast = renderer.render(replace(scene, render=replace(scene.render, prepass=8)), W, H)
    assert_finite(fast, scene.render.max_iterations, prepass=True)
    a = gpu_reference_agreement(fast, ref)
    eps = view_of(scene.camera, W, H).footprint * scene.render.epsilon_scale
    assert a.off_edge_hit == 0 and a.off_edge_depth <= 2.0 * eps and a.hit >= 0.985, a


@pytest.mark.parametrize(
    "broken",
    [
        # a sphere 1 % too large
        (
            "kernels.glsl",
            "return length(p - kernel_rec(i, 1).xyz) - kernel_rec(i, 1).w;",
            "return length(p - kernel_rec(i, 1).xyz) - 1.01 * kernel_rec(i, 1).w;",
        ),
        # a fold that leaves points within 0.01 behind a mirror unreflected
        ("krs.glsl", "p -= 2.0 * max(e, 0.0) * u;", "p -= 2.0 * (e > 1e-2 ? e : 0.0) * u;"),
    ],
)
def test_a_deliberately_broken_shader_fails_the_comparison(tmp_path, broken):
    """Negative control of the pixel comparison [issue 16]: a copy of the shaders with a
    small, deliberate error must fail it, while the intact copy passes; the every-pixel rule
    away from outlines is among what finds them."""
    import shutil

    from krsview.gpu.program import SHADER_DIR
    from krsview.gpu.renderer import Renderer
    from krsview.scene.presets import resolve

    from .conftest import agreement, failures

    shutil.copytree(SHADER_DIR, tmp_path / "shaders")
    scene = load_scene(resolve("sierpinski"))
    ref = render_reference(scene, W, H)
    intact = Renderer(shader_dir=tmp_path / "shaders")
    assert failures(agreement(intact.render(scene, W, H), ref)) == []
    name, old, new = broken
    path = tmp_path / "shaders" / name
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))
    a = agreement(Renderer(shader_dir=tmp_path / "shaders").render(scene, W, H), ref)
    problems = failures(a)
    assert problems, "a broken shader passed the comparison"
    assert problems[0].startswith("away from outlines every pixel must agree")
