"""Mesh export [issue 18 §2]: analytic spheres, a dense marching cubes as the narrow band's
oracle, vertices certified on the surface by a sign change of the reference, watertightness,
and the files trimesh writes."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest
import trimesh
from skimage.measure import marching_cubes

from krsview.compile.geometry import compile_geometry
from krsview.reference.geometry import scene_distance
from krsview.reference.mokrs import distance_estimate
from krsview.scene import KRS, Empty, Level, Mirror, Sphere, load_scene
from krsview.scene.presets import resolve
from krsview.share.mesh import BRICK, REFINE_STEPS, box_of, build_mesh

from .conftest import krsview_cli

BASE = load_scene(resolve("tree"))
CENTER, RADIUS = (0.3, 1.0, -0.2), 1.3


def sphere_scene():
    return BASE.with_geometry(KRS([Level(Sphere(CENTER, RADIUS))]))


def test_a_sphere_has_the_analytic_volume_and_area_and_is_closed():
    mesh, st = build_mesh(sphere_scene(), 64)
    assert st.resolution == 64 and mesh.is_watertight and mesh.euler_number == 2
    assert abs(mesh.volume / (4 / 3 * math.pi * RADIUS**3) - 1) < 0.002  # outward faces
    assert abs(mesh.area / (4 * math.pi * RADIUS**2) - 1) < 0.002
    r = np.linalg.norm(mesh.vertices - CENTER, axis=1)
    assert np.abs(r - RADIUS).max() < st.voxel * 2.0**-REFINE_STEPS
    # negative control: the level set half a voxel out is another sphere
    fat, st = build_mesh(sphere_scene(), 64, lod=0.5)
    expected = 4 / 3 * math.pi * (RADIUS + 0.5 * st.voxel) ** 3
    assert abs(fat.volume / expected - 1) < 0.002
    assert fat.volume / (4 / 3 * math.pi * RADIUS**3) - 1 > 0.02


def test_mirrored_spheres_are_two_closed_pieces():
    """One reflection doubles the sphere: two components, each closed [KRS17 Alg. 1]."""
    krs = KRS(
        [Level(Sphere((-1.0, 0.5, 0.0), 0.6)), Level(Empty(), Mirror((1.0, 0.0, 0.0), 0.0))]
    )  # folds x > 0 onto x < 0
    mesh, _ = build_mesh(BASE.with_geometry(krs), 64)
    parts = mesh.split(only_watertight=False)
    assert len(parts) == 2 and all(p.is_watertight for p in parts)
    assert sorted(np.sign(p.centroid[0]) for p in parts) == [-1, 1]
    assert abs(mesh.volume / (2 * 4 / 3 * math.pi * 0.6**3) - 1) < 0.01


def tree(levels: int = 12):
    return BASE.with_geometry(BASE.geometry().truncated(levels))


def test_the_narrow_band_finds_what_a_dense_grid_finds(monkeypatch):
    """A dense marching cubes over every voxel is the oracle: the bricks the octree kept must
    give the same triangles (before the vertices are moved onto the surface)."""
    scene = tree()
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    mesh, st = build_mesh(scene, 64)
    lo, side = box_of(scene, c, None)
    n, h = st.resolution, st.voxel
    axis = np.arange(n + 1) * h
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3) + lo
    vol = scene_distance(c, grid).reshape(n + 1, n + 1, n + 1)
    _, faces, _, _ = marching_cubes(vol, 0.0, allow_degenerate=False)
    assert len(faces) == st.triangles
    assert st.bricks < (n // BRICK) ** 3
    # negative control: an octree test with balls half too small drops bricks that hold
    # surface, and the dense grid sees the loss
    import krsview.share.mesh as module

    field = module.surface_field

    def shrunk(c, dist):
        value, is_empty = field(c, dist)
        return value, lambda x, r: is_empty(x, 0.5 * r)

    monkeypatch.setattr(module, "surface_field", shrunk)
    assert build_mesh(scene, 64)[1].triangles != len(faces)


@pytest.mark.parametrize("name, lod", [("tree", 0.0), ("tree", 0.5), ("bent-tree", 0.0)])
def test_every_vertex_is_certified_on_the_surface(name, lod):
    """On its grid edge, the reference changes sign within 2^-8 voxel of each vertex (the
    level set lod voxels out, where lod > 0); the mesh is closed."""
    base = load_scene(resolve(name))
    scene = base.with_geometry(base.geometry().truncated(12))
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    mesh, st = build_mesh(scene, 96, lod=lod)
    assert mesh.is_watertight
    f = lambda x: scene_distance(c, x) - lod * st.voxel  # noqa: E731
    certified, missed = sign_change_near(mesh.vertices, f, st.voxel, 2.0**-REFINE_STEPS)
    assert missed.mean() < 0.01 and certified.mean() > 0.99
    # negative control: vertices a third of a voxel off the surface are not certified
    off = mesh.vertices + st.voxel / 3 * mesh.vertex_normals
    assert sign_change_near(off, f, st.voxel, 2.0**-REFINE_STEPS)[0].mean() < 0.1


def sign_change_near(v: np.ndarray, f, h: float, fraction: float):
    """Per vertex: does f change sign within ``fraction`` voxels along some axis (the
    vertex's grid edge is one of them)? (certified, not certified)"""
    ok = np.zeros(len(v), dtype=bool)
    for axis in np.eye(3):
        a, b = f(v - fraction * h * axis), f(v + fraction * h * axis)
        ok |= (np.minimum(a, b) <= 0) & (np.maximum(a, b) >= 0)
    return ok, ~ok


def test_a_mobius_scene_meshes_on_its_zero_set():
    """A MöKRS has no distance function: its first-order distance estimate is sampled, and
    Alg. 3's free balls prune the octree. Its sign is exact, so vertices sit on the surface."""
    shell = load_scene(resolve("shell"))
    scene = shell.with_geometry(shell.geometry().truncated(12))
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    mesh, st = build_mesh(scene, 64)
    assert mesh.is_watertight and st.bricks < (st.resolution // BRICK) ** 3
    certified, _ = sign_change_near(
        mesh.vertices, lambda x: distance_estimate(c, x), st.voxel, 2.0**-REFINE_STEPS
    )
    assert certified.mean() > 0.99


def run(*args: str) -> subprocess.CompletedProcess:
    return krsview_cli("export", "mesh", *args)


@pytest.mark.parametrize("suffix", [".glb", ".ply", ".stl", ".obj"])
def test_each_format_loads_back_with_the_same_triangles(tmp_path, suffix):
    out, link = tmp_path / f"tree{suffix}", tmp_path / f"link{suffix}"
    link.symlink_to(out)  # the save replaced a link by a file; now it writes what it names
    r = run("tree", "-o", str(link), "--resolution", "32")  # bark and leaves
    assert r.returncode == 0, r.stderr
    assert link.is_symlink() and out.is_file()
    triangles = int(r.stdout.split(" triangles")[0].split()[-1].replace(",", ""))
    mesh = trimesh.load(out, force="mesh")
    assert len(mesh.faces) == triangles and mesh.is_watertight
    if suffix != ".stl":  # STL has no colours: the others carry the kernels' albedo
        colors = np.asarray(mesh.visual.vertex_colors)[:, :3]
        assert len(np.unique(colors, axis=0)) >= 2


@pytest.mark.parametrize(
    "args, message",
    [
        (["tree", "-o", "t.fbx"], "-o = 't.fbx': the file must end in .glb, .ply, .stl or .obj"),
        (["grass", "-o", "g.glb"], "geometry = 'grass': is unbounded"),
        (["tree", "-o", "t.glb", "--box", "1,2,3"], "--box '1,2,3': expected six numbers within"),
        # a region past the scene's coordinate limit gave a mesh of NaN vertices [review]
        (["tree", "-o", "t.glb", "--box", "0,0,0,1,1,1e300"], "within ±1e+09 (XMIN"),
        (
            ["tree", "-o", "t.glb", "--box", "0,0,0,1,-1,1"],
            "each max (the last three) must exceed its min",
        ),
        (["tree", "-o", "t.glb", "--resolution", "8"], "--resolution '8': allowed 16 ≤ value"),
        (["tree", "-o", "t.glb", "--lod", "nan"], "--lod 'nan': allowed 0.0 ≤ value ≤ 4.0"),
        (["tree", "-o", "t.glb", "--box", "50,50,50,51,51,51"], "no surface inside the region"),
    ],
)
def test_bad_mesh_options_are_one_line_errors(tmp_path, args, message):
    r = krsview_cli("export", "mesh", *args, timeout=120, cwd=tmp_path)
    assert r.returncode == 2 and message in r.stderr, r.stderr
    assert len([line for line in r.stderr.splitlines() if "error" in line]) == 1
    assert "Traceback" not in r.stderr


def test_a_mobius_scene_in_the_wind_meshes_bent():
    """`export mesh palm-wind` bends the MöKRS as the tracer does (reference/wind.py): each
    vertex x is certified on the bent field's zero set, the rest estimate at g(x), and the
    forward bend (test_wind's bent_forward, by bisection, not the reference's g) takes g(x)
    back to x. Negative control: the rest mesh's vertices are not on the bent surface."""
    from krsview.reference.wind import Wind

    from .test_wind import bent_forward

    palm = load_scene(resolve("palm-wind"))
    scene = palm.with_geometry(palm.geometry().truncated(12)).at(2.0)
    scene = scene.edit("effect_settings.wind_strength", 30.0)
    wind = Wind.of(scene)
    bent, st = build_mesh(scene, 32)  # the bend is per vertex (the MöKRS at 64: above)
    assert bent.is_watertight
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    rest_point = lambda x: wind.unwind(0, np.asarray(x))  # noqa: E731
    field = lambda x: distance_estimate(c, rest_point(x))  # noqa: E731
    certified, _ = sign_change_near(bent.vertices, field, st.voxel, 2.0**-REFINE_STEPS)
    assert certified.mean() > 0.99
    back = bent_forward(wind, rest_point(bent.vertices))
    assert np.abs(back - bent.vertices).max() < 1e-6 * st.voxel
    rest, _ = build_mesh(scene.with_effects([e for e in scene.effects if e != "wind"]), 32)
    assert sign_change_near(rest.vertices, field, st.voxel, 2.0**-REFINE_STEPS)[0].mean() < 0.5


def test_the_mesh_reports_the_resolution_it_sampled_and_steps_its_progress(tmp_path):
    """`--resolution 48` said "meshing at 48" and sampled 64 voxels a side; and the bar
    moved once, at the end, where every brick fitted one call [review]."""
    r = krsview_cli("export", "mesh", "sierpinski", "-o", "s.glb", "--resolution", "48",
                    timeout=120, cwd=tmp_path)  # fmt: skip
    assert r.returncode == 0 and "meshing at 64 voxels a side" in r.stdout, r.stderr
    calls = []
    _, st = build_mesh(load_scene(resolve("sierpinski")), 48, progress=lambda *c: calls.append(c))
    assert st.resolution == 64 and len(calls) >= 10, (len(calls), st.bricks)  # it was 1
    done = [d for d, _ in calls]
    assert done == sorted(done) and calls[-1][0] == calls[-1][1]  # one way, to the end
    assert all(d < n for d, n in calls[:-1])  # a bar closes at its total: not before the end
    # the vertices' bisections were silent, as long as the bricks' sampling [review]: now
    # REFINE_STEPS + 1 calls after the bricks', and the colours' last
    bricks = [c for c in calls if c[1] == calls[0][1]]
    assert len(calls) - len(bricks) == REFINE_STEPS + 2, calls


def test_export_mesh_takes_the_moment_as_render_does(tmp_path):
    """`export mesh` had no --time, though exports take time as any scene value [review]:
    palm-curl's tracks curl it, so two moments mesh apart and one moment alike."""

    def mesh_at(t: str, name: str) -> bytes:
        r = krsview_cli("export", "mesh", "palm-curl", "-o", name, "--resolution", "16",
                        "--time", t, timeout=120, cwd=tmp_path)  # fmt: skip
        assert r.returncode == 0, r.stderr
        return (tmp_path / name).read_bytes()

    at_zero = mesh_at("0", "a.ply")
    assert at_zero == mesh_at("0", "b.ply") and at_zero != mesh_at("3", "c.ply")
