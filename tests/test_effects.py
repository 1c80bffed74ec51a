"""Effects [KRS17 §5, §8; KRS14 §6]: each one against the float64 reference on a small
scene, specialisation proven on the compiled source, and the properties the issue names
(smooth shading removes the crease, distortions never overshoot)."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.geometry import compile_geometry
from krsview.compile.krs import compile_krs
from krsview.gpu.program import SHADER_DIR, Source
from krsview.gpu.renderer import read_buffers
from krsview.gpu.uniforms import variant_defines
from krsview.reference import distance, render_reference
from krsview.reference.distortion import Distortion
from krsview.reference.geometry import scene_distance
from krsview.scene import (
    EFFECTS,
    KRS,
    EffectSettings,
    EmptyZone,
    Level,
    Plane,
    load_scene,
    scene_from_toml,
)
from krsview.scene.presets import resolve

from .conftest import assert_finite, check_against_reference, per_pixel
from .test_distance_bound import ALBEDO, arbitrary_krs, clipped_samples

W, H = 160, 120


def with_effects(scene, effects, **settings):
    return replace(
        scene, effects=effects, effect_settings=replace(scene.effect_settings, **settings)
    )


def tree():
    s = load_scene(resolve("tree"))
    return replace(s, tree=replace(s.tree, levels=14))


# (test id, scene factory): every effect appears at least once; MöKRS where it is allowed.
CASES = {
    "smooth_shading": lambda: with_effects(load_scene(resolve("rock")), ["smooth_shading"]),
    "triplanar_texture": lambda: with_effects(
        load_scene(resolve("rock")), ["triplanar_texture"], texture_strength=1.0
    ),
    "kernel_texture": lambda: with_effects(
        tree(), ["kernel_texture"], texture_scale=0.5, texture_strength=1.0
    ),
    "shadows": lambda: with_effects(tree(), ["shadows"]),
    "soft_shadows": lambda: with_effects(load_scene(resolve("rock")), ["soft_shadows"]),
    "ambient_occlusion": lambda: with_effects(
        load_scene(resolve("rock")), ["ambient_occlusion"], ao_step=0.2, ao_strength=2.0
    ),
    "twist": lambda: with_effects(tree(), ["twist"], twist=25.0),
    "wind": lambda: with_effects(tree(), ["wind"], wind_strength=12.0).at(1.5),
    "empty_zones": lambda: with_effects(
        tree(),
        ["empty_zones"],
        empty_zones=[EmptyZone((1.0, 4.0, 0.0), 1.6), EmptyZone((-2.0, 3.0, 0.5), 0.8)],
    ),
    "sky+fog+tone_mapping": lambda: with_effects(
        tree(), ["sky", "fog", "tone_mapping"], fog_density=0.08
    ),
    "mokrs-shadows+sky": lambda: with_effects(
        load_scene(resolve("tree-mokrs")), ["shadows", "sky", "triplanar_texture"]
    ),
    "mokrs-soft_shadows+fog": lambda: with_effects(
        load_scene(resolve("shell")), ["soft_shadows", "fog", "tone_mapping"]
    ),
}


def test_every_effect_has_a_pixel_test():
    covered = {e for case in CASES for e in case.removeprefix("mokrs-").split("+")}
    assert covered == set(EFFECTS)


@pytest.mark.parametrize("case", CASES)
def test_effect_matches_reference(renderer, case):
    """Every level is drawn: the level of detail's cut, a float comparison, may fall
    differently in float32 and float64 and move a penumbra (tests/test_lod.py)."""
    scene = CASES[case]()
    scene = per_pixel(replace(scene, render=replace(scene.render, lod=0.0)))
    gpu = renderer.render(scene, W, H)
    ref = render_reference(scene, W, H)
    plain = render_reference(replace(scene, effects=[]), W, H)
    assert_finite(gpu, scene.render.max_iterations)
    changed = np.abs(ref.color - plain.color).max(-1) > 4 / 255
    assert changed.mean() > 0.01, f"{case} changes only {changed.mean():.2%} of the pixels"
    check_against_reference(f"effect-{case}", gpu, ref)


def test_all_effects_variant_switched_by_uniforms_equals_the_specialised(renderer):
    """The benchmark's baseline draws the same image: bits on ⇒ the effects, bits off ⇒ none."""
    scene = CASES["shadows"]()
    for effects in (["shadows", "kernel_texture", "fog"], []):
        s = per_pixel(replace(scene, effects=effects))  # the all-effects variant: one pass
        with renderer.current():
            prog = renderer.prepare(s, W, H, all_effects=True)
            uber = read_buffers(renderer.draw(prog, W, H), W, H)
        special = renderer.render(s, W, H)
        assert "u_effects" in prog
        assert (np.abs(uber.color - special.color).max(-1) <= 1 / 255).mean() > 0.999
        assert (uber.hit == special.hit).all()


# ---------------------------------------------------------------- specialisation, proven
def effect_lines(effect: str) -> set[tuple[str, int]]:
    """(file, line) of every shader line that is compiled only for ``effect``: inside a
    positive #ifdef / #if naming KRS_<EFFECT>, or in a file included only there."""
    macro = f"KRS_{effect.upper()}"
    owned: set[tuple[str, int]] = set()
    for path in SHADER_DIR.glob("*"):
        stack: list[bool] = []
        for k, line in enumerate(path.read_text().splitlines(), 1):
            d = re.match(r"\s*#\s*(ifdef|ifndef|if|else|endif)\b(.*)", line)
            if d and d.group(1) in ("ifdef", "if"):
                # a disjunction (#if defined(A) || defined(B)) is not owned by A alone
                stack.append(
                    re.search(rf"\b{macro}\b", d.group(2)) is not None and "||" not in d.group(2)
                )
            elif d and d.group(1) == "ifndef":
                stack.append(False)
            elif d and d.group(1) == "else":
                stack[-1] = False
            elif d and d.group(1) == "endif":
                stack.pop()
            elif any(stack):
                owned.add((path.name, k))
    return owned


@pytest.mark.parametrize("effect", EFFECTS)
def test_a_scene_without_an_effect_compiles_none_of_its_code(effect):
    base = load_scene(resolve("rock"))
    off = replace(base, effects=[])
    on = replace(base, effects=[effect])
    c = compile_geometry(base.geometry(), base.material.albedo)
    src_off = Source("render.frag", variant_defines(off, c))
    src_on = Source("render.frag", variant_defines(on, c))
    owned = effect_lines(effect)
    assert owned, f"no shader code is guarded by KRS_{effect.upper()}"
    assert not owned & set(src_off.origin), "effect code in a variant without the effect"
    assert f"KRS_{effect.upper()}" not in src_off.text
    assert owned & set(src_on.origin), "the effect's own code is missing when it is on"
    assert len(src_on.text) > len(src_off.text)


def test_a_plain_scene_compiles_no_optional_file():
    """The cheap path: none of the effect files, no effect uniform."""
    scene = replace(load_scene(resolve("rock")), effects=[])
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    src = Source("render.frag", variant_defines(scene, c))
    files = {f for f, _ in src.origin}
    for name in (
        "shadows.glsl",
        "occlusion.glsl",
        "texture.glsl",
        "twist.glsl",
        "empty_zones.glsl",
    ):
        assert name not in files
    assert "uniform int u_effects" not in src.text and "shadow_visibility" not in src.text


# ------------------------------------------------------------------------ smooth shading
CREASE = """
[camera]
position = [0.0, 3.0, -4.0]
target = [0.0, 0.0, 0.0]
[material]
background = [0.0, 0.0, 0.0]
[[krs.levels]]
kernel = { type = "plane", normal = [0.37139067635410367, 0.9284766908852593, 0.0], offset = 0.0 }
[[krs.levels]]
kernel = { type = "empty" }
mirror = { normal = [1.0, 0.0, 0.0], offset = 0.0 }
[effect_settings]
smooth_width = 0.6
"""
CREASE_ANGLE = 2 * np.degrees(np.arctan(0.4))  # the two planes' normals differ by 43.6°
SMOOTH_BOUND = 8.0  # degrees between neighbour pixels: the band spans ≥ 10 pixels here


def largest_neighbour_turn(normal: np.ndarray, hit: np.ndarray) -> float:
    a, b = normal[:, :-1], normal[:, 1:]
    both = hit[:, :-1] & hit[:, 1:]
    cos = np.clip((a * b).sum(-1)[both], -1, 1)
    return float(np.degrees(np.arccos(cos)).max())


def test_smooth_shading_removes_the_crease_at_a_mirror(renderer):
    """A plane folded by a mirror makes a roof whose normal jumps by 43.6° on the ridge; with
    the effect the largest change between neighbouring pixels stays under SMOOTH_BOUND."""
    scene = scene_from_toml(CREASE)
    for render in (render_reference, renderer.render):
        flat = largest_neighbour_turn(*_nh(render(scene, W, H)))
        smooth = largest_neighbour_turn(
            *_nh(render(replace(scene, effects=["smooth_shading"]), W, H))
        )
        assert flat > 0.9 * CREASE_ANGLE, flat
        assert smooth < SMOOTH_BOUND, smooth


def _nh(b):
    return b.normal, b.hit


# ------------------------------------------------------------------- distortion bounds
def twist_forward(p: np.ndarray, k: float, center: np.ndarray) -> np.ndarray:
    """The twist f itself, written independently of the reference's inverse: turn (x, z)
    around the vertical axis through ``center`` by k × height."""
    r = p - center
    a = k * r[:, 1]
    rot = np.stack(
        [
            r[:, 0] * np.cos(a) - r[:, 2] * np.sin(a),
            r[:, 1],
            r[:, 0] * np.sin(a) + r[:, 2] * np.cos(a),
        ],
        axis=1,
    )
    return center + rot


def twisted_bound(krs, k_deg, center, x, lipschitz=True):
    d = Distortion(np.radians(k_deg), np.asarray(center, float), np.zeros((0, 4)))
    D = distance(compile_krs(krs, ALBEDO), d.untwist(x))
    return d.twist_step(x, D) if lipschitz else D


@pytest.mark.parametrize("seed", range(12))
def test_twisted_distance_never_overshoots(seed):
    """Against brute force: points sampled inside the clipped expansion, twisted forward, are
    never nearer than the bound [KRS17 §5.2]."""
    rng = np.random.default_rng(seed)
    krs = arbitrary_krs(rng, int(rng.integers(1, 6)))
    k, center = rng.uniform(-90, 90), rng.normal(size=3)
    samples = twist_forward(clipped_samples(krs, rng, 400), np.radians(k), center)
    if len(samples) == 0:
        return
    x = rng.normal(size=(300, 3)) * 3.0
    bound = twisted_bound(krs, k, center, x)
    nearest = np.min(np.linalg.norm(x[:, None] - samples[None], axis=2), axis=1)
    assert np.all(bound <= nearest + 1e-9), (bound - nearest).max()


def test_twist_without_the_lipschitz_factor_would_overshoot():
    """The check above can fail: the undistorted distance alone overshoots a strong twist."""
    krs = KRS([Level(Plane((0.0, 0.0, 1.0), -1.0))])  # the half-space z ≤ −1 … twisted
    x = np.array([[3.0, 0.0, 0.0]])
    naive = twisted_bound(krs, 90.0, (0, 0, 0), x, lipschitz=False)[0]
    safe = twisted_bound(krs, 90.0, (0, 0, 0), x)[0]
    u, v = np.meshgrid(np.linspace(-8, 8, 801), np.linspace(-3, 3, 601))
    plane = np.stack([u.ravel(), v.ravel(), np.full(u.size, -1.0)], 1)
    true = np.min(np.linalg.norm(twist_forward(plane, np.radians(90.0), np.zeros(3)) - x, axis=1))
    assert naive > 4 * true and 0.5 * true < safe <= true


@pytest.mark.parametrize("seed", range(6))
def test_empty_zones_keep_the_bound_and_remove_what_they_cover(seed):
    rng = np.random.default_rng(seed)
    krs = arbitrary_krs(rng, 4)
    zones = [EmptyZone(tuple(rng.normal(size=3)), float(rng.uniform(0.3, 1.5))) for _ in range(3)]
    scene = replace(
        load_scene(resolve("rock")),
        krs=krs,
        effects=["empty_zones"],
        effect_settings=EffectSettings(empty_zones=zones),
    )
    c = compile_krs(krs, ALBEDO)
    dist = Distortion.of(scene)
    samples = clipped_samples(krs, rng, 400)
    depth, _ = dist.zone_depth(samples)
    kept = samples[depth < 0]
    if len(kept) == 0:
        return
    x = rng.normal(size=(300, 3)) * 3.0
    bound = scene_distance(c, x, dist)
    nearest = np.min(np.linalg.norm(x[:, None] - kept[None], axis=2), axis=1)
    assert np.all(bound <= nearest + 1e-9)
    inside = np.array([z.center for z in zones])
    assert np.all(scene_distance(c, inside, dist) > 0), "a zone's centre is not empty"


def test_a_ground_planes_texture_has_no_streaks():
    """The bark's stretch (long along a branch) drew a ground plane as horizontal streaks
    that read as motion blur (grove, forest): a plane's texture is now as fine along both
    of its axes. Measured on the float64 twin: the mean change of the pattern between
    points a small step apart, along each axis of the plane. Control: the bark's stretch on
    the same plane (the old texture) changes several times faster along one axis."""
    from krsview.compile.constants import BARK_STRETCH
    from krsview.reference.texture import fbm, kernel_texture, kernel_uv

    plane = np.zeros((3, 4))
    plane[1, :3] = (0.0, 1.0, 0.0)  # the ground's normal
    t = np.linspace(0.0, 20.0, 4001)
    fine = np.full(len(t), 1e-6)  # a footprint that filters nothing

    def along(axis):
        x = np.zeros((len(t), 3))
        x[:, axis] = t
        return x

    def roughness(pattern):
        return np.abs(np.diff(pattern)).mean()

    a, b = (roughness(kernel_texture("plane", plane, along(k), fine, 0.5)) for k in (0, 2))
    assert 0.8 < a / b < 1.25, (a, b)
    old = [
        roughness(fbm(np.array(BARK_STRETCH) * kernel_uv("plane", plane, along(k)) / 0.5, fine))
        for k in (0, 2)
    ]
    assert max(old) / min(old) > 4.0, old


@pytest.mark.filterwarnings("ignore::RuntimeWarning")  # the control's overflow in NumPy too
def test_the_finest_texture_and_the_slowest_gust_allowed_draw_as_the_reference(renderer):
    """The floors of texture_scale and wind_frequency (scene/effects.py's SHORTEST and
    SLOWEST_GUST; wind_height shares the first) draw what the float64 reference draws, and a
    value below each is refused in one line. Negative control: past the schema, at 1e-39
    the GPU's float32 1/x overflows, the texture turns black and the sway's phase infinite,
    and the frames leave the reference (the images the floors were set against)."""
    from krsview.scene import SceneError
    from krsview.scene.effects import SHORTEST, SLOWEST_GUST

    rock, wind = load_scene(resolve("rock")), load_scene(resolve("tree-wind"))
    cases = {"texture_scale": (rock, 0.0, SHORTEST), "wind_frequency": (wind, 2.5, SLOWEST_GUST)}
    for field, (scene, t, floor) in cases.items():
        with pytest.raises(SceneError, match=rf"effect_settings\.{field} = 1e-39: allowed"):
            scene.edit(f"effect_settings.{field}", 1e-39)
        for value, agrees in ((floor, True), (1e-39, False)):
            settings = replace(scene.effect_settings, **{field: value})  # past the schema
            s = per_pixel(
                replace(scene, effect_settings=settings, render=replace(scene.render, lod=0.0))
            )
            s = s.at(t)
            gpu, ref = renderer.render(s, 48, 27), render_reference(s, 48, 27)
            apart = (np.abs(gpu.color - ref.color).max(-1) > 8 / 255).mean()
            assert (apart < 0.02) == agrees, (field, value, apart)
