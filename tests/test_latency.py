"""`krsview bench latency` (krsview/editor/latency.py): a fork dragged in a real window, one
step per turn through the gizmo's path, each frame time-stamped; what can be checked without
asserting wall time: every step lands, once, and is timed from its edit to its frame."""

from __future__ import annotations

import shutil

import numpy as np

from krsview.editor import latency
from krsview.scene.presets import resolve


def test_the_latency_bench_drags_a_fork_and_times_every_step(display, tmp_path):
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    m = latency.drag_latency(path, (96, 54), steps=5)
    # the fork moved by the five steps, each one turn: nothing more (negative control of the
    # driver: a turn without a step moves nothing)
    assert np.allclose(m["moved"], 5 * m["step"]) and np.linalg.norm(m["step"]) > 0
    assert len(m["latencies"]) == 5 and all(t > 0 for t in m["latencies"])
    assert len(m["turns"]) == 4 and 0 < m["first_full"] <= m["still"]
    assert not path.with_suffix(".toml.recovery").exists() and not list(tmp_path.glob("*.rec*"))
    row = latency.summary(m)[0]
    assert row["scene"] == "tree" and row["window"] == "96×54"
    assert row["latency_ms_p90"] >= row["latency_ms_median"] > 0
