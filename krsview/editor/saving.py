"""Saving where it is safe: a shipped preset is a template, so saving it asks where its copy
goes (by default ``./NAME.toml`` if free, else the user's krsview folder; never the package);
and an autosave that cannot write is said at once in the status line."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

from imgui_bundle import imgui

from ..document.document import Document, copy_target
from ..viewer.commands import Command
from ..viewer.window import STATUS_SECONDS, Viewer
from . import commands as ec

DIALOG = "save a copy"


@dataclass(frozen=True)
class CopyAsk:
    """The copy dialog: where the copy goes, and the question that wanted the save (closing
    or opening another scene with unsaved edits), answered once the copy is saved."""

    text: str
    then: tuple[str, Path | None] | None = None


class Saving(Protocol):
    """What saving reads and calls of the editor."""

    viewer: Viewer
    copy_to: CopyAsk | None  # None: no dialog
    asking: tuple[str, Path | None] | None

    @property
    def doc(self) -> Document: ...
    @property
    def path(self) -> Path: ...
    def save_as(self, text: str) -> None: ...
    def answer_save(self) -> None: ...


def save_as_default(doc: Document) -> str:
    """What the save-as field starts with: the file itself, or for a shipped preset the
    copy's default (``./NAME.toml``, else the user's folder), never the package's folder."""
    return str(copy_target(doc.path) if doc.template else doc.path)


def ask_copy(e: Saving) -> bool:
    """Saving a template: ask where the copy goes (the default filled in), taking over the
    unsaved-edits question if that is what asked; nothing is saved yet."""
    e.copy_to, e.asking = CopyAsk(str(copy_target(e.path)), e.asking), None
    return False


def save_copy(e: Saving) -> None:
    """Save to the named copy; then go on with the question that asked (close, open)."""
    ask = e.copy_to
    if ask is None:
        return
    e.save_as(ask.text)
    if e.doc.template:
        return  # refused: the dialog stays, with the error
    e.copy_to = None
    if ask.then is not None:
        e.asking = ask.then
        e.answer_save()


def autosave(e: Saving, now: float) -> None:
    """Autosave, and when it newly cannot write, say so at once (status line and error)."""
    before = e.doc.autosave_error
    e.doc.autosave(now)
    problem = e.doc.autosave_error
    if problem and problem != before:
        v = e.viewer
        v.error, v.status = problem, (problem, v.clock + STATUS_SECONDS)


SAVING_HANDLERS: dict[type[Command], Callable[[Any, Any], None]] = {
    ec.SetCopyText: lambda e, c: setattr(e, "copy_to", replace(e.copy_to, text=c.text)),
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
    changed, text = imgui.input_text("##copy", e.copy_to.text if e.copy_to else "")
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
