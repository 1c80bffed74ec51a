"""The shadow cone (``[render] shadow_cone``, shadows.glsl and reference/occlusion.py,
cone_entry): a shadow ray steps a component only from where the component's ball or
half-space, grown by ε, meets the ray's cone (radius t/k for soft shadows, the ray itself
for hard ones). Before that point the component can neither block the ray nor lower its
visibility, so a grove's shadow rays skip the trees they pass far from and the ground they
leave, and the image stays that of the exact shadows."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview import api
from krsview.bench.truth import truth_scene
from krsview.compile.geometry import compile_geometry, components
from krsview.gpu.renderer import read_plane
from krsview.gpu.uniforms import variant_defines
from krsview.reference import render_reference
from krsview.reference.geometry import Bounds, component_distance, shadow_bounds
from krsview.reference.occlusion import cone_entry
from krsview.scene import SceneError, load_scene
from krsview.scene.presets import resolve

from .conftest import check_against_reference, per_pixel

W, H = 96, 54
SOFT = 1.0 / 12.0  # grove's softness k = 12


def grove(cone: str = "on", effects: tuple[str, ...] | None = None):
    scene = load_scene(resolve("grove"))
    if effects is not None:
        scene = replace(scene, effects=list(effects))
    return per_pixel(replace(scene, render=replace(scene.render, shadow_cone=cone)))


def compiled(scene):
    return compile_geometry(scene.geometry(), scene.material.albedo)


def rays(seed: int, n: int, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """n shadow rays: origins uniform in the box [lo, hi], directions uniform on the upper
    half sphere (towards a light above the ground)."""
    rng = np.random.default_rng(seed)
    o = rng.uniform(lo, hi, (n, 3))
    d = rng.normal(size=(n, 3))
    d[:, 1] = np.abs(d[:, 1])
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)


def violations(c, bounds: Bounds, slope: float, eps: float, seed: int) -> tuple[int, int]:
    """Over random rays, the points before each component's cone_entry where its distance
    bound (Alg. 1, every level: an independent lower bound of the true distance) is at or
    below ε + slope·t, which the entry says cannot happen; and how many rays entered late."""
    bad = late = 0
    for j, part in enumerate(components(c)):
        o, l = rays(seed + j, 24, (-8.0, 0.2, -6.0), (8.0, 9.0, 14.0))
        for dir_ in l:  # one direction per batch of origins keeps cone_entry's l a vector
            t0 = cone_entry(bounds, o, dir_, np.full(len(o), eps), slope, 100.0)[:, j]
            late += int((t0 > 0).sum())
            ts = np.linspace(0.0, 1.0, 200)[None, :] * np.minimum(t0, 100.0)[:, None]
            p = (o[:, None, :] + ts[..., None] * dir_).reshape(-1, 3)
            d = component_distance(part, p).reshape(ts.shape)
            close = d[:, :-1] <= eps + slope * ts[:, :-1]
            bad += int((close & (t0 > 0)[:, None]).sum())
    return bad, late


@pytest.mark.parametrize("slope", [SOFT, 0.0], ids=["soft", "hard"])
def test_the_cone_entry_is_never_late(slope):
    """Brute force over grove's eight components (seven trees and the ground plane) and
    576 rays each: before the entry no sampled point has the component within ε + slope·t.
    Negative control: with every ball shrunk to a third of its radius (and the ground's
    half-space lowered by 0.5) the same check finds such points."""
    scene = grove()
    c = compiled(scene)
    bounds = shadow_bounds(scene, c, None)
    assert bounds is not None
    assert (bounds.half_spaces[:, :3] != 0).any(axis=1).sum() == 1  # the ground alone
    bad, late = violations(c, bounds, slope, 0.01, seed=1)
    assert late > 1000 and bad == 0, (late, bad)
    shrunk = Bounds(
        bounds.balls * np.where(bounds.balls[:, 3:] >= 0, [1.0, 1.0, 1.0, 1 / 3], 1.0),
        bounds.half_spaces - np.where(bounds.half_spaces[:, 1:2] > 0, [0, 0, 0, 0.5], 0.0),
    )
    bad, _ = violations(c, shrunk, slope, 0.01, seed=1)
    assert bad > 0


def shadow_work(renderer, scene) -> tuple[float, float]:
    """Shadow steps and levels per pixel (the counting variant, render.frag's z and w)."""
    with renderer.current():
        prog = renderer.prepare(scene, W, H, probes=("KRS_COUNT_LEVELS",))
        it = read_plane(renderer.draw(prog, W, H), 2, W, H)
    return float(it[..., 2].mean()), float(it[..., 3].mean())


def test_the_cone_spares_grove_most_of_its_shadow_steps(renderer):
    """Grove's shadow rays take under half the steps and levels with the cone; the tree's
    start inside its one ball (but for a few on its outermost twigs), so they take about the
    same: within 2 % (negative control)."""
    on, off = shadow_work(renderer, grove("on")), shadow_work(renderer, grove("off"))
    assert off[0] > 0 and on[0] < 0.5 * off[0] and on[1] < 0.5 * off[1], (on, off)
    tree = per_pixel(load_scene(resolve("tree")))
    same = [
        shadow_work(renderer, replace(tree, render=replace(tree.render, shadow_cone=s)))
        for s in ("on", "off")
    ]
    assert same[1][0] > 0 and 0.98 * same[1][0] <= same[0][0] <= same[1][0], same


@pytest.mark.parametrize(
    "effects",
    [
        ("soft_shadows", "sky"),
        ("shadows", "sky"),
        ("wind", "soft_shadows", "sky"),
    ],
    ids=["soft", "hard", "wind"],
)
def test_gpu_matches_the_reference_with_the_cone(renderer, effects):
    """Grove with the cone on: the GPU and the float64 twin agree pixel by pixel (the
    reference's tolerances), soft, hard, and bent by the wind (the swept balls)."""
    scene = grove("on", effects)
    assert "KRS_SHADOW_CONE" in variant_defines(scene, compiled(scene))
    check_against_reference(
        "grove-cone", renderer.render(scene, W, H), render_reference(scene, W, H)
    )


def test_the_cone_changes_the_shadows_by_less_than_a_level():
    """Against the exact shadows (cone off) the reference's image with the cone differs by
    under 0.5/255 on average over the hits and in under 1 % of them by more than 2/255; the
    same comparison against an image without shadows differs a lot (negative control)."""
    on, off = render_reference(grove("on"), W, H), render_reference(grove("off"), W, H)
    assert np.array_equal(on.hit, off.hit)
    diff = np.abs(on.color - off.color)[on.hit].max(axis=1) * 255
    assert diff.mean() < 0.5 and (diff > 2).mean() < 0.01, (diff.mean(), (diff > 2).mean())
    unlit = render_reference(grove("off", ("sky", "fog")), W, H)
    assert (np.abs(unlit.color - off.color)[on.hit].max(axis=1) * 255).mean() > 5


def test_off_compiles_the_exact_shadows_and_a_mokrs_never_has_the_cone(renderer):
    """shadow_cone = off compiles today's shadow rays (no KRS_SHADOW_CONE), which the
    reference without the cone matches, and the accuracy bench's truth has it off; a MöKRS
    has no balls for it, so on and off draw the same image there, the reference's."""
    off = grove("off")
    assert truth_scene(grove("on")).render.shadow_cone == "off"  # the accuracy bench's truth
    assert api.exact_settings(grove("on")).render.shadow_cone == "off"  # --exact
    assert "KRS_SHADOW_CONE" not in variant_defines(off, compiled(off))
    assert shadow_bounds(off, compiled(off), None) is None
    check_against_reference("grove-exact", renderer.render(off, W, H), render_reference(off, W, H))
    mokrs = load_scene(resolve("tree-mokrs"))
    mokrs = per_pixel(replace(mokrs, effects=["soft_shadows", "sky"]))
    images = [
        renderer.render(replace(mokrs, render=replace(mokrs.render, shadow_cone=s)), W, H)
        for s in ("on", "off")
    ]
    assert np.array_equal(images[0].color, images[1].color)
    check_against_reference("tree-mokrs-soft", images[0], render_reference(mokrs, W, H))


def test_a_bad_shadow_cone_is_a_one_line_error():
    scene = load_scene(resolve("grove"))
    with pytest.raises(SceneError) as err:
        scene.edit(("render", "shadow_cone"), "maybe")
    msg = str(err.value)
    assert "shadow_cone" in msg and "maybe" in msg and "on" in msg and "\n" not in msg
