"""Controls as data (key ↦ movement or command, the pygfx habit) and one input layer fed by
GLFW callbacks or by tests with synthetic events."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from .commands import (
    AddBookmark,
    Command,
    NextBookmark,
    Quit,
    Redo,
    Replay,
    ResetView,
    Screenshot,
    ToggleHud,
    ToggleOrbit,
    TogglePlay,
    ToggleRecording,
    Undo,
)

# Held keys move the camera: (right, up, forward) components.
MOVES: dict[str, tuple[int, int, int]] = {
    "W": (0, 0, 1),
    "S": (0, 0, -1),
    "A": (-1, 0, 0),
    "D": (1, 0, 0),
    "Q": (0, -1, 0),
    "E": (0, 1, 0),
}
# Pressed keys (Ctrl+key as "ctrl+KEY", "ctrl+shift+KEY") give a command once.
VIEWER_KEYS: dict[str, Command] = {
    "R": ResetView(),
    "O": ToggleOrbit(),
    "F12": Screenshot(),
    "F1": ToggleHud(),
    "B": AddBookmark(),
    "N": NextBookmark(),
    "F5": ToggleRecording(),
    "F6": Replay(),
    "Space": TogglePlay(),
    "ctrl+Z": Undo(),
    "ctrl+shift+Z": Redo(),
    "ctrl+Y": Redo(),
    "ctrl+Q": Quit(),
}
LOOK_BUTTON = "right"  # hold to look around (fly) …
ORBIT_BUTTON = "left"  # … or drag to orbit in orbit mode
CLICK_PIXELS = 4.0  # a left press and release closer than this is a click, not a drag


@dataclass
class Input:
    keymap: dict[str, Command] = field(default_factory=lambda: dict(VIEWER_KEYS))
    held: set[str] = field(default_factory=set)
    pressed: list[str] = field(default_factory=list)  # key presses since the last frame
    buttons: set[str] = field(default_factory=set)
    cursor: tuple[float, float] = (0.0, 0.0)
    drag: tuple[float, float] = (0.0, 0.0)  # cursor motion while a button is held
    scroll: float = 0.0
    press: tuple[float, float] | None = None  # where the left button went down
    click: tuple[float, float] | None = None  # the last left click not yet taken
    claimed: bool = False  # a press now is not the camera's (a gizmo is being dragged)
    look_hides_cursor: bool = True  # flying: the look button captures the cursor
    # The editor: a left press may be a gizmo's, which only the next frame tells (judged);
    # the motion since such a press waits for it, so the camera never moves by a gizmo's.
    judged_by_frame: bool = False
    unjudged: tuple[float, float] | None = None  # that motion, until the frame
    # such a press dragged past a click and let go before any frame saw it: (press, release)
    flick: tuple[tuple[float, float], tuple[float, float]] | None = None

    def key(self, name: str, down: bool) -> None:
        """A key named as in MOVES and the keymap went down or up (others are ignored)."""
        if name not in MOVES and name not in self.keymap:
            return
        if down:
            if name not in self.held:
                self.pressed.append(name)
            self.held.add(name)
        else:
            self.held.discard(name)

    def chord(self, name: str) -> None:
        """A Ctrl+key press, named "ctrl+KEY" or "ctrl+shift+KEY"."""
        if name in self.keymap:
            self.pressed.append(name)

    def button(self, name: str, down: bool) -> None:
        (self.buttons.add if down else self.buttons.discard)(name)
        if name != "left":
            return
        if down:
            self.press = self.cursor
            if self.judged_by_frame:
                self.unjudged = (0.0, 0.0)
        elif self.press is not None:
            moved = math.dist(self.cursor, self.press)
            if moved <= CLICK_PIXELS:
                self.click = self.cursor
            elif self.unjudged is not None:
                self.flick = (self.press, self.cursor)
            self.press = None

    def let_go(self, name: str) -> None:
        """The press of button ``name`` was not the view's after all (a frame that saw the
        pointer there found a gizmo under it): no drag and no click from it."""
        self.buttons.discard(name)
        if name == "left":
            self.press, self.unjudged = None, None

    def judged(self) -> None:
        """A frame has seen the last left press (``judged_by_frame``): what the view still
        holds of it is the view's, with the motion held since."""
        if self.unjudged is not None:
            self.drag = (self.drag[0] + self.unjudged[0], self.drag[1] + self.unjudged[1])
            self.unjudged = None

    def move_cursor(self, x: float, y: float) -> None:
        if self.buttons:
            d = (x - self.cursor[0], y - self.cursor[1])
            if self.unjudged is not None:
                self.unjudged = (self.unjudged[0] + d[0], self.unjudged[1] + d[1])
            else:
                self.drag = (self.drag[0] + d[0], self.drag[1] + d[1])
        self.cursor = (x, y)

    def wheel(self, dy: float) -> None:
        self.scroll += dy

    def commands(self) -> list[Command]:
        """The commands of the keys pressed since the last call."""
        out = [self.keymap[k] for k in self.pressed if k in self.keymap]
        self.pressed.clear()
        return out

    def movement(self) -> tuple[float, float, float]:
        v = [0.0, 0.0, 0.0]
        for key, d in MOVES.items():
            if key in self.held:
                v = [a + b for a, b in zip(v, d)]
        return (v[0], v[1], v[2])

    def take_drag(self) -> tuple[float, float]:
        d, self.drag = self.drag, (0.0, 0.0)
        return d

    def take_scroll(self) -> float:
        s, self.scroll = self.scroll, 0.0
        return s

    def take_click(self) -> tuple[float, float] | None:
        c, self.click = self.click, None
        return c

    def take_flick(self) -> tuple[tuple[float, float], tuple[float, float]] | None:
        f, self.flick = self.flick, None
        return f
