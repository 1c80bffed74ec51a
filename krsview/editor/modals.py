"""The editor's modal dialogs: one in the middle of the window, never wider than it, and a
line of answers, each a command that closes the dialog (panels.py, structure_panel.py)."""

from __future__ import annotations

from collections.abc import Sequence

from imgui_bundle import imgui

from ..viewer.commands import Command

MODAL_WIDTH = 420.0  # pixels, or the window's width where it is narrower


def begin_modal(name: str) -> bool:
    """A modal dialog in the middle of the window, never wider than it (its text wraps)."""
    size = imgui.get_io().display_size
    width = min(MODAL_WIDTH, size.x - 16)
    imgui.set_next_window_pos(
        imgui.ImVec2(size.x / 2, size.y / 2), imgui.Cond_.always, imgui.ImVec2(0.5, 0.5)
    )
    imgui.set_next_window_size(imgui.ImVec2(width, 0))
    return imgui.begin_popup_modal(name, None, imgui.WindowFlags_.no_resize)[0]


def answer_buttons(answers: Sequence[tuple[str, Command]], out: list[Command]) -> None:
    """The dialog's answers on one line: the one clicked is returned as its command and
    closes the dialog."""
    for k, (label, command) in enumerate(answers):
        if k:
            imgui.same_line()
        if imgui.button(label):
            out.append(command)
            imgui.close_current_popup()
