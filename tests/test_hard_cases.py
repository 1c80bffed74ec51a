"""Hard cases are inputs, not accidents (docs/architecture.md): the catalogue in
krsview.bench.hard_cases, each case with its invariants (finite, within the cap and capped rays
counted, continuous, GPU = reference or a documented precision limit) and the behaviour written
beside it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.bench import hard_cases, stability
from krsview.bench.hard_cases import CASES
from krsview.reference import render_reference

from .conftest import agreement, assert_finite, check_against_reference, failures, per_pixel

W, H = 120, 90


def test_the_catalogue_names_at_least_fifteen_cases_with_expectations():
    assert len(CASES) >= 15
    for name, case in CASES.items():
        assert case.name == name and len(case.expect) > 20


@pytest.mark.parametrize("name", CASES)
def test_hard_case_keeps_its_invariants(renderer, name):
    case = CASES[name]
    o = stability.check(case.build(), renderer)
    assert o.finite and o.within_cap, o
    assert o.changed <= stability.CONTINUITY, f"a 1/100-pixel nudge changed {o.changed:.2%}"
    assert o.agreement == "ok", o.agreement
    # a documented float32 limit is met by the double shader, and only such a case needs it
    assert o.precision == ("double" if case.precision_limit else "float"), o.precision
    # capped rays are expected (and then counted on both sides) or absent
    if case.capped:
        assert o.capped_reference > 0 and abs(o.capped_gpu - o.capped_reference) <= 0.01 * np.prod(
            stability.SIZE
        ), o
    else:
        assert o.capped_reference == 0 and o.capped_gpu == 0, o


def test_continuity_measure_sees_a_real_move(renderer):
    """Negative control of the continuity invariant: a 10-pixel move changes many pixels."""
    scene = CASES["camera-on-mirror"].build()
    a = renderer.render(scene, *stability.SIZE)
    moved = scene
    for _ in range(1000):  # 1000 nudges of 1/100 pixel
        moved = stability.nudged(moved, stability.SIZE)
    b = renderer.render(moved, *stability.SIZE)
    assert (a.hit != b.hit).mean() > stability.CONTINUITY


def test_grazing_rays_reach_the_cap_and_stop_there(renderer):
    scene = CASES["grazing-ground"].build()
    gpu = renderer.render(scene, W, H)
    assert gpu.iterations.max() == scene.render.max_iterations  # the case really is hard


def test_inside_a_kernel_every_ray_hits_at_the_eye(renderer):
    gpu = renderer.render(CASES["inside-kernel"].build(), W, H)
    assert gpu.hit.all() and np.all(gpu.depth == 0.0) and np.all(gpu.iterations == 1)


def test_inside_a_mobius_solid_every_ray_hits_at_the_eye(renderer):
    """Binary tracing at t = 0 inside a solid: ε(0) = 0, so a blocked probe converges at
    MIN_PROBE on both sides (the float32 probe used to underflow to 0 and hit while the
    float64 one reached the cap)."""
    scene = CASES["mobius-alpha-zero"].build()
    inside = replace(scene, camera=replace(scene.camera, position=(0.3, 0.4, -3.0)))
    gpu, ref = renderer.render(inside, 32, 18), render_reference(inside, 32, 18)
    for b in (gpu, ref):
        assert b.hit.all() and np.all(b.depth == 0.0)
    assert np.array_equal(gpu.iterations, ref.iterations)


def test_levels_cases_have_the_instances_they_claim():
    assert CASES["levels-30"].build().geometry().instance_count() >= 2**30
    assert CASES["levels-63"].build().geometry().instance_count() == 2**64 - 1


def test_image_changes_little_when_the_camera_crosses_a_mirror(renderer):
    """Continuity: a 1e-6 nudge of the eye across the mirror plane changes few pixels."""
    s = CASES["camera-on-mirror"].build()
    u = np.array(s.geometry().mirrors[-1].normal)
    a = renderer.render(
        replace(
            s, camera=replace(s.camera, position=tuple(np.array(s.camera.position) - 1e-6 * u))
        ),
        W,
        H,
    )
    b = renderer.render(
        replace(
            s, camera=replace(s.camera, position=tuple(np.array(s.camera.position) + 1e-6 * u))
        ),
        W,
        H,
    )
    assert (a.hit != b.hit).mean() < 0.002
    assert (np.abs(a.color - b.color).max(-1) > 4 / 255).mean() < 0.005


def deep_zoom_thirty_levels():
    """The eye a few twig radii from the finest kernel of a 30-level tree: that twig is
    1e-5 of the tree's size, drawn from camera-relative float32 data."""
    s = CASES["levels-30"].build()
    twig = s.geometry().kernels[0]
    mid = (np.array(twig.start) + np.array(twig.end)) / 2
    axis = np.array(twig.end) - np.array(twig.start)
    side = np.cross(axis, (0.0, 1.0, 0.0))
    side /= np.linalg.norm(side)
    return hard_cases.look(s, mid + 12 * twig.radius * side, mid)


def test_deep_zoom_thirty_levels_down_is_stable(renderer):
    scene = per_pixel(deep_zoom_thirty_levels())
    assert scene.geometry().kernels[0].radius < 3e-5
    gpu = renderer.render(scene, W, H)
    ref = render_reference(scene, W, H)
    assert_finite(gpu, scene.render.max_iterations)
    assert gpu.hit.mean() > 0.05, "the twig is not in view"
    check_against_reference("hard_deep_zoom", gpu, ref)
    # No jitter: a sub-pixel nudge of the eye (1e-3 twig radii) changes almost nothing.
    nudged = replace(
        scene,
        camera=replace(
            scene.camera,
            position=tuple(
                np.array(scene.camera.position) + 1e-3 * scene.geometry().kernels[0].radius
            ),
        ),
    )
    again = renderer.render(nudged, W, H)
    assert (again.hit != gpu.hit).mean() < 0.002


@pytest.mark.parametrize("name", ["deep-zoom-1e-6", "deep-zoom-1e-9"])
def test_double_precision_follows_the_reference_where_float_cannot(renderer, name):
    """precision = "double" [issue 15]: at a deep zoom the float64 shader agrees with the
    reference; the float32 one (the negative control) does not: the case is a real limit."""
    case = CASES[name]
    scene = case.build()
    assert case.precision_limit
    ref = render_reference(scene, 48, 27)
    assert 0.3 < ref.hit.mean() < 0.95, "the horizon is not in view"
    double = renderer.render(
        replace(scene, render=replace(scene.render, precision="double")), 48, 27
    )
    assert_finite(double, scene.render.max_iterations)
    check_against_reference(f"hard_{name}_double", double, ref)
    single = renderer.render(scene, 48, 27)
    assert scene.render.precision == "float"
    assert failures(agreement(single, ref)), "float32 followed a 1e-6 zoom: not a hard case"


def test_double_precision_uploads_the_geometry_in_float64():
    from krsview.compile.geometry import compile_geometry
    from krsview.gpu.uniforms import krs_block

    s = hard_cases.preset("tree")
    c = compile_geometry(s.geometry(), s.material.albedo)
    single, double = krs_block(c, "float"), krs_block(c, "double")
    assert len(double) == 2 * len(single)
    mirrors = np.frombuffer(double, np.float64)[: 4 * c.n].reshape(c.n, 4)
    assert np.array_equal(mirrors, c.mirrors)  # not rounded through float32
    assert not np.array_equal(
        np.frombuffer(single, np.float32)[: 4 * c.n].reshape(c.n, 4).astype(np.float64), c.mirrors
    )


def test_a_twisted_ground_plane_stays_a_plane(monkeypatch):
    """A horizontal plane is invariant under a twist about a vertical axis, so twisting it
    must not add a single hit [issue 16: the horizon rose]. Far rays may run out of
    iterations (counted as capped, drawn as sky) — never stop above the ground. Negative
    control: with ε not scaled by the twist's Lipschitz bound, the horizon rises again."""
    from krsview.reference import distortion
    from krsview.scene import KRS, Camera, Level, Plane, Render, Scene

    plane = Scene(
        name="ground",
        camera=Camera((0.0, 2.0, -10.0), (0.0, 1.5, 10.0)),
        render=Render(max_distance=100.0),
        krs=KRS([Level(Plane((0.0, 1.0, 0.0), 0.0, (0.4, 0.5, 0.3)), None)]),
    )
    flat = render_reference(plane, 80, 45)
    twisted = replace(
        plane, effects=["twist"], effect_settings=replace(plane.effect_settings, twist=8.0)
    )
    t = render_reference(twisted, 80, 45)
    assert not (t.hit & ~flat.hit).any()
    capped = (t.iterations >= plane.render.max_iterations) & ~t.hit
    assert (flat.hit & ~t.hit & ~capped).sum() == 0  # every lost ground pixel is counted
    monkeypatch.setattr(distortion.Distortion, "lod_scale", lambda self, p: np.ones(len(p)))
    rose = render_reference(twisted, 80, 45)
    assert (rose.hit & ~flat.hit).sum() > 100


def test_control_on_chord_really_degenerates_to_a_capsule():
    from krsview.compile.krs import compile_krs

    types = compile_krs(CASES["control-on-chord"].build().geometry(), (1.0, 1.0, 1.0)).types
    assert types[-1] == "capsule" and types[-2] == "toroidal_capsule"
