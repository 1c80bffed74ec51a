"""Saving where it is safe: a shipped preset is a template, so saving it asks where its copy
goes (by default ``./NAME.toml`` if free, else the user's krsview folder; never the package);
and an autosave that cannot write is said at once in the status line."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Protocol

from imgui_bundle import imgui

from ..document.document import Document, copy_target
from ..viewer.commands import Command
from ..viewer.window import STATUS_SECONDS, Viewer
from . import commands as ec

DIALOG = "save a copy"


class Saving(Protocol):
    """What saving reads and calls of the editor."""

    viewer: Viewer
    copy_to: str | None  # the copy dialog's field; None: no dialog

    @property
    def doc(self) -> Document: ...
    @property
    def path(self) -> Path: ...
    def save_as(self, text: str) -> None: ...


def ask_copy(e: Saving) -> bool:
    """Ctrl+S on a template: open the dialog with the default copy; nothing saved yet."""
    e.copy_to = str(copy_target(e.path))
    return False


def save_copy(e: Saving) -> None:
    e.save_as(e.copy_to or "")
    if not e.doc.template:
        e.copy_to = None


def autosave(e: Saving, now: float) -> None:
    """Autosave, and when it newly cannot write, say so at once (status line and error)."""
    before = e.doc.autosave_error
    e.doc.autosave(now)
    problem = e.doc.autosave_error
    if problem and problem != before:
        v = e.viewer
        v.error, v.status = problem, (problem, v.clock + STATUS_SECONDS)


SAVING_HANDLERS: dict[type[Command], Callable[[Any, Any], None]] = {
    ec.SetCopyText: lambda e, c: setattr(e, "copy_to", c.text),
    ec.SaveCopy: lambda e, c: save_copy(e),
    ec.CancelCopy: lambda e, c: setattr(e, "copy_to", None),
}


def copy_dialog(e: Saving) -> list[Command]:
    """The modal that asks where a shipped preset's copy goes."""
    out: list[Command] = []
    if e.copy_to is not None and not imgui.is_popup_open(DIALOG):
        imgui.open_popup(DIALOG)
    if not imgui.begin_popup_modal(DIALOG, None, imgui.WindowFlags_.always_auto_resize)[0]:
        return out
    imgui.text(f"{e.doc.path.name} is a preset shipped with krsview: a template, never")
    imgui.text("overwritten. Save your version as:")
    imgui.set_next_item_width(420)
    changed, text = imgui.input_text("##copy", e.copy_to or "")
    if changed:
        out.append(ec.SetCopyText(text))
    if e.viewer.error and e.copy_to is not None:
        imgui.text_wrapped(e.viewer.error)
    if imgui.button("save the copy"):
        out.append(ec.SaveCopy())
    imgui.same_line()
    if imgui.button("cancel"):
        out.append(ec.CancelCopy())
    if e.copy_to is None:
        imgui.close_current_popup()
    imgui.end_popup()
    return out
