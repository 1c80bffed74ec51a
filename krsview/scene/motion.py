"""Where a scene's keyframe tracks may break a rule between their keys, checked before the
work (`krsview check`, :func:`krsview.check`): the moments posed, and the vector tracks that
pass through what they must keep away from. The tracks themselves: animation.py."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from .animation import MAX_TIME, Track, field_meta, pose
from .edits import parse_path


def moments(scene: Any) -> list[float]:
    """The times at which `krsview check` poses a scene with tracks: the loop's ends, every
    key and the middle of every pair of keys (where two keys symmetric about a forbidden
    value, a direction and its opposite, meet it exactly). Numbers between two valid keys
    stay valid: a field's range is an interval, and a track's value between two keys stays
    between theirs (linear, or smooth with its limited tangents, ``Track._tangent``), also
    per component; the sway is checked over a period at load."""
    a = scene.animation
    if a is None or not a.tracks:
        return []
    out = {0.0, float(a.duration)}
    for tr in a.tracks:
        times = [k.time for k in tr.keys]
        out.update(times)
        out.update((p + q) / 2 for p, q in zip(times, times[1:]))
    return sorted(t for t in out if t <= MAX_TIME)


NEAR_MISS = 1e-6  # of the keys' own distance from it: a vector track that flips there


def near_misses(scene: Any) -> list[str]:
    """Warnings for vector tracks that pass almost through what they must keep away from
    (the camera's target for its position and back; a direction's zero vector): valid at
    every time but one, they flip the view or the direction in an instant there."""
    a = scene.animation
    out: list[str] = []
    for k, tr in enumerate(a.tracks if a is not None else ()):
        if not isinstance(tr.keys[0].value, tuple):
            continue
        path = parse_path(tr.path)
        other = {("camera", "position"): "target", ("camera", "target"): "position"}.get(path)
        if other is None and not field_meta(scene, path).get("unit_vector"):
            continue  # a point or a colour may pass through zero: only a direction flips
        away = np.array(getattr(scene.camera, other)) if other else np.zeros(len(tr.keys[0].value))
        scale = max(float(np.linalg.norm(np.subtract(key.value, away))) for key in tr.keys)
        times = [key.time for key in tr.keys]
        for p, q in zip(times, times[1:]):
            t, gap = _nearest_time(tr, p, q, away)
            if gap < NEAR_MISS * scale:
                what = f"the camera's {other}" if other else "the zero vector"
                out.append(
                    f"animation.tracks[{k}]: {tr.path} passes through {what} at t ≈ {t:.4g} s "
                    "and flips there"
                )
    return out


def _nearest_time(tr: Track, p: float, q: float, away: np.ndarray) -> tuple[float, float]:
    """The time in [p, q] where the track's value (not re-normalised) is nearest ``away``,
    and that distance: the least of 33 samples, refined by golden sections between its
    neighbours."""

    def gap(t: float) -> float:
        return float(np.linalg.norm(np.subtract(tr.value_at(t, False, False), away)))

    ts = np.linspace(p, q, 33)
    k = int(np.argmin([gap(t) for t in ts]))
    lo, hi = ts[max(k - 1, 0)], ts[min(k + 1, 32)]
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        lo, hi = (lo, b) if gap(a) < gap(b) else (a, hi)
    t = float((lo + hi) / 2)
    return t, gap(t)


def check_motion(scene: Any, times: list[float] | None = None) -> int:
    """Pose ``scene`` at each of ``times`` (default: :func:`moments`); a value that breaks
    its field's rule there is the one-line error :func:`pose` raises, naming the track and
    the time. Returns how many moments were posed."""
    times = moments(scene) if times is None else times
    for t in times:
        pose(replace(scene, animation=replace(scene.animation, time=t)))
    return len(times)
