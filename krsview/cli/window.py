"""`krsview view` and `krsview edit`: open a window (:func:`krsview.app.view`,
:func:`krsview.app.edit`); their options are generated from the viewer's settings fields."""

from __future__ import annotations

import argparse
from dataclasses import MISSING, fields

from .. import app
from ..scene.presets import resolve
from ..scene.settings import EDITOR_SETTINGS, ViewerSettings
from . import options

FLAGS = {"target_fps": "--fps"}  # fields whose flag is not --FIELD-NAME
NOTES = {"prepass": "default: unset"}
EDITOR = ("size", "target_fps")  # the settings the editor takes


def settings_options(sp: argparse.ArgumentParser, names, **defaults) -> None:
    """PRESET and one option per settings field in ``names`` (``defaults``: per command)."""
    options.preset(sp)
    for name in names:
        options.field_option(
            sp,
            ViewerSettings,
            name,
            FLAGS.get(name),
            defaults.get(name, MISSING),
            NOTES.get(name),
        )


def add(sub) -> None:
    v = sub.add_parser(
        "view",
        help="fly through a scene in a window",
        description="Open PRESET in a window. WASD/QE fly (speed follows the "
        "distance to the nearest surface; scroll scales it), right-drag "
        "looks, O orbits the point at the centre, R resets, B saves a "
        "bookmark in the scene file (a shipped preset's in a copy, ./NAME.toml, or in "
        "~/.local/share/krsview/ where the working folder will not do), N cycles "
        "bookmarks, F5 records and F6 replays a camera path, F12 "
        "saves a screenshot beside the scene file (NAME.screenshots/; a shipped preset's in "
        "the pictures folder, ~/Pictures/krsview) and shows where at the foot of the window, "
        "F1 hides the HUD, Ctrl+Q closes; Ctrl+Z / Ctrl+Shift+Z undo and redo the HUD's "
        "changes. Editing the preset or a shader reloads it. "
        "Example: krsview view forest --fps 60 --prepass 8",
    )
    settings_options(v, [f.name for f in fields(ViewerSettings)])
    v.set_defaults(func=run_view)

    e = sub.add_parser(
        "edit",
        help="shape a tree: drag forks, control points and mirror normals; undo, save",
        description="Open PRESET in the editor. Click a handle (forks orange, "
        "control points cyan, mirror normals pink), an outline entry "
        "or the geometry to select; drag the gizmo to move it (Shift "
        "snaps). A grown [tree] is baked into an editable route with "
        "one click. Ctrl+Z / Ctrl+Shift+Z (Ctrl+Y) undo and redo, "
        "Ctrl+S saves atomically (only what changed, your comments kept), Ctrl+Shift+S "
        "asks where to save; unsaved "
        "edits are autosaved beside the file as NAME.toml.recovery (a shipped preset's in "
        "~/.local/share/krsview/recovery/) and offered back "
        "after a crash. Insert / Delete / Ctrl+D insert, remove or duplicate the selected "
        "level (also by right-clicking an outline entry); the structure section tapers, "
        "scales and moves the tree and grows it again from its growth parameters. A shipped "
        "preset is a template: Ctrl+S asks where its copy goes (default ./NAME.toml). "
        "The viewer's keys fly the camera. Example: krsview edit tree",
    )
    settings_options(e, EDITOR, size=EDITOR_SETTINGS.size)
    e.set_defaults(func=run_edit)


def chosen(args: argparse.Namespace, names) -> dict:
    return {name: getattr(args, name) for name in names}


def run_view(args: argparse.Namespace) -> int:
    app.view(resolve(args.preset), **chosen(args, [f.name for f in fields(ViewerSettings)]))
    return 0


def run_edit(args: argparse.Namespace) -> int:
    app.edit(resolve(args.preset), **chosen(args, EDITOR))
    return 0
