"""The viewer's and the editor's own options, which are not scene fields: one declaration with
range, default and help (the scene schema's metadata style), read by the windows, their HUD
and the command line, so no option has two ranges or two defaults."""

from __future__ import annotations

import typing
from dataclasses import dataclass, fields, replace
from typing import Any

from ..messages import SceneError
from .render import VIEW_PREPASS
from .schema import check_value, param

MAX_SIDE = 8192  # pixels, each side of a window


@dataclass(frozen=True)
class ViewerSettings:
    """How a window opens and draws (``krsview view`` and ``krsview edit`` options)."""

    size: tuple[int, int] = param(
        (960, 540), lo=48, hi=MAX_SIDE, unit="pixels", help="window size, width × height"
    )
    target_fps: float = param(
        30.0,
        lo=1.0,
        hi=240.0,
        unit="frames/s",
        help="frame rate held while moving or dragging, by lowering the internal resolution",
    )
    prepass: int | None = param(
        None,
        lo=0,
        hi=64,
        unit="pixels",
        help="tile size of the low-resolution pre-pass while viewing (0: off; unset: the "
        f"scene's [render] prepass, else {VIEW_PREPASS}); the HUD's knob sets the scene's",
    )
    hud: bool = param(True, help="show the HUD (F1 hides and shows it)")
    moving_effects: bool = param(
        False,
        help="trace shadow rays in moving frames and refinement steps as in the still image "
        "(the scene's [render] shadow_block; a lower resolution at the target FPS); off: "
        "one per 2×2 pixels at least (3×3 from 240 pixels wide), blended along depth, for "
        "the same lighting at a higher resolution",
    )


EDITOR_SETTINGS = ViewerSettings(size=(1280, 720))  # the editor's panels need a larger window


def settings_meta(name: str) -> dict:
    """The range, unit and help of the option ``name`` (for widgets and the command line)."""
    return next(dict(f.metadata) for f in fields(ViewerSettings) if f.name == name)


def make_settings(base: ViewerSettings = ViewerSettings(), **options: Any) -> ViewerSettings:
    """``base`` with ``options`` replaced, each checked against its field's range: a bad one
    is a SceneError naming the option, the value and what is allowed."""
    hints = typing.get_type_hints(ViewerSettings)
    known = {f.name for f in fields(ViewerSettings)}
    for name, value in options.items():
        if name not in known:
            raise SceneError(name, value, "unknown option; allowed: " + ", ".join(sorted(known)))
        meta = settings_meta(name)
        if name == "size":  # two sides; the schema's tuples are 3-vectors
            if not isinstance(value, (tuple, list)) or len(value) != 2:
                raise SceneError(name, value, "expected (width, height)")
            value = tuple(check_value(int, s, f"size[{i}]", meta) for i, s in enumerate(value))
        else:
            value = check_value(hints[name], value, name, meta)
        options[name] = value
    return replace(base, **options)
