"""Controls as data (action ↦ key, the pygfx habit) and one input layer fed by GLFW callbacks
or by tests with synthetic events."""

from __future__ import annotations

from dataclasses import dataclass, field

# Held keys move the camera; pressed keys trigger an action once.
CONTROLS: dict[str, str] = {
    "forward": "W",
    "back": "S",
    "left": "A",
    "right": "D",
    "down": "Q",
    "up": "E",
    "reset": "R",
    "orbit": "O",
    "screenshot": "F12",
    "hud": "F1",
    "bookmark": "B",
    "next_bookmark": "N",
    "record": "F5",
    "replay": "F6",
}
MOVES = {
    "forward": (0, 0, 1),
    "back": (0, 0, -1),
    "left": (-1, 0, 0),
    "right": (1, 0, 0),
    "down": (0, -1, 0),
    "up": (0, 1, 0),
}
LOOK_BUTTON = "right"  # hold to look around (fly) …
ORBIT_BUTTON = "left"  # … or drag to orbit in orbit mode


@dataclass
class Input:
    held: set[str] = field(default_factory=set)
    pressed: list[str] = field(default_factory=list)  # key presses since the last frame
    buttons: set[str] = field(default_factory=set)
    cursor: tuple[float, float] = (0.0, 0.0)
    drag: tuple[float, float] = (0.0, 0.0)  # cursor motion while a button is held
    scroll: float = 0.0

    def key(self, name: str, down: bool) -> None:
        if down:
            if name not in self.held:
                self.pressed.append(name)
            self.held.add(name)
        else:
            self.held.discard(name)

    def button(self, name: str, down: bool) -> None:
        (self.buttons.add if down else self.buttons.discard)(name)

    def move_cursor(self, x: float, y: float) -> None:
        if self.buttons:
            self.drag = (self.drag[0] + x - self.cursor[0], self.drag[1] + y - self.cursor[1])
        self.cursor = (x, y)

    def wheel(self, dy: float) -> None:
        self.scroll += dy

    def actions(self) -> list[str]:
        """Actions pressed since the last call."""
        by_key = {k: a for a, k in CONTROLS.items()}
        out = [by_key[k] for k in self.pressed if k in by_key]
        self.pressed.clear()
        return out

    def movement(self) -> tuple[float, float, float]:
        v = [0.0, 0.0, 0.0]
        for action, d in MOVES.items():
            if CONTROLS[action] in self.held:
                v = [a + b for a, b in zip(v, d)]
        return (v[0], v[1], v[2])

    def take_drag(self) -> tuple[float, float]:
        d, self.drag = self.drag, (0.0, 0.0)
        return d

    def take_scroll(self) -> float:
        s, self.scroll = self.scroll, 0.0
        return s
