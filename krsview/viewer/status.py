"""The status line: a line at the window's foot (a screenshot's path; an error in red), HUD
shown or not, placed where no other window covers it: at the foot's left, else to the right
of the windows that reach the foot (the HUD, the editor's panel), else above them (the editor's
timeline spans the foot); where it fits whole on one line nowhere, it is wrapped into the
widest gap at the foot. Where it does not fit on one line beside the HUD, the HUD ends above
it (:func:`status_room`): a HUD reaching the foot scrolls its knobs in less height while
there is something to say, and neither covers the other."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator

from imgui_bundle import imgui

from .widgets import RED

MARGIN = 8.0  # pixels between the status line and the window's edges or other windows
MIN_ROOM = 150.0  # pixels: a gap narrower than this is no place for a wrapped line
Rect = tuple[float, float, float, float]  # x0, y0, x1, y1
Measure = Callable[[float], tuple[float, float]]  # a width to wrap at → the box's (w, h)


def status_spot(display: tuple[float, float], measure: Measure, rects: list[Rect]):
    """Where the status line goes in a ``display`` (w, h) beside the windows ``rects``: its
    left edge, its foot and the width it may take (x, y, room); ``measure(width)`` is its
    box wrapped at ``width``. One line in the lowest band with room for it, leftmost; else
    wrapped in the widest gap that holds MIN_ROOM, in the lowest band with one (above the
    editor's timeline, beside its panel); else at the foot's left, over the other windows."""
    w, h = measure(math.inf)
    feet = list(_feet(display, h, rects))
    for foot in feet:
        for x, room in _gaps(display[0], foot, h, rects):
            if room >= w:
                return x, foot, room
    for foot in feet:
        for x, room in sorted(_gaps(display[0], foot, h, rects), key=lambda g: -g[1]):
            top = foot - measure(room)[1]
            if (
                room >= MIN_ROOM
                and top >= 0
                and not any(meets(r, (x, top, x + room, foot)) for r in rects)
            ):
                return x, foot, room
    return MARGIN, display[1] - MARGIN, display[0] - 2 * MARGIN


def _feet(display: tuple[float, float], h: float, rects: list[Rect]) -> Iterator[float]:
    """The bands a line of height ``h`` may sit on, from the window's foot up: each next one
    just above the lowest window that reaches into the band below it."""
    foot = display[1] - MARGIN
    while foot - h >= 0:
        yield foot
        band = [r for r in rects if r[1] < foot and r[3] > foot - h]
        if not band:
            return
        foot = max(r[1] for r in band) - MARGIN  # above the lowest one only


def meets(a: Rect, b: Rect) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _gaps(width: float, foot: float, h: float, rects: list[Rect]) -> Iterator[tuple[float, float]]:
    """The free spans (x, room) of the band of height ``h`` above ``foot``, left to right."""
    x = MARGIN
    for x0, x1 in sorted((r[0], r[2]) for r in rects if r[1] < foot and r[3] > foot - h):
        if x0 - MARGIN > x:
            yield x, x0 - MARGIN - x
        x = max(x, x1 + MARGIN)
    if width - MARGIN > x:
        yield x, width - MARGIN - x


def window_rect(w) -> Rect:
    """An ImGui window's rectangle as it was last drawn."""
    return w.pos.x, w.pos.y, w.pos.x + w.size.x, w.pos.y + w.size.y


def drawn_rect(name: str) -> Rect | None:
    """The rectangle of the window ``name`` as it was last drawn; None before it was."""
    w = imgui.internal.find_window_by_name(name)
    return None if w is None else window_rect(w)


def _other_windows() -> list[Rect]:
    """The rectangles of the top-level windows drawn this frame that show something: not
    tooltips and popups (they move or close of themselves), not an overlay that takes no
    mouse or has no background (the editor's gizmo draws over the whole window in one),
    not ImGui's own implicit "Debug" window."""
    skip = (
        imgui.WindowFlags_.tooltip
        | imgui.WindowFlags_.popup
        | imgui.WindowFlags_.child_window
        | imgui.WindowFlags_.no_background
        | imgui.WindowFlags_.no_mouse_inputs
    )
    out = []
    for w in imgui.get_current_context().windows:
        if w.active and not w.hidden and not (w.flags & skip) and not w.name.startswith("Debug##"):
            out.append(window_rect(w))
    return out


def _measure(text: str) -> Measure:
    """The status line's box, ``text`` wrapped at a width (inf: one line)."""
    pad = imgui.get_style().window_padding

    def measure(width: float) -> tuple[float, float]:
        wrap = width - 2 * pad.x if math.isfinite(width) else -1.0
        size = imgui.calc_text_size(text, False, wrap)
        return size.x + 2 * pad.x, size.y + 2 * pad.y

    return measure


def status_room(
    text: str, span: tuple[float, float], width: float, hud: Rect | None = None
) -> float:
    """Pixels above the foot the HUD leaves the status line ``text``: 0 with none, or where
    it fits on one line beside the ``hud`` (as last drawn); else its box wrapped into the
    columns ``span`` (x0, x1) of a window ``width`` wide that the view keeps (all of them, or
    those the editor's panel leaves), inside the margins, with the margin above it: the gap
    status_spot then finds free."""
    if not text:
        return 0.0
    measure = _measure(text)
    lo, hi = max(span[0], MARGIN), min(span[1], width - MARGIN)
    if hud is not None and max(hud[0] - MARGIN - lo, hi - hud[2] - MARGIN) >= measure(math.inf)[0]:
        return 0.0
    return measure(hi - lo)[1] + MARGIN


def draw_status(text: str, error: bool = False) -> None:
    """The status line ``text`` (red for an ``error``), where no other window covers it."""
    if not text:
        return
    pad = imgui.get_style().window_padding
    display = imgui.get_io().display_size
    x, y, room = status_spot((display.x, display.y), _measure(text), _other_windows())
    imgui.set_next_window_pos(imgui.ImVec2(x, y), imgui.Cond_.always, imgui.ImVec2(0, 1))
    imgui.set_next_window_bg_alpha(0.75)
    flags = imgui.WindowFlags_.no_decoration | imgui.WindowFlags_.always_auto_resize
    imgui.begin("##status", None, flags | imgui.WindowFlags_.no_inputs)
    # over the others where no gap holds it (a HUD or a panel drawn later hid it)
    imgui.internal.bring_window_to_display_front(imgui.internal.get_current_window())
    imgui.push_text_wrap_pos(imgui.get_cursor_pos().x + room - 2 * pad.x)
    if error:
        imgui.push_style_color(imgui.Col_.text, RED)
    imgui.text(text)
    if error:
        imgui.pop_style_color()
    imgui.pop_text_wrap_pos()
    imgui.end()
