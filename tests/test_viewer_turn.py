"""The viewer's turn around the trace [issue 27 §4]: the display pass (one variant per view
mode) against a NumPy upsampling of the same targets, and the time a turn spends besides its
tracing, as the window measures it for the adaptive resolution."""

from __future__ import annotations

import shutil
from types import SimpleNamespace

import numpy as np
import pytest

from krsview.compile.constants import VIEW_MODES
from krsview.gpu.display import Display, view_defines
from krsview.heatmap import heat
from krsview.scene.presets import resolve

SOURCE = (7, 5)  # the traced image, (w, h)
TARGET = (31, 20)  # the window: a scale that is no whole number
CAP, DEPTH_SCALE = 60.0, 3.0


def planes(seed: int = 1) -> list[np.ndarray]:
    """Colour (rgb, hit), normal and depth (xyz, t), iterations (x): (h, w, 4) float32 each,
    rows top → bottom, as the renderer's targets hold them."""
    rng = np.random.default_rng(seed)
    w, h = SOURCE
    color = rng.uniform(0, 1, (h, w, 4))
    color[..., 3] = rng.uniform(0, 1, (h, w)) > 0.3  # hit
    normal = np.concatenate([rng.uniform(-1, 1, (h, w, 3)), rng.uniform(0.1, 20, (h, w, 1))], -1)
    iterations = np.zeros((h, w, 4))
    iterations[..., 0] = rng.integers(0, 80, (h, w))
    return [p.astype(np.float32) for p in (color, normal, iterations)]


def bilinear(plane: np.ndarray, size: tuple[int, int], wrap: bool = False) -> np.ndarray:
    """``plane`` sampled at the centres of a ``size`` target's pixels as GL's LINEAR filter
    does: texel centres at +½, edges clamped (``wrap``: repeated, GL's default)."""
    h, w = plane.shape[:2]
    x = (np.arange(size[0]) + 0.5) / size[0] * w - 0.5
    y = (np.arange(size[1]) + 0.5) / size[1] * h - 0.5
    x0, y0 = np.floor(x).astype(int), np.floor(y).astype(int)
    fx, fy = (x - x0)[None, :, None], (y - y0)[:, None, None]

    def at(ys, xs):
        ys, xs = (ys % h, xs % w) if wrap else (np.clip(ys, 0, h - 1), np.clip(xs, 0, w - 1))
        return plane[ys[:, None], xs[None, :]].astype(np.float64)

    top = at(y0, x0) * (1 - fx) + at(y0, x0 + 1) * fx
    bottom = at(y0 + 1, x0) * (1 - fx) + at(y0 + 1, x0 + 1) * fx
    return top * (1 - fy) + bottom * fy


def expected(view: str, p: list[np.ndarray], wrap: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """display.frag's colour for ``view`` from NumPy's upsampling, and the pixels where it is
    sure (the interpolated hit not within 0.05 of the 0.5 threshold)."""
    color, normal, iterations = (bilinear(q, TARGET, wrap) for q in p)
    hit = color[..., 3] > 0.5
    sure = np.abs(color[..., 3] - 0.5) > 0.05
    if view == "shaded":
        return color[..., :3], np.ones_like(sure)
    if view == "iterations":
        return heat(iterations[..., 0] / CAP), np.ones_like(sure)
    if view == "depth":
        grey = 1.0 - np.log(1.0 + normal[..., 3] / DEPTH_SCALE) / 4.0
        return np.where(hit[..., None], grey[..., None].repeat(3, -1), 0.0), sure
    return np.where(hit[..., None], normal[..., :3] * 0.5 + 0.5, 0.0), sure


@pytest.fixture(scope="module")
def shown(renderer):
    """Each view mode's window image of the same targets: (h, w, 3) in [0, 1], rows top →
    bottom (the window's own rows run bottom → top)."""
    ctx = renderer.ctx
    p = planes()
    with renderer.current():
        tex = [ctx.texture(SOURCE, 4, q.tobytes(), dtype="f4") for q in p]
        source = ctx.framebuffer(color_attachments=tex)
        target = ctx.framebuffer(color_attachments=[ctx.texture(TARGET, 4)])
        display = Display(ctx, renderer.programs, VIEW_MODES)
        out = {}
        for view in VIEW_MODES:
            display.show(source, target, TARGET, view, int(CAP), DEPTH_SCALE, SOURCE)
            raw = np.frombuffer(target.read(components=3), np.uint8)
            out[view] = raw.reshape(TARGET[1], TARGET[0], 3)[::-1] / 255.0
        progs = {v: display._vao(v).program for v in VIEW_MODES}
    return out, p, progs


@pytest.mark.parametrize("view", VIEW_MODES)
def test_the_display_pass_is_a_bilinear_upsampling_of_the_targets(shown, view):
    out, p, _ = shown
    want, sure = expected(view, p)
    err = np.abs(out[view] - want).max(-1)
    assert sure.mean() > 0.8 and err[sure].max() <= 2.5 / 255, f"{view}: {err[sure].max()}"
    # negative controls: another view's colours, and GL's default wrap at the edges (the
    # border pixels would blend in the far side's)
    other = VIEW_MODES[(VIEW_MODES.index(view) + 1) % len(VIEW_MODES)]
    assert np.abs(out[view] - expected(other, p)[0]).max(-1)[sure].max() > 0.1
    wrapped = np.abs(out[view] - expected(view, p, wrap=True)[0]).max(-1)
    assert wrapped[sure].max() > 0.02


def test_each_view_is_its_own_variant_and_the_shaded_one_reads_one_target(shown):
    """llvmpipe runs every branch for every window pixel, so the modes are not branches."""
    _, _, progs = shown
    assert len({id(prog) for prog in progs.values()}) == len(VIEW_MODES)
    textures = {
        v: {u for u in ("u_color", "u_normal", "u_iterations") if u in progs[v]} for v in progs
    }
    assert textures == {
        "shaded": {"u_color"},
        "iterations": {"u_iterations"},
        "depth": {"u_color", "u_normal"},
        "normals": {"u_color", "u_normal"},
    }
    with pytest.raises(ValueError, match="view mode 'heat': allowed: shaded, iterations"):
        view_defines("heat")


class Clock:
    """perf_counter for frames.py: time passes only where the test says."""

    def __init__(self):
        self.t = 100.0

    def perf_counter(self) -> float:
        return self.t


@pytest.fixture
def clocked(display, tmp_path, monkeypatch):
    """A small viewer whose frames read ``Clock``: a moving frame's tracing takes TRACE,
    each turn's rest (the test advances it) what the test says."""
    from krsview.gpu.passes import PassImage
    from krsview.viewer import frames
    from krsview.viewer.window import Viewer

    clock = Clock()
    monkeypatch.setattr(frames, "time", SimpleNamespace(perf_counter=clock.perf_counter))
    prepare = PassImage.prepare  # once per moving frame (and per refining turn)

    def timed(self, *a, **k):
        out = prepare(self, *a, **k)
        clock.t += TRACE
        return out

    monkeypatch.setattr(PassImage, "prepare", timed)
    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(96, 54), hud=False)
    yield v, clock
    v.close()


TRACE, REST = 0.02, 0.011


def test_the_controller_counts_the_turns_rest_besides_the_tracing_not_idle_waits(clocked):
    v, clock = clocked
    for _ in range(200):  # the first image, its refinement, then idle turns
        clock.t += REST
        v.step(REST)
        if v.frames.refined:
            break
    a = v.frames.adaptive
    assert v.frames.refined and a.rests == []  # the first frame had no turn before it
    clock.t += 5.0  # an idle wait: the next turn's rest is not a turn's
    v.step(5.0)
    v.input.key("W", True)
    for _ in range(5):
        clock.t += REST
        v.step(REST)
    v.input.key("W", False)
    # five moving frames, each traced in TRACE; the first follows an idle turn, whose 5 s
    # (with the wait) are not counted, the four after it count what the turn spent besides;
    # the HUD's moving frames are the four that followed a moving frame
    assert a.history[-5:] == pytest.approx([TRACE] * 5)
    assert v.frames.frame_seconds == pytest.approx([TRACE] * 4)
    assert a.rests == pytest.approx([REST] * 4) and a.rest == pytest.approx(REST)
    assert a.trace_budget == pytest.approx(a.budget - REST)
    for _ in range(200):
        clock.t += REST
        v.step(REST)
        if v.frames.refined:
            break
    v.frames.dirty = True  # one image anew (a reload, a bookmark, a resize): not a flight's
    v.step(REST)
    assert len(a.history) == 6 and len(v.frames.frame_seconds) == 4


def test_the_window_keeps_no_stale_pixels_without_the_clear(clocked):
    """The display pass covers every window pixel, so the turn skips the clear: a view
    changed under a red-filled screen leaves no red."""
    v, _ = clocked
    v.step(0.0)
    v.ctx.screen.use()
    v.ctx.clear(1.0, 0.0, 0.0)
    red = v.read_window()
    assert (red == [255, 0, 0]).all()  # control: the fill is there to be covered
    v.frames.dirty = True
    v.step(0.0)
    shot = v.read_window().astype(int)
    assert not ((shot[..., 0] > 250) & (shot[..., 1] < 5) & (shot[..., 2] < 5)).any()
