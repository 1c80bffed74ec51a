"""The accuracy benchmark: hit sets are nested in ε (so the errors it reports move the right
way), the Pareto front (with and without a noise floor), settings doing the same work
grouped, the noise floor and 'within noise', work that no machine load changes, the
ground-truth cache, and the report a run writes."""

from __future__ import annotations

import statistics
from dataclasses import replace

import numpy as np
import pytest

from krsview.bench.accuracy import Setting, levels_walked, same_work, settings, work
from krsview.bench.accuracy_report import pareto, verdict
from krsview.bench.harness import noise_floor
from krsview.bench.metrics import compare
from krsview.bench.truth import cache_key, ground_truth, truth_scene
from krsview.compile.camera import view_of
from krsview.gpu.renderer import Renderer
from krsview.reference import render_reference
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import krsview_cli

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


def test_with_a_noise_floor_only_a_difference_beyond_it_dominates():
    """A setting slower than another by less than the floor, and less accurate, stays on
    the time front (within noise); without a floor it is beaten."""
    rows = [
        dict(ms=100, mask_error=0.02),
        dict(ms=104, mask_error=0.03),
        dict(ms=105, mask_error=0.01),
        dict(ms=130, mask_error=0.03),
    ]
    assert pareto(rows) == [rows[0], rows[2]]
    assert pareto(rows, floor=0.1) == [rows[0], rows[1], rows[2]]
    # one setting per group doing the same work: a row the same as another is left out
    same = [dict(r, same_as=k) for k, r in enumerate(rows)] + [dict(rows[0], same_as=0)]
    assert pareto(same) == [same[0], same[2]]


def test_the_noise_floor_is_the_spread_of_fastest_rounds_of_the_same_work():
    groups = [[[1.0, 1.1, 1.4], [1.2, 1.3, 1.25]], [[5.0, 9.0]], [[2.0, 2.0], [2.0, 2.2]]]
    assert noise_floor(groups) == pytest.approx(1.2 / 1.0 - 1)
    assert noise_floor(groups, statistics.median) == pytest.approx(1.25 / 1.1 - 1)
    assert noise_floor([[[1.0, 3.0]]]) == 0.0  # no two variants of the same work: unmeasured


def test_the_fastest_round_holds_where_a_busy_machine_slows_half_the_rounds():
    """Seven settings doing the same work on a machine whose other tenants slowed up to
    half of each one's rounds by 10-60 % (rock's 'scene as saved' group, 9 rounds, measured
    this way): their medians spread 20 % and the report's noise floor with them; the
    fastest rounds agree within a few per cent. Contention only adds time, so the fastest
    round is the estimate least disturbed [Chen and Revels 2016]."""
    rng = np.random.default_rng(7)
    work = 28.5
    groups = []
    for _ in range(7):
        slow = rng.random(9) < 0.5
        times = work * (1 + rng.uniform(0, 0.02, 9)) * np.where(slow, rng.uniform(1.1, 1.6, 9), 1)
        groups.append(list(times))
    assert noise_floor([groups]) < 0.03
    assert noise_floor([groups], statistics.median) > 0.1  # control: the medians' spread


def verdict_rows(ms_half: float, floor: float) -> list[dict]:
    """Synthetic report rows: the scene (= ε-scale 1) and ε-scale 0.5 at ``ms_half`` ms."""
    row = dict(
        knob="scene",
        value="as saved",
        ms=100.0,
        work=50.0,
        mask_error=0.02,
        holes=0.0,
        false_hits=0.02,
        depth_eps_p99=3.0,
        noise_floor=floor,
    )
    return [
        row,
        dict(row, knob="epsilon_scale", value="1"),
        dict(row, knob="epsilon_scale", value="0.5", ms=ms_half, work=55.0, mask_error=0.01),
    ]


def test_a_time_difference_under_the_noise_floor_is_said_to_be_within_noise():
    (small,) = verdict(verdict_rows(106.0, 0.1))
    assert "+6% time (within noise: floor 10.0%)" in small and "+10% work" in small
    (large,) = verdict(verdict_rows(150.0, 0.1))
    assert "+50% time and +10% work" in large and "within noise" not in large
    (no_floor,) = verdict(verdict_rows(106.0, 0.0))
    assert "within noise" not in no_floor
    (same,) = verdict(verdict_rows(99.99, 0.0))
    assert "costs 0% time and" in same  # no "-0%"


def test_settings_doing_the_same_work_are_grouped_and_others_not():
    """A cap that never binds, the compute path's rounds and its persistent lanes draw the
    very same frames as the scene; only the cap compiles the same variant, and the rounds
    and the lanes are two ways of running. A looser ε (another image) and double precision
    (the same iterations, other colours) are not grouped either."""
    scene = load_scene(resolve("sierpinski"))
    runs = [Setting("scene", "as saved", scene)] + [
        Setting(k, str(v), with_render(scene, **{k: v}))
        for k, v in (
            ("max_iterations", 4096),
            ("path", "compute"),
            ("epsilon_scale", 8.0),
            ("precision", "double"),
        )
    ]
    runs.append(Setting("path", "lanes", with_render(scene, path="compute", steps=0)))
    r = Renderer()
    images = {s.name: r.render(s.scene, W, H, s.geometry) for s in runs}
    walked = {s.name: levels_walked(r, s, (W, H)) for s in runs}
    a = images["scene as saved"]
    for name in ("max_iterations 4096", "path compute", "path lanes"):  # identical frames
        assert np.array_equal(images[name].color, a.color)
        assert np.array_equal(images[name].iterations, a.iterations)
    rep = same_work(r, runs, images, walked, (W, H))
    assert rep == {
        "scene as saved": "scene as saved",
        "max_iterations 4096": "scene as saved",
        "path compute": "path compute",
        "epsilon_scale 8.0": "epsilon_scale 8.0",
        "precision double": "precision double",
        "path lanes": "path lanes",
    }


def test_work_counts_the_levels_walked_and_is_the_same_in_every_run():
    """Two renderers count the same levels, equal to the renderer's own count for the
    scene's geometry; a truncated geometry walks fewer levels, a looser ε fewer steps."""
    scene = load_scene(resolve("tree"))
    g = scene.geometry()
    own = Setting("scene", "as saved", scene)
    cut = Setting("levels", "8", scene, g.truncated(8))
    loose = Setting("epsilon_scale", "8", with_render(scene, epsilon_scale=8.0))
    r1, r2 = Renderer(), Renderer()
    first = levels_walked(r1, own, (W, H))
    assert np.array_equal(first, levels_walked(r2, own, (W, H)))
    assert np.array_equal(first, r2.levels(scene, W, H))
    works = {
        s.name: [
            work(r.render(s.scene, W, H, s.geometry), levels_walked(r, s, (W, H)), s)
            for r in (r1, r2)
        ]
        for s in (own, cut, loose)
    }
    assert all(a == b for a, b in works.values())
    assert works[cut.name][0] < works[own.name][0] and works[loose.name][0] < works[own.name][0]


def test_every_knob_is_swept_and_a_mokrs_only_with_binary_tracing():
    knobs = {s.knob for s in settings(load_scene(resolve("tree")))}
    assert knobs == {
        "scene",
        "epsilon_scale",
        "max_iterations",
        "tracer",
        "precision",
        "culling",
        "walk_restart",  # a single KRS, sphere-traced
        "lod",
        "shadow_block",  # its soft shadows: rays shared by pixel blocks or not
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
        "lod",
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


def test_ground_truth_draws_every_level():
    """The truth is the walk without the level of detail, whatever the scene's lod: the
    settings are measured against it (and the same truth serves every lod)."""
    scene = load_scene(resolve("tree"))
    assert scene.render.lod > 0 and truth_scene(scene).render.lod == 0
    assert cache_key(scene, (16, 9)) == cache_key(
        replace(scene, render=replace(scene.render, lod=2.0)), (16, 9)
    )


def test_bench_accuracy_writes_a_readable_report(tmp_path):
    out = tmp_path / "report"
    r = krsview_cli(
        "bench",
        "accuracy",
        "sierpinski",
        "--size",
        "48x27",
        "--rounds",
        "3",
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
    assert "Noise floor" in text and "| work |" in text and "= scene as saved" in text
    head = csv[0].split(",")
    assert {"knob", "value", "ms", "mask_error", "ms_median", "ms_max", "noise_floor"} <= set(head)
    assert "work" in head
    assert "same_as" in head
    # the pre-pass unset and 0 draw alike: one time, no "prepass 0" row timed apart [review]
    assert "| prepass | 0 |" not in text
    rows = list(__import__("csv").DictReader(csv))
    # each time is the fastest round, the median and the slowest beside it
    assert all(float(r["ms"]) <= float(r["ms_median"]) <= float(r["ms_max"]) for r in rows)
    tiles = [r for r in rows if r["knob"] == "prepass"]
    assert tiles and all(r["value"] != "0" for r in tiles)
    assert "| prepass | 4 |" in text and "†" in text  # its work marked: cones not counted
    front = text[text.index("Pareto front in work") :].split("\n")[0]
    assert "prepass" not in front
    # one or two rounds give no spread to judge by: refused before any work
    r = krsview_cli("bench", "accuracy", "sierpinski", "--rounds", "2", "--out", str(out))
    assert r.returncode == 2 and "--rounds '2': allowed 3 ≤ value" in r.stderr


def test_a_setting_is_never_worth_it_only_when_beaten_on_every_error():
    """ "Never worth it" named a setting that was better on depth and beaten by a few
    pixels of hit mask (forest's ε 0.5 by levels 18), or one beaten by a setting that
    traded false hits for holes (rock's cap 64) [review]."""
    from krsview.bench.accuracy_report import dominated

    def row(ms, mask, holes, depth):
        return dict(ms=ms, mask_error=mask, holes=holes, depth_eps_p99=depth, same_as=None)

    rows = [row(60, 0.004, 0.0, 130), row(62, 0.0040, 0.0009, 142), row(79, 0.0043, 0.0, 128)]
    rows += [row(90, 0.0043, 0.0, 128)]  # the control: beaten on time, alike in every error
    for k, r in enumerate(rows):
        r["same_as"] = k
    assert dominated(rows, 0.05) == [rows[3]]
    rows[1]["depth_eps_p99"] = 120  # better depth: now it beats the third, 0.03 % off in mask
    assert dominated(rows, 0.05) == [rows[2], rows[3]]


def test_bench_accuracy_refuses_a_file_as_its_folder_before_any_work(tmp_path):
    f = tmp_path / "x.txt"
    f.write_text("")
    r = krsview_cli("bench", "accuracy", "sierpinski", "--out", str(f))
    assert r.returncode == 2 and "is a file; give a folder" in r.stderr
    assert "Traceback" not in r.stderr and "ground truth" not in r.stdout
