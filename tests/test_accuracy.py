"""The accuracy benchmark: hit sets are nested in ε (so the errors it reports move the right
way), the Pareto front, the ground-truth cache, and the report a run writes."""

from __future__ import annotations

import os
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from krsview.bench.accuracy import pareto, settings
from krsview.bench.metrics import compare
from krsview.bench.truth import cache_key, ground_truth
from krsview.compile.camera import view_of
from krsview.reference import render_reference
from krsview.scene import load_scene
from krsview.scene.presets import resolve

W, H = 48, 27


def with_render(scene, **kw):
    return replace(scene, render=replace(scene.render, **kw))


@pytest.mark.parametrize(
    "preset, tracer", [("sierpinski", "sphere"), ("rock", "sphere"), ("sierpinski", "binary")]
)
def test_a_looser_epsilon_hits_a_superset_and_never_has_more_false_hits(preset, tracer):
    """Both tracers take the same steps at every ε until a ray converges, and a looser ε
    converges no later: so, with a cap that is never reached, the hit sets are nested,
    holes against a tighter truth are zero and false hits grow with ε."""
    scene = with_render(load_scene(resolve(preset)), tracer=tracer, max_iterations=4096)
    fp = view_of(scene.camera, W, H).footprint
    truth = render_reference(with_render(scene, epsilon_scale=0.125), W, H)
    last_false, last_hit = -1.0, truth.hit
    for eps in (0.25, 1.0, 4.0):
        img = render_reference(with_render(scene, epsilon_scale=eps), W, H)
        assert (img.hit | ~last_hit).all(), f"ε-scale {eps} lost a hit a tighter ε had"
        e = compare(img, truth, fp, 4096)
        assert e.holes == 0 and e.false_hits >= last_false and e.capped == 0
        last_false, last_hit = e.false_hits, img.hit
    assert last_false > 0, "ε did not change the image: the property was not exercised"


def test_where_a_tighter_epsilon_legitimately_has_more_holes_a_small_cap():
    """The stated exception: a tight ε needs more steps near a silhouette, so under a small
    cap its rays run out and miss (capped rays are holes) where a loose ε had converged."""
    scene = with_render(load_scene(resolve("sierpinski")), max_iterations=10)
    fp = view_of(scene.camera, W, H).footprint
    truth = render_reference(with_render(scene, epsilon_scale=0.125, max_iterations=4096), W, H)
    tight = compare(render_reference(with_render(scene, epsilon_scale=0.25), W, H), truth, fp, 10)
    loose = compare(render_reference(with_render(scene, epsilon_scale=4.0), W, H), truth, fp, 10)
    assert tight.holes > loose.holes and tight.capped > loose.capped


def test_pareto_front_keeps_only_undominated_settings():
    rows = [
        dict(ms=10, mask_error=0.2),
        dict(ms=12, mask_error=0.3),
        dict(ms=15, mask_error=0.1),
        dict(ms=20, mask_error=0.1),
        dict(ms=25, mask_error=0.0),
    ]
    assert pareto(rows) == [rows[0], rows[2], rows[4]]


def test_every_knob_is_swept_and_a_mokrs_only_with_binary_tracing():
    knobs = {s.knob for s in settings(load_scene(resolve("tree")))}
    assert knobs == {
        "scene",
        "epsilon_scale",
        "max_iterations",
        "tracer",
        "precision",
        "culling",
        "path",
        "prepass",
        "levels",
    }
    palm = settings(load_scene(resolve("palm")))
    assert {s.knob for s in palm} == {
        "scene",
        "epsilon_scale",
        "max_iterations",
        "tracer",
        "precision",
        "path",
        "prepass",
        "levels",
    }
    assert all(s.scene.render.tracer == "binary" for s in palm)


def test_ground_truth_is_cached_by_content(tmp_path):
    scene = load_scene(resolve("sierpinski"))
    a = ground_truth(scene, (16, 9), tmp_path)
    (f,) = tmp_path.glob("*.npz")
    b = ground_truth(scene, (16, 9), tmp_path)
    assert np.array_equal(a.hit, b.hit) and np.array_equal(a.color, b.color)
    other = replace(scene, camera=replace(scene.camera, fov_y=50.0))
    assert cache_key(other, (16, 9)) != cache_key(scene, (16, 9)) != cache_key(scene, (16, 10))
    # the cached file is what is returned: altering it shows up
    with np.load(f) as z:
        data = dict(z)
    data["hit"][:] = False
    np.savez(f, **data)
    assert not ground_truth(scene, (16, 9), tmp_path).hit.any()


def run(*args):
    return subprocess.run(
        [sys.executable, "-m", "krsview", *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "DISPLAY": ""},
    )


def test_bench_accuracy_writes_a_readable_report(tmp_path):
    out = tmp_path / "report"
    r = run(
        "bench",
        "accuracy",
        "sierpinski",
        "--size",
        "48x27",
        "--rounds",
        "1",
        "--out",
        str(out),
        "--cache",
        str(tmp_path / "cache"),
    )
    assert r.returncode == 0, r.stderr
    names = {p.name for p in out.iterdir()}
    assert {"README.md", "accuracy.csv", "time-vs-error.png", "pareto.png"} <= names
    assert any(n.startswith("errors-") for n in names)
    csv = (out / "accuracy.csv").read_text().splitlines()
    assert len(csv) == 1 + len(settings(load_scene(resolve("sierpinski"))))
    text = (out / "README.md").read_text()
    assert "## Verdict" in text and "Pareto front" in text and "Halving ε" in text


def test_bench_accuracy_refuses_a_file_as_its_folder_before_any_work(tmp_path):
    f = tmp_path / "x.txt"
    f.write_text("")
    r = run("bench", "accuracy", "sierpinski", "--out", str(f))
    assert r.returncode == 2 and "is a file; give a folder" in r.stderr
    assert "Traceback" not in r.stderr and "ground truth" not in r.stdout
