"""Saving where it can be seen: the dialog that asks where a shipped preset's copy goes (a
template, never overwritten: by default ``./NAME.toml`` if free, else the user's krsview
folder; never the package), and an autosave that cannot write said at once in the status
line. The file part (file_actions.py) holds what they show."""

from __future__ import annotations

from imgui_bundle import imgui

from ..viewer.commands import Command
from . import commands as ec
from .file_actions import FileActions

DIALOG = "###save"  # the dialog's id, whichever title it shows
FIELD = 420  # pixels: the name field, and the width its notes wrap at


def autosave(f: FileActions, now: float) -> None:
    """Autosave, and when it newly cannot write, say so at once (status line and error)."""
    before = f.doc.autosave_error
    f.doc.autosave(now)
    problem = f.doc.autosave_error
    if problem and problem != before:
        f.viewer.error = problem
        f.viewer.say(problem)


def copy_dialog(f: FileActions) -> list[Command]:
    """The modal that asks where a shipped preset's copy goes."""
    out: list[Command] = []
    if f.copy_to is not None and not imgui.is_popup_open(DIALOG):
        imgui.open_popup(DIALOG)
    template = f.doc.template
    title = ("save a copy" if template else "save as") + DIALOG
    if not imgui.begin_popup_modal(title, None, imgui.WindowFlags_.always_auto_resize)[0]:
        return out
    if template:
        imgui.text(f"{f.doc.path.name} is a preset shipped with krsview: a template, never")
        imgui.text("overwritten. Save your version as:")
        if f.copy_to is not None and f.copy_to.why:  # not NAME.toml here: say why
            imgui.push_text_wrap_pos(imgui.get_cursor_pos_x() + FIELD)
            imgui.text_disabled(f"(not in the working folder: {f.copy_to.why})")
            imgui.pop_text_wrap_pos()
    else:
        imgui.text(f"Save {f.doc.path.name} as:")
    imgui.set_next_item_width(FIELD)
    if imgui.is_window_appearing():
        imgui.set_keyboard_focus_here()
    enter = imgui.InputTextFlags_.enter_returns_true
    done, text = imgui.input_text("##copy", f.copy_to.text if f.copy_to else "", enter)
    if text != (f.copy_to.text if f.copy_to else ""):
        out.append(ec.SetCopyText(text))
    if f.copy_to is not None and f.copy_to.said:  # this dialog's refusal, not an older one
        imgui.text_wrapped(f.copy_to.said)
    asked = f.copy_to is not None and f.replace_asked(f.copy_to.text)
    if imgui.button("replace it" if asked else "save the copy" if template else "save") or done:
        out.append(ec.SaveCopy())
    imgui.same_line()
    if imgui.button("cancel (Esc)") or imgui.is_key_pressed(imgui.Key.escape):
        out.append(ec.CancelCopy())
    if f.copy_to is None:
        imgui.close_current_popup()
    imgui.end_popup()
    return out
