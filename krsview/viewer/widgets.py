"""ImGui widgets generated from the scene schema (the Fragmentarium habit,
docs/architecture.md): a field's type picks the widget, its metadata gives the range, unit and
tooltip, so panels never repeat a range by hand. A widget returns the new value; the document
validates it.

Each widget reports its interaction: a slider or drag held down is one interaction, so the many
values it produces merge into one undo step (docs/architecture.md, One seam for edits). A value
the schema refuses stays in its field, marked red, with the message under it, until a valid
value replaces it or Esc cancels it (the scene keeps its last valid value meanwhile)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from imgui_bundle import imgui

from ..scene.schema import describe_range

WHOLE_LIMIT = 2**24  # the whole numbers an int field (a float32 widget) holds exactly
CLAMPED = imgui.SliderFlags_.always_clamp  # a value typed past a slider's ends is taken there
LOG_CLAMPED = imgui.SliderFlags_.logarithmic | CLAMPED
LOG_RATIO = 100.0  # a range spanning more than this factor gets a logarithmic slider
RED = imgui.ImVec4(1.0, 0.45, 0.4, 1.0)
RED_FRAME = imgui.ImVec4(0.55, 0.08, 0.06, 1.0)


@dataclass(frozen=True)
class Refused:
    """A value typed or dragged into a field that the schema refused, and why."""

    value: Any
    message: str


@dataclass
class Interactions:
    """Numbers each press-and-drag of a widget, so its edits merge into one undo step; keeps
    where each field's widget was drawn (window pixels), for automation and window tests; and
    the refused values of the fields that show their errors themselves."""

    count: int = 0
    rects: dict[tuple, tuple[float, float, float, float]] = field(default_factory=dict)
    refused: dict[tuple, Refused] = field(default_factory=dict)
    inline: set[tuple] = field(default_factory=set)  # fields drawn with refusal()

    def refusal(self, path: tuple) -> Refused | None:
        """Call before the field's widget: its refused value, if any (and from now on its
        errors are shown at the field, not elsewhere)."""
        self.inline.add(path)
        return self.refused.get(path)

    def key(self, path: tuple) -> tuple:
        """Call right after the widget: a new number when it was just activated. A refused
        field's message goes under it; Esc cancels the refused value."""
        if imgui.is_item_activated():
            self.count += 1
        self.place(path)
        if path in self.refused:
            if imgui.is_key_pressed(imgui.Key.escape):
                del self.refused[path]
            else:
                red_text(self.refused[path].message)
        return ("panel", path, self.count)

    def place(self, path: tuple) -> None:
        """Keep where the last widget was drawn, as ``path``'s."""
        lo, hi = imgui.get_item_rect_min(), imgui.get_item_rect_max()
        self.rects[path] = (lo.x, lo.y, hi.x, hi.y)

    def settle(self, path: tuple, value: Any, error: str) -> bool:
        """An edit of ``path`` was applied (``error`` empty) or refused: a field showing its
        own errors keeps the refused value, or drops it once a value is taken. True when the
        error is shown at the field."""
        if not error:
            self.refused.pop(path, None)
            return False
        if path not in self.inline:
            return False
        self.refused[path] = Refused(value, error)
        return True


TIP_EMS = 22.0  # a tooltip wraps at this many font sizes


def tooltip(text: str) -> None:
    """The hovered item's tooltip, wrapped at TIP_EMS font sizes: ImGui's own is one line,
    cut off at the window's edge."""
    imgui.begin_tooltip()
    imgui.push_text_wrap_pos(TIP_EMS * imgui.get_font_size())
    imgui.text_unformatted(text)
    imgui.pop_text_wrap_pos()
    imgui.end_tooltip()


def one_line(text: str) -> None:
    """``text`` dimmed on one line, cut with "…" where the window is narrower (whole on
    hover): a line that wraps, or runs past the edge, moves or widens what is around it."""
    room = imgui.get_content_region_avail().x
    shown = text
    if imgui.calc_text_size(text).x > room:
        lo, hi = 0, len(text)  # the longest start of it that fits with "…"
        while lo < hi:
            mid = (lo + hi + 1) // 2
            lo, hi = (
                (mid, hi) if imgui.calc_text_size(text[:mid] + "…").x <= room else (lo, mid - 1)
            )
        shown = text[:lo].rstrip() + "…"
    imgui.text_disabled(shown)
    if shown != text and imgui.is_item_hovered():
        tooltip(text)


def red_text(text: str) -> None:
    """A refusal or a warning: ``text`` wrapped, in red (nothing for none)."""
    if text:
        imgui.push_style_color(imgui.Col_.text, RED)
        imgui.text_wrapped(text)
        imgui.pop_style_color()


def tooltip_text(meta: dict, kind: type) -> str:
    """A field's tooltip: its help, the range it allows in the words its errors use (an open
    bound says <, not ≤), and for a number how to type one."""
    text = meta.get("help", "")
    if meta.get("lo") is not None or meta.get("hi") is not None:
        text += f" ({describe_range(meta, int if kind is int else float)})"
    if text and kind not in (bool, str):
        text += "\n(ctrl+click or double-click to type a value)"
    return text


def as_typed(new: float, old: float) -> float:
    """A number from an ImGui float widget, which holds float32: ``old`` itself (float64, bit
    for bit) where the widget left it, else the shortest decimal that float32 reads as the
    widget's value, so typing 0.09 sets 0.09, not 0.09000000357627869."""
    if np.float32(new) == np.float32(old):
        return float(old)
    return float(str(np.float32(new)))


def shown_vector(value: tuple) -> tuple:
    """A vector as its field shows it: a component below 1e-9 of the largest (rounding left
    by a conversion, 4.6e-17 beside 6.3) and −0 read 0; the value itself is kept where the
    field is not changed."""
    tiny = 1e-9 * max(abs(c) for c in value)
    return tuple(0.0 if abs(c) <= tiny else float(c) for c in value)


def _speed(value: float, meta: dict) -> float:
    """Change per pixel dragged: 1 % of the value, at most 1/500 of a bounded range."""
    speed = max(abs(value) * 0.01, 1e-4)
    lo, hi = meta.get("lo"), meta.get("hi")
    if lo is not None and hi is not None:
        speed = min(speed, (hi - lo) / 500.0)
    return speed


def field_widget(
    label: str, value: Any, meta: dict, refused: Refused | None = None
) -> tuple[bool, Any]:
    """One widget for one field (of the scene, or of the viewer's settings); (changed, new
    value). A ``refused`` value is shown instead of ``value``, on red."""
    if refused is None:
        changed, new = _widget(label, value, meta)
        text = tooltip_text(meta, type(value))
        if text and imgui.is_item_hovered():
            tooltip(text)
        return changed, new
    # no tooltip: it would cover the refusal's message under the field (Interactions.key)
    imgui.push_style_color(imgui.Col_.frame_bg, RED_FRAME)
    changed, new = _widget(label, refused.value, meta, type(value))  # the field's own kind
    imgui.pop_style_color()
    return changed, new


def _whole(x: float) -> bool:
    """A whole number an int field holds exactly (WHOLE_LIMIT)."""
    return float(x).is_integer() and abs(x) <= WHOLE_LIMIT


def _widget(label: str, value: Any, meta: dict, kind: type | None = None) -> tuple[bool, Any]:
    """The widget of a value of ``kind`` (by default the value's own: a refused 2.5 shown in
    a whole-number field is still typed into a whole-number field)."""
    lo, hi = meta.get("lo"), meta.get("hi")
    if isinstance(value, bool):
        changed, value = imgui.checkbox(label, value)
    elif isinstance(value, str) and meta.get("choices"):
        choices = list(meta["choices"])
        changed, k = imgui.combo(label, choices.index(value), choices)
        value = choices[k]
    elif (kind or type(value)) is int:
        # a float field showing whole numbers: ImGui's int field read a typed 1e30 as 1 and
        # 2.5 as 2 without a word; typed, they come back as typed and the schema refuses
        # them (float32 holds every whole number up to 2^24 exactly)
        shown = "%.0f" if _whole(value) else "%g"  # a refused 2.5 shows as typed, not as 2
        changed, new = imgui.drag_float(
            label, float(value), 0.2, float(lo or 0), float(hi or 0), shown
        )
        value = int(new) if _whole(new) else float(new)
    elif (
        isinstance(value, float)
        and lo is not None
        and hi is not None
        and lo > 0
        and hi / lo > LOG_RATIO
    ):
        changed, new = imgui.slider_float(
            label, value, lo, hi, "%.4g", imgui.SliderFlags_.logarithmic
        )
        value = as_typed(new, value)
    elif isinstance(value, float):
        changed, new = imgui.drag_float(
            label,
            value + 0.0,  # −0 shown as 0
            _speed(value, meta),
            lo if lo is not None else 0.0,
            hi if hi is not None else 0.0,
            "%.5g",
        )
        value = as_typed(new, value)
    elif isinstance(value, tuple) and len(value) == 3 and lo == 0.0 and hi == 1.0:
        changed, rgb = imgui.color_edit3(label, list(value), imgui.ColorEditFlags_.float)
        value = tuple(as_typed(c, old) for c, old in zip(rgb, value))
    elif isinstance(value, tuple) and len(value) == 3:
        speed = max(max(abs(c) for c in value) * 0.005, 1e-4)
        shown = shown_vector(value)
        changed, v = imgui.drag_float3(label, list(shown), speed, 0.0, 0.0, "%.5g")
        value = tuple(
            old if np.float32(c) == np.float32(s) else as_typed(c, s)
            for c, s, old in zip(v, shown, value)
        )
    else:
        imgui.text_disabled(f"{label}: {value!r}")
        return False, value
    return changed, value
