"""The HUD's time section for scenes that move (issue 29): play/pause, the moment shown on a
slider over one loop, and the playback speed. It reads the viewer's clock and returns
commands."""

from __future__ import annotations

import math

from imgui_bundle import imgui

from . import commands as c
from .playback import SPEED_RANGE, Playback


def draw_time(playback: Playback, out: list[c.Command]) -> None:
    """Play/pause (Space), time and speed: the section a moving scene shows first."""
    if imgui.button("pause (Space)" if playback.playing else "play (Space)"):
        out.append(c.TogglePlay())
    imgui.same_line()
    imgui.set_next_item_width(-60)
    changed, t = imgui.slider_float(
        "time##playback", playback.time, 0.0, playback.duration, "%.2f s"
    )
    if changed:
        out.append(c.SetTime(t))
    lo, hi = (math.log2(s) for s in SPEED_RANGE)
    changed, k = imgui.slider_float(
        "speed##playback", math.log2(playback.speed), lo, hi, f"×{playback.speed:.2f}"
    )
    if changed:
        out.append(c.SetSpeed(2.0**k))
