"""Compound of KRSs [KRS17 §5.1]: the tracer with one free distance per component draws the
per-pixel nearest of the components drawn alone, with no more work than all of them alone;
placing a component moves its distance as a similarity; bad compounds get clear errors."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from krsview.bench.metrics import HIT_AGREEMENT
from krsview.compile.geometry import compile_geometry
from krsview.compile.krs import compile_krs
from krsview.frame import Frame
from krsview.gpu.program import Source
from krsview.gpu.uniforms import variant_defines
from krsview.reference import distance, render_reference
from krsview.scene import (
    Compound,
    EffectSettings,
    EmptyZone,
    SceneError,
    Tree,
    scene_from_toml,
    scene_to_toml,
)
from krsview.scene.compound import Placement

from .conftest import assert_finite, check_against_reference, per_pixel

W, H = 96, 72
CAP = 2048  # far above what any pixel needs, so the cap never cuts a trace short

SCENE = f"""
name = "three"
[camera]
position = [0.3, 1.6, -7.0]
target = [0.0, 1.3, 0.0]
[render]
max_iterations = {CAP}
[[compound]]
position = [-1.2, 0.0, 0.0]
[compound.tree]
levels = 7
[[compound]]
position = [1.1, 0.0, 0.6]
angle = 40.0
scale = 0.8
[compound.tree]
levels = 6
branch_angle = 40.0
bark = [0.5, 0.2, 0.1]
leaf = [0.6, 0.6, 0.1]
[[compound]]
[compound.krs]
levels = [{{kernel = {{type = "plane", normal = [0.0, 1.0, 0.0], color = [0.3, 0.5, 0.2]}}}}]
"""


def compound_scene(tracer: str = "sphere"):
    s = scene_from_toml(SCENE)
    return replace(s, render=replace(s.render, tracer=tracer))


def nearest_of(parts: list[Frame]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per pixel: any component hit, the nearest one's index, and its depth."""
    hit = np.stack([p.hit for p in parts])
    depth = np.where(hit, np.stack([p.depth for p in parts]), np.inf)
    return hit.any(0), depth.argmin(0), depth.min(0)


@pytest.mark.parametrize("tracer", ["sphere", "binary"])
def test_compound_is_the_nearest_of_its_components(tracer):
    """Each component's own sequence of free distances is the one it has alone, and the ray
    stops at the first convergence in order of t: so the depth is exactly the least of the
    components' own depths (float64, no tolerance)."""
    s = compound_scene(tracer)
    comp = render_reference(s, W, H)
    parts = [render_reference(s, W, H, geometry=p) for p in s.geometry().parts]
    hit, win, depth = nearest_of(parts)
    assert 0.3 < comp.hit.mean() < 0.95 and len(set(win[hit].tolist())) == 3
    np.testing.assert_array_equal(comp.hit, hit)
    np.testing.assert_array_equal(comp.depth[hit], depth[hit])
    # Work: never more than all components alone; a miss is exactly that (every component
    # leaves the far limit); a hit needs at least the nearest component's own steps.
    iters = np.stack([p.iterations for p in parts])
    assert comp.iterations.max() < CAP
    assert np.all(comp.iterations <= iters.sum(0))
    np.testing.assert_array_equal(comp.iterations[~hit], iters.sum(0)[~hit])
    own = np.take_along_axis(iters, win[None], 0)[0]
    assert np.all(comp.iterations[hit] >= own[hit])
    # Colour: the nearest component's (the compound's level slots name the right kernel),
    # except where another component is nearer to the hit point than the one that stopped.
    color = np.take_along_axis(np.stack([p.color for p in parts]), win[None, ..., None], 0)[0]
    same = np.abs(comp.color - color).max(-1) < 1e-9
    assert same[hit].mean() > 0.99, f"colour of the nearest component on {same[hit].mean():.2%}"


DISTORTED = EffectSettings(twist=12.0, empty_zones=[EmptyZone((-1.2, 2.2, 0.0), 0.8)])


@pytest.mark.parametrize(
    "tracer, effects",
    [
        ("sphere", []),
        ("binary", []),
        ("sphere", ["twist", "empty_zones"]),
        ("sphere", ["smooth_shading", "kernel_texture", "ambient_occlusion"]),
    ],
    ids=lambda v: "+".join(v) if isinstance(v, list) else v,
)
def test_gpu_compound_matches_reference(renderer, tracer, effects):
    """Both tracers, and effects that act per component (distortions, nearest-kernel
    shading) or on the whole compound (AO samples the least distance)."""
    s = replace(compound_scene(tracer), effects=effects, effect_settings=DISTORTED)
    gpu = renderer.render(s, W, H)
    assert_finite(gpu, CAP)
    ref = render_reference(s, W, H)
    if effects:
        assert (
            np.mean(
                np.abs(ref.color - render_reference(compound_scene(), W, H).color).max(-1) > 0.02
            )
            > 0.01
        ), "the effects changed nothing"
    check_against_reference(f"compound-{tracer}-{'+'.join(effects)}", gpu, ref)


def test_gpu_compound_is_the_nearest_of_its_components(renderer):
    """The same on the GPU, in float32: the compound variant against the single-KRS variant
    of each component."""
    s = compound_scene()
    comp = renderer.render(s, W, H)
    hit, win, depth = nearest_of([renderer.render(s, W, H, geometry=p) for p in s.geometry().parts])
    assert (comp.hit == hit).mean() >= HIT_AGREEMENT
    both = comp.hit & hit
    rel = np.abs(comp.depth[both] - depth[both]) / depth[both]
    assert np.mean(rel <= 1e-5) > 0.995


def test_compound_shadows_fall_across_components(renderer):
    """A tree's shadow darkens the ground, another component: shadow rays see the whole
    compound (and agree with the reference)."""
    s = per_pixel(replace(compound_scene(), effects=["soft_shadows"]))
    gpu, ref = renderer.render(s, W, H), render_reference(s, W, H)
    check_against_reference("compound-soft-shadows", gpu, ref)
    plain = render_reference(replace(s, effects=[]), W, H)
    ground = ref.hit & (ref.normal[..., 1] > 0.999)
    darker = ref.color[ground].sum(-1) < plain.color[ground].sum(-1) - 0.05
    assert darker.mean() > 0.05, "no tree shadow on the ground"


def test_single_scene_compiles_no_compound_code():
    s = compound_scene()
    single = s.with_geometry(s.geometry().parts[0])
    src_single = Source(
        "render.frag", variant_defines(single, compile_geometry(single.geometry(), (1, 1, 1)))
    ).text
    src_comp = Source(
        "render.frag", variant_defines(s, compile_geometry(s.geometry(), (1, 1, 1)))
    ).text
    assert "u_component" not in src_single and "u_component" in src_comp


small_trees = st.builds(
    lambda lv, a, b: Tree(levels=lv, branch_angle=a, bend=b),
    st.integers(1, 6),
    st.floats(5, 60),
    st.floats(-0.3, 0.3),
)
placements = st.builds(
    lambda axis, angle, scale, pos: Placement(
        position=pos, axis=tuple(axis / np.linalg.norm(axis)), angle=angle, scale=scale
    ),
    st.lists(st.floats(-1, 1), min_size=3, max_size=3)
    .map(np.array)
    .filter(lambda v: np.linalg.norm(v) > 0.1),
    st.floats(-360, 360),
    st.floats(0.05, 20),
    st.tuples(*[st.floats(-50, 50)] * 3),
)


@settings(max_examples=40, deadline=None)
@given(tree=small_trees, place=placements, seed=st.integers(0, 2**31))
def test_placement_moves_the_distance_as_a_similarity(tree, place, seed):
    """d_placed(s R x + p) = s · d(x): the moved kernels and mirrors are the same KRS."""
    x = np.random.default_rng(seed).normal(0.0, 2.0, (64, 3))
    krs = tree.krs()
    moved = place.krs(krs)
    y = x @ place.linear.T + np.array(place.position)
    got = distance(compile_krs(moved, (1, 1, 1)), y)
    want = place.scale * distance(compile_krs(krs, (1, 1, 1)), x)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * place.scale * (1 + abs(y).max()))


def error_of(text: str) -> str:
    with pytest.raises(SceneError) as e:
        scene_from_toml(text, "grove.toml")
    return str(e.value)


def test_bad_compounds_get_clear_errors():
    tree = "[[compound]]\n[compound.tree]\nlevels = 3\n"
    msg = error_of(tree * 9)
    assert "grove.toml" in msg and "<9 components>" in msg and "at most 8" in msg
    msg = error_of(
        "[[compound]]\n[compound.tree]\n[compound.krs]\nlevels = [{kernel = {type = 'sphere'}}]\n"
    )
    assert "compound[0].krs / compound[0].tree" in msg and "exactly one" in msg
    assert "MöKRS cannot join" in error_of("[[compound]]\n")
    msg = error_of("[[compound]]\nmokrs = {}\n")
    assert "compound[0].mokrs" in msg and "allowed fields" in msg
    msg = error_of(tree + "[tree]\nlevels = 3\n")
    assert "tree and compound" in msg and "exactly one geometry" in msg
    msg = error_of(tree.replace("[compound.tree]", "scale = 0\n[compound.tree]"))
    assert "compound[0].scale = 0" in msg and "0.001" in msg


def test_compound_round_trips_and_truncates():
    s = compound_scene()
    again = scene_from_toml(scene_to_toml(s))
    assert again.geometry() == s.geometry()
    g = s.geometry()
    assert isinstance(g, Compound) and g.depth == 8
    cut = g.truncated(3)
    assert [p.depth for p in cut.parts] == [3, 3, 1]
    assert s.with_geometry(cut).geometry() == cut


def test_an_edit_of_one_component_compiles_that_component_alone():
    """Compiled components are kept by value: moving one tree of the grove compiles that tree
    anew (equal to compiling it alone), and hands back the others' compiled forms."""
    from krsview.api import load

    grove = load("grove")
    before = compile_geometry(grove.geometry(), (1, 1, 1)).parts
    moved = grove.edit(("compound", 2, "position"), (-4.0, 0.0, 3.0))
    after = compile_geometry(moved.geometry(), (1, 1, 1)).parts
    alone = compile_krs(moved.geometry().parts[2], (1, 1, 1))
    assert all(after[k] is before[k] for k in range(len(before)) if k != 2)
    assert after[2] is not before[2]  # negative control: the moved tree is compiled anew
    for name in ("mirrors", "bounds", "records", "ball"):
        assert np.array_equal(getattr(after[2], name), getattr(alone, name)), name
        assert not np.array_equal(getattr(after[2], name), getattr(before[2], name)), name
