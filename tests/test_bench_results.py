"""The benchmarks return data (issue 26): each bench function gives its rows, with the CSV's
columns, and its ``table`` prints those rows; what the rows must hold is checked against
what the bench was asked to measure (no wall time is asserted)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import krsview
from krsview.bench import (
    accuracy,
    accuracy_report,
    effects,
    harness,
    levels,
    paths,
    split,
    tracers,
)
from krsview.bench.report import Measured, markdown, write_csv
from krsview.scene import SceneError
from krsview.scene.effects import allowed_effects

SIZE = (16, 9)


def data_rows(table: str) -> list[str]:
    """The body rows of the Markdown table in ``table``."""
    lines = table.splitlines()
    head = next(k for k, line in enumerate(lines) if line.startswith("|---"))
    return [line for line in lines[head + 1 :] if line.startswith("| ")]


def test_levels_returns_a_row_per_level_count():
    scene = krsview.load("sierpinski")
    m = levels.bench_levels(scene, SIZE, step=8, rounds=1)
    assert isinstance(m, Measured) and m.size == SIZE and m.rounds == 1
    assert m.column("levels") == [8, 16, 22]
    assert list(m.rows[0]) == [
        "levels",
        "instances",
        "ms",
        "ms_median",
        "ms_max",
        "time_ratio",
        "time_ratio_min",
        "time_ratio_max",
        "to_previous",
        "to_previous_min",
        "to_previous_max",
        "iterations",
        "ratio_per_iteration",
        "ms_every_level",
        "lod_speedup",
        "lod_speedup_min",
        "lod_speedup_max",
    ]
    assert m.rows[0]["time_ratio"] == 1.0 and m.rows[0]["ratio_per_iteration"] == 1.0
    assert all(r["ms"] == r["ms_median"] == r["ms_max"] for r in m.rows)  # one round
    assert m.column("instances") == [
        scene.geometry().truncated(n).instance_count() for n in (8, 16, 22)
    ]
    assert len(data_rows(levels.table(m))) == 3 and "linear fit" in levels.table(m)
    # negative control: two level counts make no fit
    two = Measured(m.scene, m.size, 1, m.rows[:2])
    assert "linear fit" not in levels.table(two) and len(data_rows(levels.table(two))) == 2


def test_tracers_returns_sphere_and_binary_against_sphere():
    m = tracers.bench_tracers(krsview.load("sierpinski"), SIZE, rounds=1, sweep=False)
    assert m.column("tracer") == ["sphere", "binary"]
    first = m.rows[0]
    assert first["iteration_ratio"] == 1.0 and first["hit_agreement"] == 1.0
    assert m.rows[1]["xi_bonus"] == 2.0 and m.rows[1]["xi_penalty"] == 0.3
    assert 0 < m.rows[1]["hit_fraction"] < 1
    assert "fastest ξ pair" not in tracers.table(m)  # one binary setting: no pair to pick
    with pytest.raises(SceneError, match="--no-sweep"):  # a MöKRS has nothing to compare
        tracers.bench_tracers(krsview.load("palm"), SIZE, rounds=1, sweep=False)


def test_effects_returns_plain_each_effect_and_the_compiled_variants():
    scene = krsview.load("sierpinski")
    m = effects.bench_effects(scene, SIZE, rounds=1)
    names = m.column("variant")
    assert names[0] == "plain" and m.rows[0]["ratio_to_plain"] == 1.0
    assert set(allowed_effects(False)) <= set(names)
    assert "none on, all compiled" in names and "compound of 1" in names
    for row in m.rows:
        assert row["incremental"] == pytest.approx(row["ratio_to_plain"] - 1.0)
    assert len(data_rows(effects.table(m))) == len(m.rows)
    # a compound's components summed: a sum of fastest rounds, with no median or slowest
    summed = dict(m.rows[0], variant="components alone, summed", ms_median="", ms_max="")
    last = data_rows(effects.table(replace(m, rows=[*m.rows, dict(summed, low="", high="")])))
    assert f"| {summed['ms']:.1f} |" in last[-1] and "[" not in last[-1]
    assert "[" in last[0]  # control: a timed variant's spread
    # negative control: a scene without effects has no specialised-vs-compiled pair
    assert ("scene, specialised" in names) == bool(scene.effects)


def test_split_parts_add_up_to_the_frame_and_no_prepass_has_no_coarse_part():
    tree = krsview.load("tree")
    with_prepass = split.bench_split(tree.edit("render.prepass", 4), SIZE, rounds=1)
    ms = dict(zip(with_prepass.column("part"), with_prepass.column("ms")))
    alternatives = ("a shadow ray per pixel", "shadow cone off")  # other frames, not parts
    parts = [
        p
        for p in ms
        if not p.startswith(("frame", "moving")) and not any(a in p for a in alternatives)
    ]
    assert len(parts) == 4 and sum(ms[p] for p in parts) == pytest.approx(ms["frame"])
    for a in alternatives:  # each alternative frame is the frame without effects + its own
        own = ms["frame without secondary effects"] + ms[f"secondary effects, {a}"]
        assert own == pytest.approx(ms[f"frame, {a}"])
    assert ms["coarse passes"] > 0
    without = split.bench_split(tree.edit("render.prepass", 0), SIZE, rounds=1)
    assert dict(zip(without.column("part"), without.column("ms")))["coarse passes"] == 0.0


def test_paths_returns_every_lever_at_two_sizes():
    scene = krsview.load("sierpinski")
    m = paths.bench_paths(scene, (8, 6), rounds=1)
    assert len(m.rows) == 2 * len(paths.levers(scene))
    assert {row["size"] for row in m.rows} == {"8x6", "16x12"}
    plain = [r for r in m.rows if (r["path"], r["culling"], r["prepass"]) == ("fragment", "off", 0)]
    assert [r["speedup"] for r in plain] == [1.0, 1.0]
    assert all((r["coarse_share"] > 0) == (r["prepass"] > 0) for r in m.rows)
    # a share above the whole frame is noise of sub-millisecond frames (it read 1007 %)
    assert paths.share(0.254) == "25%" and paths.share(1.0) == "100%"
    assert paths.share(10.07) == "— (noise)"


def test_accuracy_returns_a_row_per_setting_and_error_images(tmp_path):
    scene = krsview.load("sierpinski")
    acc = accuracy.bench_accuracy(scene, SIZE, rounds=1, cache=tmp_path / "cache")
    m = acc.measured
    assert [(r["knob"], r["value"]) for r in m.rows] == [
        (s.knob, s.value) for s in accuracy.settings(scene)
    ]
    assert m.rows[0]["time_ratio"] == 1.0
    assert all(r["mask_error"] == r["holes"] + r["false_hits"] for r in m.rows)
    assert acc.errors and all(
        name.endswith(".png") and img.shape == (SIZE[1], SIZE[0], 3) and img.dtype == np.uint8
        for name, img in acc.errors.items()
    )
    # the loosest ε loses pixels the truth has; the scene's own setting far fewer
    eps = {r["value"]: r["mask_error"] for r in m.rows if r["knob"] == "epsilon_scale"}
    assert eps["8"] > eps["0.125"]
    text = accuracy_report.write_report(acc, tmp_path / "report")
    assert text == (tmp_path / "report" / "README.md").read_text()
    assert {name for name in acc.errors} <= {p.name for p in (tmp_path / "report").iterdir()}


def test_accuracy_runs_on_a_mokrs(tmp_path):
    """A MöKRS's walk is counted as a KRS's (the levels ISUNBOUNDING walks per probe): its
    work lies between one kernel per step and the walk's bound, every level at every step,
    well below that bound (a probe that misses a level's bound stops there)."""
    scene = krsview.load("palm")
    m = accuracy.bench_accuracy(scene, (12, 8), rounds=1, cache=tmp_path / "cache").measured
    n = scene.geometry().n
    for r in m.rows[:3]:
        assert r["iterations"] < r["work"] < 0.5 * r["iterations"] * (1 + n), r


def test_markdown_and_csv_hold_the_rows(tmp_path):
    rows = [dict(part="shadow rays, occlusion", ms=1.5), dict(part="frame", ms=3.0)]
    assert markdown(("part", "ms"), "lr", [(r["part"], r["ms"]) for r in rows]) == (
        "| part | ms |\n|---|---:|\n| shadow rays, occlusion | 1.5 |\n| frame | 3.0 |"
    )
    path = write_csv(rows, tmp_path / "sub" / "x.csv")
    assert path.read_text() == 'part,ms\n"shadow rays, occlusion",1.5\nframe,3.0\n'


def test_split_table_names_the_prepass_it_measured():
    tree = krsview.load("tree")
    m = Measured(replace(tree, render=replace(tree.render, prepass=8)), SIZE, 1, [])
    assert "pre-pass 8 × 2" in split.table(m)
    assert "pre-pass off" in split.table(Measured(tree, SIZE, 1, []))


def test_a_split_part_whose_rounds_disagree_on_its_sign_is_within_noise():
    """A part is a difference of two variants' times: on a busy machine its rounds may
    straddle zero (−0.6 ms, −24 % was printed as a finding). Such a part is said to be
    within noise; one whose rounds agree is not (the control), nor is a whole frame."""
    row = dict(part="secondary effects (shadow rays, occlusion)", low=-0.8, high=0.5)
    assert split.noted(row).endswith("(within noise)")
    assert split.noted({**row, "low": 0.1}) == row["part"]
    assert split.noted({**row, "part": "frame"}) == "frame"


def test_an_effect_cost_whose_rounds_disagree_on_its_sign_is_within_noise():
    """smooth_shading −20 % was printed as a finding from two noisy rounds."""
    row = dict(variant="smooth_shading", low=-0.2, high=0.05)
    assert effects._noise(row) == " (within noise)"
    assert effects._noise({**row, "low": 0.02}) == ""  # the control: a cost every round
    assert effects._noise({**row, "variant": "plain"}) == ""


def test_a_lever_whose_rounds_straddle_the_plain_frame_is_within_noise():
    """Culling on against off read 0.65× with the very same work and no spread shown
    [review]: each speed-up now carries its round-by-round [min–max], and where that holds
    1× it is said to be within noise."""
    scene = krsview.load("sierpinski")
    m = paths.bench_paths(scene, (8, 6), rounds=2)
    assert all(r["speedup_min"] <= r["speedup"] <= r["speedup_max"] for r in m.rows)
    row = dict(m.rows[1], speedup=0.65, speedup_min=0.55, speedup_max=1.1)
    text = paths.table(replace(m, rows=[row, dict(row, speedup_max=0.7)]))
    lines = [x for x in text.splitlines() if x.startswith("| 8x6")]
    assert "0.65× [0.55–1.10] within noise" in lines[0]
    assert "0.65× [0.55–0.70] |" in lines[1]  # control: slower in every round


def test_a_ratio_carries_its_round_by_round_range_and_is_within_noise_where_it_holds_one():
    """bench levels, zoom and tracers printed bare ratios of medians (L30/L23 1.07× with no
    spread): each now carries the [min–max] of its round-by-round ratio."""
    assert harness.ratio_range([2.0, 3.0, 4.0], [2.0, 2.0, 2.0]) == (1.0, 2.0)
    assert harness.with_range(1.07, 0.98, 1.12) == "1.07× [0.98–1.12] within noise"
    assert harness.with_range(1.07, 1.03, 1.12) == "1.07× [1.03–1.12]"  # control: every round
    with pytest.raises(ValueError):  # rounds of two runs do not pair
        harness.ratio_range([1.0, 2.0], [1.0])
    scene = krsview.load("sierpinski")
    m = levels.bench_levels(scene, SIZE, step=11, rounds=2)
    assert all(r["time_ratio_min"] <= r["time_ratio"] <= r["time_ratio_max"] for r in m.rows)
    row = dict(m.rows[1], to_previous=1.07, to_previous_min=0.9, to_previous_max=1.2)
    lines = data_rows(
        levels.table(replace(m, rows=[m.rows[0], row, dict(row, to_previous_min=1.01)]))
    )
    assert "1.07× [0.90–1.20] within noise" in lines[1]
    assert "1.07× [1.01–1.20] |" in lines[2]  # control: slower in every round


def test_the_tracers_base_row_is_its_own_unit_not_a_range_within_noise():
    """The sphere tracer's row read "1.00× [1.00–1.00] within noise": a ratio to itself."""
    m = tracers.bench_tracers(krsview.load("sierpinski"), SIZE, rounds=2, sweep=False)
    lines = data_rows(tracers.table(m))
    assert "| 1.00× |" in lines[0] and "within noise" not in lines[0]
    assert "× [" in lines[1]  # control: the binary tracer's ratio carries its range


def test_every_bench_times_a_variant_by_its_fastest_round(monkeypatch):
    """Load from other work only adds time, so a variant's time is its fastest round, the
    median and slowest beside it; a ratio is fastest to fastest (within the round-by-round
    range). Here every other round of every variant is slowed by 50 % (a busy neighbour):
    the times and ratios are the quiet rounds'; the medians, the control, moved."""
    assert harness.time_columns([0.003, 0.001, 0.002]) == dict(ms=1.0, ms_median=2.0, ms_max=3.0)
    quiet = {}  # name → its quiet time (s), made up: 1, 2, … ms, every level 10 % more

    def busy(r, variants, size, rounds, label):
        for k, name in enumerate(v for v in variants if not v.endswith("every level")):
            quiet[name] = (k + 1) * 1e-3
            quiet[f"{name}, every level"] = 1.1 * quiet[name]
        return {n: [quiet[n] * (1.5 if j % 2 else 1.0) for j in range(rounds)] for n in variants}

    monkeypatch.setattr(levels, "round_times", busy)
    m = levels.bench_levels(krsview.load("sierpinski"), SIZE, step=11, rounds=4)
    base = quiet[f"{m.rows[0]['levels']} levels"]
    for r in m.rows:
        t = quiet[f"{r['levels']} levels"]
        assert r["ms"] == pytest.approx(t * 1e3) and r["ms_max"] == pytest.approx(1.5 * t * 1e3)
        assert r["ms_median"] == pytest.approx(1.25 * t * 1e3)  # control: the medians moved
        assert r["time_ratio"] == pytest.approx(t / base)
        assert r["time_ratio_min"] <= r["time_ratio"] <= r["time_ratio_max"]
        assert r["lod_speedup"] == pytest.approx(1.1)
    assert "fastest round [median–slowest]" in levels.table(m)
