"""Shading after shadow rays per block (gpu/passes.py, upsampled.frag): a shade pass without
shadow-ray code lists the outline pixels (a lit light that no block near the pixel's depth
gives a visibility), and a pass of their own shades only those, with their own rays. The
image is the one of a single shade pass that runs shadow-ray code for every pixel, bit for
bit; the listed pixels are the ones the blocks' rule leaves unlit; only they run the outline
pass."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.gpu import bins, passes, program
from krsview.gpu.passes import SAMPLERS, PassImage
from krsview.gpu.renderer import read_buffers

from .test_passes import SIZE, scene_of


def image_of(renderer, targets, scene, one_pass=False, blocks=None, size=SIZE) -> PassImage:
    """``scene``'s image with 2 × 2 blocks, every pass drawn; ``one_pass``: its shade pass
    upsampled.frag with KRS_SHADOW_UPSAMPLED alone, which traces an outline pixel's rays in
    the same pass (and lists nothing, so no outline pass is drawn)."""
    image = PassImage(renderer, targets, scene, size, scene.geometry(), 2, blocks=blocks)
    image.prepare()
    if one_pass:
        split = image._programs["shade"]
        single = renderer.companion(
            image._programs["trace"], "upsampled.frag", {"KRS_SHADOW_UPSAMPLED": None}
        )
        for name in ("u_block", "u_depth_slack", "u_coarse_origin", "u_coarse_size", *SAMPLERS):
            single[name].value = split[name].value
        image._programs["shade"] = single
    for name, _, rows in image.passes:
        image.draw(name, 0, rows)
    return image


def listed(targets, image: PassImage) -> np.ndarray:
    """The pixels the shade pass listed, as a mask (rows top → bottom, as the targets')."""
    buffer = targets.outline(image.output).pixels
    count = int(np.frombuffer(buffer.read(4), np.uint32)[0])
    pixels = np.frombuffer(buffer.read(4 * count, offset=4), np.uint32)
    mask = np.zeros(image.size[1] * image.size[0], bool)
    mask[pixels] = True
    assert len(pixels) == count and mask.sum() == count  # each listed once
    return mask.reshape(image.size[1], image.size[0])


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_outline_pixels_apart_make_the_one_pass_image(renderer, targets, name):
    scene = scene_of(name)
    with renderer.current():
        for blocks in (None, image_of(renderer, targets, scene, size=(80, 45))):
            split = image_of(renderer, targets, scene, blocks=blocks)
            outline = listed(targets, split)
            got = read_buffers(split.output, *SIZE)
            want = read_buffers(image_of(renderer, targets, scene, True, blocks).output, *SIZE)
            assert outline.mean() > 0.002, blocks
            for plane in ("color", "depth", "normal", "iterations", "hit"):
                assert np.array_equal(getattr(got, plane), getattr(want, plane)), plane
        # negative control: the shade pass alone (the outline pixels not redrawn) is off at
        # outline pixels, and only there
        split._fill(split._programs["shade"], split.output, SIZE, 0, SIZE[1])
        alone = read_buffers(split.output, *SIZE)
    off = np.abs(alone.color - want.color).max(-1) > 0
    assert off.any() and not (off & ~outline).any()


def blocks_rule(image: PassImage) -> tuple[np.ndarray, np.ndarray]:
    """NumPy's outline pixels of ``image`` (GL rows): hits facing a light for which none of
    the 2 × 2 blocks around it within the depth slack has a visibility; and the pixels
    within rounding of a threshold (the dot product or the depth slack)."""
    w, h = image.size
    raw = image.output.read(attachment=1, components=4, dtype="f4")
    nt = np.frombuffer(raw, np.float32).reshape(h, w, 4)
    hit = np.frombuffer(image.traced.read(components=4, dtype="f4"), np.float32)
    hit = hit.reshape(h, w, 4)[..., 3] > 0.5
    coarse = image.coarse_target()
    cw, ch = image.coarse
    vis, cdepth = (
        np.frombuffer(
            coarse.read((*image.origin, cw, ch), attachment=k, components=4, dtype="f4"),
            np.float32,
        ).reshape(ch, cw, 4)
        for k in (0, 1)
    )
    shade = image._programs["shade"]
    block, footprint = np.float32(shade["u_block"].value[0]), np.float32(shade["u_footprint"].value)
    k = shade["u_light_count"].value
    light_dir = np.asarray(shade["u_light_dir"].value, np.float32)[:k]
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    cx, cy = (x + 0.5) / block - 0.5, (y + 0.5) / block - 0.5
    x0, y0 = np.floor(cx).astype(int), np.floor(cy).astype(int)
    t = nt[..., 3]
    slack = np.float32(shade["u_depth_slack"].value) * footprint * block * t
    lit = np.zeros((h, w, 4), bool)
    near = np.zeros((h, w), bool)
    for j in (0, 1):
        for i in (0, 1):
            qx, qy = np.clip(x0 + i, 0, cw - 1), np.clip(y0 + j, 0, ch - 1)
            tq = cdepth[qy, qx, 0]
            gap = np.abs(tq - t)
            ok = (tq >= 0) & (gap <= slack)
            near |= (tq >= 0) & (np.abs(gap - slack) <= 1e-4 * slack)
            lit |= ok[..., None] & (vis[qy, qx] >= 0)
    facing = nt[..., :3] @ light_dir.T  # (h, w, lights)
    outline = hit & ((facing[..., :k] > 0) & ~lit[..., :k]).any(-1)
    near |= (np.abs(facing[..., :k]) < 1e-5).any(-1)
    return outline, hit & near


def test_the_listed_pixels_are_those_no_block_lights(renderer, targets, monkeypatch):
    """The shade pass lists exactly NumPy's outline pixels (up to pixels within rounding of
    a threshold); with no block ever near enough (negative control), every hit that faces
    a light."""
    grove = scene_of("grove")
    with renderer.current():
        for slack in (passes.DEPTH_SLACK, -1.0):
            monkeypatch.setattr(passes, "DEPTH_SLACK", slack)
            image = image_of(renderer, targets, grove)
            outline, near = blocks_rule(image)
            got = listed(targets, image)
            assert not ((got ^ outline) & ~near).any() and near.mean() < 0.005, slack
            assert 0.002 < outline.mean() < 0.2 if slack > 0 else outline.mean() > 0.3


def test_only_listed_pixels_run_the_outline_pass(renderer, targets, monkeypatch):
    """Fragments kept by each of the shading passes (an occlusion query): the hits' depth
    every pixel of its rows, the sky's pass and the shade pass the two parts of them, the
    outline pass one per listed pixel, in the rows they fill 128 pixels wide (two bins)."""
    tree = scene_of("tree")
    drawn: list[tuple[str, int, int]] = []
    fill = PassImage._fill

    def counted(image, prog, target, size, y0, rows, origin=(0, 0)):
        name = next(k for k, p in image._programs.items() if p is prog)
        query = renderer.ctx.query(samples=True)
        with query:
            fill(image, prog, target, size, y0, rows, origin)
        drawn.append((name, rows, query.samples))

    monkeypatch.setattr(PassImage, "_fill", counted)
    with renderer.current():
        image = image_of(renderer, targets, tree)
        count = int(listed(targets, image).sum())
    w, h = SIZE
    assert [d[0] for d in drawn] == ["visibility", "rays", "hits", "sky", "shade", "outline"]
    assert drawn[2] == ("hits", h, w * h) and drawn[3][2] + drawn[4][2] == w * h
    assert 0 < count < w * h / 20 and drawn[5] == ("outline", 2 * -(-count // 256), count)


@pytest.mark.parametrize(
    "size, listed, want",
    [
        ((320, 180), 1000, (128, 8)),  # two bins across, not five
        ((160, 90), 300, (128, 4)),  # whole 4 × 2 groups: an even number of rows
        ((320, 180), 128 * 180, (128, 180)),
        ((320, 180), 128 * 180 + 1, (256, 92)),  # two bins would need more rows than 180
        ((320, 180), 256 * 180 + 1, (320, 146)),  # and four
        ((100, 50), 120, (100, 2)),  # narrower than two bins
        ((102, 51), 102 * 51, (104, 52)),  # every pixel, in whole groups
    ],
)
def test_a_packed_pass_spans_whole_pairs_of_bins_in_whole_groups(size, listed, want):
    """A packed pass's image (the outline pixels', the blocks' rays'): the fewest pairs of
    64-pixel bins across whose rows hold the listed entries within the image's height,
    else the image's width, in whole 4 × 2 groups of lanes; more entries than pixels
    (negative control) are refused."""
    assert bins.packed(size, listed) == want
    with pytest.raises(ValueError, match=f"{104 * 52 + 1} entries in groups of lanes"):
        bins.packed((102, 51), 104 * 52 + 1)


def test_the_shade_pass_compiles_no_shadow_ray(renderer, targets, monkeypatch):
    """llvmpipe runs every branch's code for every pixel: the shade pass's source calls no
    shadow ray (shadows.glsl's definition alone names it); the outline pass's does."""
    calls: dict[str, int] = {}
    build = program.build_program

    def recording(ctx, vertex, fragment, defines, shader_dir=program.SHADER_DIR):
        for define in ("KRS_SHADOW_MARK", "KRS_SHADOW_OUTLINE"):
            if define in defines:
                text = program.Source(fragment, defines).text
                calls[define] = text.count("shadow_visibility(")
        return build(ctx, vertex, fragment, defines, shader_dir)

    monkeypatch.setattr(program, "build_program", recording)
    monkeypatch.setattr(renderer, "programs", program.ProgramCache(renderer.ctx))  # all anew
    with renderer.current():
        image_of(renderer, targets, scene_of("tree"), size=(16, 9))
    assert calls == {"KRS_SHADOW_MARK": 1, "KRS_SHADOW_OUTLINE": 2}
