"""The editor's modal dialogs: one in the middle of the window, never wider than it, and a
line of answers, each a command that closes the dialog (panels.py, structure_panel.py);
and the right-click menu of a list's entry (the outline's, a MöKRS's levels)."""

from __future__ import annotations

from collections.abc import Callable, Sequence

from imgui_bundle import imgui

from ..viewer.commands import Command
from . import commands as ec

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


MenuItem = tuple[str, str, Callable[[], list[Command]]]  # text, its keys, its commands


def entry_menu(menu_id: str, k: int, name: str, items: Sequence[MenuItem]) -> list[Command]:
    """The right-click menu of list entry k, titled by its ``name`` (call right after its
    selectable); opening it selects the entry, so what is marked is what the menu acts on.
    The commands of the item chosen."""
    out: list[Command] = []
    if imgui.begin_popup_context_item(menu_id):
        if imgui.is_window_appearing():
            out.append(ec.SelectLevel(k))
        imgui.text_disabled(name)
        imgui.separator()
        for text, keys, commands in items:
            if imgui.menu_item(text, keys, False)[0]:
                out += commands()
        imgui.end_popup()
    return out
