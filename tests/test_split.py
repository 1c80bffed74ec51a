"""`krsview bench split` [issue 17]: where a frame's time goes, as differences of variants.
What can be checked without asserting wall time: the tracing-only variant traces exactly as
the frame does and shades nothing, and the report has every part, adding up to the frame,
with the shadow rays' work (steps, levels) on the frames with and without the shadow cone."""

from __future__ import annotations

import csv
from dataclasses import replace

import numpy as np
import pytest

from krsview.gpu.readback import read_buffers
from krsview.scene import load_scene
from krsview.scene.presets import resolve

from .conftest import krsview_cli


def test_the_tracing_only_variant_traces_as_the_frame_and_shades_nothing(renderer):
    """Same hit mask, depths and iterations as the full frame, bit for bit; no colour.
    Negative control: the full frame has colour where it hits."""
    scene = load_scene(resolve("tree"))
    scene = replace(scene, render=replace(scene.render, prepass=8))
    full = renderer.render(scene, 64, 36)
    with renderer.current():
        prog = renderer.prepare(scene, 64, 36, probes=("KRS_TRACE_ONLY",))
        trace = read_buffers(renderer.draw(prog, 64, 36), 64, 36)
    assert full.hit.any() and np.array_equal(trace.hit, full.hit)
    assert np.array_equal(trace.depth[trace.hit], full.depth[full.hit])
    assert np.array_equal(trace.iterations, full.iterations)
    assert (trace.color == 0).all() and (full.color[full.hit] > 0).any()


def test_bench_split_reports_every_part(tmp_path):
    out = tmp_path / "split.csv"
    r = krsview_cli(
        "bench",
        "split",
        "tree",
        "--size",
        "32x18",
        "--rounds",
        "1",
        "--prepass",
        "4",
        "--csv",
        str(out),
    )
    assert r.returncode == 0, r.stderr
    table = list(csv.DictReader(out.open()))
    rows = {row["part"]: float(row["ms"]) for row in table}
    parts = (
        "coarse passes",
        "tracing",
        "nearest kernel and shading",
        "secondary effects (shadow rays, occlusion)",
    )
    per_pixel = ("secondary effects, a shadow ray per pixel", "frame, a shadow ray per pixel")
    cone_off = ("secondary effects, shadow cone off", "frame, shadow cone off")
    assert set(rows) == {*parts, "frame", "frame without secondary effects", *per_pixel, *cone_off}
    assert sum(rows[p] for p in parts) == pytest.approx(rows["frame"])
    for extra, whole in (per_pixel, cone_off):
        assert rows["frame without secondary effects"] + rows[extra] == pytest.approx(rows[whole])
    # the work measure on the two frames only; the tree's shadow rays start inside its one
    # ball, so the cone spares them nothing (tests/test_shadows_cone.py: grove's it does)
    work = {row["part"]: (row["shadow steps/px"], row["shadow levels/px"]) for row in table}
    assert {p for p, w in work.items() if w != ("", "")} == {"frame", cone_off[1]}
    steps = {p: float(w[0]) for p, w in work.items() if w != ("", "")}
    assert 0 < steps["frame"] <= steps[cone_off[1]], steps
    assert rows["coarse passes"] > 0 and "| tracing |" in r.stdout
    assert "shadow rays per 2×2 px;" in r.stdout  # the tree's still frame shares them
    bad = krsview_cli("bench", "split", "tree", "--prepass-levels", "9", timeout=60)
    assert bad.returncode == 2 and "--prepass-levels" in bad.stderr
    assert "Traceback" not in bad.stderr
