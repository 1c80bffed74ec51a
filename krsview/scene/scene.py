"""The scene: geometry (an explicit KRS or a tree), camera, lights, material, render settings
and the effect set; loaded from and saved to TOML."""

from __future__ import annotations

import numbers
import os
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

from ..files import write_atomic
from ..messages import SceneError
from .animation import (
    DEFAULT_DURATION,
    Animation,
    check_animation,
    check_time,
    pose,
    reads_time,
)
from .compound import Component, Compound, check_compound
from .edits import apply_edit, checked, parse_path, vouched
from .effects import EffectSettings, check_effects
from .model import KRS
from .mokrs import MoKRS, check_view
from .render import Camera, Light, Material, Render
from .route import Route
from .schema import from_dict, param, to_dict
from .toml_writer import dumps
from .tree import Tree

Geometry = KRS | MoKRS | Compound
GEOMETRY_KEYS = ("krs", "tree", "route", "mokrs", "compound")  # a scene has exactly one


@dataclass(frozen=True)
class Bookmark:
    """A named camera saved in the scene file by the viewer."""

    name: str = param("view", help="shown in the viewer's bookmark list")
    camera: Camera = param(Camera())


MAX_LIGHTS = 4  # the shaders' light slots (given to them by compile/constants.py)


@dataclass(frozen=True)
class Scene:
    """What a scene file holds: one geometry (a ``krs``, ``tree``, ``route`` or ``mokrs``
    table, or a ``compound`` list), the camera, lights, material, render settings, the
    effect set and its settings, bookmarks and an animation. A frozen value, compared and
    hashed by value: :meth:`edit` returns a new scene validated as a file would be (change
    none of its lists in place); ``krsview.load`` reads one, ``krsview.save`` writes one."""

    name: str = param("untitled", help="shown in the viewer and reports")
    description: str = param("", help="one line about the scene")
    camera: Camera = param(Camera())
    lights: list[Light] = param([Light()], help=f"directional lights (at most {MAX_LIGHTS})")
    material: Material = param(Material())
    render: Render = param(Render())
    effects: list[str] = param(
        [],
        help="effects compiled into this scene's shader; "
        "allowed: see krsview.scene.effects.EFFECTS (README, Effects)",
    )
    effect_settings: EffectSettings = param(EffectSettings())
    krs: KRS | None = param(None, help="explicit kernel–reflection sequence")
    tree: Tree | None = param(None, help="tree growth parameters (instead of krs)")
    route: Route | None = param(
        None,
        help="a tree given by its route: forks, control "
        "points, widths, fork mirrors (the editor's form of a tree)",
    )
    mokrs: MoKRS | None = param(None, help="Möbius kernel–reflection sequence (instead of krs)")
    compound: list[Component] = param(
        [], help="up to 8 placed KRSs or trees, drawn as one scene (instead of krs) [KRS17 §5.1]"
    )
    bookmarks: list[Bookmark] = param([], help="saved cameras")
    animation: Animation | None = param(
        None, help="time: the moment drawn and the playback loop (issue 29); none: time 0"
    )

    @property
    def time(self) -> float:
        """The moment drawn, in seconds (0 without an [animation] table)."""
        return self.animation.time if self.animation is not None else 0.0

    @property
    def duration(self) -> float:
        """One playback loop, in seconds (the viewer's, the page's, Shadertoy's)."""
        return self.animation.duration if self.animation is not None else DEFAULT_DURATION

    def at(self, t: float, path: str = "time") -> Scene:
        """This scene at time ``t`` (seconds): what moves is read from the scene's time.

        >>> from krsview import load
        >>> load("tree").at(2.5).time
        2.5
        """
        t = check_time(t, path)
        return replace(self, animation=replace(self.animation or Animation(), time=t))

    @property
    def animated(self) -> bool:
        """Whether anything drawn changes with time: keyframe tracks, sway, or an effect that
        reads the time (the wind)."""
        a = self.animation
        return (a is not None and a.moves) or reads_time(self.effects)

    def __hash__(self) -> int:
        """By value, as ``==`` compares: scenes can be keys of a dict or members of a set.
        (Its lists are Python lists: a scene changed in place hashes anew, so change one by
        :meth:`edit`.)"""
        return hash(_frozen(to_dict(self)))

    def posed(self) -> Scene:
        """The static scene drawn at this scene's time: its tracks' values there and its sway
        applied, without tracks or sway (posing twice is posing once), time kept. Made once
        per scene (scenes are frozen); a scene that does not move is its own pose.

        >>> from krsview import load
        >>> swaying = load("tree").edit("animation", {"time": 1.0, "sway": {"amplitude": 2.0}})
        >>> s = swaying.posed()
        >>> s.time, s.animation.sway, s.posed() is s, s.route.levels[-1].normal != (
        ...     swaying.tree.route().levels[-1].normal)
        (1.0, None, True, True)
        """
        if self.animation is None or not self.animation.moves:
            return self
        if "_posed" not in self.__dict__:
            object.__setattr__(self, "_posed", pose(self))
        return self.__dict__["_posed"]

    def validate(self, path: str) -> None:
        given = [k for k in GEOMETRY_KEYS if getattr(self, k)]
        if len(given) != 1:
            raise SceneError(
                " / ".join(GEOMETRY_KEYS),
                "<" + (" and ".join(given) or "none") + ">",
                "a scene has exactly one geometry: a [krs], [tree], [route] or "
                "[mokrs] table, or a [[compound]] list",
            )
        check_compound(self.compound)
        if len(self.lights) > MAX_LIGHTS:
            raise SceneError(
                "lights", f"<{len(self.lights)} lights>", f"allowed: at most {MAX_LIGHTS}"
            )
        check_effects(self.effects, self.mokrs is not None)
        self.check_tracer(self.render.tracer)
        if self.mokrs is not None:
            check_view(self.mokrs, self.camera.position, "camera.position")
            for i, b in enumerate(self.bookmarks):
                check_view(self.mokrs, b.camera.position, f"bookmarks[{i}].camera.position")
        if self.animation is not None and self.animation.moves:
            check_animation(self)  # last: the keys are edits of the scene checked above

    def validate_edit(self, path: str, tables: set[str]) -> None:
        """The scene's rules after an edit of the top-level ``tables`` alone, the scene
        valid before it. An edit of [render] alone meets only the rules that read it: the
        tracer's, and the keys of tracks on render values. The rest cannot have changed, so
        a render knob on animated palm-curl takes a millisecond, not the 0.7 s of every
        track's keys checked against the MöKRS's view again."""
        if tables != {"render"}:
            self.validate(path)
            return
        self.check_tracer(self.render.tracer)
        if self.animation is not None and self.animation.moves:
            check_animation(self, under="render")

    def check_tracer(self, tracer: str, path: str = "render.tracer") -> None:
        """The one rule for a tracer choice, from a file, the CLI or the HUD: a MöKRS needs
        binary tracing; over-relaxed tracing is for a single KRS (a compound's per-component
        free distances must be verified ones)."""
        if self.mokrs is not None and tracer != "binary":
            raise SceneError(
                path,
                tracer,
                "this scene is a MöKRS, which has no distance "
                "function, only unbounding tests: it needs binary tracing; "
                "allowed: 'binary'",
            )
        if self.compound and tracer == "relaxed":
            raise SceneError(
                path,
                tracer,
                "over-relaxed tracing steps past what is verified "
                "free, which a compound's nearest-component rule cannot allow; "
                "allowed here: 'sphere', 'binary'",
            )

    def single_krs(self, purpose: str) -> KRS:
        """The scene's one KRS ([krs], [tree] or [route]), or a one-line error saying that
        ``purpose`` (e.g. "bench zoom flies into its finest kernel") needs one."""
        g = self.geometry()
        if not isinstance(g, KRS) or self.compound:
            raise SceneError(
                "PRESET",
                self.name,
                f"{purpose}: it needs one KRS, a [krs], [tree] or [route] scene "
                "(not a compound or a MöKRS)",
            )
        return g

    def geometry(self) -> Geometry:
        """What is drawn at the scene's time: the explicit KRS or MöKRS, the tree expanded
        [KRS17 §9.2], or the compound's components placed in the world [KRS17 §5.1]; where
        tracks or sway move it, its pose's (:meth:`posed`)."""
        if self.animation is not None and self.animation.moves:
            return self.posed().geometry()
        if self.tree is not None:
            return self.tree.krs()
        if self.route is not None:
            return self.route.krs()
        if self.compound:
            return Compound(tuple(c.placed() for c in self.compound))
        return self.krs if self.krs is not None else self.mokrs  # type: ignore[return-value]

    def edit(self, path: str | tuple, value: object) -> Scene:
        """A new scene with the value at ``path`` replaced, validated by the schema that
        reads files (a SceneError names the field and what is allowed; this scene is left as
        it is). ``path``: ``"render.tracer"``, ``"route.levels[3].fork"`` or a tuple. A table
        given whole (``edit("camera", {...})``) replaces it: the fields it leaves out take
        their defaults, so set one field by its own path (``"camera.position"``). ``None``
        is what a file that leaves the field out gets: its default (``edit("name", None)``
        names the scene "untitled"), and an optional table goes (``edit("animation",
        None)``: the scene stands still). Scenes share their unchanged parts: change one by
        ``edit``, not in place (a list changed in place changes every scene holding it).

        >>> from krsview import load
        >>> load("tree").edit("render.epsilon_scale", 0.5).render.epsilon_scale
        0.5
        """
        return apply_edit(self, parse_path(path), value)

    def with_levels(self, levels: int, path: str = "levels") -> Scene:
        """The scene drawn with only its coarsest ``levels`` levels (LOD by truncation), as
        posed at its time (see :meth:`with_geometry`): the finest go, so a tree keeps its
        trunk and loses its leaves first (a tree grown with fewer forks, ``tree.levels``,
        keeps its leaves on the last levels it grows). The result no longer moves: to draw
        a moving scene's levels at another moment, ``krsview.configure(scene, time=T,
        levels=N)`` poses it first."""
        scene = checked(self)  # validated (a copy, where its lists changed in place)
        g = scene.posed().geometry()
        if not isinstance(levels, numbers.Integral) or isinstance(levels, bool):
            raise SceneError(path, levels, f"expected a whole number, 1..{g.depth}")
        if not 1 <= levels <= g.depth:
            raise SceneError(path, levels, f"this scene has {g.depth} levels; allowed 1..{g.depth}")
        return scene.with_geometry(g.truncated(int(levels)))

    def with_effects(self, effects: list[str], path: str = "effects") -> Scene:
        """The scene with this effect set compiled in (checked against what it allows)."""
        check_effects(effects, self.mokrs is not None, path)
        return replace(self, effects=list(effects))

    def with_geometry(self, geometry: Geometry) -> Scene:
        """This scene drawing ``geometry`` instead; a scene that moves is posed at its time
        first, since its tracks and sway address the geometry that is replaced."""
        base = self.posed()
        none = dict(krs=None, tree=None, route=None, mokrs=None, compound=[])
        if isinstance(geometry, MoKRS):
            return replace(base, **{**none, "mokrs": geometry})
        if isinstance(geometry, Compound):
            return replace(base, **{**none, "compound": [Component(krs=p) for p in geometry.parts]})
        return replace(base, **{**none, "krs": geometry})


def _frozen(data: object) -> object:
    """A TOML-ready value as nested tuples, to hash."""
    if isinstance(data, dict):
        return tuple((k, _frozen(v)) for k, v in data.items())
    if isinstance(data, list):
        return tuple(_frozen(v) for v in data)
    return data


MAX_FILE_BYTES = 4 * 1024 * 1024


DEEP, TOO_DEEP = (
    "arrays or tables nested hundreds deep",
    "not read (a scene nests a few: a kernel in a level in a table)",
)


BOM = "\ufeff"  # a byte-order mark: Windows' Notepad starts UTF-8 files with one


def scene_from_toml(text: str, file: str = "<string>") -> Scene:
    """The scene a file's ``text`` holds (a leading byte-order mark is no text)."""
    try:
        data = tomllib.loads(text.removeprefix(BOM))
    except tomllib.TOMLDecodeError as e:
        what, _, where = str(e).rpartition(" (at ")  # tomllib: "... (at line 2, column 8)"
        where = where.rstrip(")") if what else "the file"
        raise SceneError("<syntax>", where, f"not valid TOML ({what or e})", file) from None
    except RecursionError:  # tomllib reads nested arrays and tables recursively
        raise SceneError("<syntax>", DEEP, TOO_DEEP, file) from None
    try:
        return from_dict(Scene, data)
    except SceneError as e:
        raise e.in_file(file) from None
    except RecursionError:
        raise SceneError("<syntax>", DEEP, TOO_DEEP, file) from None


def load_scene(path: str | os.PathLike) -> Scene:
    """Read and validate a scene file; every mistake raises SceneError naming file and field."""
    p = Path(path)
    try:
        size = p.stat().st_size
        if size > MAX_FILE_BYTES:  # refuse before parsing: 500,000 levels took 100 s and 900 MB
            raise SceneError(
                "<file>",
                f"{size:,} bytes",
                f"scene files hold at most "
                f"{MAX_FILE_BYTES:,} bytes (a compound of 8 × 64 levels is far "
                "smaller)",
                str(p),
            )
        raw = p.read_bytes()
    except OSError as e:
        raise SceneError("<file>", str(p), f"cannot read: {e.strerror}", str(p)) from None
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark (Windows' Notepad writes one) is no text
    except UnicodeDecodeError as e:
        bom = raw[:2] in (b"\xff\xfe", b"\xfe\xff")
        raise SceneError(
            "<file>",
            f"byte 0x{raw[e.start]:02x} at offset {e.start}",
            "a scene file is UTF-8 text (TOML)"
            + ("; this one is UTF-16: save it as UTF-8" if bom else ""),
            str(p),
        ) from None
    return vouched(scene_from_toml(text, str(p)))


def scene_to_toml(scene: Scene) -> str:
    return dumps(to_dict(scene))


def save_scene(scene: Scene, path: str | os.PathLike) -> None:
    """Atomic save, so an edit is never lost half-written."""
    write_atomic(path, scene_to_toml(scene))
