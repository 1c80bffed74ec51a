"""A turn's ImGui frame in two parts around the frame traced in it [issue 27 §4]: the HUD but
that frame's numbers while llvmpipe's threads trace it, on the core they leave idle part of
the time (the main thread used to wait then, and the cores to wait for it after); the numbers
of the image on screen once it is done, so the HUD describes the frame it is drawn over."""

from __future__ import annotations

from typing import Protocol

from imgui_bundle import imgui

from . import commands as c
from .hud import HUD_TITLE, Viewed, begin_hud, finish_hud
from .platform import Platform
from .status import draw_status, drawn_rect, status_room
from .widgets import Interactions


class HudViewer(Viewed, Protocol):
    """What the turn's ImGui frame reads of the viewer besides what the HUD does."""

    platform: Platform
    interactions: Interactions
    hud: bool  # the HUD shown (else only the status line, where there is one)

    def status_is_error(self, status: str) -> bool: ...


class HudFrame:
    """One turn's ImGui frame: :meth:`while_tracing` (or :meth:`begin` in a turn that traces
    no moving frame), then :meth:`finish` after the display pass, then :meth:`draw`."""

    def __init__(self, viewer: HudViewer, status: str):
        self.v, self.status = viewer, status
        self.commands: list[c.Command] = []
        self.slot = None  # where the numbers go (begin_hud), once begun with the HUD shown
        self.begun = False

    def while_tracing(self) -> None:
        """A moving frame's first pass is issued: start it (glFlush), then build."""
        self.v.platform.flush()
        self.begin()

    def begin(self) -> None:
        """Read the window and build the HUD but the numbers of the image on screen."""
        if self.begun:
            return
        self.begun = True
        self.v.platform.new_frame()
        if self.v.hud:
            width = imgui.get_io().display_size.x  # the HUD ends above the status line
            foot = status_room(self.status, (0.0, width), width, drawn_rect(HUD_TITLE))
            self.commands, self.slot = begin_hud(self.v, self.v.interactions, foot)

    def finish(self) -> list[c.Command]:
        """The numbers of the image on screen into the HUD; its commands, to apply before
        :meth:`draw` (the order of a HUD drawn at once)."""
        self.begin()
        if self.slot is not None:
            finish_hud(self.v, self.slot)
        return self.commands

    def draw(self) -> None:
        """The status line, then ImGui's drawing over the image."""
        draw_status(self.status, self.v.status_is_error(self.status))
        self.v.platform.render()
