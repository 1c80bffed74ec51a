"""The viewer's ImGui HUD: frame time plot, resolution, accuracy knobs (from the scene schema),
effects, view mode, presets, bookmarks, screenshot, and any error from a hot reload. It reads
the viewer and returns commands; it never writes the viewer's fields."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path
from typing import Protocol

import numpy as np
from imgui_bundle import imgui, implot

from ..compile.constants import VIEW_MODES
from ..document.document import Document, shipped
from ..heatmap import heat
from ..scene import EFFECTS, Render, Scene
from ..scene.effects import allowed_effects
from ..scene.presets import preset_names, resolve
from ..scene.settings import settings_meta
from . import commands as c
from .drawn import Drawn
from .files import ViewerFile
from .frames import Frames
from .measured import apply_row, best_within, matches
from .navigation import Navigation
from .timeline import draw_time
from .widgets import CLAMPED, LOG_CLAMPED, Interactions, field_widget, red_text, tooltip

HUD_TITLE = "krsview (F1 hides)"
HUD_BODY = "##hud body"  # the part under the numbers: it scrolls, they stay
HUD_WIDTH = 440  # pixels; it is as tall as its content, up to the window's height
HUD_AT = 8  # pixels from the window's top left corner, where the HUD first opens
FOLDED_BELOW = 2.0  # a window narrower than this many HUD widths opens with the HUD folded
HUD_RIGHT = HUD_AT + HUD_WIDTH  # its right edge there
PLOT_HEIGHT = 130  # the frame-time plot, tall enough for readable axis labels
PLOTTED = 120  # moving frames in the plot
LEGEND_STEPS = 24  # the iterations view's legend: its ramp in this many blends
TRACER_KNOBS = {"xi_bonus": "binary", "xi_penalty": "binary", "relaxation": "relaxed"}
# the last one sits beside the pre-pass tile slider
KNOBS = (
    "tracer",
    "epsilon_scale",
    "max_iterations",
    *TRACER_KNOBS,
    "precision",
    "culling",
    "lod",
    "walk_restart",
    "path",
    "steps",
    "shadow_tasks",
    "component_tasks",
    "prepass_levels",
)
COMPUTE_KNOBS = ("steps", "shadow_tasks", "component_tasks")  # on the compute path only
TASK_KNOBS = ("shadow_tasks", "component_tasks")  # rounds of tasks: not with lanes (steps 0)
RENDER_META = {f.name: dict(f.metadata) for f in fields(Render)}


class Viewed(Protocol):
    """What the HUD reads of the viewer (it writes nothing: it returns commands)."""

    doc: Document
    frames: Frames
    file: ViewerFile  # its camera path's recorder
    drawn: Drawn  # the moment shown, the levels kept
    view: str
    iteration_scale: int  # the iterations view: white at this many
    nav: Navigation
    moving_effects: bool
    message: str
    error: str

    @property
    def scene(self) -> Scene: ...
    @property
    def path(self) -> Path: ...
    @property
    def prepass(self) -> int: ...
    @property
    def measured(self) -> list[dict] | None: ...
    def nearest_distance(self) -> float: ...
    def status_line(self) -> str: ...


def draw_hud(v: Viewed, interactions: Interactions, foot: float = 0.0) -> list[c.Command]:
    """The whole HUD at once (:func:`begin_hud`, then :func:`finish_hud`); its commands."""
    out, slot = begin_hud(v, interactions, foot)
    finish_hud(v, slot)
    return out


def begin_hud(
    v: Viewed, interactions: Interactions, foot: float = 0.0
) -> tuple[list[c.Command], imgui.ImVec2]:
    """The HUD but the numbers of the image on screen, which :func:`finish_hud` draws into
    the slot left for them (returned, with the commands): this part reads nothing of the
    frame traced this turn, so the viewer builds it while that frame is traced. It ends
    ``foot`` pixels above the window's foot (the editor's timeline keeps them), scrolling
    what does not fit."""
    out: list[c.Command] = []
    interactions.inline.clear()  # the fields drawn this frame show their own errors
    imgui.set_next_window_pos(imgui.ImVec2(HUD_AT, HUD_AT), imgui.Cond_.first_use_ever)
    display = imgui.get_io().display_size
    if display.x < FOLDED_BELOW * HUD_WIDTH:  # unfolded, it would hide most of the view
        imgui.set_next_window_collapsed(True, imgui.Cond_.first_use_ever)
    tallest, widest = display.y - 2 * HUD_AT - foot, display.x - 2 * HUD_AT
    width = max(min(HUD_WIDTH, widest), 160)  # a small window: as wide as it (it scrolls)
    imgui.set_next_window_size_constraints(
        imgui.ImVec2(width, 0), imgui.ImVec2(width, max(tallest, 100))
    )
    imgui.set_next_window_bg_alpha(0.75)
    imgui.begin(HUD_TITLE, None, imgui.WindowFlags_.always_auto_resize)
    slot = imgui.get_cursor_pos()
    imgui.dummy(imgui.ImVec2(0, numbers_height()))
    imgui.separator()
    # the rest scrolls under the numbers, which stay in sight (the whole HUD scrolled once,
    # and the state of the frame on screen went with it)
    bottom = display.y - HUD_AT - foot - imgui.get_window_pos().y  # its room, where it is
    rest = bottom - imgui.get_cursor_pos().y - imgui.get_style().window_padding.y
    imgui.set_next_window_size_constraints(
        imgui.ImVec2(0, 0), imgui.ImVec2(width, max(rest, 3 * imgui.get_frame_height()))
    )
    imgui.begin_child(HUD_BODY, imgui.ImVec2(0, 0), imgui.ChildFlags_.auto_resize_y)
    _controls(v, out)
    if v.scene.animated and imgui.collapsing_header("time", imgui.TreeNodeFlags_.default_open):
        draw_time(v.drawn.playback, out, interactions)
    if imgui.collapsing_header("accuracy and view"):
        _accuracy(v, out, interactions)
    if imgui.collapsing_header("measured accuracy"):
        _measured(v, out)
    if imgui.collapsing_header("scene, camera, output"):
        _scene(v, out)
    if v.message and v.message != v.status_line():  # said at the foot now: not twice
        imgui.text_wrapped(v.message)
    red_text("\n".join(v.error.splitlines()[1:]))  # the first is the status line (status.py)
    imgui.end_child()
    imgui.end()
    return out, slot


def finish_hud(v: Viewed, slot: imgui.ImVec2) -> float:
    """The numbers of the image on screen into the HUD's ``slot`` (:func:`begin_hud`), once
    that image is done; the height in the window where they end (the slot's end)."""
    imgui.begin(HUD_TITLE, None, imgui.WindowFlags_.always_auto_resize)  # appends to it
    imgui.set_cursor_pos(slot)
    _numbers(v)
    end = imgui.get_cursor_pos().y
    imgui.end()
    return end


def numbers_height() -> float:
    """The height of :func:`_numbers` (four lines and the plot) less the spacing after it."""
    return 4 * imgui.get_text_line_height_with_spacing() + PLOT_HEIGHT


def _numbers(v: Viewed) -> None:
    """The image on screen (state, resolution, time), then the moving frames' times against
    their budget: the frame budget less the rest of a turn."""
    shown = v.frames.frame_state()
    imgui.text(shown.text())
    imgui.text(f"{shown.timing()}; {v.view} view")
    times = np.array(v.frames.frame_seconds[-PLOTTED:] or [0.0], dtype=np.float32) * 1e3
    a = v.frames.adaptive
    budget, rest = 1e3 * a.trace_budget, 1e3 * a.rest
    moved = f"median {np.median(times):.1f} ms" if v.frames.frame_seconds else "none yet"
    imgui.text(f"moving frames: {moved}, budget {budget:.1f} ms")
    imgui.text(f"the rest of a turn (display, HUD, swap): {rest:.1f} ms")
    readout = implot.Flags_.no_legend | implot.Flags_.no_inputs  # the wheel scrolls the HUD
    if implot.begin_plot("##frametime", imgui.ImVec2(-1, PLOT_HEIGHT), readout):
        implot.setup_axes("moving frames", "ms")
        implot.setup_axes_limits(
            0, PLOTTED, 0, max(2 * budget, float(times.max()) * 1.1), implot.Cond_.always
        )
        implot.plot_line("frame ms", times)
        implot.plot_line("budget", np.full(2, budget, dtype=np.float32), xscale=PLOTTED)
        implot.end_plot()


def _controls(v: Viewed, out: list) -> None:
    """The frame rate aimed at, supersampling, and moving frames' shadows."""
    changed, fps_target = field_widget(
        "target FPS", v.frames.adaptive.target_fps, settings_meta("target_fps")
    )
    if changed:
        out.append(c.SetTargetFps(fps_target))
    changed, ss = imgui.checkbox("supersample still images 2×2", v.frames.adaptive.supersample == 2)
    if changed:
        out.append(c.SetSupersample(2 if ss else 1))
    changed, on = field_widget(
        "shadows as still while moving", v.moving_effects, settings_meta("moving_effects")
    )
    if changed:
        out.append(c.SetMovingEffects(on))


def knobs_shown(r: Render) -> tuple[str, ...]:
    """The render knobs that act on this setting: another tracer's, the compute path's
    on the fragment path and the tasks' with persistent lanes change nothing, so the HUD
    does not offer them."""
    return tuple(
        name
        for name in KNOBS
        if TRACER_KNOBS.get(name, r.tracer) == r.tracer
        and (name not in COMPUTE_KNOBS or r.path == "compute")
        and (name not in TASK_KNOBS or r.steps > 0)
    )


def _accuracy(v: Viewed, out: list, interactions: Interactions) -> None:
    r = v.scene.render
    for name in knobs_shown(r):
        meta = RENDER_META[name]
        if name == "tracer" and v.scene.mokrs is not None:
            meta = {**meta, "choices": ("binary",)}  # a MöKRS has only unbounding tests
        refused = interactions.refusal(("render", name))  # a refused value stays here
        shown = getattr(r, name)
        if shown is None:  # not set (the path): the first choice is what the view draws
            shown = meta["choices"][0]
        changed, value = field_widget(f"{name}##render", shown, meta, refused)
        key = interactions.key(("render", name))
        if changed:
            out.append(c.Edit(("render", name), value, key))
    refused = interactions.refusal(("render", "prepass"))
    changed, tile = field_widget("prepass##render", v.prepass, RENDER_META["prepass"], refused)
    key = interactions.key(("render", "prepass"))
    if changed:
        out.append(c.SetPrepass(tile, key))
    total = v.drawn.geometry.depth
    changed, levels = imgui.slider_int("levels", v.drawn.levels or total, 1, total, flags=CLAMPED)
    interactions.place(("view", "levels"))
    if changed:
        out.append(c.SetLevels(levels))
    changed, k = imgui.combo("view", VIEW_MODES.index(v.view), list(VIEW_MODES))
    if changed:
        out.append(c.SetViewMode(VIEW_MODES[k]))
    if v.view == "iterations":
        _iteration_legend(v, out)
    imgui.text("effects (each compiles its own shader variant, cached)")
    for name in allowed_effects(v.scene.mokrs is not None):
        changed, on = imgui.checkbox(name, name in v.scene.effects)
        if changed:
            out.append(c.SetEffect(name, on))
        if imgui.is_item_hovered():
            tooltip(EFFECTS[name].help)


def _iteration_legend(v: Viewed, out: list) -> None:
    """The iterations view's scale (white at N iterations of a pixel, up to the cap) and
    its legend: the ramp with 0, N/2 and N under it, as `krsview render --view iterations`
    draws below its image."""
    cap = v.scene.render.max_iterations
    changed, n = imgui.slider_int(
        "white at (iterations)", v.iteration_scale, 1, cap, flags=LOG_CLAMPED
    )
    if changed:
        out.append(c.SetIterationScale(n))
    draw, x0 = imgui.get_window_draw_list(), imgui.get_cursor_screen_pos()
    width, h = imgui.calc_item_width(), imgui.get_frame_height() * 0.6
    ramp = (np.round(heat(np.linspace(0.0, 1.0, LEGEND_STEPS + 1)) * 255)).astype(int)
    for k in range(LEGEND_STEPS):
        a, b = (imgui.IM_COL32(*ramp[j], 255) for j in (k, k + 1))
        p0 = imgui.ImVec2(x0.x + width * k / LEGEND_STEPS, x0.y)
        p1 = imgui.ImVec2(x0.x + width * (k + 1) / LEGEND_STEPS, x0.y + h)
        draw.add_rect_filled_multi_color(p0, p1, a, b, b, a)
    imgui.dummy(imgui.ImVec2(width, h))
    y = imgui.get_cursor_screen_pos().y
    for k, text in enumerate(("0", f"{v.iteration_scale / 2:g}", f"{v.iteration_scale}")):
        label = imgui.calc_text_size(text).x  # left, middle, right under the ramp
        imgui.set_cursor_screen_pos(imgui.ImVec2(x0.x + (width - label) * k / 2, y))
        imgui.text(text)


def _scene(v: Viewed, out: list) -> None:
    """The shipped presets to open, and the last file of the person's own shown, named as
    that file."""
    mine = v.file.mine
    shown = v.path.stem if shipped(v.path) else f"{v.path.name} (your file)"
    entries = [(f"{mine.name} (your file)", mine)] if mine is not None else []
    entries += [(name, resolve(name)) for name in preset_names()]
    if imgui.begin_combo("preset", shown):
        for label, path in entries:
            if imgui.selectable(label, label == shown)[0] and label != shown:
                out.append(c.OpenPreset(path))
        imgui.end_combo()
    typed = v.file.open_text  # any scene file: its path, Enter or the button opens it
    imgui.set_next_item_width(imgui.calc_item_width() - imgui.calc_text_size("open").x - 16)
    entered, text = imgui.input_text_with_hint(
        "##open",
        "a scene file: path/to/scene.toml",
        typed,
        imgui.InputTextFlags_.enter_returns_true,
    )
    if text != typed:
        out.append(c.SetOpenText(text))
    imgui.same_line()
    if (imgui.button("open") or entered) and text.strip():
        out.append(c.OpenPreset(Path(text.strip()).expanduser()))
    imgui.text(
        f"speed ×{v.nav.speed_factor:.2f} of the nearest distance "
        f"({v.nearest_distance():.3g}); scroll to change"
    )
    for label, command, same_line in (
        ("screenshot (F12)", c.Screenshot(), True),
        ("reset view (R)", c.ResetView(), True),
        ("orbit (O)" if v.nav.orbit_pivot is None else "fly (O)", c.ToggleOrbit(), False),
        ("add bookmark (B)", c.AddBookmark(), False),
    ):
        if imgui.button(label):
            out.append(command)
        if same_line:
            imgui.same_line()
    for i, b in enumerate(v.scene.bookmarks):
        imgui.same_line()
        if imgui.button(f"{b.name}##{i}"):
            out.append(c.GoToBookmark(i))
    recording = v.file.recorder.recording is not None
    if imgui.button("stop recording (F5)" if recording else "record path (F5)"):
        out.append(c.ToggleRecording())
    imgui.same_line()
    if imgui.button("replay path (F6)"):
        out.append(c.Replay())


def padded(values: np.ndarray, share: float = 0.08) -> tuple[float, float]:
    """The span of ``values`` with ``share`` of it added each side (a span of at least 1 %
    of the values' size, so a single value or equal ones still get room)."""
    lo, hi = float(values.min()), float(values.max())
    pad = share * max(hi - lo, 0.01 * max(abs(lo), abs(hi), 1e-6))
    return lo - pad, hi + pad


def _measured(v: Viewed, out: list) -> None:
    """Where the current setting sits on the preset's measured time/error curve, and a
    button for the most accurate measured setting that fits the frame budget."""
    rows = v.measured
    if rows is None:
        imgui.text_wrapped(
            f"no accuracy report for {v.path.stem}: run `krsview bench accuracy {v.path.stem}`"
        )
        return
    now = [
        r
        for r in rows
        if matches(r, v.scene, v.doc.saved, v.drawn.levels, v.drawn.geometry.depth, v.prepass)
    ]
    w, h = v.frames.rest_size or v.frames.adaptive.moving_size()  # steady while flying
    if implot.begin_plot("##accuracy", imgui.ImVec2(-1, 150), implot.Flags_.no_inputs):
        implot.setup_axes("ms (report size)", "hit-mask error %")
        ms = np.array([r["ms"] for r in rows], dtype=np.float32)
        err = np.array([100 * r["mask_error"] for r in rows], dtype=np.float32)
        (x0, x1), (y0, y1) = padded(ms), padded(err)  # no marker cut in half at an edge
        implot.setup_axes_limits(x0, x1, y0, y1, implot.Cond_.always)
        implot.plot_scatter("measured", ms, err)
        if now:
            implot.plot_scatter(
                "now",
                np.array([now[0]["ms"]], np.float32),
                np.array([100 * now[0]["mask_error"]], np.float32),
            )
        implot.end_plot()
    if now:
        r = now[0]
        imgui.text(
            f"now: {r['knob']} {r['value']}: {r['mask_error']:.2%} error, "
            f"{r['ms']:.0f} ms at {r['width']:.0f}×{r['height']:.0f}"
        )
    else:
        imgui.text_disabled("the current setting was not measured (change one knob at a time)")
    budget = 1e3 / v.frames.adaptive.target_fps
    best = best_within(rows, budget, w * h)
    imgui.text_disabled(f"budget: {budget:.0f} ms a frame at {w}×{h} (the moving frames)")
    if best is None:
        imgui.text_disabled("no measured setting fits it")
    elif imgui.button(f"most accurate that fits: {best['knob']} {best['value']}"):
        out += apply_row(best, v.doc.saved)
