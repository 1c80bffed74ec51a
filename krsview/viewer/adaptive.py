"""Adaptive internal resolution: while the view moves, scale the image so that a turn of the
event loop (its tracing, and the rest: display, HUD, swap, input) fits the target frame time;
when it stops, refine through sharper images, each traced in bands of rows within a per-turn
time budget (so input is never blocked by a slow frame) and shown when done. No GL here:
frames.py draws what this schedules."""

from __future__ import annotations

import math
import statistics
from dataclasses import dataclass, field

SHADOW_RATIO = 2  # moving frames and refinement steps: a shadow ray per 2 × 2 pixels at least
MOVING_RATIO = 3  # ... and per 3 × 3 in one wide enough to keep MIN_BLOCKS_ACROSS blocks
MIN_BLOCKS_ACROSS = 80  # (docs/speed.md, "Moving frames": the colour and the time measured)
STEP_GAIN = 1.5  # a refinement step's side is at least this many times the moving frame's
STEP_WAIT = 0.4  # seconds: an image predicted to take longer gets one of half its side first
FIRST_BAND = 16  # rows of a pass's first band, before its cost per pixel is measured
PROFILE_SLOTS = 32  # a pass's cost per pixel is kept per 1/32 of the image's height
REFINING_TURNS = 2.0  # a refining turn traces for at most this many frame budgets
REST_TURNS = 9  # the recent turns whose rest (display, HUD, swap, input) a moving frame counts
MIN_TRACE_SHARE = 0.5  # a moving frame's tracing keeps at least this share of the budget
DAMPED = (0.7, 1.25)  # a moving frame's scale changes by at most these factors ...
OVERRUN = 2.0  # ... unless it took this many trace budgets: then at once, down to
OVERRUN_FACTOR = 0.35  # this factor at least


@dataclass
class AdaptiveResolution:
    full: tuple[int, int]  # window size in pixels
    target_fps: float = 30.0
    min_scale: float = 0.1
    scale: float = 0.5  # start near 320×180 for a 640×360 window (docs/architecture.md)
    supersample: int = 1  # still images: 1, or 2 for 2×2 supersampling
    history: list[float] = field(default_factory=list)
    rests: list[float] = field(default_factory=list)  # the last REST_TURNS turns' rest

    @property
    def budget(self) -> float:
        """Seconds a turn of the event loop may take at the target frame rate."""
        return 1.0 / self.target_fps

    @property
    def rest(self) -> float:
        """Seconds of a turn besides its tracing: the median of the recent turns' (a slow
        one, a file reloaded, moves it little)."""
        return statistics.median(self.rests) if self.rests else 0.0

    @property
    def trace_budget(self) -> float:
        """Seconds a moving frame's tracing may take so that the whole turn (display, HUD,
        swap and input besides) fits the frame budget; at least MIN_TRACE_SHARE of it, so a
        window slow to draw still gets an image of some size."""
        return max(self.budget - self.rest, MIN_TRACE_SHARE * self.budget)

    def size_at(self, scale: float) -> tuple[int, int]:
        """The internal resolution at ``scale`` of the window's side."""
        return (max(1, round(self.full[0] * scale)), max(1, round(self.full[1] * scale)))

    def moving_size(self) -> tuple[int, int]:
        return self.size_at(self.scale)

    def still_size(self) -> tuple[int, int]:
        return self.size_at(self.supersample)

    def frame_done(self, seconds: float, rest: float | None = None) -> None:
        """After a moving frame traced in ``seconds``, the turn before it having spent
        ``rest`` besides its tracing (None: it traced nothing, its time is an idle wait):
        cost ∝ pixels ∝ scale², so aim scale at the trace budget, damped."""
        self.history = (self.history + [seconds])[-120:]
        if rest is not None:
            self.rests = (self.rests + [rest])[-REST_TURNS:]
        if seconds <= 0:
            return
        factor = math.sqrt(self.trace_budget / seconds)
        low = DAMPED[0] if seconds < OVERRUN * self.trace_budget else OVERRUN_FACTOR
        factor = min(DAMPED[1], max(low, factor))  # damped: a noisy frame moves scale a little
        self.scale = min(1.0, max(self.min_scale, self.scale * factor))

    def predict(self, seconds_per_pixel: float) -> None:
        """Before the first moving frame after a rest: the scale whose image fits the trace
        budget at ``seconds_per_pixel`` (measured by the refinement just traced), so that
        flying starts at its rate (it started at the last flight's scale, or half the side,
        and shrank by DAMPED[0] a frame: half a second of slow frames, or after a resize)."""
        if seconds_per_pixel > 0:
            pixels = self.trace_budget / seconds_per_pixel
            scale = math.sqrt(pixels / (self.full[0] * self.full[1]))
            self.scale = min(1.0, max(self.min_scale, scale))


def moving_ratio(width: int, still: int) -> int:
    """The side of the pixel blocks that share a shadow ray in a moving frame ``width`` pixels
    wide whose still image's is ``still``: MOVING_RATIO where that leaves MIN_BLOCKS_ACROSS
    blocks across it (the mean colour of its hits within 1/255 of one with a ray per pixel
    on tree and grove), else SHADOW_RATIO; never below ``still``."""
    wide = width >= MOVING_RATIO * MIN_BLOCKS_ACROSS
    return max(still, MOVING_RATIO if wide else SHADOW_RATIO)


def refining_budget(budget: float, rest: float) -> float:
    """Seconds a turn of the refinement may trace: as long as the rest of the last turn took
    (drawing the window, its UI) but at least one frame ``budget`` and at most REFINING_TURNS
    of them, so a slow window (half of each turn under Xvfb) does not starve the refinement,
    and a new move waits for at most that long."""
    return budget * min(REFINING_TURNS, max(1.0, rest / budget))


@dataclass(frozen=True)
class Step:
    """One image the view refines through: ``scale`` of the window's side, and its shadow
    rays (gpu/passes.py's ratio): 0 every effect in one pass, 1 a shadow ray per pixel in a
    pass after the tracing, r ≥ 2 one per r × r pixels, blended along depth. ``primary``:
    the primary rays alone, shaded with the shadow blocks of the image before it (no lighting
    jump, no shadow rays yet); the next step, at the same scale, adds its own to this tracing."""

    scale: float
    ratio: int
    primary: bool = False


def refinement_steps(
    moving_scale: float, moving_seconds: float, supersample: int, ratio: int, still: int
) -> list[Step]:
    """The images after the view stops, the last one the still image: one at the window's
    size, and where that would take longer than STEP_WAIT to trace (predicted from the moving
    frame's time, cost ∝ pixels) one of half its side before it, and so on down to STEP_GAIN
    times the moving frame's side, so each step is visibly sharper and all
    before the window-size one cost at most 1/3 of it. ``ratio``: the passes (gpu/passes.py)
    of the moving frames and these steps; ``still``: those of the still image. Where they
    differ (shadow rays per pixel in the still image only), the still image adds them to the
    tracing of the window-size image before it; else that image is the still one. Where
    shadow rays are shared per block, the window-size image comes first without its own
    (:func:`primary_first`)."""
    scales = [1.0] if moving_scale * STEP_GAIN < 1.0 else []
    while (
        scales
        and scales[0] / 2 > moving_scale * STEP_GAIN
        and moving_seconds * (scales[0] / moving_scale) ** 2 > STEP_WAIT
    ):
        scales.insert(0, scales[0] / 2)
    steps = [Step(s, ratio) for s in scales]
    if still != ratio:
        steps.append(Step(float(supersample), still))
    else:
        if not steps and moving_scale < 1.0:
            steps = [Step(1.0, ratio)]
        steps += [Step(float(supersample), still)] if supersample > 1 else []
    return primary_first(steps, ratio) if moving_scale < 1.0 else steps


def primary_first(steps: list[Step], ratio: int) -> list[Step]:
    """``steps`` with the window-size image first traced alone and shaded with the shadow
    blocks of the image before it (issue 28 §5: a full-resolution primary image, then its
    effects), where the images before it share shadow rays per block (``ratio`` ≥ 2) and it
    has shadow rays of its own; the step after it reuses its tracing. Where the still image
    follows at the window's size, it adds its shadow rays to that tracing directly."""
    k = next((i for i, s in enumerate(steps) if s.scale == 1.0), None)
    if ratio < 2 or k is None or steps[k].ratio == 0:
        return steps
    rest = steps[k:]
    if len(rest) > 1 and rest[1].scale == 1.0:  # the still image at the window's size
        rest = rest[1:]
    return steps[:k] + [Step(1.0, ratio, primary=True)] + rest


@dataclass
class Refinement:
    """The steps' images traced pass by pass in bands of rows, a few bands per event-loop
    turn, each band sized to the turn's budget by the measured seconds per pixel of its pass
    (``cost``, by pass name, shared between refinements) and where its rows lie
    (``profile``, by pass name: the seconds per pixel of the last band drawn over each
    PROFILE_SLOTS-th of the height, shared too). Rows differ: a crown at the top of the
    image costs many times the sky or ground below it, and the pass's mean, let alone the
    cost of the last band drawn (the image's foot), would size a first band over the crown
    to several budgets."""

    steps: list[Step]
    cost: dict[str, float] = field(default_factory=dict)
    k: int = 0  # the step being traced; len(steps): all shown
    passes: list[tuple[str, int, int]] = field(default_factory=list)  # step k's: name, w, rows
    p: int = 0  # the pass being drawn
    next_row: int = 0
    profile: dict[str, list[float]] = field(default_factory=dict)

    @property
    def done(self) -> bool:
        return self.k >= len(self.steps)

    @property
    def started(self) -> bool:
        """Step k's passes are known (:meth:`begin`)."""
        return bool(self.passes)

    def begin(self, passes: list[tuple[str, int, int]]) -> None:
        """Step k's passes, in order: name, width and rows of each."""
        self.passes, self.p, self.next_row = passes, 0, 0

    def next_band(self, budget: float) -> tuple[str, int, int]:
        """The next band of the current pass, (name, first row, rows), sized to ``budget``
        seconds by its measured cost."""
        name, width, height = self.passes[self.p]
        rows = FIRST_BAND
        if self.cost.get(name, 0.0) > 0:
            rows = self._rows_within(name, width, height, budget)
        return name, self.next_row, min(rows, height - self.next_row)

    def _rows_within(self, name: str, width: int, height: int, budget: float) -> int:
        """Rows from ``next_row`` on that fit ``budget`` seconds by the pass's profile (its
        mean cost where a slot has none), at least one."""
        slots = self.profile.get(name, ())
        left, rows, y = budget * (1.0 + 1e-9), 0, self.next_row
        while y < height:
            s = y * PROFILE_SLOTS // height
            end = min(height, -(-(s + 1) * height // PROFILE_SLOTS))  # the next slot's first row
            per_row = (slots[s] if slots and slots[s] > 0 else self.cost[name]) * width
            if (end - y) * per_row > left:
                rows += int(left / per_row)
                break
            rows, left, y = rows + end - y, left - (end - y) * per_row, end
        return max(1, rows)

    def band_done(self, band: tuple[str, int, int], seconds: float) -> bool:
        """Record a drawn band; True when it finished step k's image (k moves on)."""
        name, y0, rows = band
        width, height = self.passes[self.p][1:]
        per_pixel = seconds / max(rows * width, 1)
        old = self.cost.get(name, 0.0)
        self.cost[name] = per_pixel if old == 0 else 0.5 * old + 0.5 * per_pixel
        slots = self.profile.setdefault(name, [0.0] * PROFILE_SLOTS)
        first, last = y0 * PROFILE_SLOTS // height, (y0 + rows - 1) * PROFILE_SLOTS // height
        for s in range(first, min(last, PROFILE_SLOTS - 1) + 1):
            slots[s] = per_pixel
        self.next_row = y0 + rows
        if self.next_row < height:
            return False
        self.p, self.next_row = self.p + 1, 0
        if self.p < len(self.passes):
            return False
        self.k, self.passes, self.p = self.k + 1, [], 0
        return True
