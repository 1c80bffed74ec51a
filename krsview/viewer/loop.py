"""The event loop of a window (the viewer's, the editor's): wait for events while the image is
final, poll while it is being traced or the camera moves."""

from __future__ import annotations

import time
from typing import Protocol

import glfw  # noqa: E402  (after imgui: the windows import it first)

IDLE_WAIT = 0.05  # seconds an idle window sleeps between checks of the watched files


class Runnable(Protocol):
    def should_close(self) -> bool: ...
    def is_idle(self) -> bool: ...
    def step(self, dt: float) -> None: ...
    def close(self) -> None: ...


def run(app: Runnable) -> None:
    """Turn the loop until the window is closed; close it on the way out, error or not."""
    last = time.perf_counter()
    try:
        while not app.should_close():
            if app.is_idle():
                glfw.wait_events_timeout(IDLE_WAIT)
            else:
                glfw.poll_events()
            now = time.perf_counter()
            app.step(now - last)
            last = now
    finally:
        app.close()
