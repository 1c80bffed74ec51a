"""The font of both windows: Roboto from imgui-bundle's assets (installed with it, so every
machine that runs a window has it), which holds every glyph the messages, labels and
tooltips use (em dash, ≤, ε, ·, ×, °, ö …; tests/test_fonts.py scans the strings). ImGui's
built-in font has ASCII only and draws the rest as '?'."""

from __future__ import annotations

from pathlib import Path

import imgui_bundle
from imgui_bundle import imgui

FONT = Path(imgui_bundle.__file__).parent / "assets" / "fonts" / "Roboto" / "Roboto-Regular.ttf"
FONT_SIZE = 14.0  # pixels: as tall as ImGui's own font draws its text, a little wider


def load_font() -> None:
    """Make FONT the default font of the current ImGui context (before its first frame).
    ImGui ≥ 1.92 bakes glyphs on demand, so no glyph ranges are needed."""
    imgui.get_io().fonts.add_font_from_file_ttf(str(FONT), FONT_SIZE)
