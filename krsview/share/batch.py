"""`krsview batch`: the frames of a camera path rendered by a pool of Ray actors [issue 18 §4].

Farm practice: each actor holds one EGL context and the compiled shader variant for its
whole life, and takes chunks of frames, so start-up (a context, a compile) is paid once per
actor, not per frame. Actors send PNG bytes back and the driver writes them atomically into
the output folder, so workers need no shared disk. Frames already in the folder are never
scheduled (a restarted batch resumes); a chunk whose task fails is retried, on a fresh actor
if its actor died; the result is the same set of files a local `krsview render
--camera-path` writes (frames are a pure function of scene, path and frame number).

Ray starts a local cluster unless given the address of an existing one (``ray://…`` or
``auto``). The accuracy bench of many presets runs the same way, one task per preset
(`krsview bench accuracy P1 P2 … --workers N`)."""

from __future__ import annotations

import os
import re
import socket
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ..scene import Scene, SceneError
from .frames import FrameJob, frame_png, write_frame


@dataclass
class BatchReport:
    frames: int = 0  # rendered by this run
    skipped: int = 0  # already in the folder
    retried: list[list[int]] = field(default_factory=list)  # chunks that failed once or more
    failed: list[list[int]] = field(default_factory=list)  # chunks that ran out of retries
    startup: float = 0.0  # seconds to start Ray and the actors (context + compile)
    seconds: float = 0.0  # seconds rendering, after start-up

    @property
    def fps(self) -> float:
        return self.frames / self.seconds if self.seconds > 0 else 0.0


class FrameWorker:
    """One actor: an EGL context and its program cache, kept for every chunk it renders."""

    def __init__(self, job: FrameJob):
        from ..gpu.renderer import Renderer

        self.job = job
        self.renderer = Renderer()
        self.renderer.prepare(job.frame_scene(0), *job.size)  # compile before timing starts

    def ready(self) -> int:
        return os.getpid()

    def render(self, frames: list[int]) -> list[tuple[int, bytes]]:
        return [(k, frame_png(self.job, k, self.renderer)) for k in frames]


class ClusterError(RuntimeError):
    """Ray could not be started or joined (one line, exit status 3)."""


def check_address(address: str | None, flag: str = "--address") -> None:
    """Before any work: the address has a form Ray takes, and its host answers (Ray itself
    waits a long time, or for ever, on an address where nothing listens)."""
    if address is None or address == "auto":
        return
    m = re.fullmatch(r"(ray://)?([^:/\s]+):(\d{1,5})", address)
    if m is None:
        raise SceneError(
            flag,
            address,
            "expected ray://HOST:PORT (the Ray client), HOST:PORT (a head node's GCS) or auto",
        )
    try:
        socket.create_connection((m.group(2), int(m.group(3))), timeout=5).close()
    except OSError as e:
        raise SceneError(
            flag, address, f"cannot reach {m.group(2)}:{m.group(3)}: {e.strerror or e}"
        ) from None


def start_ray(workers: int, address: str | None) -> None:
    """Join ``address``, or start a local cluster with one CPU per worker; each worker's
    llvmpipe gets its share of the cores (on a GPU machine the variable is ignored)."""
    import ray

    if ray.is_initialized():
        return
    threads = max(1, (os.cpu_count() or 1) // workers)
    try:
        ray.init(
            address=address,
            num_cpus=None if address else workers,
            include_dashboard=False,
            log_to_driver=False,
            configure_logging=False,
            runtime_env={"env_vars": {"LP_NUM_THREADS": str(threads), "DISPLAY": ""}},
        )
    except (ConnectionError, TimeoutError, RuntimeError, ValueError) as e:
        where = address or "a local cluster"
        raise ClusterError(f"Ray at {where}: {str(e).strip().splitlines()[-1]}") from None


def chunks_of(frames: list[int], size: int) -> list[list[int]]:
    return [frames[k : k + size] for k in range(0, len(frames), size)]


def run_batch(
    job: FrameJob,
    frames: range,
    workers: int = 2,
    chunk: int = 8,
    address: str | None = None,
    retries: int = 2,
    done: Callable[[int], None] | None = None,
    worker: type = FrameWorker,
) -> BatchReport:
    """Render the frames of ``frames`` not yet in ``job.folder`` on ``workers`` Ray actors in
    chunks of ``chunk``; ``done(k)`` after each frame written. ``worker`` is the actor class
    (tests pass one that fails on purpose)."""
    import ray

    report = BatchReport()
    todo = job.missing(frames)
    report.skipped = len(frames) - len(todo)
    if not todo:
        return report
    t0 = time.perf_counter()
    start_ray(workers, address)
    actor = ray.remote(num_cpus=1, max_restarts=0)(worker)
    pool = [actor.remote(job) for _ in range(workers)]
    actors = list(pool)  # every actor started, to stop them
    ray.get([a.ready.remote() for a in pool])
    report.startup = time.perf_counter() - t0
    t1 = time.perf_counter()
    queue = [(c, 0) for c in chunks_of(todo, chunk)]
    idle, running = list(pool), {}
    while queue or running:
        while queue and idle:
            frames_, attempt = queue.pop(0)
            a = idle.pop()
            running[a.render.remote(frames_)] = (a, frames_, attempt)
        ready, _ = ray.wait(list(running), num_returns=1)
        a, frames_, attempt = running.pop(ready[0])
        try:
            for k, png in ray.get(ready[0]):
                write_frame(job.folder, k, png)
                report.frames += 1
                if done is not None:
                    done(k)
            idle.append(a)
        except ray.exceptions.RayActorError:  # the actor died: start another
            report.retried.append(frames_)
            actors.append(actor.remote(job))
            idle.append(actors[-1])
            _requeue(queue, report, frames_, attempt, retries)
        except ray.exceptions.RayTaskError:  # the task raised: the actor lives on
            report.retried.append(frames_)
            idle.append(a)
            _requeue(queue, report, frames_, attempt, retries)
    report.seconds = time.perf_counter() - t1
    for a in actors:
        ray.kill(a, no_restart=True)
    return report


def _requeue(
    queue: list, report: BatchReport, frames: list[int], attempt: int, retries: int
) -> None:
    if attempt < retries:
        queue.append((frames, attempt + 1))
    else:
        report.failed.append(frames)


def accuracy_report(
    scene: Scene, size: tuple[int, int], rounds: int, cache: Path | None = None
) -> tuple[dict[str, bytes], list[str]]:
    """One preset's `bench accuracy` (bench/accuracy.py) in a scratch folder: its files as
    bytes, so the driver writes them wherever it likes, and the report's verdict. ``cache``:
    the ground-truth cache on the worker's machine (None: its default)."""
    from ..bench.accuracy import bench_accuracy
    from ..bench.accuracy_report import verdict, write_report

    acc = bench_accuracy(scene, size, rounds, cache)
    with tempfile.TemporaryDirectory() as d:
        write_report(acc, Path(d))
        files = {str(p.relative_to(d)): p.read_bytes() for p in Path(d).rglob("*") if p.is_file()}
    return files, verdict(acc.measured.rows)


def run_accuracy_sweep(
    scenes: dict[str, Scene],
    size: tuple[int, int],
    rounds: int,
    outs: dict[str, Path],
    workers: int,
    address: str | None,
    done: Callable[[str, list[str] | None, str], None],
    cache: Path | None = None,
) -> list[str]:
    """The accuracy bench of every scene as one Ray task each (retried if its worker dies);
    each report is written to ``outs[name]`` as it arrives and ``done(name, verdict, error)``
    called. Returns the names that failed. Time ratios are measured within each task, side
    by side; tasks sharing one machine's cores inflate absolute times, not the ratios' sense."""
    import ray

    start_ray(workers, address)
    task = ray.remote(num_cpus=1, max_retries=2)(accuracy_report)
    running = {task.remote(scene, size, rounds, cache): name for name, scene in scenes.items()}
    failed = []
    while running:
        ready, _ = ray.wait(list(running), num_returns=1)
        name = running.pop(ready[0])
        try:
            files, lines = ray.get(ready[0])
        except ray.exceptions.RayError as e:
            failed.append(name)
            done(name, None, str(e).strip().splitlines()[-1])
            continue
        for rel, data in files.items():
            target = outs[name] / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
        done(name, lines, "")
    return failed
