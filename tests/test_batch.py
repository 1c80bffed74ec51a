"""Batch rendering on Ray [issue 18 §4]: a local Ray with two workers writes the same frames
as a local render, skips finished frames on restart, and retries chunks whose task failed
or whose actor died."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
import ray
from PIL import Image

from krsview.scene import load_scene
from krsview.scene.camera_path import load_camera_path
from krsview.scene.presets import resolve
from krsview.share.batch import FrameWorker, run_batch
from krsview.share.frames import FrameJob, frame_file, render_frames

from .conftest import krsview_cli

# one local Ray for the module: under `pytest -n` its tests run in the same worker
pytestmark = pytest.mark.xdist_group("ray")
SIZE = (64, 36)
POSES = [
    dict(t=0.0, position=[0.0, 2.0, -9.0], yaw=0.0, pitch=0.0),
    dict(t=1.0, position=[1.0, 2.5, -7.0], yaw=-0.3, pitch=0.1),
]


@pytest.fixture(scope="module")
def cluster():
    ray.init(
        num_cpus=2,
        include_dashboard=False,
        log_to_driver=False,
        configure_logging=False,
        runtime_env={"env_vars": {"LP_NUM_THREADS": "1"}},
    )
    ray.cloudpickle.register_pickle_by_value(sys.modules[__name__])  # the failing workers
    yield
    ray.shutdown()


@pytest.fixture
def path_file(tmp_path):
    path = tmp_path / "tree.path.json"
    path.write_text(json.dumps({"poses": POSES}))
    return path


@pytest.fixture
def job(tmp_path, path_file):
    folder = tmp_path / "frames"
    folder.mkdir()
    return FrameJob(load_scene(resolve("tree")), load_camera_path(path_file), 8.0, SIZE, folder)


def read(path: Path) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def local_frames(job: FrameJob, tmp_path: Path, renderer) -> Path:
    folder = tmp_path / "local"
    folder.mkdir()
    render_frames(
        FrameJob(job.scene, job.path, job.fps, job.size, folder), list(range(job.count)), renderer
    )
    return folder


def test_two_workers_write_the_frames_a_local_render_writes(cluster, job, tmp_path, renderer):
    report = run_batch(job, range(job.count), workers=2, chunk=3)
    assert report.frames == job.count == 9 and not report.failed and not report.retried
    local = local_frames(job, tmp_path, renderer)
    assert sorted(p.name for p in job.folder.iterdir()) == sorted(p.name for p in local.iterdir())
    for k in range(job.count):
        assert np.array_equal(read(frame_file(job.folder, k)), read(frame_file(local, k))), k
    # negative control: neighbouring frames differ, so equality above means something
    assert not np.array_equal(read(frame_file(local, 0)), read(frame_file(local, 1)))
    # a restart skips the finished frames and renders only what is missing
    frame_file(job.folder, 4).unlink()
    again = run_batch(job, range(job.count), workers=2, chunk=3)
    assert again.skipped == 8 and again.frames == 1
    assert np.array_equal(read(frame_file(job.folder, 4)), read(frame_file(local, 4)))


class FailsOnce(FrameWorker):
    """Raises on the first chunk holding frame 2 (a marker file remembers across actors)."""

    def render(self, frames):
        marker = self.job.folder.parent / "failed-once"
        if 2 in frames and not marker.exists():
            marker.write_text("")
            raise RuntimeError("a flaky worker")
        return super().render(frames)


class DiesOnce(FrameWorker):
    """Its process exits in the middle of the first chunk holding frame 5: the actor dies."""

    def render(self, frames):
        marker = self.job.folder.parent / "died-once"
        if 5 in frames and not marker.exists():
            marker.write_text("")
            os._exit(1)
        return super().render(frames)


class AlwaysFails(FrameWorker):
    def render(self, frames):
        if 7 in frames:
            raise RuntimeError("a broken frame")
        return super().render(frames)


@pytest.mark.parametrize("worker", [FailsOnce, DiesOnce])
def test_a_failed_chunk_is_retried_and_the_frames_are_complete(cluster, job, worker):
    report = run_batch(job, range(job.count), workers=2, chunk=2, worker=worker)
    assert len(report.retried) == 1 and not report.failed
    assert report.frames == job.count and job.missing(range(job.count)) == []


def test_a_chunk_out_of_retries_is_reported_and_the_rest_is_written(cluster, job):
    report = run_batch(job, range(job.count), workers=2, chunk=2, retries=1, worker=AlwaysFails)
    assert report.failed == [[6, 7]] and len(report.retried) == 2
    assert job.missing(range(job.count)) == [6, 7]


def test_batch_on_the_command_line(tmp_path, path_file):
    """`krsview batch` with a local Ray of two workers, then a resumed run."""
    args = ["batch", "tree", "--camera-path", str(path_file), "--fps", "4", "--size", "64x36"]
    args += ["-o", str(tmp_path / "f"), "--workers", "2"]
    r = krsview_cli(*args)
    assert r.returncode == 0 and "0 already there, 5 rendered" in r.stdout, r.stderr[-3000:]
    r = krsview_cli(*args)
    assert r.returncode == 0 and "5 already there, 0 rendered" in r.stdout
    # the files are those `render --camera-path` writes: batch drew its frames with other
    # settings (no fast settings), 6.6 % of the pixels apart, and could not resume them [review]
    rendered = tmp_path / "r"
    r = krsview_cli(*(["render", *args[1:8], "-o", str(rendered)]))
    assert r.returncode == 0, r.stderr[-3000:]
    for k in range(5):
        a, b = (np.asarray(Image.open(frame_file(d, k))) for d in (tmp_path / "f", rendered))
        assert np.array_equal(a, b), f"frame {k} differs"
    assert (tmp_path / "f" / "frames.json").read_text() == (rendered / "frames.json").read_text()
    # control: --exact draws other frames, so its run refuses the folder of the fast ones
    r = krsview_cli(*args, "--exact")
    assert r.returncode == 2 and "frames drawn with other render settings (lod: 0.5" in r.stderr


def test_a_local_cluster_takes_a_worker_per_cpu_and_no_more_than_its_chunks(tmp_path, path_file):
    base = ["batch", "tree", "--camera-path", str(path_file), "--fps", "4", "--size", "32x18"]
    many = os.cpu_count() + 1
    r = krsview_cli(*base, "-o", str(tmp_path / "f"), "--workers", str(many))
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1, r.stderr  # it hung [review]
    assert f"--workers = {many}: a local cluster runs one worker per CPU" in r.stderr
    assert not (tmp_path / "f").exists()
    r = krsview_cli(*base, "-o", str(tmp_path / "g"), "--frames", "0-1", "--workers", "2")
    assert r.returncode == 0 and "on 1 worker(s)" in r.stdout, r.stderr[-2000:]  # one chunk


def test_an_accuracy_sweep_on_ray_measures_what_the_local_bench_measures(cluster, tmp_path):
    """Two presets as two tasks: a report's error columns equal a local run's (times
    differ; errors are a function of the images and the ground truth)."""
    import csv

    from krsview.bench.accuracy import bench_accuracy
    from krsview.bench.accuracy_report import write_report
    from krsview.share.batch import run_accuracy_sweep

    names = ("sierpinski", "rock")
    scenes = {n: load_scene(resolve(n)) for n in names}
    outs = {n: tmp_path / "ray" / n for n in names}
    seen = {}
    failed = run_accuracy_sweep(
        scenes, (32, 18), 1, outs, 2, None, lambda n, lines, err: seen.setdefault(n, (lines, err))
    )
    assert failed == [] and set(seen) == set(names) and all(v[0] for v in seen.values()), seen
    columns = ("knob", "value", "holes", "false_hits", "mask_error", "depth_eps_p99")
    for n in names:
        assert (outs[n] / "README.md").exists() and (outs[n] / "pareto.png").exists()
    n = names[1]  # one compared with a local run: the other's report is the control below
    local = tmp_path / "local" / n
    write_report(bench_accuracy(scenes[n], (32, 18), rounds=1), local)
    ray_rows, local_rows = (
        list(csv.DictReader((d / "accuracy.csv").open())) for d in (outs[n], local)
    )
    assert [[r[c] for c in columns] for r in ray_rows] == [
        [r[c] for c in columns] for r in local_rows
    ]
    # negative control: the two presets' reports differ
    a, b = (
        list(csv.DictReader((outs[n] / "accuracy.csv").read_text().splitlines())) for n in names
    )
    assert [r["mask_error"] for r in a] != [r["mask_error"] for r in b]


@pytest.mark.parametrize(
    "args, message",
    [
        (
            ["--address", "ray://127.0.0.1:1"],
            "--address = 'ray://127.0.0.1:1': cannot reach 127.0.0.1:1",
        ),
        (["--address", "http://x"], "expected ray://HOST:PORT"),
        (["--workers", "0"], "--workers '0': allowed 1 ≤ value"),
    ],
)
def test_bad_cluster_options_are_one_line_errors(tmp_path, path_file, args, message):
    """An address where nothing listens is refused at once (Ray alone waits 30 s, or for
    ever). ('auto' with no cluster running is one line too, but whether one runs depends on
    the machine: this module's own fixture starts one.)"""
    out = str(tmp_path / "f")
    r = krsview_cli(
        "batch",
        "tree",
        "--camera-path",
        str(path_file),
        "-o",
        out,
        *args,
        timeout=120,
        RAY_ADDRESS="",
    )
    assert r.returncode in (2, 3) and message in r.stderr, r.stderr
    assert "Traceback" not in r.stderr
    assert len([line for line in r.stderr.splitlines() if "error" in line]) == 1
