"""Camera paths: the poses the viewer records (F5) and replays (F6), saved beside the preset
as ``NAME.path.json``, and what ``krsview render --camera-path`` and ``krsview batch`` turn
into frames. A pose is a time, an eye position and the fly camera's yaw and pitch; between
poses the camera moves linearly, so frame k of a path at F frames per second is one camera,
whoever renders it."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..algebra.vectors import cross
from ..messages import SceneError
from .animation import MAX_TIME
from .render import Camera
from .schema import COORDINATE_LIMIT

POSE_KEYS = ("t", "position", "yaw", "pitch")
FORMAT = '{"poses": [{"t": seconds, "position": [x, y, z], "yaw": radians, "pitch": radians}, …]}'


@dataclass(frozen=True)
class Pose:
    t: float  # seconds since the recording began
    position: tuple[float, float, float]
    yaw: float  # radians around the world up axis
    pitch: float  # radians above the horizon


def horizontal_axes(up: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit axes ⟂ up; yaw 0 looks along ``north`` (+z for a y-up world)."""
    ref = np.array([0.0, 0.0, 1.0]) if abs(up[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    north = ref - (ref @ up) * up
    north /= np.linalg.norm(north)
    east = cross(up, north)
    return east, north


def look_direction(yaw: float, pitch: float, up: np.ndarray) -> np.ndarray:
    """The unit view direction of a fly camera with world axis ``up``."""
    east, north = horizontal_axes(up)
    cp = math.cos(pitch)
    return cp * math.sin(yaw) * east + cp * math.cos(yaw) * north + math.sin(pitch) * up


@dataclass(frozen=True)
class CameraPath:
    poses: tuple[Pose, ...]  # at least one, times non-decreasing

    @property
    def duration(self) -> float:
        return self.poses[-1].t - self.poses[0].t

    def frame_count(self, fps: float) -> int:
        """Frames 0 … count−1 cover the path, frame k at k / fps seconds from its start."""
        return int(math.floor(self.duration * fps + 1e-9)) + 1

    def pose_at(self, t: float) -> Pose:
        """The pose ``t`` seconds after the start, interpolated linearly (yaw the short way
        round); clamped to the ends."""
        times = [p.t - self.poses[0].t for p in self.poses]
        k = int(np.searchsorted(times, t, side="right"))
        if k == 0:
            return self.poses[0]
        if k >= len(times):
            return self.poses[-1]
        a, b = self.poses[k - 1], self.poses[k]
        span = times[k] - times[k - 1]
        s = 0.0 if span <= 0 else (t - times[k - 1]) / span
        turn = math.remainder(b.yaw - a.yaw, 2 * math.pi)
        pos = tuple(float(x + s * (y - x)) for x, y in zip(a.position, b.position))
        return Pose(a.t + s * span, pos, a.yaw + s * turn, a.pitch + s * (b.pitch - a.pitch))

    def camera(self, frame: int, fps: float, base: Camera) -> Camera:
        """The camera of ``frame``: ``base``'s up axis and field of view, the path's pose."""
        pose = self.pose_at(frame / fps)
        up = np.array(base.up, dtype=np.float64)
        eye = np.array(pose.position, dtype=np.float64)
        target = eye + look_direction(pose.yaw, pose.pitch, up)
        return Camera(pose.position, tuple(float(c) for c in target), base.up, base.fov_y)


class _DuplicateKey(ValueError):
    def __init__(self, key: str):
        super().__init__(key)
        self.key = key


def _refuse_duplicates(pairs: list[tuple[str, object]]) -> dict:
    """A JSON object whose key appears twice (JSON keeps the last silently; TOML refuses)."""
    out: dict = {}
    for key, value in pairs:
        if key in out:
            raise _DuplicateKey(key)
        out[key] = value
    return out


def _number(v: object) -> float:
    """A JSON number; ``float`` alone would take true as 1 and "1.5" as 1.5."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise TypeError(f"{v!r} is not a number")
    return float(v)


def load_camera_path(path: str | Path) -> CameraPath:
    """Read a path file; a damaged one is a SceneError naming the file, the pose and field."""
    f = Path(path)
    try:
        data = json.loads(f.read_text(encoding="utf-8"), object_pairs_hook=_refuse_duplicates)
    except _DuplicateKey as e:
        raise SceneError(
            "<file>",
            f"key {e.key!r} given twice in one object",
            "each key at most once (which one counts would be a guess)",
            str(f),
        ) from None
    except OSError as e:
        raise SceneError("<file>", str(f), f"cannot read: {e.strerror}", str(f)) from None
    except json.JSONDecodeError as e:
        raise SceneError(
            "<file>",
            f"line {e.lineno} column {e.colno}",
            f"not JSON ({e.msg}); expected {FORMAT}",
            str(f),
        ) from None
    except UnicodeDecodeError as e:
        raise SceneError(
            "<file>",
            f"byte 0x{e.object[e.start]:02x} at offset {e.start}",
            "not UTF-8 text",
            str(f),
        ) from None
    if not isinstance(data, dict):
        kind = {list: "a JSON array", str: "a JSON string"}.get(type(data), "a single value")
        raise SceneError("<file>", kind, f"an object; expected {FORMAT}", str(f))
    poses = data.get("poses")
    if not isinstance(poses, list) or not poses:
        raise SceneError("poses", poses, f"a non-empty list; expected {FORMAT}", str(f))
    out = []
    for i, p in enumerate(poses):
        if not isinstance(p, dict):
            raise SceneError(f"poses[{i}]", p, f"an object with {', '.join(POSE_KEYS)}", str(f))
        unknown = sorted(set(p) - set(POSE_KEYS))
        if unknown:
            raise SceneError(
                f"poses[{i}].{unknown[0]}",
                p[unknown[0]],
                f"unknown key; a pose has {', '.join(POSE_KEYS)}",
                str(f),
            )
        try:
            pose = Pose(
                _number(p["t"]),
                tuple(_number(c) for c in p["position"]),
                _number(p["yaw"]),
                _number(p["pitch"]),
            )
        except (KeyError, TypeError, ValueError) as e:
            why = f"{e} is missing" if isinstance(e, KeyError) else str(e)
            raise SceneError(
                f"poses[{i}]",
                p,
                f"needs t, position [x, y, z], yaw and pitch as numbers ({why})",
                str(f),
            ) from None
        values = (pose.t, *pose.position, pose.yaw, pose.pitch)
        if len(pose.position) != 3 or not all(math.isfinite(v) for v in values):
            raise SceneError(f"poses[{i}]", p, "finite numbers and a 3-vector position", str(f))
        if not all(abs(c) <= COORDINATE_LIMIT for c in pose.position):
            raise SceneError(
                f"poses[{i}].position",
                list(pose.position),
                f"allowed ±{COORDINATE_LIMIT:g}",
                str(f),
            )
        if pose.t - (out[0].t if out else pose.t) > MAX_TIME or abs(pose.t) > MAX_TIME:
            raise SceneError(
                f"poses[{i}].t", pose.t, f"a path lasts at most {MAX_TIME:g} s", str(f)
            )
        if out and pose.t < out[-1].t:
            raise SceneError(
                f"poses[{i}].t",
                pose.t,
                f"times must not decrease (the pose before is at {out[-1].t})",
                str(f),
            )
        if abs(pose.pitch) >= math.pi / 2:
            raise SceneError(f"poses[{i}].pitch", pose.pitch, "allowed −π/2 < pitch < π/2", str(f))
        out.append(pose)
    return CameraPath(tuple(out))


def camera_path_json(poses: list[Pose]) -> str:
    """The file text of a path (written atomically by the caller)."""
    return json.dumps(
        {
            "poses": [
                dict(t=p.t, position=list(p.position), yaw=p.yaw, pitch=p.pitch) for p in poses
            ]
        },
        indent=1,
    )
