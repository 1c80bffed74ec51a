"""The HUD's time section for scenes that move (issue 29): play/pause, the moment shown on a
slider over one loop, and the playback speed. It reads the viewer's clock and returns
commands."""

from __future__ import annotations

from imgui_bundle import imgui

from . import commands as c
from .playback import SPEED_RANGE, Playback
from .widgets import CLAMPED, LOG_CLAMPED, Interactions


def draw_time(playback: Playback, out: list[c.Command], interactions: Interactions) -> None:
    """Play/pause (Space), time and speed: the section a moving scene shows first."""
    if imgui.button("pause (Space)" if playback.playing else "play (Space)"):
        out.append(c.TogglePlay())
    imgui.same_line()
    imgui.set_next_item_width(-60)
    changed, t = imgui.slider_float(
        "time##playback", playback.time, 0.0, playback.duration, "%.2f s", CLAMPED
    )
    if changed:
        out.append(c.SetTime(t))
    # the speed itself on a logarithmic scale: a value typed (Ctrl+click) is the speed; it
    # was the slider's exponent, so 2 played ×4 and 1024 overflowed 2**k and closed the window
    changed, speed = imgui.slider_float(
        "speed##playback", playback.speed, *SPEED_RANGE, "×%.2f", LOG_CLAMPED
    )
    interactions.place(("playback", "speed"))
    if changed:
        out.append(c.SetSpeed(speed))
