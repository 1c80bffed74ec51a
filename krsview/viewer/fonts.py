"""The font of both windows: Roboto from imgui-bundle's assets (installed with it, so every
machine that opens a window has it) for the text, with Inconsolata, also shipped there, merged
in for the symbols Roboto lacks (→, ∈, █). Together they hold every glyph the messages,
labels and tooltips use (em dash, ≤, ε, ·, ×, °, ö …; tests/test_fonts.py scans the strings).
ImGui's built-in font has ASCII only and drew the rest as '?'."""

from __future__ import annotations

from pathlib import Path

import imgui_bundle
from imgui_bundle import imgui

FONTS = Path(imgui_bundle.__file__).parent / "assets" / "fonts"
FONT = FONTS / "Roboto" / "Roboto-Regular.ttf"
SYMBOLS = FONTS / "Inconsolata-Medium.ttf"  # merged: its glyphs where FONT has none
FONT_SIZE = 14.0  # pixels: as tall as ImGui's own font draws its text, a little wider


def load_font() -> None:
    """Make FONT, with SYMBOLS merged, the default font of the current ImGui context (before
    its first frame). ImGui ≥ 1.92 bakes glyphs on demand, so no glyph ranges are needed."""
    fonts = imgui.get_io().fonts
    fonts.add_font_from_file_ttf(str(FONT), FONT_SIZE)
    merged = imgui.ImFontConfig()
    merged.merge_mode = True
    fonts.add_font_from_file_ttf(str(SYMBOLS), FONT_SIZE, merged)
