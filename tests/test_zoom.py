"""`krsview bench zoom`: the flight's cameras, and the rows the bench returns."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import krsview
from krsview.bench.zoom import END_RADII, bench_zoom, finest_kernel_ball, spread, stops, table


def test_the_flight_goes_straight_into_the_finest_twig_at_a_constant_zoom_rate():
    tree = krsview.load("tree")
    ball = finest_kernel_ball(tree)
    twig = tree.geometry().kernels[0]  # K_0: the finest level's branch, its tip at `end`
    assert np.linalg.norm(np.array(twig.end) - ball[:3]) <= ball[3]
    assert ball[3] < 0.01 * finest_kernel_ball(tree.with_levels(1))[3]  # 22 levels finer
    views = stops(tree, 6)
    eye = np.array(tree.camera.position)
    d = [np.linalg.norm(np.array(v.camera.position) - ball[:3]) for v in views]
    assert d[0] == pytest.approx(np.linalg.norm(eye - ball[:3]))
    assert d[-1] == pytest.approx(END_RADII * ball[3])
    assert np.allclose(np.diff(np.log(d)), np.log(d[1] / d[0]))  # geometric
    for v in views:  # on the line from the eye, looking at the twig
        assert np.allclose(v.camera.target, ball[:3])
        u = np.array(v.camera.position) - ball[:3]
        assert np.linalg.norm(np.cross(u, eye - ball[:3])) < 1e-9 * np.linalg.norm(eye) ** 2
    with pytest.raises(krsview.SceneError, match="not a compound or a MöKRS"):
        finest_kernel_ball(krsview.load("grove"))


def test_bench_zoom_returns_rows_and_draws_its_plot(tmp_path):
    tree = krsview.load("tree")
    m = bench_zoom(tree, (24, 14), rounds=1, stops_count=3, plot=tmp_path / "zoom.png")
    assert [r["stop"] for r in m.rows] == ["stop 0", "stop 1", "stop 2"]
    assert m.column("distance") == sorted(m.column("distance"), reverse=True)
    assert all(0 < r["levels_per_iteration"] <= tree.geometry().depth for r in m.rows)
    assert spread(m) >= 1.0 and "slowest frame / fastest" in table(m)
    assert Image.open(tmp_path / "zoom.png").size[0] > 300
    # the work is deterministic (a busy machine changes only the times) …
    again = bench_zoom(tree, (24, 14), rounds=1, stops_count=3)
    assert m.column("iterations") == again.column("iterations")
    # … and it does see the flight: the views differ in what they hit
    assert len(set(m.column("hit"))) > 1
