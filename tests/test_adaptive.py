"""The viewer's scheduling without a window (viewer/adaptive.py): the moving frames' scale
controller, the refinement's steps after the view stops, and the bands each step is traced in
within a turn's budget."""

from __future__ import annotations

import pytest

from krsview.viewer.adaptive import (
    FIRST_BAND,
    MIN_BLOCKS_ACROSS,
    MOVING_RATIO,
    SHADOW_RATIO,
    AdaptiveResolution,
    Refinement,
    Step,
    moving_ratio,
    refinement_steps,
    refining_budget,
)


def test_the_scale_drops_when_slow_and_grows_back_when_fast():
    a = AdaptiveResolution((640, 360), target_fps=30)
    for _ in range(20):
        a.frame_done(0.2)  # far over budget: shrink to the floor
    assert a.scale == a.min_scale and a.moving_size() == (64, 36)
    for _ in range(40):
        a.frame_done(0.001)  # far under budget: grow back to full
    assert a.scale == 1.0 and a.moving_size() == (640, 360)
    a.supersample = 2
    assert a.still_size() == (1280, 720) and a.size_at(0.5) == (320, 180)


def test_a_frame_far_over_budget_shrinks_the_next_at_once():
    """A review saw the first flight open with frames of 250, 200, 150 and 100 ms: the scale
    fell by at most 0.7× a frame. A frame over OVERRUN trace budgets now sets the next
    frame's scale to fit (down to 0.35×); one a little over is still damped (the control)."""
    a = AdaptiveResolution((960, 540), target_fps=30)
    a.frame_done(0.25)  # 7.5 budgets
    assert a.scale == pytest.approx(0.5 * 0.365, rel=0.01)
    b = AdaptiveResolution((960, 540), target_fps=30)
    b.frame_done(0.05)  # 1.5 budgets: noise-like, damped
    assert b.scale == pytest.approx(0.5 * 0.816, rel=0.01)


def test_the_first_moving_frame_after_a_rest_is_sized_by_the_measured_cost():
    """From the refinement's seconds per pixel, the scale whose frame fits the trace budget
    (the window's pixels times that cost: the whole budget), within the scale's limits."""
    a = AdaptiveResolution((960, 540), target_fps=30)
    a.predict(1.0 / 30 / (480 * 270))
    assert a.moving_size() == (480, 270)
    a.predict(1.0)  # far too slow for any image: the floor
    assert a.scale == a.min_scale
    a.predict(1e-12)
    assert a.scale == 1.0
    a.predict(0.0)  # nothing measured: unchanged
    assert a.scale == 1.0


P = True  # a primary step (Step.primary)


@pytest.mark.parametrize(
    "moving, seconds, supersample, ratio, still, steps",
    [
        # the still image with shadow rays per pixel: sharper images with shadow rays per 2 × 2
        # pixels, then the window-size tracing alone (P: shaded with the blocks of the image
        # before it), then the still image adds shadow rays per pixel to that tracing
        (0.35, 0.03, 1, 2, 1, [(1.0, 2, P), (1.0, 1)]),
        (0.2, 0.03, 1, 2, 1, [(0.5, 2), (1.0, 2, P), (1.0, 1)]),  # 0.75 s at the window's size
        (0.2, 0.01, 1, 2, 1, [(1.0, 2, P), (1.0, 1)]),  # 0.25 s: no step before it
        (0.1, 0.03, 1, 2, 1, [(0.25, 2), (0.5, 2), (1.0, 2, P), (1.0, 1)]),
        (0.1, 0.005, 1, 2, 1, [(0.5, 2), (1.0, 2, P), (1.0, 1)]),  # ½: 0.125 s
        (0.8, 0.03, 1, 2, 1, [(1.0, 2, P), (1.0, 1)]),  # too close to the window for a step
        (1.0, 0.03, 1, 2, 1, [(1.0, 1)]),  # the moving frame's tracing, shadowed per pixel
        # supersampled: the window-size image with its blocks, then traced anew at twice the side
        (0.35, 0.03, 2, 2, 1, [(1.0, 2, P), (1.0, 2), (2.0, 1)]),
        # moving frames drawn as the still image (shadow rays per block, or every effect in
        # one pass): the window-size tracing, then the still image adds its blocks' shadow rays
        (0.35, 0.03, 1, 2, 2, [(1.0, 2, P), (1.0, 2)]),
        (0.2, 0.03, 1, 3, 3, [(0.5, 3), (1.0, 3, P), (1.0, 3)]),
        (1.0, 0.03, 1, 2, 2, []),
        (1.0, 0.03, 2, 2, 2, [(2.0, 2)]),
        # no blocks before it (shadow rays per pixel throughout, or none in a pass of their
        # own): no primary step
        (0.35, 0.03, 1, 1, 1, [(1.0, 1)]),
        (0.35, 0.03, 1, 0, 0, [(1.0, 0)]),
        (0.2, 0.03, 1, 0, 0, [(0.5, 0), (1.0, 0)]),
        (0.8, 0.03, 1, 0, 0, [(1.0, 0)]),
        (1.0, 0.03, 1, 0, 0, []),  # the moving frame is the still image
        (1.0, 0.03, 2, 0, 0, [(2.0, 0)]),
    ],
)
def test_refinement_steps(moving, seconds, supersample, ratio, still, steps):
    assert refinement_steps(moving, seconds, supersample, ratio, still) == [Step(*s) for s in steps]


def ladder_ok(moving: float, steps: list[Step]) -> bool:
    """Each image at least 1.5× the side of the one before, and all but the still image
    together costing at most 1/3 more pixels than the last of them."""
    traced = [s for s in steps if s.ratio != 1 and not (s.scale == 1.0 and not s.primary)]
    sides = [moving] + [s.scale for s in traced]
    pixels = [s * s for s in sides[1:]]
    return all(b >= 1.5 * a for a, b in zip(sides, sides[1:])) and sum(pixels) <= (
        4 / 3 * pixels[-1] + 1e-12
    )


def test_each_step_is_visibly_sharper_and_all_cost_at_most_a_third_more():
    for k in range(1, 100):
        moving = k / 100
        steps = refinement_steps(moving, 1.0, 1, 2, 1)  # slow: every step there can be
        assert steps[-2:] == [Step(1.0, 2, primary=True), Step(1.0, 1)]
        if moving < 1 / 1.5:
            assert ladder_ok(moving, steps), moving
    # negative controls: a step too close to the one before, and a ladder too dense
    assert not ladder_ok(0.4, [Step(0.5, 2), Step(1.0, 2, True)])
    assert not ladder_ok(0.1, [Step(0.2, 2), Step(0.4, 2), Step(0.7, 2), Step(1.0, 2, True)])


PASSES = [("trace", 100, 50), ("visibility", 50, 25), ("shade", 100, 50)]
COST = {"trace": 4e-5, "visibility": 2e-5, "shade": 1e-5}  # seconds per pixel


def run_turns(r: Refinement, budget: float, cost: dict[str, float]) -> list[list[tuple]]:
    """Drive ``r`` as frames.py does, each band costing ``cost`` per pixel: the bands drawn
    in each turn, and the steps finished."""
    turns = []
    while not r.done:
        bands, spent = [], 0.0
        while not r.done and spent < budget:
            if not r.started:
                r.begin(list(PASSES))
            band = r.next_band(budget - spent)
            width = next(w for name, w, _ in PASSES if name == band[0])
            seconds = cost[band[0]] * width * band[2]
            spent += seconds
            bands.append((*band, r.band_done(band, seconds)))
        turns.append(bands)
    return turns


def test_bands_cover_every_row_of_every_pass_in_order_within_the_budget():
    r = Refinement([Step(1.0, 2), Step(1.0, 1)])
    turns = run_turns(r, 0.02, COST)
    bands = [b for t in turns for b in t]
    end = [k for k, b in enumerate(bands) if b[3]]  # the bands finishing a step
    assert len(end) == 2 and end[-1] == len(bands) - 1 and r.done and r.k == 2
    for step in (bands[: end[0] + 1], bands[end[0] + 1 :]):
        rows = {name: [] for name, _, _ in PASSES}
        for name, y0, n, _ in step:
            rows[name].append((y0, n))
        for name, _, height in PASSES:
            ys = [y for y0, n in rows[name] for y in range(y0, y0 + n)]
            assert ys == list(range(height)), name  # each row once, top to bottom
    assert bands[0][2] == FIRST_BAND  # before any cost is known
    # once its pass is measured, no band overruns its turn's budget by more than a row
    seen: set[str] = set()
    width = {name: w for name, w, _ in PASSES}
    for t in turns:
        measured = [(name, n) for name, _, n, _ in t if name in seen]
        seen |= {name for name, _, _, _ in t}
        spent = sum(COST[name] * width[name] * n for name, n in measured)
        assert spent <= 0.02 + 100 * COST["trace"] + 1e-12
    assert len(turns) > 10 and seen == set(width)
    # negative control: a pass twice as costly as measured gets bands half as tall
    r2 = Refinement([Step(1.0, 2)], cost=dict(COST))
    r2.begin(list(PASSES))
    tall = r2.next_band(0.02)[2]
    r2.band_done(("trace", 0, tall), 2 * COST["trace"] * 100 * tall)
    assert r2.next_band(0.02)[2] < tall


def test_costs_carry_over_to_the_next_refinement():
    cost: dict[str, float] = {}
    run_turns(Refinement([Step(1.0, 2)], cost), 0.02, COST)
    assert cost == pytest.approx(COST)
    r = Refinement([Step(1.0, 2)], cost)
    r.begin(list(PASSES))
    assert r.next_band(0.02)[2] == int(0.02 / (COST["trace"] * 100))
    assert Refinement([Step(1.0, 2)]).cost == {}  # control: a fresh one knows none


def test_a_costly_top_does_not_make_the_next_refinements_first_band_overrun():
    """Rows run top → bottom and a crown at the top costs many times the sky below it: the
    last band of an image (its foot) is cheap, and the next refinement's first band (its top)
    is sized by where its rows lie, not by that last band's cost."""
    width, height, budget = 10, 50, 0.02
    crown = 10  # the top fifth costs ten times the rest

    def seconds(y0: int, rows: int) -> float:
        costly = max(0, min(y0 + rows, height // 5) - y0)
        return COST["trace"] * width * (crown * costly + rows - costly)

    def first_bands(images: int, profiled: bool = True) -> list[float]:
        """The seconds of each image's first band, one image after another."""
        cost: dict[str, float] = {}
        profile: dict[str, list[float]] = {}
        firsts = []
        for _ in range(images):
            r = Refinement([Step(1.0, 2)], cost, profile=profile)
            r.begin([("trace", width, height)])
            while not r.done:
                band = r.next_band(budget)
                firsts += [] if band[1] else [seconds(*band[1:])]
                r.band_done(band, seconds(*band[1:]))
                if not profiled:
                    profile.clear()
        return firsts

    firsts = first_bands(4)
    assert firsts[1] <= 1.5 * budget  # the profile of bands as coarse as the first image's
    assert max(firsts[2:]) <= budget * 1.001
    # negative control: by the pass's cost alone, as measured last (the cheap foot)
    assert min(first_bands(4, profiled=False)[1:]) > 2 * budget


def test_a_refining_turn_traces_as_long_as_the_rest_of_the_turn_within_two_budgets():
    budget = 1 / 30
    assert refining_budget(budget, 0.05) == pytest.approx(0.05)  # a window drawn in 50 ms
    assert refining_budget(budget, 1.0) == pytest.approx(2 * budget)  # after an idle wait
    # control: a fast window leaves the turn's tracing at one frame budget
    assert refining_budget(budget, 0.0) == refining_budget(budget, 0.01) == budget


def fly(a: AdaptiveResolution, rest, turns: int = 60, per_pixel: float = 1e-6) -> list[float]:
    """Turns of a flight with tracing ∝ pixels and ``rest(k)`` seconds besides it (None: an
    idle turn before): the turns' times."""
    out = []
    for k in range(turns):
        w, h = a.moving_size()
        seconds = per_pixel * w * h
        r = rest(k)
        a.frame_done(seconds, r)
        out.append(seconds + (r or 0.0))
    return out


def test_the_controller_aims_the_whole_turn_at_the_frame_budget():
    budget = 1 / 30
    a = AdaptiveResolution((960, 540), target_fps=30)
    turns = fly(a, lambda k: 0.008)  # display, HUD and swap: 8 ms a turn
    assert turns[-1] == pytest.approx(budget, rel=0.05)
    assert a.trace_budget == pytest.approx(budget - 0.008)
    # negative control: a controller blind to the rest aims the tracing alone at the
    # budget, and each turn overruns it by the rest
    blind = AdaptiveResolution((960, 540), target_fps=30)
    turns = fly(blind, lambda k: None)
    assert turns[-1] == pytest.approx(budget, rel=0.05)  # the tracing alone
    assert turns[-1] + 0.008 > 1.2 * budget


def test_a_slow_turn_or_an_idle_wait_moves_the_aim_little():
    a = AdaptiveResolution((960, 540), target_fps=30)
    fly(a, lambda k: 0.008, turns=40)
    steady = a.scale
    # one turn with a file reloaded (0.3 s besides the tracing), one after an idle wait
    fly(a, lambda k: {0: 0.3, 1: None}.get(k, 0.008), turns=3)
    assert a.rest == pytest.approx(0.008) and a.scale == pytest.approx(steady, rel=0.02)
    # control: a window that takes longer to draw every turn shrinks the image
    fly(a, lambda k: 0.016, turns=40)
    assert a.rest == pytest.approx(0.016) and a.scale < 0.9 * steady


def test_the_tracing_keeps_half_the_budget_when_the_rest_takes_more():
    a = AdaptiveResolution((960, 540), target_fps=30)
    fly(a, lambda k: 0.05)  # a window slower than the whole budget
    assert a.trace_budget == pytest.approx(0.5 * a.budget)
    assert a.history[-1] == pytest.approx(0.5 * a.budget, rel=0.05)
    assert a.moving_size()[0] > 0.1 * 960  # control: not driven to the floor


def blocks_rule_broken(rule) -> list[tuple[int, int]]:
    """(width, still) where ``rule`` differs from the block side counted for each width: the
    largest side from SHADOW_RATIO to MOVING_RATIO that leaves at least MIN_BLOCKS_ACROSS
    blocks across the frame (SHADOW_RATIO where none does), never below the still image's
    ``still``."""
    broken = []
    for still in (2, 3, 4):
        for width in range(1, 1500):
            r = rule(width, still)
            fits = [
                q for q in range(SHADOW_RATIO, MOVING_RATIO + 1) if width / q >= MIN_BLOCKS_ACROSS
            ]
            if r != max([still, SHADOW_RATIO, *fits]):
                broken.append((width, still))
    return broken


def test_moving_frames_share_shadow_rays_in_blocks_as_wide_as_keep_enough_across():
    """moving_ratio against a count of the blocks across each width; negative controls: 3 × 3
    blocks in every frame, or the still image's side alone, break the count."""
    assert blocks_rule_broken(moving_ratio) == []
    assert moving_ratio(239, 2) == 2 and moving_ratio(240, 2) == 3 and moving_ratio(960, 4) == 4
    assert blocks_rule_broken(lambda w, still: max(still, 3))
    assert blocks_rule_broken(lambda w, still: still)
