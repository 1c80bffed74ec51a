"""An image in passes (gpu/passes.py): the tracing, then the shading, is render.frag's image;
shadow rays per 2 × 2 pixels light the image as per-pixel ones do; a pixel with no block at
its depth traces its own; bands make the same image as one draw; the new stages are valid
desktop GLSL."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import krsview
from krsview import api
from krsview.frame import Frame
from krsview.gpu import passes, program
from krsview.gpu.passes import PassImage, Targets, splits_shadows
from krsview.gpu.renderer import read_buffers
from krsview.scene.scene import MAX_LIGHTS

from .test_glsl_portable import VERSIONS, validate

SIZE = (160, 90)


def scene_of(name: str) -> krsview.Scene:
    return krsview.configure(krsview.load(name), prepass=4)


def draw(renderer, targets, scene, ratio: int, size=SIZE) -> Frame:
    with renderer.current():
        image = PassImage(renderer, targets, scene, size, scene.geometry(), ratio)
        return read_buffers(image.draw_all(), *size)


def lit(frame: Frame) -> np.ndarray:
    """Mean colour over the hit pixels."""
    return frame.color[frame.hit].mean(0)


def test_tracing_then_shading_is_render_frags_image(renderer, targets):
    tree = scene_of("tree")
    one = draw(renderer, targets, tree, 0)
    two = draw(renderer, targets, tree, 1)
    assert one.hit.mean() > 0.1
    for name in ("color", "depth", "normal", "iterations", "hit"):
        assert np.array_equal(getattr(one, name), getattr(two, name)), name
    # negative control: blocks of 2 × 2 pixels sharing shadow rays change some pixels
    assert not np.array_equal(one.color, draw(renderer, targets, tree, 2).color)


def test_a_pixel_with_no_block_at_its_depth_traces_its_own_shadow(renderer, targets, monkeypatch):
    tree = scene_of("tree")
    one = draw(renderer, targets, tree, 0)
    monkeypatch.setattr(passes, "DEPTH_SLACK", -1.0)  # no block is ever near enough
    assert np.array_equal(draw(renderer, targets, tree, 2).color, one.color)
    monkeypatch.setattr(passes, "DEPTH_SLACK", 3.0)  # control: blocks are used
    assert not np.array_equal(draw(renderer, targets, tree, 2).color, one.color)


@pytest.mark.parametrize("name", ["tree", "grove", "forest"])
def test_shadow_rays_per_block_light_like_per_pixel_ones(renderer, targets, name):
    """Over the hits, the mean colour within 1.5/255 of per-pixel shadows' and 93 % of the
    pixels within 8/255; without shadows (what moving frames drew before) neither holds."""
    scene = scene_of(name)
    assert splits_shadows(scene) and MAX_LIGHTS <= 4  # a block's visibilities: one vec4
    exact = draw(renderer, targets, scene, 0)
    coarse = draw(renderer, targets, scene, 2)
    plain = replace(scene, effects=[e for e in scene.effects if "shadow" not in e])
    unshadowed = draw(renderer, targets, plain, 0)
    hit = exact.hit
    assert np.array_equal(coarse.hit, hit) and np.array_equal(unshadowed.hit, hit)

    def close(f: Frame) -> float:
        return (np.abs(f.color - exact.color).max(-1)[hit] <= 8 / 255).mean()

    assert np.abs(lit(coarse) - lit(exact)).max() < 1.5 / 255 and close(coarse) > 0.93
    assert np.abs(lit(unshadowed) - lit(exact)).max() > 4 / 255 and close(unshadowed) < 0.9


def test_bands_make_the_image_of_one_draw_and_images_alternate_targets(renderer, targets):
    tree = scene_of("tree")
    whole = draw(renderer, targets, tree, 2)

    def banded(skip: tuple[str, int] | None = None) -> tuple[PassImage, Frame]:
        """Every pass in bands of 7 rows, leaving out band ``skip`` (pass, first row)."""
        image = PassImage(renderer, targets, tree, SIZE, tree.geometry(), 2)
        image.output.clear()
        image.prepare()
        for name, _, rows in image.passes:
            for y0 in range(0, rows, 7):
                if (name, y0) != skip:
                    image.draw(name, y0, min(7, rows - y0))
        return image, read_buffers(image.output, *SIZE)

    with renderer.current():
        image, bands = banded()
        assert [p[0] for p in image.passes] == ["trace", "visibility", "shade"]
        assert image.passes[1][1:] == (80, 45)
        # a later image of the same size never draws into this one's targets
        after = PassImage(renderer, targets, tree, SIZE, tree.geometry(), 1, traced=image)
        assert after.output is not image.output and [p[0] for p in after.passes] == [
            "shadows+shade"
        ]
        reused = read_buffers(after.draw_all(), *SIZE)
        holed = banded(("shade", 42))[1]  # negative control: one band left out
    assert np.array_equal(bands.color, whole.color)
    assert np.array_equal(reused.color, draw(renderer, targets, tree, 0).color)
    assert not np.array_equal(holed.color, whole.color)


def test_the_passes_are_valid_desktop_glsl(renderer, tmp_path, monkeypatch):
    sources: dict[str, str] = {}
    build = program.build_program

    def recording(ctx, vertex, fragment, defines, shader_dir=program.SHADER_DIR):
        if fragment in ("coarse_visibility.frag", "upsampled.frag") or (
            fragment == "render.frag" and "KRS_TRACE_KERNELS" in defines  # the trace pass
        ):
            key = f"s{len(sources):02d}-{fragment.replace('.', '-')}.frag"
            sources[key] = program.Source(fragment, defines).text
        return build(ctx, vertex, fragment, defines, shader_dir)

    monkeypatch.setattr(program, "build_program", recording)
    monkeypatch.setattr(renderer, "programs", program.ProgramCache(renderer.ctx))  # all anew
    mokrs = krsview.load("tree-mokrs")  # a MöKRS's shadow rays probe with unbounding balls
    for scene in (scene_of("tree"), scene_of("grove"), replace(mokrs, effects=["soft_shadows"])):
        for ratio in (1, 2):
            draw(renderer, Targets(renderer.ctx), scene, ratio, (16, 9))
    # per scene: the trace pass (and its free tiles' pass, with tree's and grove's pre-pass);
    # ratio 1: the shading; 2: blocks listed, their rays, hits' depth, sky, shading, outline
    assert len(sources) == 26
    for version in VERSIONS:
        assert validate(sources, tmp_path, version) == ""
    # negative control: a call the language does not have
    key = next(k for k in sources if "upsampled" in k and "u_coarse_depth" in sources[k])
    bad = {"bad.frag": sources[key].replace("(u_coarse_depth, q, 0)", "(u_coarse_depth, q)")}
    assert "texelFetch" in validate(bad, tmp_path, VERSIONS[1])


def test_a_headless_frame_shares_shadow_rays_as_its_scene_says(renderer, targets):
    """Renderer.render draws the still image in passes per ``[render] shadow_block``, the
    same pixels as the viewer's PassImage, with or without progress bands; 1 is the one-pass
    image; the exact settings (the reference's image) trace a shadow ray per pixel."""
    tree = scene_of("tree")
    assert tree.render.shadow_block == 2 and passes.still_ratio(tree) == 2
    w, h = SIZE
    for block, ratio in ((1, 0), (2, 2), (3, 3)):
        scene = tree.edit(("render", "shadow_block"), block)
        expected = draw(renderer, targets, scene, ratio)
        calls: list[tuple[int, int]] = []
        assert np.array_equal(renderer.render(scene, w, h).color, expected.color), block
        banded = renderer.render(scene, w, h, progress=lambda *c, out=calls: out.append(c))
        assert np.array_equal(banded.color, expected.color), block
        assert calls[-1][0] == calls[-1][1] == len(calls) > 1
    # negative control: the blocks' sizes light the image differently
    assert not np.array_equal(
        renderer.render(tree, w, h).color,
        renderer.render(tree.edit(("render", "shadow_block"), 3), w, h).color,
    )
    assert api.exact_settings(tree).render.shadow_block == 1


def test_shadow_rays_are_per_pixel_where_they_cannot_be_a_pass_of_their_own():
    tree = scene_of("tree")
    assert passes.still_ratio(tree) == 2
    for knob, value in (("path", "compute"), ("precision", "double"), ("shadow_block", 1)):
        assert passes.still_ratio(tree.edit(("render", knob), value)) == 0, knob
    assert passes.still_ratio(tree.with_effects(["sky"])) == 0
