"""The toroidal capsule's record (compile/krs.py): centre and r, the quaternion of the arc's
frame (e1 its bisector) scaled by 1/√R, and t = tan(phi/4) — 9 numbers where Alg. 1's level
reads the arc. Checked against the arc through the kernel's own three points, sampled densely
(the scene's geometry, not the record), in NumPy and in float32 on the GPU."""

from __future__ import annotations

import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

from krsview.compile.krs import compile_krs
from krsview.gpu.uniforms import krs_block
from krsview.reference.kernels import arc_half_angle, arc_local, kernel_distance
from krsview.scene import KRS, Capsule, Empty, Level, Mirror, Sphere, ToroidalCapsule, arc_of
from krsview.scene.model import MAX_LEVELS, STRAIGHT_RATIO

ALBEDO = (0.5, 0.5, 0.5)
# The shortest arc drawn as an arc: chord R/STRAIGHT_RATIO, a little above it.
SHORTEST = 2.0 * math.asin(1.0 / (2.0 * 0.99 * STRAIGHT_RATIO))
ANGLES = (SHORTEST, 0.3, 1.0, math.pi / 2, 2.5, math.pi, 4.0, 5.5, 2.0 * math.pi - 0.05)


def arc_kernel(rng: np.random.Generator, phi: float) -> ToroidalCapsule:
    """A toroidal capsule whose arc spans ``phi``, in a random frame near the origin."""
    O, R = rng.normal(size=3) * 0.5, rng.uniform(0.3, 2.0)
    e1, e2 = np.linalg.qr(rng.normal(size=(3, 2)))[0].T
    at = lambda a: tuple(O + R * (math.cos(a) * e1 + math.sin(a) * e2))  # noqa: E731
    return ToroidalCapsule(at(0.0), at(phi * rng.uniform(0.2, 0.8)), at(phi), R * 0.1)


def arc_samples(k: ToroidalCapsule, count: int = 20001) -> np.ndarray:
    arc = arc_of(k)
    a = np.linspace(0.0, arc.phi, count)[:, None]
    return np.array(arc.center) + arc.R * (np.cos(a) * arc.e1 + np.sin(a) * arc.e2)


def points_near(k: ToroidalCapsule, rng: np.random.Generator, n: int = 400) -> np.ndarray:
    """Points around the arc, around its ends (where the wedge test decides) and on its axis."""
    arc = arc_of(k)
    O = np.array(arc.center)
    ends = np.array([k.start, k.end])
    around = O + rng.normal(size=(n, 3)) * arc.R
    near_ends = ends[rng.integers(0, 2, n)] + rng.normal(size=(n, 3)) * 3.0 * k.radius
    axis = O + np.outer(rng.normal(size=n // 4), np.cross(arc.e1, arc.e2))
    return np.concatenate([around, near_ends, axis])


def misfit(rec: np.ndarray, k: ToroidalCapsule, x: np.ndarray, got: np.ndarray) -> float:
    """How far ``got`` lies outside [brute − spacing, brute], brute the distance to the dense
    arc samples minus r: 0 for an exact kernel distance that never overshoots."""
    core = arc_samples(k)
    brute = (
        np.concatenate(
            [
                np.min(np.linalg.norm(y[:, None] - core[None], axis=2), axis=1)
                for y in x.reshape(-1, 50, 3)
            ]
        )
        - k.radius
    )
    spacing = float(np.max(np.linalg.norm(np.diff(core, axis=0), axis=1)))
    return float(max(np.max(got - brute), np.max(brute - got - spacing), 0.0))


@pytest.mark.parametrize("phi", ANGLES)
def test_arc_record_is_the_arc_through_the_kernels_points(phi):
    """NumPy's distance from the record against the dense arc, for every arc angle; the record
    places start, control and end where the layout says: (c, ∓s, 0) and on the unit circle
    inside the wedge, in units of R."""
    rng = np.random.default_rng(int(phi * 1000))
    k = arc_kernel(rng, phi)
    rec = compile_krs(KRS([Level(k)]), ALBEDO).records[0]
    x = points_near(k, rng)
    assert misfit(rec, k, x, kernel_distance("toroidal_capsule", rec, x)) < 1e-12
    c, s = arc_half_angle(rec)
    assert c == pytest.approx(math.cos(phi / 2), abs=1e-14)
    a = arc_local(rec[2], np.array([k.start, k.control, k.end]) - rec[1, :3])
    assert np.allclose(a[[0, 2]], [[c, -s, 0.0], [c, s, 0.0]], atol=1e-12)
    assert abs(np.hypot(*a[1, :2]) - 1.0) < 1e-12 and abs(a[1, 2]) < 1e-12 and a[1, 0] > c
    assert 1.0 / float(rec[2] @ rec[2]) == pytest.approx(arc_of(k).R, rel=1e-14)


def arc_misplaced(rec: np.ndarray, k: ToroidalCapsule) -> float:
    """How far the record puts the kernel's start and end from (c, ∓s, 0), and its control
    off the unit circle, in units of R (0 for the arc through the kernel's points)."""
    c, s = arc_half_angle(rec)
    a = arc_local(rec[2], np.array([k.start, k.control, k.end]) - rec[1, :3])
    ends = np.abs(a[[0, 2]] - [[c, -s, 0.0], [c, s, 0.0]]).max()
    return float(max(ends, abs(np.hypot(*a[1, :2]) - 1.0), abs(a[1, 2])))


def test_a_krs_of_every_kind_compiles_each_arc_into_its_own_level():
    """Compiling finds a KRS's arcs all at once (scene.arcs_of, compile/krs.py); each
    level's record still holds its own kernel: every arc angle between spheres, capsules,
    empties and a straight arc (drawn as a capsule), each arc's points where the layout puts
    them. Negative control: the arcs' records in each other's levels misplace them."""
    rng = np.random.default_rng(7)
    arcs = [arc_kernel(rng, phi) for phi in ANGLES]
    straight = ToroidalCapsule((0.0, 0.0, 0.0), (0.5, 1e-9, 0.0), (1.0, 0.0, 0.0), 0.1)
    others = [Sphere((0.0, 1.0, 0.0), 0.2), Capsule(radius=0.05), Empty(), straight]
    kernels = [k for pair in zip(arcs, others * 3) for k in pair]
    mirror = Mirror((0.0, 0.0, 1.0), 3.0)
    c = compile_krs(KRS([Level(k, mirror if i else None) for i, k in enumerate(kernels)]), ALBEDO)
    at = [i for i, k in enumerate(kernels) if k in arcs]
    assert [c.types[i] for i in at] == ["toroidal_capsule"] * len(arcs)
    assert {c.types[i] for i, k in enumerate(kernels) if k is straight} == {"capsule"}
    assert max(arc_misplaced(c.records[i], kernels[i]) for i in at) < 1e-12
    swapped = [arc_misplaced(c.records[i], kernels[j]) for i, j in zip(at, at[1:] + at[:1])]
    assert min(swapped) > 1e-3


def test_the_rational_half_angle_is_accurate_in_float32_where_a_square_root_is_not():
    """Why t = tan(phi/4): on the shortest arc, cos and sin of phi/2 from t in float32 are
    within a few ulps; sin from a stored float32 cos, √(1 − c²), is off by far more."""
    t = np.float32(math.tan(SHORTEST / 4))
    one = np.float32(1.0)
    c, s = (one - t * t) / (one + t * t), np.float32(2.0) * t / (one + t * t)
    assert abs(float(s) / math.sin(SHORTEST / 2) - 1.0) < 4 * 2.0**-23
    assert abs(float(c) - math.cos(SHORTEST / 2)) < 4 * 2.0**-24
    c32 = np.float32(math.cos(SHORTEST / 2))
    from_cos = float(np.sqrt(one - c32 * c32))
    assert abs(from_cos / math.sin(SHORTEST / 2) - 1.0) > 1e-3  # the control


PROBE = """layout(local_size_x = 64) in;
#include "scene_block.glsl"
#include "kernels.glsl"
layout(std430, binding = 1) readonly buffer Points { vec4 u_points[]; };
layout(std430, binding = 2) writeonly buffer Values { float u_values[]; };
void main() {
    uint k = gl_GlobalInvocationID.x;
    if (k < uint(u_points.length())) u_values[k] = float(kernel_distance(0, u_points[k].xyz));
}
"""


@pytest.fixture(scope="module")
def probe(renderer, tmp_path_factory):
    """The shaders' kernel_distance at points, in float32: a compute shader beside kernels.glsl
    that reads the record from the KRSBlock as every tracer does."""
    from krsview.compile.constants import BINDING_KRS_BLOCK
    from krsview.gpu.program import SHADER_DIR, build_compute

    shaders = tmp_path_factory.mktemp("probe") / "shaders"
    shutil.copytree(SHADER_DIR, shaders)
    (shaders / "probe.comp").write_text(PROBE)
    defines = {"KRS_SLOTS": MAX_LEVELS, "KRS_KERNEL_TOROIDAL_CAPSULE": None}
    ctx = renderer.ctx
    with ctx:  # current only inside (gpu/context.py)
        cs = build_compute(ctx, "probe.comp", defines, shaders)
        cs["KRSBlock"].binding = BINDING_KRS_BLOCK

    def run(c, x: np.ndarray) -> np.ndarray:
        with ctx:
            return evaluate(c, x)

    def evaluate(c, x: np.ndarray) -> np.ndarray:
        ubo = ctx.buffer(krs_block(c))
        pts = ctx.buffer(np.concatenate([x, np.zeros((len(x), 1))], axis=1).astype("f4"))
        out = ctx.buffer(reserve=4 * len(x))
        ubo.bind_to_uniform_block(BINDING_KRS_BLOCK)
        pts.bind_to_storage_buffer(1)
        out.bind_to_storage_buffer(2)
        cs.run(-(-len(x) // 64))
        values = np.frombuffer(out.read(), dtype="f4").astype(np.float64)
        for b in (ubo, pts, out):
            b.release()
        return values

    return run


@pytest.mark.parametrize("phi", ANGLES)
def test_float32_arc_distance_never_overshoots_on_the_gpu(probe, phi):
    """kernels.glsl's distance from the float32 record against the dense arc: below it up to
    float32 rounding of the scene's size, and no further below than the samples' spacing."""
    rng = np.random.default_rng(int(phi * 1000) + 1)
    k = arc_kernel(rng, phi)
    c = compile_krs(KRS([Level(k)]), ALBEDO)
    x = points_near(k, rng).astype(np.float32).astype(np.float64)
    scale = float(np.max(np.abs(x)))
    assert misfit(c.records[0], k, x, probe(c, x)) < 8 * 2.0**-23 * scale


@pytest.mark.parametrize("phi", (0.3, 1.0, 2.5, 4.0))
def test_the_wedge_taken_at_the_whole_angle_is_found(probe, phi):
    """Negative control of both: the record's half angle as the whole angle (c = cos phi, the
    old record's number) draws another arc, and the dense samples say so, in NumPy and on the
    GPU."""
    rng = np.random.default_rng(7)
    k = arc_kernel(rng, phi)
    c = compile_krs(KRS([Level(k)]), ALBEDO)
    x = points_near(k, rng).astype(np.float32).astype(np.float64)
    assert misfit(c.records[0], k, x, probe(c, x)) < 1e-5  # the intact record passes
    wrong = c.records.copy()
    wrong[0, 3, 0] = math.tan(phi / 2)
    broken = replace(c, records=wrong)
    assert misfit(wrong[0], k, x, kernel_distance("toroidal_capsule", wrong[0], x)) > 1e-3
    assert misfit(wrong[0], k, x, probe(broken, x)) > 1e-3
