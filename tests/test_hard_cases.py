"""Hard cases are inputs, not accidents (DESIGN.md): finite pixels, bounded iterations, and
GPU/reference agreement with the same tolerances as the presets."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.reference import render_reference
from krsview.scene import (KRS, Camera, Empty, Level, Mirror, Plane, Render, Scene, Sphere,
                           load_scene)
from krsview.presets import resolve

from krsview.bench import hard_cases

from .conftest import agreement, assert_finite, check_against_reference, failures

W, H = 120, 90


def tree_scene() -> Scene:
    return load_scene(resolve("tree"))


def camera_on_top_mirror() -> Scene:
    """The eye exactly on mirror R_{n-1} (the first fork's plane), looking along it."""
    s = tree_scene()
    m = s.geometry().mirrors[-1]
    u, w = np.array(m.normal), m.offset
    project = lambda p: np.array(p) - (np.array(p) @ u - w) * u  # noqa: E731
    eye, target = project(s.camera.position), project(s.camera.target)
    assert abs(eye @ u - w) < 1e-12
    return replace(s, camera=replace(s.camera, position=tuple(eye), target=tuple(target)))


def grazing_plane() -> Scene:
    """Rays skimming a ground plane and sphere silhouettes; a low iteration cap is hit."""
    levels = [Level(Sphere((0.0, 0.3, 0.0), 0.3), None),
              Level(Empty(), Mirror((1.0, 0.0, 0.0), 0.8)),
              Level(Plane((0.0, 1.0, 0.0), 0.0, (0.4, 0.5, 0.3)), Mirror((0.0, 0.0, 1.0), 1.5))]
    return Scene(name="grazing", camera=Camera((0.0, 0.02, -4.0), (0.0, 0.0, 10.0)),
                 render=Render(max_iterations=48, max_distance=60.0), krs=KRS(levels))


def camera_inside_trunk() -> Scene:
    s = tree_scene()
    return replace(s, camera=replace(s.camera, position=(0.02, 0.5, 0.01), target=(0.0, 3.0, 1.0)))


def thirty_levels() -> Scene:
    s = tree_scene()
    return replace(s, tree=replace(s.tree, levels=30))


CASES = {"camera_on_mirror": camera_on_top_mirror, "grazing": grazing_plane,
         "inside_kernel": camera_inside_trunk, "levels_30": thirty_levels}


@pytest.mark.parametrize("name", CASES)
def test_hard_case_is_finite_bounded_and_matches_reference(renderer, name):
    scene = CASES[name]()
    gpu = renderer.render(scene, W, H)
    ref = render_reference(scene, W, H)
    assert_finite(gpu, scene.render.max_iterations)
    assert_finite(ref, scene.render.max_iterations)
    check_against_reference(f"hard_{name}", gpu, ref)


def test_grazing_rays_reach_the_cap_and_stop_there(renderer):
    scene = grazing_plane()
    gpu = renderer.render(scene, W, H)
    assert gpu.iterations.max() == scene.render.max_iterations  # the case really is hard


def test_inside_a_kernel_every_ray_hits_at_the_eye(renderer):
    gpu = renderer.render(camera_inside_trunk(), W, H)
    assert gpu.hit.all() and np.all(gpu.depth == 0.0) and np.all(gpu.iterations == 1)


def test_thirty_levels_has_a_billion_instances():
    assert thirty_levels().geometry().instance_count() >= 2**30


def test_image_changes_little_when_the_camera_moves_little(renderer):
    """Continuity: a 1e-6 nudge of the eye across the mirror plane changes few pixels."""
    s = camera_on_top_mirror()
    u = np.array(s.geometry().mirrors[-1].normal)
    a = renderer.render(replace(s, camera=replace(
        s.camera, position=tuple(np.array(s.camera.position) - 1e-6 * u))), W, H)
    b = renderer.render(replace(s, camera=replace(
        s.camera, position=tuple(np.array(s.camera.position) + 1e-6 * u))), W, H)
    assert (a.hit != b.hit).mean() < 0.002
    assert (np.abs(a.color - b.color).max(-1) > 4 / 255).mean() < 0.005


def deep_zoom() -> Scene:
    """The eye a few twig radii from the finest kernel of a 30-level tree: that twig is
    1e-5 of the tree's size, drawn from camera-relative float32 data."""
    s = thirty_levels()
    twig = s.geometry().kernels[0]
    mid = (np.array(twig.start) + np.array(twig.end)) / 2
    axis = np.array(twig.end) - np.array(twig.start)
    side = np.cross(axis, (0.0, 1.0, 0.0))
    side /= np.linalg.norm(side)
    eye = mid + 12 * twig.radius * side
    return replace(s, camera=replace(s.camera, position=tuple(eye), target=tuple(mid)))


def test_deep_zoom_thirty_levels_down_is_stable(renderer):
    scene = deep_zoom()
    assert scene.geometry().kernels[0].radius < 3e-5
    gpu = renderer.render(scene, W, H)
    ref = render_reference(scene, W, H)
    assert_finite(gpu, scene.render.max_iterations)
    assert gpu.hit.mean() > 0.05, "the twig is not in view"
    check_against_reference("hard_deep_zoom", gpu, ref)
    # No jitter: a sub-pixel nudge of the eye (1e-3 twig radii) changes almost nothing.
    nudged = replace(scene, camera=replace(scene.camera, position=tuple(
        np.array(scene.camera.position) + 1e-3 * scene.geometry().kernels[0].radius)))
    again = renderer.render(nudged, W, H)
    assert (again.hit != gpu.hit).mean() < 0.002


@pytest.mark.parametrize("name", ["deep-zoom-1e-6", "deep-zoom-1e-9"])
def test_double_precision_follows_the_reference_where_float_cannot(renderer, name):
    """precision = "double" [issue 15]: at a deep zoom the float64 shader agrees with the
    reference; the float32 one (the negative control) does not: the case is a real limit."""
    case = hard_cases.CASES[name]
    scene = case.build()
    assert case.precision_limit
    ref = render_reference(scene, 48, 27)
    assert 0.3 < ref.hit.mean() < 0.95, "the horizon is not in view"
    double = renderer.render(replace(scene, render=replace(scene.render, precision="double")), 48, 27)
    assert_finite(double, scene.render.max_iterations)
    check_against_reference(f"hard_{name}_double", double, ref)
    single = renderer.render(scene, 48, 27)
    assert scene.render.precision == "float"
    assert failures(agreement(single, ref)), "float32 followed a 1e-6 zoom: not a hard case"


def test_double_precision_uploads_the_geometry_in_float64():
    from krsview.gpu.uniforms import krs_block
    from krsview.reference.geometry import compile_geometry
    s = tree_scene()
    c = compile_geometry(s.geometry(), s.material.albedo)
    single, double = krs_block(c, "float"), krs_block(c, "double")
    assert len(double) == 2 * len(single)
    mirrors = np.frombuffer(double, np.float64)[:4 * c.n].reshape(c.n, 4)
    assert np.array_equal(mirrors, c.mirrors)          # not rounded through float32
    assert not np.array_equal(np.frombuffer(single, np.float32)[:4 * c.n].reshape(c.n, 4)
                              .astype(np.float64), c.mirrors)
