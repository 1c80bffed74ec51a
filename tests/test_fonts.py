"""The windows' font holds every glyph the code's messages, labels and tooltips use: each
string literal (docstrings aside) of the modules whose text reaches a window is scanned, and
each printable character must be in the character map of the font or of the symbol font
merged into it (read with fontTools, independently of ImGui). ImGui's built-in font drew
these as '?'."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest
from fontTools.ttLib import TTFont

import krsview
from krsview.viewer.fonts import FONT, SYMBOLS

PACKAGE = Path(krsview.__file__).parent
SHOWN = ("viewer", "editor", "scene", "document", "gpu", "compile", "app.py")  # reach a window


def ui_characters(paths) -> dict[str, str]:
    """Each non-ASCII character of the string literals in ``paths`` → a file using it."""
    out: dict[str, str] = {}
    for path in paths:
        tree = ast.parse(path.read_text())
        docs = {
            id(node.body[0].value)
            for node in ast.walk(tree)
            if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and node.body
            and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)
        }
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Constant)
                and isinstance(node.value, str)
                and id(node) not in docs
            ):
                for c in node.value:
                    if ord(c) > 126 and (c.isprintable() or c.isspace()):  # NBSP too
                        out.setdefault(c, path.name)
    return out


def shown_files():
    for name in SHOWN:
        p = PACKAGE / name
        yield from (sorted(p.rglob("*.py")) if p.is_dir() else [p])


@pytest.fixture(scope="module")
def cmap() -> dict[int, str]:
    return TTFont(FONT).getBestCmap() | TTFont(SYMBOLS).getBestCmap()


def test_every_character_the_windows_show_is_in_the_font(cmap):
    used = ui_characters(shown_files())
    assert {"—", "≤", "ε", "·", "×", "°", "ö"} <= set(used), "the scan misses known messages"
    missing = {c: f for c, f in used.items() if ord(c) not in cmap}
    assert not missing, "not in the fonts: " + ", ".join(f"{c!r} ({f})" for c, f in missing.items())


def test_a_character_outside_the_font_is_found(tmp_path, cmap):
    """Negative control: a message with a glyph neither font has is reported."""
    probe = tmp_path / "probe.py"
    probe.write_text('"""doc ⟂ is not scanned"""\nMESSAGE = "a ⟂ b — c → d"\n')
    used = ui_characters([probe])
    assert set(used) == {"⟂", "—", "→"}
    assert [c for c in used if ord(c) not in cmap] == ["⟂"]
