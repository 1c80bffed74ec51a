"""The compute path [issue 17 §3]: rays in a storage buffer, traced in rounds of a few
iterations, finished rays leaving the queue, the next round sized by the GPU (indirect
dispatch), shading deferred over a G-buffer. It takes the same steps as the fragment path,
so the image is the same, bit for bit, for every tracer and geometry family, with and without
the pre-pass, whole or drawn in bands. Negative control: rounds that drop the rays still
live (no requeue) lose them."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from krsview.gpu.renderer import Renderer
from krsview.scene import load_scene
from krsview.scene.presets import preset_names, resolve
from krsview.scene.render import VIEW_PREPASS

from .conftest import broken_shaders, same, same_field

W, H = 64, 36


def on_path(scene, path, **render):
    """``scene`` on ``path`` with ``render`` knobs, a shadow ray per pixel: the compute path
    traces no other (passes.still_ratio), so the fragment path's image it equals is that."""
    return replace(scene, render=replace(scene.render, path=path, shadow_block=1, **render))


@pytest.mark.parametrize(
    "name, tracer",
    [
        ("tree", "sphere"),
        ("tree", "binary"),
        ("tree", "relaxed"),
        ("grove", "sphere"),
        ("grove", "binary"),
        ("palm", "binary"),
        ("inversion", "binary"),
        ("sierpinski", "sphere"),
    ],
)
@pytest.mark.parametrize("prepass", [0, 8])
def test_compute_image_equals_fragment_image(renderer, name, tracer, prepass):
    scene = on_path(load_scene(resolve(name)), "fragment", tracer=tracer, prepass=prepass)
    fragment = renderer.render(scene, W, H)
    compute = renderer.render(on_path(scene, "compute", steps=4), W, H)
    assert same(fragment, compute)
    assert fragment.hit.any() and (fragment.iterations > 4).any()  # several rounds ran


@pytest.mark.parametrize("name", preset_names())
def test_every_preset_draws_the_same_on_both_paths(renderer, name):
    """Every preset with its own tracer and effects, at the viewer's pre-pass: the compute
    path's image equals the fragment path's, bit for bit."""
    scene = on_path(load_scene(resolve(name)), "fragment", prepass=VIEW_PREPASS)
    assert same(
        renderer.render(scene, W, H), renderer.render(on_path(scene, "compute", steps=4), W, H)
    )


def test_compute_in_bands_double_precision_and_any_round_size(renderer):
    """Drawn in progress bands (each band its own rays and rounds), in double precision,
    and with rounds of 1 or 1000 iterations: the same image."""
    scene = on_path(load_scene(resolve("tree")), "fragment")
    fragment = renderer.render(on_path(scene, "fragment", precision="double"), W, H)
    banded = renderer.render(
        on_path(scene, "compute", precision="double", steps=3),
        W,
        H,
        progress=lambda done, total: None,
    )
    assert same(fragment, banded)
    plain = renderer.render(scene, W, H)
    for steps in (1, 1000):
        assert same(plain, renderer.render(on_path(scene, "compute", steps=steps), W, H))


def test_rounds_that_drop_live_rays_lose_them(tmp_path, renderer):
    """Negative control: a copy of the compute shader that does not requeue the rays still
    live after a round leaves them out of the image."""
    shaders = broken_shaders(
        tmp_path,
        "compute.comp",
        "if (r.state == RAY_LIVE) requeue(ray);",
        "",
    )
    scene = on_path(load_scene(resolve("tree")), "compute", steps=2)
    broken = Renderer(shader_dir=shaders).render(scene, W, H)
    assert not same(renderer.render(scene, W, H), broken)
    assert not same(renderer.render(on_path(scene, "fragment"), W, H), broken)


@pytest.mark.parametrize(
    "name, effects, tracer",
    [
        ("tree", None, "sphere"),  # soft shadows, a KRS
        ("grove", None, "binary"),  # soft shadows, a compound
        ("palm", ["shadows", "sky"], "binary"),  # hard shadows, a MöKRS
        ("palm", ["soft_shadows"], "binary"),
        ("rock", None, "sphere"),  # soft shadows with occlusion and textures
    ],
)
def test_shadow_rays_traced_as_tasks_shade_the_same_image(renderer, name, effects, tracer):
    """The compute path traces shadow rays as tasks of their own (one per hit pixel and
    light, in rounds through the same queues) and shades with their visibilities: the image
    equals the fragment path's, where shade() traces them inline."""
    scene = load_scene(resolve(name))
    scene = on_path(
        replace(scene, effects=effects if effects is not None else scene.effects),
        "fragment",
        tracer=tracer,
    )
    from krsview.compile.geometry import compile_geometry
    from krsview.gpu.uniforms import variant_defines

    c = compile_geometry(scene.geometry(), scene.material.albedo)
    assert "KRS_SHADOW_TASKS" in variant_defines(on_path(scene, "compute"), c)
    fragment = renderer.render(scene, W, H)
    assert same(fragment, renderer.render(on_path(scene, "compute", steps=3), W, H))
    inline = on_path(scene, "compute", steps=3, shadow_tasks="off")  # the knob's other side
    assert "KRS_SHADOW_TASKS" not in variant_defines(inline, c)
    assert same(fragment, renderer.render(inline, W, H))
    unshadowed = replace(scene, effects=[e for e in scene.effects if "shadows" not in e])
    assert not np.array_equal(fragment.color, renderer.render(unshadowed, W, H).color)


def test_shadow_rounds_that_drop_live_tasks_lose_the_shadows(tmp_path, renderer):
    """Negative control: shadow tasks not requeued after a round count as lit."""
    shaders = broken_shaders(
        tmp_path,
        "compute.comp",
        "if (sh.state == SHADOW_LIVE) requeue(slot);",
        "",
    )
    scene = on_path(replace(load_scene(resolve("palm")), effects=["shadows"]), "compute", steps=2)
    broken = Renderer(shader_dir=shaders).render(scene, W, H)
    good = renderer.render(scene, W, H)
    assert np.array_equal(good.hit, broken.hit) and not np.array_equal(good.color, broken.color)


@pytest.mark.parametrize("tracer, prepass", [("sphere", 0), ("binary", 0), ("sphere", 8)])
def test_a_task_per_component_keeps_every_hit(renderer, tracer, prepass):
    """A compound on the compute path with a task per pixel and component: each component
    traced to its own hit, the nearest kept. The ray's nearest component converges at the
    same point whether or not the others are interleaved with it, so colour, depth, normal
    and hits equal the fragment path's; the tasks do more work (the others run on past the
    nearest hit), and the iterations are their sum."""
    from krsview.compile.geometry import compile_geometry
    from krsview.gpu.uniforms import variant_defines

    scene = on_path(load_scene(resolve("grove")), "fragment", tracer=tracer, prepass=prepass)
    tasks = on_path(scene, "compute", steps=4, component_tasks="on")
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    assert "KRS_COMPONENT_TASKS" in variant_defines(tasks, c)
    assert "KRS_COMPONENT_TASKS" not in variant_defines(on_path(scene, "compute"), c)
    fragment, traced = renderer.render(scene, W, H), renderer.render(tasks, W, H)
    assert same(fragment, traced, ("color", "depth", "normal", "hit"))
    assert fragment.hit.any() and (traced.iterations >= fragment.iterations).all()
    assert (traced.iterations > fragment.iterations).any()


def test_component_tasks_count_the_cap_per_task(renderer):
    """The iteration cap counts each task's steps: where the fragment path's ray stopped
    short of the cap, the image is the same; some capped rays find their hit as tasks."""
    scene = on_path(load_scene(resolve("grove")), "fragment", max_iterations=12)
    fragment = renderer.render(scene, W, H)
    traced = renderer.render(on_path(scene, "compute", component_tasks="on"), W, H)
    free = fragment.iterations < 12
    assert (~free).any()
    for field in ("color", "depth", "hit"):
        assert same_field(getattr(fragment, field)[free], getattr(traced, field)[free], field)
    assert (traced.hit & ~fragment.hit).any()


def test_keeping_the_farthest_component_hit_fails(tmp_path, renderer):
    """Negative control: a resolve pass that keeps the farthest of a pixel's component hits
    draws trees behind the ones in front."""
    shaders = broken_shaders(tmp_path, "compute.comp", "q.t < r.t", "q.t > r.t")
    scene = on_path(load_scene(resolve("grove")), "compute", component_tasks="on")
    broken = Renderer(shader_dir=shaders).render(scene, W, H)
    good = renderer.render(scene, W, H)
    assert np.array_equal(good.hit, broken.hit) and not np.array_equal(good.depth, broken.depth)
