"""The catalogue of hard cases: named scenes, each with the behaviour expected of it written
beside it (docs/architecture.md: hard cases are inputs, not accidents). The tests and
``krsview check --stability hard`` run the invariants of :mod:`krsview.bench.stability` over
every case; docs/stability.md reports the outcomes."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..algebra.vectors import cross
from ..compile.camera import pixel_ray, view_of
from ..compile.geometry import compile_geometry
from ..reference.geometry import component_distances, nearest, scene_distance
from ..reference.trace import sphere_trace
from ..scene import (
    KRS,
    Camera,
    Capsule,
    Component,
    Empty,
    Level,
    Mirror,
    Plane,
    Render,
    Scene,
    Sphere,
    load_scene,
)
from ..scene.presets import resolve


@dataclass(frozen=True)
class HardCase:
    name: str
    build: Callable[[], Scene]
    expect: str  # what must hold, in words
    precision_limit: str = ""  # where float32 on the GPU cannot follow, and the mitigation
    capped: bool = False  # rays are expected to reach the iteration cap (counted)


# ------------------------------------------------------------------------------ helpers
def preset(name: str) -> Scene:
    return load_scene(resolve(name))


def look(scene: Scene, position, target, fov_y: float | None = None) -> Scene:
    cam = replace(
        scene.camera, position=tuple(map(float, position)), target=tuple(map(float, target))
    )
    return replace(scene, camera=cam if fov_y is None else replace(cam, fov_y=fov_y))


def surface_point(
    scene: Scene, x: float, y: float, width: int = 64, height: int = 36
) -> tuple[np.ndarray, np.ndarray]:
    """The surface point seen through window point (x, y) of the scene's camera, and its
    world normal: the reference traces the ray (at the view's own level of detail), then
    Newton steps p ← p − d(p)·n(p) put p on the surface to float64 rounding (the traced hit
    is only within ε of it)."""
    view = view_of(scene.camera, width, height)
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    d = pixel_ray(view, x, y)[None]
    tr = sphere_trace(component_distances(c, None), view.origin, d, view.footprint, 4096, 1e3)
    if not tr.hit[0]:
        raise ValueError(f"{scene.name}: no surface at window point ({x}, {y})")
    p = view.origin + tr.t[0] * d[0]
    for _ in range(32):
        _, n, _ = nearest(c, p[None])
        p = p - scene_distance(c, p[None])[0] * n[0]
    return p, n[0]


def zoomed(scene: Scene, x: float, y: float, scale: float) -> Scene:
    """The camera about ``scale`` scene units from the surface point at window point (x, y),
    looking at it at a grazing 14°, so the surface's horizon crosses the image: a deep zoom
    when ``scale`` is 1e-6 of the scene's size."""
    p, n = surface_point(scene, x, y)
    side = cross(n, scene.camera.up)
    if np.linalg.norm(side) < 1e-9:
        side = cross(n, (1.0, 0.0, 0.0))
    eye = p + scale * (0.25 * n + side / np.linalg.norm(side))
    return replace(look(scene, eye, p), name=f"{scene.name}-zoom-{scale:g}")


def tree_levels(levels: int) -> Scene:
    s = preset("tree")
    return replace(s, name=f"tree-{levels}", tree=replace(s.tree, levels=levels))


def krs_scene(name: str, levels: list[Level], camera: Camera, **render) -> Scene:
    return Scene(name=name, camera=camera, render=Render(**render), krs=KRS(levels))


# ------------------------------------------------------------------------------ the cases
def camera_on_mirror() -> Scene:
    """The eye exactly on mirror R_{n−1} (the first fork's plane), looking along it."""
    s = preset("tree")
    m = s.geometry().mirrors[-1]
    u, w = np.array(m.normal), m.offset
    on = lambda p: np.array(p) - (np.array(p) @ u - w) * u  # noqa: E731
    return look(s, on(s.camera.position), on(s.camera.target))


def points_on_planes() -> Scene:
    """Kernel centres and the eye's line of sight exactly on the mirror planes: every fold
    meets e = u·x − w = 0 exactly (a sphere centred on each of three mirrors)."""
    return krs_scene(
        "points-on-planes",
        [
            Level(Sphere((0.0, 0.5, 0.0), 0.3), None),
            Level(Sphere((0.0, 1.2, 0.0), 0.2), Mirror((1.0, 0.0, 0.0), 0.0)),
            Level(Sphere((0.0, 0.5, 0.0), 0.15), Mirror((0.0, 0.0, 1.0), 0.0)),
            Level(Empty(), Mirror((0.0, 1.0, 0.0), 0.5)),
        ],
        Camera((0.0, 0.5, -4.0), (0.0, 0.5, 0.0)),
    )


def grazing_ground() -> Scene:
    """Rays skimming a ground plane and sphere silhouettes; a low cap of 48 is reached."""
    return krs_scene(
        "grazing-ground",
        [
            Level(Sphere((0.0, 0.3, 0.0), 0.3), None),
            Level(Empty(), Mirror((1.0, 0.0, 0.0), 0.8)),
            Level(Plane((0.0, 1.0, 0.0), 0.0, (0.4, 0.5, 0.3)), Mirror((0.0, 0.0, 1.0), 1.5)),
        ],
        Camera((0.0, 0.02, -4.0), (0.0, 0.0, 10.0)),
        max_iterations=48,
        max_distance=60.0,
    )


def grazing_kernel() -> Scene:
    """The line of sight runs along a capsule's surface, tangent to it, and along its mirror
    copy: steps shrink to the distance to the surface for the whole length."""
    r = 0.2
    return krs_scene(
        "grazing-kernel",
        [
            Level(Capsule((0.0, 0.0, 0.0), (0.0, 0.0, 6.0), r), None),
            Level(Empty(), Mirror((1.0, 0.0, 0.0), 0.5)),
        ],
        Camera((0.0, r, -2.0), (0.0, r, 6.0)),
    )


def inside_kernel() -> Scene:
    s = preset("tree")
    return look(s, (0.02, 0.5, 0.01), (0.0, 3.0, 1.0))


def inside_crown() -> Scene:
    """The eye inside the tree's crown (its bounding region), among the branches."""
    s = preset("tree")
    return look(s, (0.3, 5.2, -0.4), (0.0, 5.8, 1.0))


def tiny_radii() -> Scene:
    """A KRS of radius-1e-6 spheres 1e-5 apart, seen from 1e-5: all lengths tiny."""
    return krs_scene(
        "tiny-radii",
        [
            Level(Sphere((0.0, 0.0, 0.0), 1e-6), None),
            Level(Empty(), Mirror((1.0, 0.0, 0.0), 2e-6)),
            Level(Empty(), Mirror((0.0, 1.0, 0.0), 2e-6)),
        ],
        Camera((0.0, 2e-6, -2e-5), (2e-6, 2e-6, 0.0)),
        max_distance=1e-3,
    )


def huge_radii() -> Scene:
    """Spheres of radius 1e8 (scene coordinates near the validated 1e9), seen from 5e8."""
    return krs_scene(
        "huge-radii",
        [Level(Sphere((0.0, 0.0, 0.0), 1e8), None), Level(Empty(), Mirror((1.0, 0.0, 0.0), 1.5e8))],
        Camera((1.5e8, 5e7, -5e8), (1.5e8, 0.0, 0.0)),
        max_distance=1e9,
    )


def parallel_mirrors() -> Scene:
    """Two mirrors 1e-6 rad apart: their images pile up along a thin wedge."""
    a = 1e-6
    return krs_scene(
        "parallel-mirrors",
        [
            Level(Sphere((-0.6, 0.5, 0.0), 0.3), None),
            Level(Empty(), Mirror((1.0, 0.0, 0.0), 0.0)),
            Level(Empty(), Mirror((math.cos(a), math.sin(a), 0.0), 0.0)),
        ],
        Camera((0.0, 1.5, -4.0), (0.0, 0.5, 0.0)),
    )


def compound_overlap() -> Scene:
    """Two trees of a compound whose crowns interpenetrate, and a ground plane."""
    s = preset("tree")
    t = replace(s.tree, levels=12, ground=None)
    comps = [Component(tree=t), Component(tree=t, position=(0.8, 0.0, 0.3), angle=70.0)]
    return replace(
        s,
        name="compound-overlap",
        tree=None,
        compound=comps,
        effects=[],
        camera=replace(s.camera, position=(0.5, 3.0, -9.0), target=(0.4, 3.0, 0.0)),
    )


def twist_ground() -> Scene:
    """Twist over a ground plane: far from the axis the twist's Lipschitz bound 1 + |k|ρ
    shrinks every step. Converging on that shrunken step at ε(t) stopped rays up to
    (1 + |k|ρ)·ε above the ground (the horizon rose); ε now shrinks with it, and distant
    ground rays take many iterations instead, some reaching the cap (counted)."""
    s = preset("forest")
    fx = replace(s.effect_settings, twist=8.0)
    return replace(s, name="twist-ground", effects=["twist"], effect_settings=fx)


def mobius_pole_in_view() -> Scene:
    """`inversion` looking straight at the world pole of its outer level (12, 12, 12): rays
    pass through and near the pole, which lies 24.8 units from every sphere."""
    s = preset("inversion")
    return look(s, s.camera.position, (12.0, 12.0, 12.0), fov_y=5.0)


def mobius_alpha_zero() -> Scene:
    """A sphere that passes 1e-4 from the inversion centre: its image is a sphere of radius
    ~1e4, nearly a plane (α → 0 in App. A's αx² + β·x + γ)."""
    return _inversion_of_sphere("mobius-alpha-zero", (0.0, 0.0, 1.0 + 1e-4), 1.0)


def mobius_gamma_zero() -> Scene:
    """A sphere through the origin's image: after the inversion the sphere passes 1e-7 from
    the world origin (γ → 0)."""
    return _inversion_of_sphere("mobius-gamma-zero", (0.0, 0.0, 3.0), 2.0 - 1e-7)


def _inversion_of_sphere(name: str, center, radius: float) -> Scene:
    from ..scene import Invert, MobiusLevel, MoKRS

    lv = MobiusLevel(
        kernel=Sphere(tuple(center), radius),
        reflect=False,
        transform=[Invert((0.0, 0.0, 0.0), 1.0)],
    )
    return Scene(
        name=name,
        camera=Camera((0.3, 0.4, 3.0), (0.0, 0.0, 0.0)),
        render=Render(tracer="binary", max_distance=200.0),
        mokrs=MoKRS([lv]),
    )


def mobius_sixty_levels() -> Scene:
    """`palm`: 60 levels, so 60 quaternion Möbius maps compose along every probe (drift)."""
    return preset("palm")


def control_on_chord() -> Scene:
    """A route whose control point lies on the chord: the arc degenerates to a straight
    capsule (editor degeneracy)."""
    s = preset("bent-tree")
    r = s.route
    lv = r.levels[-1]
    a = np.array(r.base)
    b = np.array(lv.fork)
    return replace(
        s,
        name="control-on-chord",
        route=replace(r, levels=r.levels[:-1] + [replace(lv, control=tuple(a + 0.4 * (b - a)))]),
    )


# The tree's twig at window point (27.5, 0.5) of a 64×36 view: level 0, behind all 22 folds.
TWIG = (27.5, 0.5)

CASES: dict[str, HardCase] = {
    c.name: c
    for c in [
        HardCase(
            "camera-on-mirror",
            camera_on_mirror,
            "the eye on a mirror plane: both half-images drawn, no seam, GPU = reference",
        ),
        HardCase(
            "points-on-planes",
            points_on_planes,
            "folds at exactly e = 0 keep each sphere whole: GPU = reference",
        ),
        HardCase(
            "grazing-ground",
            grazing_ground,
            "rays skimming the ground reach the cap of 48; those are counted as capped",
            capped=True,
        ),
        HardCase(
            "grazing-kernel",
            grazing_kernel,
            "a line of sight tangent to a capsule for its whole length: finite, bounded",
        ),
        HardCase(
            "inside-kernel",
            inside_kernel,
            "the eye inside the trunk: every ray hits at t = 0 in one iteration",
        ),
        HardCase(
            "inside-crown", inside_crown, "the eye among the branches of the crown: GPU = reference"
        ),
        HardCase("levels-30", lambda: tree_levels(30), "a billion twigs: finite, GPU = reference"),
        HardCase("levels-40", lambda: tree_levels(40), "2^41 instances: finite, GPU = reference"),
        HardCase(
            "levels-63",
            lambda: tree_levels(63),
            "the most levels a tree may have: finite, GPU = reference",
        ),
        HardCase(
            "deep-zoom-1e-6",
            lambda: zoomed(preset("tree"), *TWIG, 1e-6),
            "a twig seen from 1e-6 scene units: depths and normals as the reference's",
            "float32 kernel records and folds are off by ~1e-7 × scene size, a tenth of "
            'this view: precision = "double" follows the reference (depth to 1e-7)',
        ),
        HardCase(
            "deep-zoom-1e-9",
            lambda: zoomed(preset("tree"), *TWIG, 1e-9),
            "a twig seen from 1e-9 scene units: depths and normals as the reference's",
            'float32 is off by 100× the view; precision = "double" follows the reference',
            capped=True,
        ),  # a few rays graze the horizon at a 1e-9 scale: counted
        HardCase("tiny-radii", tiny_radii, "lengths of 1e-6 throughout: GPU = reference"),
        HardCase("huge-radii", huge_radii, "lengths of 1e8 throughout: GPU = reference"),
        HardCase(
            "parallel-mirrors", parallel_mirrors, "mirrors 1e-6 rad apart: finite, GPU = reference"
        ),
        HardCase(
            "compound-overlap",
            compound_overlap,
            "interpenetrating components: the nearer surface wins, GPU = reference",
        ),
        HardCase(
            "twist-ground",
            twist_ground,
            "twisted forest on its ground: the ground never rises above its plane (ε shrinks "
            "with the twist's Lipschitz bound, so rays converge only at the surface), GPU = "
            "reference (a bare twisted plane, tested apart, has capped far rays: counted)",
        ),
        HardCase(
            "mobius-pole-in-view",
            mobius_pole_in_view,
            "rays through and near the pole pass (the level bound lies outside the probe's "
            "exterior image): nothing drawn there, GPU = reference",
        ),
        HardCase(
            "mobius-alpha-zero",
            mobius_alpha_zero,
            "a sphere mapped to radius ~1e4: finite, GPU = reference",
        ),
        HardCase(
            "mobius-gamma-zero",
            mobius_gamma_zero,
            "a sphere mapped through 1e-7 of the origin: finite, GPU = reference",
        ),
        HardCase(
            "mobius-60-levels",
            mobius_sixty_levels,
            "60 composed quaternion maps: no drift beyond the agreement tolerances",
        ),
        HardCase(
            "control-on-chord",
            control_on_chord,
            "a branch with its control point on the chord is a straight capsule: GPU = reference",
        ),
    ]
}
