"""`krsview bench peer`'s expansion and tessellation, checked without the peer library: the
instances against reflecting points one mirror at a time, the vertices on the kernels'
surfaces, the triangles within the tolerance and closed, and the mesh's hit mask, cast by
brute force with krsview's rays, against krsview's own image. With open3d installed
('krsview[peer]'), a tiny run of the bench itself."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

import krsview
from krsview.bench import expansion, peer
from krsview.bench.metrics import silhouette
from krsview.cli import main
from krsview.compile.camera import primary_rays, view_of
from krsview.compile.krs import compile_krs
from krsview.reference.kernels import kernel_distance
from krsview.reference.krs import distance
from krsview.scene import KRS, Camera, Capsule, Empty, Level, Mirror, SceneError, Sphere, Tree

WHITE = (1.0, 1.0, 1.0)


def reflect(m: np.ndarray, x: np.ndarray) -> np.ndarray:
    return x - 2.0 * (x @ m[:3] - m[3])[..., None] * m[:3]


def paths(c, j: int):
    """Every instance of K_j as its reflections, R_j first: {i: b_i}."""
    for bits in itertools.product((0, 1), repeat=c.n - j):
        yield dict(zip(range(j, c.n), bits))


def to_kernel(c, path: dict, y: np.ndarray) -> np.ndarray:
    """World points of instance ``path`` back in its kernel's space (R_{n−1} undone first)."""
    for i in sorted(path, reverse=True):
        if path[i]:
            y = reflect(c.mirrors[i], y)
    return y


def mixed_krs() -> KRS:
    """Spheres, a capsule and an empty level under skew mirrors, no two of which commute."""
    return KRS(
        [
            Level(Sphere((0.2, 0.1, 0.0), 0.3)),
            Level(Capsule((0.0, 0.0, 0.0), (0.5, 1.0, 0.2), 0.1), Mirror((0.6, 0.8, 0.0), 0.9)),
            Level(Empty(), Mirror((0.0, 0.6, 0.8), 1.5)),
            Level(Sphere((1.0, -0.5, 0.3), 0.25), Mirror((0.8, 0.0, 0.6), 1.8)),
        ]
    )


def rows(a) -> np.ndarray:
    """Points as a set: the rows sorted."""
    a = np.asarray(a)
    return a[np.lexsort(a.T[::-1])]


def tree_scene(levels: int):
    scene = krsview.load("tree")
    return scene, scene.geometry().truncated(levels)


def test_instance_maps_match_reflecting_point_by_point():
    c = compile_krs(mixed_krs(), WHITE)
    maps = expansion.instance_maps(c)
    p = np.array([0.3, -0.2, 0.7])
    for j, (M, t) in enumerate(maps):
        got = rows(M @ p + t)
        inside_out = [to_kernel(c, b, p) for b in paths(c, j)]  # R_{n−1} first: the wrong order
        right = []
        for b in paths(c, j):
            y = p
            for i in range(j, c.n):  # R_j first, R_{n−1} last
                if b[i]:
                    y = reflect(c.mirrors[i], y)
            right.append(y)
        assert len(M) == 2 ** (c.n - j)
        assert np.allclose(got, rows(right), atol=1e-12)
        if c.n - j >= 2:  # negative control: the other order is another set
            assert not np.allclose(got, rows(inside_out), atol=1e-6)


def test_instances_are_two_to_the_n_minus_i_per_non_empty_kernel():
    krs = mixed_krs()
    view = view_of(Camera(position=(0.0, 0.5, -8.0), target=(0.5, 0.5, 0.0)), 64, 36)
    mesh = expansion.expand(krs, view)
    n = krs.n
    solid = [i for i, k in enumerate(krs.kernels) if not isinstance(k, Empty)]
    assert mesh.instances == sum(2 ** (n - i) for i in solid) == 8 + 4 + 1
    assert mesh.instances != sum(2 ** (n - i) for i in range(n + 1))  # the empty one counts not
    assert mesh.faces.max() == len(mesh.vertices) - 1


def nearest_surface(c, y: np.ndarray) -> np.ndarray:
    """|k_j| of each point reflected back into each instance's kernel, the least over all
    instances (brute force)."""
    best = np.full(len(y), np.inf)
    for j, kind in enumerate(c.types):
        if kind != "empty":
            for b in paths(c, j):
                k = kernel_distance(kind, c.records[j], to_kernel(c, b, y))
                best = np.minimum(best, np.abs(k))
    return best


@pytest.mark.parametrize("case", ["mixed", "tree"])
def test_vertices_lie_on_the_kernels_surfaces_and_on_the_krs(case):
    """Every vertex on some instance's surface (kernel_distance of the point reflected back,
    brute force over all instances), and Alg. 1 finds no point of the KRS nearer than that
    (no vertex outside the KRS); a vertex moved off the surface fails both."""
    if case == "mixed":
        krs, camera = mixed_krs(), Camera(position=(0.0, 0.5, -8.0), target=(0.5, 0.5, 0.0))
    else:
        scene, krs = tree_scene(5)
        camera = scene.camera
    c = compile_krs(krs, WHITE)
    v = expansion.expand(krs, view_of(camera, 96, 54)).vertices.astype(np.float64)
    pushed = v + 1e-3 * np.array([0.6, 0.0, 0.8])
    assert nearest_surface(c, v).max() < 1e-5
    assert distance(c, v).max() < 1e-5
    assert nearest_surface(c, pushed).max() > 5e-4  # negative control
    assert distance(c, pushed).max() > 5e-4


def kernel_cases():
    tree = compile_krs(Tree(levels=4).krs(), WHITE)
    arc = next(j for j, kind in enumerate(tree.types) if kind == "toroidal_capsule")
    spheres = compile_krs(mixed_krs(), WHITE)
    return [
        ("toroidal_capsule", tree.records[arc]),
        ("capsule", spheres.records[1]),
        ("sphere", spheres.records[0]),
    ]


def surface_samples(v: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Points spread over every triangle: corners' mixes on a barycentric grid of 5 steps."""
    steps = [(a, b, 4 - a - b) for a in range(5) for b in range(5 - a)]
    w = np.array(steps, dtype=float) / 4
    return np.einsum("sk,fkd->fsd", w, v[f]).reshape(-1, 3)


@pytest.mark.parametrize("kind, rec", kernel_cases())
@pytest.mark.parametrize("share", [0.02, 0.3, 2.0])  # tolerance over radius: fine to one ring
def test_triangles_lie_within_the_tolerance_inside_the_surface(kind, rec, share):
    tol = share * rec[1, 3]
    v, f = expansion.kernel_mesh(kind, rec, tol)
    k = kernel_distance(kind, rec, surface_samples(v, f))
    assert np.abs(k).max() <= tol
    if kind != "toroidal_capsule":  # convex: every chord inside (a torus's inner side is not)
        assert k.max() < 1e-12
    coarse_v, coarse_f = expansion.kernel_mesh(kind, rec, 6 * tol)  # negative control
    if share < 1:
        assert kernel_distance(kind, rec, surface_samples(coarse_v, coarse_f)).min() < -tol


def closed(f: np.ndarray) -> bool:
    """Every directed edge once and its reverse once: a closed, consistently wound surface."""
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    directed = {tuple(e) for e in edges.tolist()}
    return len(directed) == len(edges) and all((b, a) in directed for a, b in directed)


@pytest.mark.parametrize("kind, rec", kernel_cases())
def test_kernel_meshes_are_closed(kind, rec):
    for share in (0.02, 2.0):
        v, f = expansion.kernel_mesh(kind, rec, share * rec[1, 3])
        assert closed(f) and np.all(np.bincount(f.ravel(), minlength=len(v)) > 0)
        assert not closed(f[1:])  # negative control: a triangle missing


def test_tolerance_is_half_a_pixel_at_the_nearest_instance():
    krs = KRS([Level(Sphere((0.0, 0.0, 10.0), 1.0))])
    view = view_of(Camera(position=(0.0, 0.0, 0.0), target=(0.0, 0.0, 1.0), fov_y=45.0), 320, 180)
    c = compile_krs(krs, WHITE)
    (tol,) = expansion.level_tolerances(krs, expansion.instance_maps(c), view, 0.5)
    assert tol == pytest.approx(0.5 * 2 * math.tan(math.radians(22.5)) / 180 * 9.0)


def brute_force_hits(mesh: expansion.Mesh, origin: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Möller–Trumbore over every ray and triangle, in float64."""
    tri = mesh.vertices.astype(np.float64)[mesh.faces]
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    s = origin - tri[:, 0]
    q = np.cross(s, e1)
    hit = np.zeros(len(d), dtype=bool)
    for k in range(0, len(d), 256):
        r = d[k : k + 256, None]
        p = np.cross(r, e2)
        det = (p * e1).sum(-1)
        inv = 1.0 / np.where(det == 0, np.inf, det)
        u = (p * s).sum(-1) * inv
        w = (r * q).sum(-1) * inv
        t = (q * e2).sum(-1) * inv
        hit[k : k + 256] = ((u >= 0) & (w >= 0) & (u + w <= 1) & (t > 0) & (det != 0)).any(1)
    return hit


def test_the_mesh_under_krsviews_rays_draws_krsviews_image(renderer):
    """Cast by brute force, the mesh's hit mask is krsview's but on the outlines (krsview at
    ε-scale 0.1 and the mesh within 0.1 px: what is left is which side of an outline a
    pixel centre falls on, and a ray grazing a twig's tip closer than the mesh follows);
    the rays upside down (rows not flipped) are not."""
    scene, krs = tree_scene(4)
    scene = scene.edit("camera.position", (0.0, 2.6, -5.0)).edit("render.epsilon_scale", 0.1)
    w, h = 64, 36
    view = view_of(scene.camera, w, h)
    mesh = expansion.expand(krs, view, 0.1)
    mine = renderer.render(peer.krsview_scene(scene, {"lod": 0.0}), w, h, krs).hit
    theirs = brute_force_hits(mesh, view.origin, primary_rays(view)).reshape(h, w)
    flipped = theirs[::-1]
    assert theirs.mean() > 0.03
    assert (theirs != mine).mean() < 0.02
    assert ((theirs != mine) & ~silhouette(theirs)).mean() < 0.002
    assert ((flipped != mine) & ~silhouette(flipped)).mean() > 0.02  # negative control


def test_a_scene_the_peer_cannot_mesh_gets_one_line():
    with pytest.raises(SceneError, match="one KRS into triangles"):
        expansion.single_krs(krsview.load("grove"))
    plane = krsview.load_dict(
        {"krs": {"levels": [{"kernel": {"type": "plane", "normal": [0, 1, 0], "offset": 0}}]}}
    )
    with pytest.raises(SceneError, match=r"levels\[0\]\.kernel.*bounded kernels"):
        expansion.single_krs(plane)
    with pytest.raises(SceneError, match=r"--levels = 24: allowed: 1\.\.23"):
        peer.check_levels(krsview.load("tree").geometry(), (16, 24), "tree")
    peer.check_levels(krsview.load("tree").geometry(), (1, 23), "tree")  # the edges are allowed


def test_without_the_peer_library_the_bench_says_how_to_install(monkeypatch, capsys):
    from krsview.cli import options

    real = options.importlib.util.find_spec
    monkeypatch.setattr(
        options.importlib.util, "find_spec", lambda m: None if m == "open3d" else real(m)
    )
    for bench in ("peer", "peer-zoom"):
        assert main(["bench", bench, "tree", "--size", "16x9"]) == 3
        err = capsys.readouterr().err.strip()
        assert err == f"krsview: error: bench {bench} needs open3d: pip install 'krsview[peer]'"
    assert main(["bench", "levels", "sierpinski", "--size", "16x9", "--rounds", "1"]) == 0


def test_level_list_option_refuses_bad_counts(capsys):
    for given in ("16,x", "0", "16,,18"):
        with pytest.raises(SystemExit):
            main(["bench", "peer", "tree", "--levels", given])
        assert "--levels" in capsys.readouterr().err


def test_bench_peer_tiny_run(renderer):
    """A few levels, a small image: the rows, the hit masks agreeing, and the ε check
    biting on a frame pushed off the surface."""
    o3d = pytest.importorskip("open3d")
    scene, krs = tree_scene(4)
    size = (48, 27)
    m = peer.bench_peer(scene, size, rounds=1, level_counts=(3, 4))
    assert m.column("renderer") == [peer.PEER, *peer.VARIANTS] * 2
    per_level = 1 + len(peer.VARIANTS)
    assert m.column("levels") == [3] * per_level + [4] * per_level
    assert m.column("instances") == [7] * per_level + [15] * per_level
    for r in m.rows:
        assert r["ms"] <= r["ms_median"] <= r["ms_max"] and r["peak_rss_mb"] > 0
        assert r["only_peer"] == 0 and r["beyond_epsilon"] == 0
    assert m.rows[0]["ratio"] == 1 and m.rows[0]["hit_differs"] == 0
    assert "| 4 | krsview, exact |" in peer.table(m)
    view = view_of(scene.camera, *size)
    bvh, _ = peer.build(o3d, expansion.expand(krs, view))
    exact = peer.krsview_scene(scene, {"lod": 0.0})
    frame = renderer.render(exact, *size, krs)
    assert peer.beyond_epsilon(o3d, bvh, frame, view, exact, expansion.TOLERANCE) == 0
    frame.depth[frame.hit] *= 1.5  # negative control
    assert peer.beyond_epsilon(o3d, bvh, frame, view, exact, expansion.TOLERANCE) > 0.01


def test_bench_peer_zoom_tiny_run(tmp_path, capsys):
    """bench zoom's flight with the peer beside krsview: a row per stop, nearer each time;
    at each stop the peer casts that stop's own rays (its hit fraction is the brute-force
    one over the same mesh; the control: stop 0's rays read elsewhere), and each renderer's
    slowest over fastest frame is read off its own column."""
    from krsview.bench import peer_zoom, zoom

    pytest.importorskip("open3d")
    scene = krsview.load("tree")
    size = (32, 18)
    csv = tmp_path / "pz.csv"
    args = ["bench", "peer-zoom", "tree", "--levels", "4", "--stops", "3", "--rounds", "2"]
    assert main([*args, "--size", "32x18", "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert "slowest frame / fastest" in out and csv.exists()
    m = peer_zoom.bench_peer_zoom(scene, size, rounds=2, levels=4, stops_count=3)
    assert m.column("stop") == ["stop 0", "stop 1", "stop 2"]
    d = m.column("distance")
    assert d[0] > d[1] > d[2] and d[0] / d[1] == pytest.approx(d[1] / d[2], rel=1e-6)
    krs = scene.geometry().truncated(4)
    cut = scene.with_geometry(krs)
    mesh = expansion.expand(krs, view_of(scene.camera, *size))
    views = [view_of(v.camera, *size) for v in zoom.stops(cut, 3)]

    def brute(view) -> float:
        return float(brute_force_hits(mesh, view.origin, primary_rays(view)).mean())

    for row, view in zip(m.rows, views):
        assert row["peer_hit"] == pytest.approx(brute(view), abs=2 / (size[0] * size[1]))
        assert row["ms"] <= row["ms_median"] <= row["ms_max"]
        assert row["ratio_min"] <= row["ratio"] <= row["ratio_max"]
    assert abs(brute(views[0]) - m.rows[2]["peer_hit"]) > 0.05  # control
    assert zoom.spread(m, "peer_ms") == max(m.column("peer_ms")) / min(m.column("peer_ms"))
    assert "Embree (Open3D) ms" in peer_zoom.table(m)
