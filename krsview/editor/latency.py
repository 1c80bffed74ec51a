"""`krsview bench latency`: how fast the editor answers a drag, in a real window [issue 28 §5].

The editor opens the scene at the window size asked (a grown tree baked into its route) and
lets the view settle. Then a fork (in a compound: one of its trees) is dragged in small
steps, one per turn of the event loop, through the gizmo's own path: each step is the edit
``Gizmo.manipulate`` returns inside the UI pass, as a pointer drag gives it (the pointer's
reading by ImGuizmo is the only part left out). Every turn is time-stamped when its frame is
on screen (after the buffer swap), so a step's latency is the time from the gizmo's edit to
the end of the first turn that traced it. After the release: the first full-resolution
image (where shadow rays are shared per block, the primary one, lit by the blocks of the
image before it) and the still one. Wall times on whatever else runs: median and p90, not a test."""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import glfw
import numpy as np

from ..scene import SceneError
from .window import Editor

DRAG_STEPS = 40  # turns with a drag step each
STEP = 0.004  # a drag step, × the scene's size (a few pixels at the preset's view)
SETTLE_TURNS = 2000  # turns the view may take to become still (else: an error)


def _turn(e: Editor) -> float:
    """One turn of the event loop (viewer/loop.py): the time its frame is on screen."""
    glfw.poll_events()
    e.step(1 / 60)
    return time.perf_counter()


def _settle(e: Editor) -> float:
    """Turn until the window shows the still image; the time it did."""
    for _ in range(SETTLE_TURNS):
        t = _turn(e)
        if e.viewer.frames.refined:
            return t
    raise RuntimeError(f"{e.path}: the view did not become still in {SETTLE_TURNS} turns")


def _handle(e: Editor):
    """What a person drags: the fork halfway down a route (it moves about half the tree),
    else the middle one of the points (a compound's component, a kernel's point)."""
    forks = [h for h in e.handles if h.path[-1] == "fork"]
    points = forks or [h for h in e.handles if h.kind == "point"]
    if not points:
        raise SceneError("PRESET", str(e.path), "has no point to drag (a MöKRS has none yet)")
    return points[len(points) // 2]


class _Drag:
    """Stands in for the pointer: while ``on``, the gizmo's next call moves the selected handle
    one step further and says when (the rest of ``Gizmo.manipulate`` is not run)."""

    def __init__(self, e: Editor, step: np.ndarray):
        self.e, self.step, self.on, self.k = e, step, False, 0
        self.edited: list[float] = []

    def manipulate(self, h, view):
        if not self.on:
            return None
        self.k += 1
        self.edited.append(time.perf_counter())
        return h.position + self.step, ("latency drag", 1)


def drag_latency(path: Path, size: tuple[int, int], steps: int = DRAG_STEPS) -> dict:
    """Drag a fork of the scene at ``path`` in an editor window of ``size`` for ``steps``
    turns: a dict of the latencies (s), the turn times while dragging (s), the internal
    sizes of the frames shown, and the times from the release to the first full-resolution
    image and to the still one."""
    e = Editor(path, size=size, visible=True)
    try:
        if e.scene.route is None and e.scene.tree is not None:
            e.bake()
        _settle(e)
        h = _handle(e)
        e.select(h)
        _settle(e)
        start = h.position
        scale = float(np.ptp(np.array([x.position for x in e.handles]), axis=0).max())
        drag = _Drag(e, np.array([STEP * scale, 0.0, 0.0]))
        e.gizmo.manipulate = drag.manipulate
        traced: list[int] = []  # per turn: the drag steps its image was traced with
        draw = e.viewer.draw_image
        e.viewer.draw_image = lambda: (traced.append(drag.k), draw())
        shown, turns, sizes = [], [], []
        drag.on = True
        last = time.perf_counter()
        for k in range(steps + 1):  # the last turn shows the last step
            drag.on = k < steps
            t = _turn(e)
            shown.append(t)
            turns.append(t - last)
            sizes.append(e.viewer.frames.frame_state().size)
            last = t
        e.viewer.draw_image = draw
        released = drag.edited[-1]
        full = e.viewer.frames.adaptive.full
        first_full = None
        for _ in range(SETTLE_TURNS):
            t = _turn(e)
            if first_full is None and e.viewer.frames.frame_state().size == full:
                first_full = t
            if e.viewer.frames.refined:
                break
        # a step's frame: the first turn that traced it (the same turn, when the gizmo
        # runs before the trace), on screen at that turn's end
        latencies = [
            shown[next(j for j, n in enumerate(traced) if n >= k)] - drag.edited[k - 1]
            for k in range(1, len(drag.edited) + 1)
        ]
        moved = next(x.position for x in e.handles if x.same(h)) - start
        return dict(
            scene=e.scene.name,
            moved=moved,
            step=drag.step,
            window=size,
            latencies=latencies,
            turns=turns[1:steps],
            sizes=sizes[:steps],
            first_full=(first_full or t) - released,
            still=t - released,
        )
    finally:
        e.doc.discard_recovery()  # the drag is not the user's work: leave no autosave
        e.close()


def summary(m: dict) -> list[dict]:
    """One row: median and p90 of the latency and of the turn (frames per second), the
    median internal size while dragging, the release's first full-resolution and still
    images."""
    lat, turns = np.array(m["latencies"]) * 1e3, np.array(m["turns"])
    w = statistics.median(s[0] for s in m["sizes"])
    h = statistics.median(s[1] for s in m["sizes"])
    return [
        dict(
            scene=m["scene"],
            window=f"{m['window'][0]}×{m['window'][1]}",
            latency_ms_median=float(np.median(lat)),
            latency_ms_p90=float(np.percentile(lat, 90)),
            fps_median=float(1 / np.median(turns)),
            fps_p10=float(1 / np.percentile(turns, 90)),
            drag_size=f"{w:.0f}×{h:.0f}",
            first_full_s=m["first_full"],
            still_s=m["still"],
        )
    ]
