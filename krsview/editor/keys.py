"""Keyframes in the editor (issue 29): K sets a key for the selected value at the moment shown;
a drag of a value that has a track sets its key there (auto-key: the track would override the
rest value). A keyed fork's subtree follows it as bones do (scene/animation.py's
``bone_offsets``), so a key holds the value less what the keyed forks above it add. The
timeline strip at the foot of the view plays, scrubs, and shows the selection's keys, which
drag along it in time (right-click deletes one). Each change is one edit of the scene's
``[animation]`` table: validated, undoable, saved."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import replace
from typing import Any, Protocol

import numpy as np
from imgui_bundle import imgui

from ..messages import counted
from ..scene import Scene, SceneError
from ..scene.animation import Animation, Key, Track, bone_offset
from ..scene.edits import Path, apply_edit, get_at, holds, parse_path, path_text, replace_at
from ..scene.mokrs import linked_edit, linked_levels
from ..viewer import commands as vc
from ..viewer.playback import Playback
from ..viewer.window import Viewer
from . import commands as ec
from .handles import Handle

KEY_SNAP = 1e-3  # seconds: a key set this close to one already there replaces it
KEY_GAP = 1e-3  # seconds kept between neighbouring keys when one is dragged in time
KEY_DIGITS = 3  # a key's time is kept to the millisecond: 1.7, not 1.7000000000000006
STRIP_DIGITS = 2  # the strip's times go by hundredths of a second (a click at "2.00 s")
STRIP_HEIGHT = 64.0  # pixels: the timeline strip at the window's foot
STRIP_ROOM = STRIP_HEIGHT + 8.0  # pixels of the foot it keeps, the gap under it with it
DIAMOND = 6.0  # pixels: a key's half size on the strip
MARK_ROOM = 2 * DIAMOND + 4.0  # pixels kept right of each field's label for its diamond
KEY, KEY_HOT = 0xFF40C0FF, 0xFF40FFFF  # ImGui's packed ABGR: a key, the key under the pointer
# A field a track moves, as Blender marks it: yellow with a key at the moment shown, green
# between keys (its frame, and a diamond beside it: filled on a key, hollow between).
ON_KEY, BETWEEN = imgui.ImVec4(0.55, 0.48, 0.08, 1.0), imgui.ImVec4(0.18, 0.42, 0.18, 1.0)
MARK_ON_KEY, MARK_BETWEEN = 0xFF30D8F0, 0xFF50C050  # the diamond, ImGui's packed ABGR


def track_index(scene: Scene, path: tuple) -> int | None:
    """Which of the scene's tracks moves the value at ``path`` (None: none)."""
    if scene.animation is None:
        return None
    text = path_text(path)
    return next((i for i, tr in enumerate(scene.animation.tracks) if tr.path == text), None)


def with_key(scene: Scene, path: tuple, t: float, value: Any) -> Animation:
    """The scene's animation with the key (t, value) in the track of ``path`` (a new track if
    it has none; a key within KEY_SNAP of t is replaced). The loop grows to reach the key."""
    a, t = scene.animation or Animation(), round(t, KEY_DIGITS)
    value = tuple(value) if isinstance(value, (list, tuple)) else value
    tracks = list(a.tracks)
    i = track_index(scene, path)
    if i is None:
        tracks.append(Track(path_text(path), [Key(t, value)]))
    else:
        keys = [k for k in tracks[i].keys if abs(k.time - t) > KEY_SNAP] + [Key(t, value)]
        tracks[i] = replace(tracks[i], keys=sorted(keys, key=lambda k: k.time))
    return replace(a, tracks=tracks, duration=max(a.duration, t))


def held(scene: Scene, path: tuple, value: Any, t: float) -> Any:
    """A value drawn at ``path`` at ``t`` as a key holds it: less what the keyed forks above
    it add there (a route's fork or control point; any other value as it is)."""
    off = bone_offset(scene.at(t), path)
    return value if off is None else tuple(float(c) for c in np.subtract(value, off))


def key_now(scene: Scene, paths: list[Path], t: float) -> Animation:
    """K: a key at ``t`` for each value at ``paths`` (``linked_paths``), holding it as drawn
    at ``t``."""
    drawn, keyed = scene.at(t).posed(), scene
    for path in paths:
        value = held(scene, path, get_at(drawn, path), t)
        keyed = replace(keyed, animation=with_key(keyed, path, t, value))
    return keyed.animation


class Keyed(Protocol):
    """What K reads and calls of the editor."""

    selected: Handle | None
    carry: bool  # step edits go to linked levels
    viewer: Viewer
    timeline: Timeline

    @property
    def scene(self) -> Scene: ...
    def edit(self, path: tuple, value: Any, interaction: Any = None, label: Any = None) -> bool: ...


def set_key(e: Keyed) -> None:
    """K: a key for the selected value (``linked_paths``) at the moment shown, holding the
    value drawn; said in the status line too, since the HUD, where the message goes, starts
    folded."""
    paths = e.timeline.paths(e.scene, e.selected, e.carry)
    if not paths:
        e.viewer.message = strip_words([], e.scene.tree is not None) + " (K)"
        return
    t = e.viewer.drawn.playback.time
    what = e.selected.label if e.timeline.field is None else path_text(paths[0])
    label = f"key at {t:.2f} s for {what}{and_linked(len(paths) - 1, 'level')}"
    if e.edit(("animation",), key_now(e.scene, paths, t), label=label):
        e.viewer.message = label
        e.viewer.say(label)


def linked_paths(scene: Scene, path: Path, carry: bool) -> list[Path]:
    """``path`` and, while step edits go to linked levels (``carry``), the same field of a
    MöKRS step in the linked levels (``linked_levels``): the values K and the timeline's key
    edits act on together, as a drag does (palm-curl's 30 curls stay alike)."""
    step = path[:2] == ("mokrs", "levels") and len(path) == 6 and path[3] == "transform"
    if not (carry and step):
        return [path]
    return [path] + [
        (*path[:2], k, *path[3:]) for k in linked_levels(scene.mokrs, path[2]) if k != path[2]
    ]


def keyed_edit(scene: Scene, path: tuple, value: Any, t: float) -> tuple[tuple, Any]:
    """A drag's edit: of the value itself, or, where a track moves that value, of its key
    at ``t`` (auto-key), ``value`` being where it is drawn."""
    if track_index(scene, path) is None:
        return path, value
    return ("animation",), with_key(scene, path, t, held(scene, path, value, t))


def carried_tracks(scene: Scene, path: Path, delta: np.ndarray) -> Animation | None:
    """A fork (or trunk foot) at ``path`` dragged by ``delta`` with its subtree: the tracks of
    the subtree's forks and control points move along, every key by ``delta`` (level i's own
    control point by half, as handles.py's carry moves it), so a keyed part of the subtree
    stays on it; None where no track moves."""
    a = scene.animation
    if a is None or not a.tracks:
        return None
    at = path[:-1] if path[-1] == "base" else path[:-3]
    i = len(get_at(scene, at).levels) if path[-1] == "base" else path[-2]
    tracks, moved = list(a.tracks), False
    for k, tr in enumerate(a.tracks):
        p = parse_path(tr.path)
        if p[:-2] != (*at, "levels") or p[-1] not in ("fork", "control"):
            continue
        f = 1.0 if p[-2] < i else 0.5 if (p[-2], p[-1]) == (i, "control") else 0.0
        if f:
            keys = [
                Key(q.time, tuple(float(c) for c in np.add(q.value, f * delta))) for q in tr.keys
            ]
            tracks[k], moved = replace(tr, keys=keys), True
    return replace(a, tracks=tracks) if moved else None


def linked_edits(scene: Scene, path: Path, value: Any, t: float) -> list[tuple[Path, Any]]:
    """A MöKRS step's field (``path``) set in its level and the linked finer levels
    (``linked_levels``: palm's leaflets bend alike): keyed at ``t`` in the levels where a
    track moves it (palm-curl's curl), the value itself in the others. A value the level
    itself refuses is set there alone, so that the refusal names that level and stays in
    its field, not in the first linked level's."""
    m = scene.mokrs
    try:
        apply_edit(scene, path, value)
    except SceneError:
        return [(path, value)]
    paths = linked_paths(scene, path, carry=True)
    tracked = [q for q in paths if track_index(scene, q) is not None]
    if not tracked:
        return [linked_edit(m, path, value)]
    keyed = scene
    for q in tracked:
        keyed = replace(keyed, animation=with_key(keyed, q, t, value))
    out: list[tuple[Path, Any]] = [(("animation",), keyed.animation)]
    if len(tracked) < len(paths):
        levels = list(m.levels)
        for q in paths:
            if q not in tracked:
                levels[q[2]] = replace_at(levels[q[2]], q[3:], value)
        out.insert(0, (path[:2], levels))
    return out


def key_marks(scene: Scene, t: float) -> dict[Path, bool]:
    """The values the scene's tracks move, by path: whether one of its keys is at ``t``."""
    if scene.animation is None:
        return {}
    return {
        parse_path(tr.path): any(abs(k.time - t) <= KEY_SNAP for k in tr.keys)
        for tr in scene.animation.tracks
    }


@contextmanager
def marked(on_key: bool | None) -> Iterator[None]:
    """Around one field's widget: a tracked field (``on_key`` not None, from
    :func:`key_marks`) framed and flagged by a diamond right of it, as Blender does."""
    if on_key is None:
        yield
        return
    imgui.push_style_color(imgui.Col_.frame_bg, ON_KEY if on_key else BETWEEN)
    try:
        yield
    finally:
        imgui.pop_style_color()
    hi, lo = imgui.get_item_rect_max(), imgui.get_item_rect_min()
    x, y, d = hi.x + DIAMOND + 2.0, 0.5 * (lo.y + hi.y), DIAMOND - 1.0
    pts = [
        imgui.ImVec2(x, y - d),
        imgui.ImVec2(x + d, y),
        imgui.ImVec2(x, y + d),
        imgui.ImVec2(x - d, y),
    ]
    draw = imgui.get_window_draw_list()
    if on_key:
        draw.add_convex_poly_filled(pts, MARK_ON_KEY)
    else:
        draw.add_polyline(pts, MARK_BETWEEN, 1.5, imgui.ImDrawFlags_.closed.value)


def keys_together(scene: Scene, tracks: list[int], track: int, key: int) -> list[tuple[int, int]]:
    """Key ``key`` of track ``track``, and in each other track of ``tracks`` (the linked
    levels') its key at the same moment (within KEY_SNAP): the keys the strip moves and
    deletes as one, as (track, key) pairs."""
    a = scene.animation
    t = a.tracks[track].keys[key].time
    out = [(track, key)]
    for i in (i for i in tracks if i != track):
        j = next((j for j, k in enumerate(a.tracks[i].keys) if abs(k.time - t) <= KEY_SNAP), None)
        if j is not None:
            out.append((i, j))
    return out


def strip_words(paths: list[Path], grown: bool = False) -> str:
    """What the timeline strip says it keys: the selected value and the levels linked to it
    (``paths``: ``linked_paths``), or how to choose one (``grown``: a grown tree, which has
    no handles; a click into one of its panel's growth fields puts it on the strip)."""
    if not paths:
        return "click a growth field to key it" if grown else "select a handle to key it"
    return path_text(paths[0]) + and_linked(len(paths) - 1, "level")


def and_linked(n: int, noun: str) -> str:
    """What an act on ``n`` linked levels (keys, …) adds to its words: " and 29 linked
    levels"; nothing for none."""
    return f" and {counted(n, 'linked ' + noun)}" if n else ""


def moved_keys(scene: Scene, keys: list[tuple[int, int]], t: float) -> Animation:
    """The animation with each key of ``keys`` ((track, key) pairs) moved to time ``t``,
    kept between its neighbours (so each track's keys keep their order)."""
    a = scene.animation
    tracks = list(a.tracks)
    for track, key in keys:
        ks = list(tracks[track].keys)
        lo = ks[key - 1].time + KEY_GAP if key > 0 else 0.0
        hi = ks[key + 1].time - KEY_GAP if key + 1 < len(ks) else a.duration
        ks[key] = Key(round(min(max(t, lo), hi), KEY_DIGITS), ks[key].value)
        tracks[track] = replace(tracks[track], keys=ks)
    return replace(a, tracks=tracks)


def without_keys(scene: Scene, keys: list[tuple[int, int]]) -> Animation:
    """The animation without the keys ``keys`` ((track, key) pairs); a track left with no key
    goes."""
    a, gone = scene.animation, set(keys)
    tracks = []
    for i, tr in enumerate(a.tracks):
        left = [k for j, k in enumerate(tr.keys) if (i, j) not in gone]
        if left:
            tracks.append(replace(tr, keys=left))
    return replace(a, tracks=tracks)


class Timeline:
    """The strip's state: the panel field it shows (else the selected handle's value), the
    keys being dragged (the one on the strip first, then the linked levels' at its moment),
    and the drag's number (one undo step)."""

    def __init__(self) -> None:
        self.field: Path | None = None  # a panel field clicked (ShowKeys); a selection clears it
        self.dragging: list[tuple[int, int]] | None = None  # (track, key) pairs
        self.drags = 0
        self.bar = (0.0, 0.0, 0.0)  # the time bar as last drawn: left x, middle y, width

    def paths(self, scene: Scene, selected: Handle | None, carry: bool) -> list[Path]:
        """The values the strip shows and K keys (``linked_paths``): the panel field clicked
        last while the scene still has it (an undo or a removed level may take it), else
        the selected handle's value; none: empty."""
        if self.field is not None and not holds(scene, self.field):
            self.field = None
        path = self.field or (selected.path if selected is not None else None)
        return [] if path is None else linked_paths(scene, path, carry)

    def draw(
        self, scene: Scene, playback: Playback, paths: list[Path], span: tuple[float, float]
    ) -> list[vc.Command]:
        """Inside the ImGui frame: play/pause, the time bar over the loop with the keys of the
        selected value (``paths[0]``; none: ``paths`` empty) on it, across the window columns
        ``span``. A key dragged or deleted there takes the keys at its moment of the values
        linked to it (``paths[1:]``: ``linked_paths``) along."""
        out: list[vc.Command] = []
        io = imgui.get_io()
        x0, x1 = span[0] + 8.0, span[1] - 8.0
        imgui.set_next_window_pos(imgui.ImVec2(x0, io.display_size.y - STRIP_ROOM))
        imgui.set_next_window_size(imgui.ImVec2(max(x1 - x0, 200.0), STRIP_HEIGHT))
        imgui.set_next_window_bg_alpha(0.75)
        flags = imgui.WindowFlags_.no_decoration | imgui.WindowFlags_.no_move
        imgui.begin("##timeline", None, flags)
        if imgui.button("pause" if playback.playing else "play"):
            out.append(vc.TogglePlay())
        imgui.same_line()
        if imgui.button("key (K)") and paths:
            out.append(ec.SetKey())
        imgui.same_line()
        tracks = [i for i in (track_index(scene, p) for p in paths) if i is not None]
        track = track_index(scene, paths[0]) if paths else None
        what = strip_words(paths, scene.tree is not None)
        imgui.text(f"{playback.time:6.2f} s / {playback.duration:g} s · {what}")
        out += self._bar(scene, playback, track, tracks)
        imgui.end()
        return out

    def _bar(
        self, scene: Scene, playback: Playback, track: int | None, tracks: list[int]
    ) -> list[vc.Command]:
        out: list[vc.Command] = []
        origin = imgui.get_cursor_screen_pos()
        width = max(imgui.get_content_region_avail().x, 1.0)
        imgui.invisible_button("##timebar", imgui.ImVec2(width, 2 * DIAMOND + 4))
        draw = imgui.get_window_draw_list()
        y = origin.y + DIAMOND + 2
        self.bar = (origin.x, y, width)

        def x_of(t: float) -> float:
            return origin.x + width * t / playback.duration

        def t_of(x: float) -> float:
            return round(
                min(max((x - origin.x) / width, 0.0), 1.0) * playback.duration, STRIP_DIGITS
            )

        draw.add_line(imgui.ImVec2(origin.x, y), imgui.ImVec2(origin.x + width, y), 0xFF808080, 2)
        mouse = imgui.get_io().mouse_pos
        keys = scene.animation.tracks[track].keys if track is not None else []
        hot = (
            next(
                (j for j, k in enumerate(keys) if abs(x_of(k.time) - mouse.x) <= DIAMOND),
                None,
            )
            if imgui.is_item_hovered()
            else None
        )
        for j, k in enumerate(keys):
            x = x_of(k.time)
            d = DIAMOND
            pts = [
                imgui.ImVec2(x, y - d),
                imgui.ImVec2(x + d, y),
                imgui.ImVec2(x, y + d),
                imgui.ImVec2(x - d, y),
            ]
            draw.add_convex_poly_filled(pts, KEY_HOT if j == hot else KEY)
        now = x_of(playback.time)
        draw.add_line(
            imgui.ImVec2(now, y - 2 * DIAMOND), imgui.ImVec2(now, y + 2 * DIAMOND), 0xFFFFFFFF, 2
        )
        if imgui.is_item_activated():
            if hot is not None:
                self.dragging = keys_together(scene, tracks, track, hot)
                self.drags += 1
            else:
                out.append(vc.SetTime(t_of(mouse.x)))
        elif imgui.is_item_active():
            if self.dragging is not None:
                moved = moved_keys(scene, self.dragging, t_of(mouse.x))
                label = f"move {self._what(scene, self.dragging)} in time"
                out.append(vc.Edit(("animation",), moved, ("key", self.drags), label=label))
            else:
                out.append(vc.SetTime(t_of(mouse.x)))
        else:
            self.dragging = None
        if hot is not None and imgui.is_item_clicked(imgui.MouseButton_.right):
            together = keys_together(scene, tracks, track, hot)
            label = f"delete {self._what(scene, together)}"
            out.append(vc.Edit(("animation",), without_keys(scene, together), label=label))
        return out

    @staticmethod
    def _what(scene: Scene, keys: list[tuple[int, int]]) -> str:
        """The keys ``keys`` named for an undo step: the first one's moment and track."""
        track, key = keys[0]
        tr = scene.animation.tracks[track]
        linked = and_linked(len(keys) - 1, "key")
        return f"the key at {tr.keys[key].time:.2f} s of {tr.path}{linked}"
