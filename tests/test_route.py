"""The route form of a tree [KRS17 §9.2]: analytic properties of the baked route, exact
reproduction of the growth tree, and defined behaviour on degenerate input."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from krsview.compile.krs import compile_krs
from krsview.reference.krs import distance
from krsview.scene import (
    KRS,
    Capsule,
    Level,
    Route,
    RouteLevel,
    SceneError,
    load_scene,
    save_scene,
    scene_from_toml,
)
from krsview.scene.edits import apply_edit
from krsview.scene.presets import resolve

ALBEDO = (0.5, 0.5, 0.5)


@pytest.fixture(scope="module")
def tree_scene():
    return load_scene(resolve("tree"))


@pytest.fixture(scope="module")
def route(tree_scene):
    return tree_scene.tree.route()


def kernel_distance_at(k, points) -> np.ndarray:
    return distance(compile_krs(KRS([Level(k)]), ALBEDO), np.asarray(points, dtype=float))


def test_each_branch_runs_from_its_lower_fork_to_its_fork_through_its_control(route):
    forks = [route.base] + [lv.fork for lv in route.levels][::-1]  # trunk foot → twig tip
    krs = route.krs()
    n = len(route.levels)
    for i, lv in enumerate(route.levels):
        k = krs.levels[i].kernel
        assert k.start == forks[n - 1 - i] and k.end == lv.fork
        # the centre line (distance −radius) passes through start, control and end: checked
        # with the reference kernel distance, not with the arc construction itself
        d = kernel_distance_at(k, [k.start, lv.control, k.end])
        np.testing.assert_allclose(d, -k.radius, atol=1e-9 * max(1.0, np.abs(lv.fork).max()))


def test_each_mirror_passes_through_its_fork_and_keeps_the_child_on_its_negative_side(route):
    krs = route.krs()
    for i in range(1, len(route.levels)):
        m = krs.levels[i].mirror
        fork = np.array(route.levels[i].fork)
        assert abs(np.array(m.normal) @ fork - m.offset) < 1e-12
        assert math.isclose(np.linalg.norm(m.normal), 1.0, abs_tol=1e-12)
        child_tip = np.array(route.levels[i - 1].fork)
        assert np.array(m.normal) @ child_tip - m.offset < 0, f"child of level {i} is clipped"


def test_baked_route_follows_the_growth_ratios(tree_scene, route):
    t = tree_scene.tree
    starts = route.starts()
    n = len(route.levels) - 1
    for i, lv in enumerate(route.levels):
        length = np.linalg.norm(np.subtract(lv.fork, starts[i]))
        assert math.isclose(length, t.trunk_length * t.length_ratio ** (n - i), rel_tol=1e-12)
        assert math.isclose(lv.radius, t.trunk_radius * t.radius_ratio ** (n - i), rel_tol=1e-12)
    assert len(route.levels) == t.levels + 1


@pytest.mark.parametrize("preset", ["tree", "forest"])
def test_baked_route_reproduces_the_growth_trees_krs_exactly_through_a_file(preset, tmp_path):
    scene = load_scene(resolve(preset))
    baked = replace(scene, tree=None, route=scene.tree.route())
    save_scene(baked, tmp_path / "baked.toml")
    again = load_scene(tmp_path / "baked.toml")
    assert again == baked  # bit-exact TOML round trip
    assert again.geometry() == scene.geometry()  # the same KRS, float for float
    assert "[tree]" not in (tmp_path / "baked.toml").read_text()


def test_a_route_compound_component_is_placed_like_a_tree(tmp_path):
    scene = load_scene(resolve("grove"))
    c0 = scene.compound[0]
    baked = replace(
        scene, compound=[replace(c0, tree=None, route=c0.tree.route())] + scene.compound[1:]
    )
    assert baked.geometry() == scene.geometry()


# ----------------------------------------------------------------------------- degenerate
def small_route() -> Route:
    return Route(
        base=(0.0, 0.0, 0.0),
        levels=[
            RouteLevel(fork=(-0.5, 2.0, 0.0), control=(-0.3, 1.6, 0.0), radius=0.05),
            RouteLevel(
                fork=(0.0, 1.0, 0.0), control=(0.1, 0.5, 0.0), radius=0.1, normal=(1.0, 0.0, 0.0)
            ),
        ],
    )


def scene_of(route: Route):
    return replace(
        scene_from_toml("[krs]\nlevels = [{ kernel = { type = 'empty' } }]\n"),
        krs=None,
        route=route,
    )


def test_control_point_on_the_chord_gives_a_straight_capsule():
    r = small_route()
    a, b = np.array(r.levels[1].fork), np.array(r.base)
    straight = replace(r, levels=[r.levels[0], replace(r.levels[1], control=tuple((a + b) / 2))])
    k = straight.krs().levels[1].kernel
    pts = np.random.default_rng(1).normal(0.5, 1.0, (500, 3))
    np.testing.assert_allclose(
        kernel_distance_at(k, pts),
        kernel_distance_at(Capsule(k.start, k.end, k.radius), pts),
        atol=1e-12,
    )
    # negative control: the bent branch is not that capsule
    bent = r.krs().levels[1].kernel
    assert (
        np.abs(
            kernel_distance_at(bent, pts)
            - kernel_distance_at(Capsule(bent.start, bent.end, bent.radius), pts)
        ).max()
        > 1e-3
    )


@pytest.mark.parametrize(
    "value, allowed",
    [
        ([0.0, 0.0, 0.0], "must not be the zero vector"),
        ([1e-12, 0.0, 0.0], "must not be the zero vector"),
        ([math.nan, 1.0, 0.0], "NaN and infinity are not allowed"),
        ([math.inf, 0.0, 0.0], "NaN and infinity are not allowed"),
    ],
)
def test_a_bad_normal_is_a_clear_error_and_changes_nothing(value, allowed):
    scene = scene_of(small_route())
    with pytest.raises(SceneError) as e:
        apply_edit(scene, ("route", "levels", 1, "normal"), value)
    assert "route.levels[1].normal" in str(e.value) and allowed in str(e.value)


def test_a_tiny_but_valid_normal_is_normalised():
    scene = apply_edit(scene_of(small_route()), ("route", "levels", 1, "normal"), [1e-6, 1e-6, 0.0])
    assert math.isclose(np.linalg.norm(scene.route.levels[1].normal), 1.0, rel_tol=1e-15)


def test_zero_radius_and_fork_on_fork_are_clear_errors():
    scene = scene_of(small_route())
    with pytest.raises(SceneError, match=r"route\.levels\[0\]\.radius = 0\.0: allowed: 0 < value"):
        apply_edit(scene, ("route", "levels", 0, "radius"), 0.0)
    with pytest.raises(
        SceneError,
        match=r"route\.levels\[0\]\.fork .*must differ from "
        r"route\.levels\[1\]\.fork",  # the whole path, as the field's own
    ):
        apply_edit(scene, ("route", "levels", 0, "fork"), [0.0, 1.0, 0.0])
    with pytest.raises(
        SceneError, match=r"route\.levels\[1\]\.fork .*must differ from route\.base"
    ):
        apply_edit(scene, ("route", "levels", 1, "fork"), [0.0, 0.0, 0.0])


def test_level_0_has_no_mirror_and_the_others_need_one():
    r = small_route()
    with pytest.raises(SceneError, match=r"levels\[0\]\.normal"):
        apply_edit(scene_of(r), ("route", "levels", 0, "normal"), [0.0, 1.0, 0.0])
    text = "[route]\nlevels = [{ fork = [0.0, 1.0, 0.0] }, { fork = [0.0, 2.0, 0.0] }]\n"
    with pytest.raises(SceneError, match=r"route\.levels\[1\]\.normal = <missing>"):
        scene_from_toml(text)


def test_a_child_crossing_its_forks_mirror_is_a_warning_naming_the_level():
    r = small_route()
    assert r.warnings() == []
    # turn the mirror so the twig (at x < 0) lies on its positive side: Alg. 1 clips it
    crossed = replace(r, levels=[r.levels[0], replace(r.levels[1], normal=(-1.0, 0.0, 0.0))])
    (w,) = crossed.warnings()
    assert (
        w.startswith(
            "levels[0] (L0): the branch crosses mirror R0 at fork P1, where it grows from "
            "(levels[1].normal)"
        )
        and "clips" in w
    )
    # the shipped trees' small bends stay inside the fork joint: no warning
    assert load_scene(resolve("tree")).tree.route().warnings() == []


def test_the_readme_route_example_loads_without_warnings():
    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    block = readme[readme.index("```toml\n[route]") + 8 :]
    scene = scene_from_toml(block[: block.index("```")], "README.md")
    assert scene.route.warnings() == [] and scene.geometry().instance_count() == 3
    # negative control: turning its mirror puts the twig on the positive side
    turned = replace(
        scene.route,
        levels=[scene.route.levels[0], replace(scene.route.levels[1], normal=(-1.0, 0.0, 0.0))],
    )
    assert turned.warnings()


def test_a_baked_radius_carries_no_float_noise():
    """A grown radius is written as the decimal it stands for (0.1036, not the float
    product 0.10360000000000001), within 1e-14 of the product. Control: the products
    themselves are noisy."""
    from krsview import load

    t = load("tree").tree
    route = t.route()
    n = len(route.levels) - 1
    noisy = 0
    for i, lv in enumerate(route.levels):
        product = t.trunk_radius
        for _ in range(n - i):
            product *= t.radius_ratio
        noisy += len(repr(product)) >= 18
        assert len(repr(lv.radius).lstrip("0.")) <= 15, lv.radius
        assert math.isclose(lv.radius, product, rel_tol=1e-14)
    assert noisy > 0


def test_a_stub_left_of_a_sibling_branch_is_warned_drawn_red_and_not_made_by_an_insert():
    """A fork inserted mid-branch (L20 of the baked tree) grew a sibling (the rest of the
    branch mirrored at the new fork) that reached across the mirror of the fork below:
    Alg. 1 cut it off there, leaving a square stub, with no warning and nothing red. The
    insert now turns the new mirror so that the sibling stays clear (the control: its route
    warns of nothing); turned as the insert turned it before, the route warns, and the part
    drawn red is what Alg. 1's distance (the float64 reference) does not draw: its centre
    line clear of the cut is outside the surface (drawn, it would lie a radius inside),
    while the sibling's kept part is inside it."""
    import krsview
    from krsview.editor.clipped import clipped_parts
    from krsview.scene.restructure import free_normal, split_level, subtree_points, tangent_at
    from krsview.scene.route import centre_at

    tree = krsview.load("tree")
    route = tree.tree.route()
    cut = split_level(route, 20, 0.5)
    assert route.warnings() == cut.warnings() == [] and clipped_parts(cut) == []
    # the normal the insert chose before: the same choice without the fork below
    k = route.kernel(20)
    q, mid_up = centre_at(k, np.array([0.5, 0.75]))
    upper = replace(k, start=tuple(q), control=tuple(mid_up))
    subtree = subtree_points(
        [route.kernel(j) for j in range(20)] + [upper], [route.mirror(j) for j in range(1, 21)]
    )
    child = centre_at(upper, np.linspace(0.0, 1.0, 41))
    before = free_normal(q, tangent_at(k, 0.5), child, subtree, route.levels[20].normal)
    levels = [*cut.levels[:21], replace(cut.levels[21], normal=before), *cut.levels[22:]]
    turned = replace(cut, levels=levels)
    (said,) = turned.warnings()
    assert said.startswith(
        "levels[20] (L20): its mirror image in R20 at fork P21 (the sibling branch) crosses "
        "mirror R21 at fork P22"
    )
    (level, red), *_ = clipped_parts(turned)
    scene = replace(tree, tree=None, route=turned)
    radius = turned.levels[20].radius
    up = turned.mirror(22)
    past = red[(red @ np.array(up.normal) - up.offset) > radius]  # clear of the cut
    assert level == 20 and len(past) and (krsview.distance(scene, past) > 0).all()
    sibling = turned.sibling(21, 65)
    kept = sibling[(sibling @ np.array(up.normal) - up.offset) < -2 * radius]
    assert len(kept) and (krsview.distance(scene, kept) < 0).all()
