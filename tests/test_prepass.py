"""The low-resolution pre-pass [issue 17 §2]: rays start where their tile's cone found them
all free. It never skips a surface — the reliable oracle certifies no hole in its images, on
presets and hard cases — it changes hit decisions only on grazing rays, and it saves
iterations. Negative control: a cone without its spread starts rays past surfaces."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.bench.hard_cases import CASES
from krsview.bench.metrics import COLOR_TOL, DEPTH_REL, NORMAL_DEG, agreement
from krsview.compile.camera import view_of
from krsview.gpu.renderer import Renderer
from krsview.oracle.certify import count_errors
from krsview.scene import load_scene
from krsview.scene.presets import preset_names, resolve

from .conftest import broken_shaders, krsview_cli, sweep

W, H = 48, 27
GRID = (32, 18)  # the grid's images: the oracle's cost grows with the rays, the skips are per ray


def with_prepass(scene, tile):
    return replace(scene, render=replace(scene.render, prepass=tile))


# every still preset: wind is not in the oracle (tests/test_wind.py holds its pre-pass), and
# a moving preset poses the geometry of its still original at each moment (the oracle
# certifies a swaying frame in tests/test_oracle.py), so it would only lengthen the run.
# `make test` runs a slice (a grown tree, a compound, a plane kernel, no balls, a MöKRS and
# the hard cases); KRSVIEW_SWEEP=full every still preset
SCENES = [n for n in preset_names() if not load_scene(resolve(n)).animated]
HARD = [
    "camera-on-mirror",
    "grazing-ground",
    "inside-crown",
    "compound-overlap",
    "mobius-pole-in-view",
]


def scene_of(name):
    return replace(CASES[name].build(), name=name) if name in CASES else load_scene(resolve(name))


@pytest.mark.parametrize(
    "name", sweep(SCENES + HARD, {"tree", "grove", "grass", "shell", "sierpinski", *HARD})
)
def test_the_prepass_skips_no_surface(renderer, name):
    """Certified by the oracle: no ray of the pre-pass image passes a surface, none stops
    in empty space beyond ε. Against the image without the pre-pass, away from outlines
    every pixel agrees: the same hit state, and depths within about one ε (each stops
    somewhere within ε(t) of the surface, ε(t) = footprint × t). On outlines a grazing ray
    that passes a surface at about ε may stop or not, depending on where its steps fall."""
    scene = scene_of(name)
    plain = renderer.render(scene, *GRID)
    img = renderer.render(with_prepass(scene, 4), *GRID)
    counts = count_errors(with_prepass(scene, 4), img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    if counts.undecided > 0.02 * counts.rays:  # as many undecided without the pre-pass?
        alone = count_errors(scene, plain, arithmetics=("affine",))  # (inversion's poles)
        assert counts.undecided <= alone.undecided + 0.02 * counts.rays, (counts, alone)
    a = agreement(img, plain, DEPTH_REL, NORMAL_DEG, COLOR_TOL)
    eps_per_t = view_of(scene.camera, *GRID).footprint * scene.render.epsilon_scale
    assert a.off_edge_hit == 0 and a.off_edge_depth <= 1.5 * eps_per_t, a


def test_a_cone_without_its_spread_skips_surfaces(tmp_path):
    """Negative control: a pre-pass that marches the tile's centre ray alone (no spread, no
    ε margin) starts the tile's other rays past twigs the centre ray missed."""
    shaders = broken_shaders(
        tmp_path, "prepass.glsl", "return sigma + real(u_eps_per_t);", "return 0.0;"
    )
    scene = with_prepass(load_scene(resolve("tree")), 8)
    img = Renderer(shader_dir=shaders).render(scene, W, H)
    assert count_errors(scene, img, arithmetics=("affine",)).holes > 0


def passes(scene, tile, levels):
    return replace(scene, render=replace(scene.render, prepass=tile, prepass_levels=levels))


@pytest.mark.parametrize("name", ["tree", "grove"])
def test_coarser_passes_skip_no_surface_and_each_starts_where_the_coarser_stopped(renderer, name):
    """Three coarse passes (tiles of 32, 8 and 2 pixels): the oracle still certifies no hole
    and no false hit. Each cone starts at the free distance of the coarser tile around it, so
    no tile's free distance is below that tile's (the coarsest pass alone is a one-pass
    pre-pass at its tile size), and most get further. Negative control in the last line: a
    finer pass that ignores the coarser one gives the one-pass pre-pass's distances."""
    scene = scene_of(name)
    deep = passes(scene, 2, 3)
    img = renderer.render(deep, W, H)
    counts = count_errors(deep, img, arithmetics=("affine",))
    assert (counts.holes, counts.false_hits) == (0, 0), counts
    used = len(getattr(scene.geometry(), "parts", [None]))  # components: the rest are 0
    fine = renderer.free_distances(passes(scene, 8, 2), W, H)[::-1, :, :used]  # rows bottom
    parent = renderer.free_distances(passes(scene, 32, 1), W, H)[::-1, :, :used]  # → top
    below = parent[np.arange(fine.shape[0])[:, None] // 4, np.arange(fine.shape[1]) // 4]
    assert (fine >= below * (1 - 2e-6)).all()
    assert (fine > below).mean() > 0.5  # the finer cones get further
    # and they started at the coarser tile's distance: a finer cone marched from the eye (as
    # in a one-pass pre-pass) also gets further, but stops at other points
    one = renderer.free_distances(passes(scene, 8, 1), W, H)[::-1, :, :used]
    assert (fine != one).mean() > 0.5


def test_a_finer_pass_that_reads_the_wrong_coarse_tile_skips_surfaces(tmp_path):
    """Negative control: a finer cone that starts at the free distance of another coarse
    tile than the one around it (the shader assuming half the renderer's tile ratio) starts
    rays past surfaces."""
    shaders = broken_shaders(
        tmp_path,
        "prepass.frag",
        "coarse_texel(tile / PREPASS_RATIO, u_layout.zw)",
        "coarse_texel(tile / (PREPASS_RATIO / 2), u_layout.zw)",
    )
    scene = passes(load_scene(resolve("tree")), 2, 2)
    scene = replace(scene, render=replace(scene.render, lod=0.0))  # every level
    img = Renderer(shader_dir=shaders).render(scene, W, H)
    assert count_errors(scene, img, arithmetics=("affine",)).holes > 0


@pytest.mark.parametrize("name", ["tree", "grove", "palm"])
def test_rays_start_at_their_tiles_free_distance(renderer, name):
    """Every ray starts no nearer than 0 and walks fewer steps: the free distances are
    finite and positive where the tile sees sky or far geometry, and the mean iteration
    count drops."""
    scene = load_scene(resolve(name))
    plain = renderer.render(scene, 160, 90)
    fast = with_prepass(scene, 8)
    img = renderer.render(fast, 160, 90)
    components = len(getattr(scene.geometry(), "parts", [None]))
    free = renderer.free_distances(fast, 160, 90)[..., :components]
    assert free.shape[:2] == (-(-90 // 8), -(-160 // 8))
    assert np.isfinite(free).all() and (free >= 0).all() and (free > 0).mean() > 0.9
    assert img.iterations.mean() < 0.6 * plain.iterations.mean()
    with pytest.raises(ValueError, match="prepass > 0"):  # no pre-pass: nothing to read
        renderer.free_distances(scene, 160, 90)


@pytest.mark.parametrize("name", preset_names())
def test_culling_changes_no_pixel(renderer, name):
    """Exact level culling off and on: the same value, so the same image, bit for bit."""
    scene = load_scene(resolve(name))
    on = renderer.render(replace(scene, render=replace(scene.render, culling="on")), 96, 54)
    off = renderer.render(replace(scene, render=replace(scene.render, culling="off")), 96, 54)
    for field in ("color", "depth", "normal", "iterations", "hit"):
        assert np.array_equal(getattr(on, field), getattr(off, field)), field


def test_bench_paths_reports_every_lever_at_two_sizes(tmp_path):
    """`krsview bench paths` times culling × pre-pass tiles on the fragment path, the
    compute path's round sizes and its persistent lanes, at --size and twice it; its CSV has
    every combination, the plain frame as the unit, and fewer full-pass iterations with the
    pre-pass (no wall-time assertion: only what the rows must contain)."""
    import csv

    out = tmp_path / "paths.csv"
    r = krsview_cli(
        "bench", "paths", "sierpinski", "--size", "32x18", "--rounds", "1", "--csv", str(out)
    )
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(out.open()))
    sizes = ("32x18", "64x36")
    key = ("size", "path", "culling", "prepass", "coarse_passes", "steps")
    assert {tuple(row[k] for k in key) for row in rows} == {
        (size, "fragment", c, str(t), "2" if t else "0", "0")
        for size in sizes
        for c in ("on", "off")
        for t in (0, 4, 8, 16)
    } | {(size, "fragment", "on", str(t), "1", "0") for size in sizes for t in (4, 8)} | {
        (size, "compute", "on", "8", "2", str(s)) for size in sizes for s in (4, 8, 16, 32)
    } | {(size, "compute", "on", "4", "2", "0") for size in sizes}  # persistent lanes
    n = len(load_scene(resolve("sierpinski")).geometry().mirrors)
    for row in rows:
        if (row["path"], row["culling"], row["prepass"]) == ("fragment", "off", "0"):
            assert float(row["speedup"]) == 1.0
        assert (float(row["coarse_share"]) > 0) == (row["prepass"] != "0")
        # no level of sierpinski has a ball: every step walks all n levels
        assert float(row["levels"]) == pytest.approx(n * float(row["iterations"]))
    iters = {
        tuple(row[k] for k in key): float(row["iterations"])
        for row in rows
        if row["culling"] == "on"
    }
    assert (
        iters[("64x36", "fragment", "on", "4", "2", "0")]
        < iters[("64x36", "fragment", "on", "0", "0", "0")]
    )
    assert (
        iters[("64x36", "compute", "on", "8", "2", "4")]
        == iters[("64x36", "fragment", "on", "8", "2", "0")]
    )
    assert (  # persistent lanes take the fragment path's steps
        iters[("64x36", "compute", "on", "4", "2", "0")]
        == iters[("64x36", "fragment", "on", "4", "2", "0")]
    )
    assert {row["shadow_rays"] for row in rows} == {""}  # sierpinski has no shadows
    from krsview.bench.paths import levers

    shadowed = {k[4:] for k in levers(load_scene(resolve("tree"))) if k[0] == "compute"}
    assert shadowed == {(s, kind) for s in (4, 8, 16, 32) for kind in ("tasks", "inline")} | {
        (0, "")  # persistent lanes: shadow rays as the fragment path traces them
    }
