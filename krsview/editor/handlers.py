"""The editor's commands, each applied to the editor (window.py's ``Editor``, passed in as
``e``): what keys, panels and modals return (commands.py) goes through this table. The
viewer's commands that the editor decides itself are here too; the rest go to the viewer's
HANDLERS."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..viewer import commands as vc
from . import commands as ec
from .file_actions import FILE_HANDLERS
from .keys import set_key
from .mokrs_levels import apply_op
from .structure import STRUCTURE_HANDLERS

# The editor's commands, and the viewer's that the editor decides itself (a bookmark is an
# edit, opening or reloading asks about unsaved edits: the file part's, FILE_HANDLERS);
# tests/test_commands.py checks them.
EDITOR_HANDLERS: dict[type[vc.Command], Callable[[Any, Any], None]] = {
    ec.Bake: lambda e, c: e.bake(c.component),
    ec.SetKey: lambda e, c: set_key(e),
    ec.ShowKeys: lambda e, c: setattr(e.timeline, "field", c.path),
    ec.Select: lambda e, c: e.select(c.handle),
    ec.SelectLevel: lambda e, c: e.select_level(c.level),
    ec.LevelOp: lambda e, c: apply_op(e, c.level, c.op),
    ec.OutlineScrolled: lambda e, c: setattr(e, "scroll_outline", False),
    ec.SetSnap: lambda e, c: setattr(e.snap, "on", c.on),
    ec.SetCarry: lambda e, c: setattr(e, "carry", c.on),
    vc.Edit: lambda e, c: e.edit(c.path, c.value, c.interaction, c.label, c.field),
    vc.ResetView: lambda e, c: e.reset_view(),
    vc.Undo: lambda e, c: e.undo(),
    vc.Redo: lambda e, c: e.undo(redo=True),
    ec.PlacePanel: lambda e, c: e.place_panel(c.side, c.width),
    ec.FoldPanel: lambda e, c: e.fold_panel(c.folded),
    **STRUCTURE_HANDLERS,
    **{kind: (lambda e, c, h=h: h(e.file, c)) for kind, h in FILE_HANDLERS.items()},
}
