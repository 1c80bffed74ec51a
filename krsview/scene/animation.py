"""Time in a scene (issue 29): the ``[animation]`` table. ``time`` is the moment drawn, in
seconds; everything that moves reads it from the scene, so a frame at time t is the scene
``scene.at(t)`` and every renderer, the NumPy reference and the exports take time the way they
take any other scene value. A scene without the table is drawn at time 0 and nothing moves."""

from __future__ import annotations

from dataclasses import dataclass

from .schema import SceneError, param

MAX_TIME = 1e6  # seconds (11.5 days): float32 keeps the time uniform to 0.06 s there


@dataclass(frozen=True)
class Animation:
    time: float = param(
        0.0, lo=0.0, hi=MAX_TIME, unit="seconds", help="the moment drawn (the viewer's time)"
    )
    duration: float = param(
        10.0,
        lo=0.0,
        lo_open=True,
        hi=MAX_TIME,
        unit="seconds",
        help="length of one playback loop (the viewer's time slider, videos)",
    )


def check_time(t: object, path: str = "time") -> float:
    """``t`` as a time in seconds, or a one-line error saying what is allowed."""
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0.0 <= t <= MAX_TIME:
        raise SceneError(path, t, f"a time in seconds; allowed 0..{MAX_TIME:g}")
    return float(t)
