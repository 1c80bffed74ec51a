"""The ImGui HUD: frame time plot, resolution, accuracy knobs, effects, view mode, presets,
bookmarks, screenshot, and any error from a hot reload."""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from imgui_bundle import imgui, implot

from ..gpu.display import VIEW_MODES
from ..presets import preset_names, resolve
from ..scene import EFFECTS, TRACERS
from ..scene.effects import allowed_effects

if TYPE_CHECKING:
    from .window import Viewer

RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)


def draw_hud(v: "Viewer") -> None:
    imgui.set_next_window_pos(imgui.ImVec2(8, 8), imgui.Cond_.first_use_ever)
    imgui.set_next_window_size(imgui.ImVec2(330, 0), imgui.Cond_.first_use_ever)
    imgui.set_next_window_bg_alpha(0.75)
    imgui.begin("krsview (F1 hides)")
    _performance(v)
    if imgui.collapsing_header("accuracy and view"):
        _accuracy(v)
    if imgui.collapsing_header("scene, camera, output"):
        _scene(v)
    if v.message:
        imgui.text_wrapped(v.message)
    if v.error:
        imgui.text_colored(RED, v.error)
    imgui.end()


def _performance(v: "Viewer") -> None:
    times = np.array(v.frame_seconds[-120:] or [0.0], dtype=np.float32) * 1e3
    fps = 1e3 / max(float(np.median(times)), 1e-6)
    w, h = v.adaptive.moving_size()
    state = "refined" if v.refined else f"refining {v.refinement.next_row}/{v.refinement.size[1]}" \
        if v.refinement else "moving"
    imgui.text(f"{fps:5.1f} FPS {np.median(times):6.1f} ms  {w}×{h} ({v.adaptive.scale:.0%})")
    imgui.text(f"{state}; {v.view} view")
    if implot.begin_plot("##frametime", imgui.ImVec2(-1, 70), implot.Flags_.no_legend):
        implot.setup_axes_limits(0, 120, 0, max(60.0, float(times.max()) * 1.1),
                                 implot.Cond_.always)
        implot.plot_line("frame ms", times)
        budget = np.full(2, 1e3 / v.adaptive.target_fps, dtype=np.float32)
        implot.plot_line("budget", budget, xscale=120)
        implot.end_plot()
    changed, fps_target = imgui.slider_float("target FPS", v.adaptive.target_fps, 5, 120, "%.0f")
    if changed:
        v.adaptive.target_fps = fps_target
    changed, ss = imgui.checkbox("supersample still images 2×2", v.adaptive.supersample == 2)
    if changed:
        v.adaptive.supersample, v.dirty = (2 if ss else 1), True


def _accuracy(v: "Viewer") -> None:
    r = v.scene.render
    edits: dict = {}
    tracers = ["binary"] if v.scene.mokrs is not None else list(TRACERS)
    changed, k = imgui.combo("tracer", tracers.index(r.tracer), tracers)
    if changed:
        edits["tracer"] = tracers[k]
    if imgui.is_item_hovered():
        imgui.set_tooltip("sphere tracing or binary sphere tracing [KRS17 Alg. 2]; switching "
                          "compiles the other variant once")
    changed, eps = imgui.slider_float("eps scale (px)", r.epsilon_scale, 0.01, 20.0, "%.3f",
                                      imgui.SliderFlags_.logarithmic)
    if changed:
        edits["epsilon_scale"] = eps
    changed, cap = imgui.slider_int("iteration cap", r.max_iterations, 8, 2048, "%d",
                                    imgui.SliderFlags_.logarithmic)
    if changed:
        edits["max_iterations"] = cap
    if r.tracer == "binary":
        changed, bonus = imgui.slider_float("xi bonus", r.xi_bonus, 1.05, 8.0, "%.2f")
        if changed:
            edits["xi_bonus"] = bonus
        changed, penalty = imgui.slider_float("xi penalty", r.xi_penalty, 0.05, 0.95, "%.2f")
        if changed:
            edits["xi_penalty"] = penalty
    if edits:
        v.set_render(**edits)
    total = v.geometry.depth
    changed, levels = imgui.slider_int("levels", v.levels or total, 1, total)
    if changed:
        v.set_levels(levels)
    changed, k = imgui.combo("view", VIEW_MODES.index(v.view), list(VIEW_MODES))
    if changed:
        v.view = VIEW_MODES[k]
    imgui.text("effects (each compiles its own shader variant, cached)")
    for name in allowed_effects(v.scene.mokrs is not None):
        changed, on = imgui.checkbox(name, name in v.scene.effects)
        if changed:
            v.set_effect(name, on)
        if imgui.is_item_hovered():
            imgui.set_tooltip(EFFECTS[name].help)


def _scene(v: "Viewer") -> None:
    names = preset_names()
    current = names.index(v.path.stem) if v.path.stem in names else -1
    changed, k = imgui.combo("preset", current, names)
    if changed:
        v.open_preset(resolve(names[k]))
    imgui.text(f"speed ×{v.speed_factor:.2f} of the nearest distance "
               f"({v.nearest_distance():.3g}); scroll to change")
    if imgui.button("screenshot (F12)"):
        v.act("screenshot")
    imgui.same_line()
    if imgui.button("reset view (R)"):
        v.act("reset")
    imgui.same_line()
    if imgui.button("orbit (O)" if v.orbit_pivot is None else "fly (O)"):
        v.act("orbit")
    if imgui.button("add bookmark (B)"):
        v.act("bookmark")
    for i, b in enumerate(v.scene.bookmarks):
        imgui.same_line()
        if imgui.button(f"{b.name}##{i}"):
            v.bookmark_index = i - 1
            v.act("next_bookmark")
    if imgui.button("stop recording (F5)" if v.recording is not None else "record path (F5)"):
        v.act("record")
    imgui.same_line()
    if imgui.button("replay path (F6)"):
        v.act("replay")
