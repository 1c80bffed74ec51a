"""Time in a scene (issue 29): the ``[animation]`` table. ``time`` is the moment drawn, in
seconds; everything that moves reads it from the scene, so a frame at time t is the scene
``scene.at(t)`` and every renderer, the NumPy reference and the exports take time the way they
take any other scene value. A scene without the table is drawn at time 0 and nothing moves.

Keyframe tracks (``[[animation.tracks]]``) move any value an edit can change: each is a
path, as ``Scene.edit`` takes it, and keys [time, value]. :func:`pose` evaluates them at the
scene's time, writes them by the edits' rule (replace, then validate) and turns the sway's
mirrors (``sway.py``): the static scene drawn at that moment. A track on a route's fork (or
its trunk's foot) moves its subtree with it, as a bone does (:func:`bone_offsets`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, is_dataclass, replace
from typing import Any, NamedTuple

import numpy as np

from ..messages import SceneError
from .edits import get_at, holds, parse_path, replace_at, revalidated
from .effects import EFFECTS
from .route import Route
from .schema import param, to_dict
from .sway import Sway, check_sway, swayed

MAX_TIME = 1e6  # seconds (11.5 days): float32 keeps the time uniform to 0.06 s there
MAX_KEYS = 256  # keys in one track (a key a frame for 10 s at 25 fps)
MAX_TRACKS = 64
DEFAULT_DURATION = 10.0  # seconds: the loop of a scene without tracks
INTERPOLATIONS = ("linear", "smooth")


def reads_time(effects: list[str]) -> bool:
    """Whether one of ``effects`` reads the scene's time in the shaders (the wind): the scene
    moves though nothing is keyed."""
    return any(EFFECTS[e].reads_time for e in effects if e in EFFECTS)


def check_time(t: object, path: str = "time") -> float:
    """``t`` as a time in seconds (a NumPy number too, taken as the decimal it shows), or a
    one-line error saying what is allowed."""
    if isinstance(t, np.floating):
        t = float(str(t))  # np.float32(0.6) is 0.6, not 0.6000000238418579
    elif isinstance(t, np.integer):
        t = int(t)
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not 0.0 <= t <= MAX_TIME:
        raise SceneError(path, t, f"a time in seconds; allowed 0..{MAX_TIME:g}")
    return float(t)


def _is_number(x: object) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _kind(value: object) -> str:
    """What a key's value is, for checking that a track's keys agree."""
    if isinstance(value, tuple):
        return f"a list of {len(value)} numbers"
    return "a number" if _is_number(value) else type(value).__name__


class Key(NamedTuple):
    """One key of a track, ``[time, value]`` in the file; a list of numbers is held as a tuple."""

    time: float
    value: Any

    @classmethod
    def from_toml(cls, data: Any, path: str) -> Key:
        if not isinstance(data, list) or len(data) != 2:
            raise SceneError(path, data, "a key is [time, value], e.g. [2.0, 0.5]")
        t, v = check_time(data[0], f"{path}[0]"), data[1]
        if isinstance(v, list) and v and len(v) <= 16 and all(map(_is_number, v)):
            return cls(t, tuple(float(c) for c in v))
        if not isinstance(v, (int, float, bool, str)) or (_is_number(v) and not math.isfinite(v)):
            raise SceneError(
                f"{path}[1]",
                v,
                "a key's value is a number, true/false, a string or a list of up to 16 numbers",
            )
        return cls(t, v)

    def to_toml(self) -> list:
        return [self.time, list(self.value) if isinstance(self.value, tuple) else self.value]


@dataclass(frozen=True)
class Track:
    """Keys for one scene value: numbers and vectors interpolate (per component; a unit
    vector is re-normalised, nlerp), whole numbers, true/false and strings step (the
    value of the last key reached). Before the first key the first value holds, after the
    last key the last."""

    path: str = param(
        "", help="the value moved, as an edit names it: route.levels[3].fork, camera.position…"
    )
    keys: list[Key] = param([], help="[time, value] pairs, times ascending")
    interpolation: str = param(
        "smooth",
        choices=INTERPOLATIONS,
        help="linear, or smooth: C¹ (Catmull–Rom tangents inside, limited so that a value never "
        "leaves the range of the two keys around it; easing in and out at the ends)",
    )

    def validate(self, path: str) -> None:
        if not 1 <= len(self.keys) <= MAX_KEYS:
            raise SceneError(
                f"{path}.keys", f"<{len(self.keys)} keys>", f"allowed: 1..{MAX_KEYS} keys"
            )
        first = self.keys[0]
        for j, (a, b) in enumerate(zip(self.keys, self.keys[1:]), 1):
            if b.time <= a.time:
                raise SceneError(
                    f"{path}.keys[{j}]",
                    b.to_toml(),
                    f"times must ascend (keys[{j - 1}] is at {a.time:g} s)",
                )
            if _kind(b.value) != _kind(first.value):
                raise SceneError(
                    f"{path}.keys[{j}]",
                    b.to_toml(),
                    f"every key of a track holds the same kind of value: this one holds "
                    f"{_kind(b.value)}, keys[0] = {first.to_toml()!r} holds {_kind(first.value)}",
                )

    def value_at(self, t: float, steps: bool, unit: bool) -> Any:
        """The track's value at time ``t``; ``steps``: hold each key's value (whole numbers,
        strings), ``unit``: re-normalise an interpolated vector (a normal, a direction)."""
        times = [k.time for k in self.keys]
        j = int(np.searchsorted(times, t, side="right")) - 1
        if j < 0:
            return self.keys[0].value
        if steps or j >= len(times) - 1:
            return self.keys[j].value
        v = [np.asarray(k.value, dtype=float) for k in self.keys]
        h = times[j + 1] - times[j]
        s = (t - times[j]) / h
        if self.interpolation == "linear":
            out = v[j] + s * (v[j + 1] - v[j])
        else:  # cubic Hermite, tangents from the neighbouring keys (limited), zero at the ends
            m0, m1 = (self._tangent(times, v, i) * h for i in (j, j + 1))
            out = (
                (2 * s**3 - 3 * s**2 + 1) * v[j]
                + (s**3 - 2 * s**2 + s) * m0
                + (-2 * s**3 + 3 * s**2) * v[j + 1]
                + (s**3 - s**2) * m1
            )
        if out.ndim == 0:
            return float(out)
        n = float(np.linalg.norm(out))
        return [float(c) for c in (out / n if unit and n > 0 else out)]

    @staticmethod
    def _tangent(times: list[float], v: list[np.ndarray], i: int) -> np.ndarray:
        """The slope at key i (per component): Catmull–Rom's, limited so that the curve
        between two keys stays between their values. Zero at a key that is a peak or a
        trough, and at most 3× the slope of either segment beside it, which keeps each
        segment's cubic monotone [de Boor and Swartz; Fritsch and Carlson 1980]; zero at
        the first and last key (easing in and out). Unlimited, keys 40, 0, 88 of an angle
        allowed 0..89 dipped to −0.008 between the first two, a pose no check foresaw."""
        if i == 0 or i == len(times) - 1:
            return np.zeros_like(v[i])
        before = (v[i] - v[i - 1]) / (times[i] - times[i - 1])
        after = (v[i + 1] - v[i]) / (times[i + 1] - times[i])
        slope = (v[i + 1] - v[i - 1]) / (times[i + 1] - times[i - 1])
        limit = 3.0 * np.minimum(np.abs(before), np.abs(after))
        return np.where(before * after > 0.0, np.clip(slope, -limit, limit), 0.0)


@dataclass(frozen=True)
class Animation:
    time: float = param(
        0.0, lo=0.0, hi=MAX_TIME, unit="seconds", help="the moment drawn (the viewer's time)"
    )
    duration: float | None = param(
        None,
        lo=0.0,
        lo_open=True,
        hi=MAX_TIME,
        unit="seconds",
        help="length of one playback loop (the viewer's time slider, videos); none: up to "
        f"the last key of the tracks, else {DEFAULT_DURATION:g} s",
    )
    tracks: list[Track] = param(
        [], help=f"keyframe tracks, each moving one scene value (at most {MAX_TRACKS})"
    )
    sway: Sway | None = param(None, help="the coarsest mirrors of a tree turning back and forth")

    def __post_init__(self) -> None:
        if self.duration is None:  # a float for every reader, once built
            object.__setattr__(self, "duration", self._loop())

    def _loop(self) -> float:
        """The loop without a duration given: up to the last key, else DEFAULT_DURATION."""
        return max((tr.keys[-1].time for tr in self.tracks if tr.keys), default=0.0) or (
            DEFAULT_DURATION
        )

    def to_toml(self) -> dict:
        """The table as a file holds it; a duration that is the default loop is left out,
        so that it keeps following the keys."""
        out = {f.name: to_dict(getattr(self, f.name)) for f in fields(self)}
        if self.duration == self._loop():
            del out["duration"]
        return {k: v for k, v in out.items() if v is not None}

    def validate(self, path: str) -> None:
        if len(self.tracks) > MAX_TRACKS:
            raise SceneError(
                f"{path}.tracks", f"<{len(self.tracks)} tracks>", f"allowed: at most {MAX_TRACKS}"
            )

    @property
    def moves(self) -> bool:
        """Whether tracks or sway move the scene (what :func:`pose` has to do)."""
        return bool(self.tracks) or self.sway is not None


def field_meta(obj: Any, path: tuple) -> dict:
    """The schema metadata of the field a path ends at ({} for an item of a list/vector)."""
    meta: dict = {}
    for key in path:
        if isinstance(key, int):
            obj, meta = obj[key], {}
        else:
            meta = next(dict(f.metadata) for f in fields(obj) if f.name == key)
            obj = getattr(obj, key)
    return meta


def _steps(rest: Any, path: tuple, track: Track) -> bool:
    """Whether a track steps: its values are strings or true/false, or the field holds a
    whole number (a tree's levels), which has no value between two keys."""
    here = get_at(rest, path)
    value = track.keys[0].value
    return isinstance(value, (str, bool)) or (isinstance(here, int) and not isinstance(here, bool))


def _sway_route(scene: Any, path: str):
    """The route the sway turns: the scene's [route], or its [tree] baked into one."""
    if scene.route is not None:
        return scene.route
    if scene.tree is not None:
        return scene.tree.route()
    raise SceneError(
        path, "<sway>", "sway turns the fork mirrors of a tree: it needs a [tree] or [route] scene"
    )


def check_animation(scene: Any, under: str = "") -> None:
    """Load-time rules that need the scene: each track's path exists and every key is a
    valid value there (by ``Scene.edit``, so the error names the key and the field's
    rule), and the sway crosses no branch over a period. ``under``: a top-level table, the
    only one changed since the scene was checked: only the tracks into it."""
    a = scene.animation
    rest = replace(scene, animation=None)
    for k, tr in enumerate(a.tracks):
        where = f"animation.tracks[{k}]"
        try:
            path = parse_path(tr.path)
        except SceneError as e:
            raise SceneError(f"{where}.path", tr.path, e.allowed) from None
        if under and path[0] != under:
            continue
        if path[:1] == ("animation",):
            raise SceneError(
                f"{where}.path",
                tr.path,
                "time itself has no track; allowed: any other value an edit can change",
            )
        if not holds(rest, path):
            raise SceneError(f"{where}.path", tr.path, "no such value in this scene")
        here = get_at(rest, path)
        if is_dataclass(here) or isinstance(here, list):
            raise SceneError(
                f"{where}.path",
                tr.path,
                "a track moves one value (a number, a "
                "vector, a string), not a table or a list of tables",
            )
        for j, key in enumerate(tr.keys):
            try:
                rest.edit(path, key.value)
            except SceneError as e:
                raise SceneError(
                    f"{where}.keys[{j}]", key.to_toml(), f"{e.path}: {e.allowed}"
                ) from None
    if a.sway is not None and not under:  # the sway turns the geometry alone
        check_sway(_sway_route(rest, "animation.sway"), a.sway, "animation.sway")


def _track_values(scene: Any) -> tuple[Any, list[tuple[tuple, Any]]]:
    """The scene without tracks or sway (its rest values), and each track's path and value
    at the scene's time."""
    a = scene.animation
    rest = replace(scene, animation=replace(a, tracks=[], sway=None))
    values = []
    for tr in a.tracks:
        path = parse_path(tr.path)
        unit = bool(field_meta(rest, path).get("unit_vector"))
        values.append((path, tr.value_at(a.time, _steps(rest, path, tr), unit)))
    return rest, values


def bone_offsets(rest: Any, values: list[tuple[tuple, Any]]) -> dict[tuple, np.ndarray]:
    """Keyed forks pose their subtrees, as bones do (and as a fork drag carries them,
    editor/handles.py): a track putting fork i at d from its rest value moves the finer
    levels' forks and control points by d too, and level i's own control point by d/2 (its
    bend stays); a track on the trunk's foot moves every level. The offsets of nested keyed
    forks add up, so a finer fork's keys hold its value as if the coarser forks were at rest.
    Per route path: an array (levels, 2, 3), each level's fork and control offsets."""
    out: dict[tuple, np.ndarray] = {}
    for path, value in values:
        if path[-1:] == ("base",):
            at, i = path[:-1], None
        elif len(path) >= 3 and path[-1] == "fork" and path[-3] == "levels":
            at, i = path[:-3], path[-2]
        else:
            continue
        route = get_at(rest, at)
        if not isinstance(route, Route):
            continue
        off = out.setdefault(at, np.zeros((len(route.levels), 2, 3)))
        if i is None:
            off += np.subtract(value, route.base)
        else:
            d = np.subtract(value, route.levels[i].fork)
            off[:i] += d
            off[i, 1] += d / 2
    return out


def bone_offset(scene: Any, path: tuple) -> np.ndarray | None:
    """What :func:`pose` adds to the route fork or control point at ``path`` for the keyed
    forks above it at the scene's time (None: nothing), so that a value drawn there can be
    keyed as the track holds it."""
    a = scene.animation
    if a is None or not a.tracks or len(path) < 3 or path[-1] not in ("fork", "control"):
        return None
    off = bone_offsets(*_track_values(scene)).get(path[:-3])
    return None if off is None else off[path[-2], int(path[-1] == "control")]


def _posed_bones(out: Any, offsets: dict[tuple, np.ndarray]) -> Any:
    """``out`` with each route's levels moved by its bone offsets."""
    for at, off in offsets.items():
        levels = [
            replace(
                lv,
                fork=tuple(float(c) for c in np.add(lv.fork, o[0])),
                control=tuple(float(c) for c in np.add(lv.control, o[1])),
            )
            for lv, o in zip(get_at(out, at).levels, off)
        ]
        out = replace_at(out, (*at, "levels"), levels)
    return out


def pose(scene: Any) -> Any:
    """The static scene drawn at ``scene.time``: every track's value there written by the
    edits' rule, the keyed forks' subtrees moved with them (:func:`bone_offsets`), then the
    sway's mirrors turned; without tracks or sway, time kept. A value between keys that
    breaks its field's rule is a one-line error naming the track and time."""
    a = scene.animation
    t = a.time
    rest, values = _track_values(scene)
    offsets = bone_offsets(rest, values)
    out = rest
    for path, value in values:
        out = replace_at(out, path, value)
    try:
        out = _posed_bones(out, offsets)
        out = revalidated(out, [path for path, _ in values] + [(*at, "levels") for at in offsets])
    except SceneError:
        out = rest
        for k, (path, value) in enumerate(values):  # which track broke it: edit one by one
            try:
                out = out.edit(path, value)
            except SceneError as e:
                raise SceneError(
                    f"animation.tracks[{k}] at t = {t:g} s",
                    value,
                    f"between its keys: {e.path}: {e.allowed}",
                ) from None
        raise
    if a.sway is not None:
        route = swayed(_sway_route(out, "animation.sway"), a.sway, t, "animation.sway")
        out = replace(out, tree=None, route=route)
    return out
