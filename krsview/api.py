"""The Python API: load a scene, change it, render it to NumPy arrays, check it. The CLI, the
viewer and the editor are users of the same functions (modelled on mitsuba3's ``load_file``,
``load_dict``, ``render`` and pyrender's offscreen renderer).

>>> import krsview
>>> scene = krsview.load("sierpinski").edit("render.epsilon_scale", 2.0)
>>> frame = krsview.render(scene, size=(32, 18))
>>> frame.color.shape, frame.hit.dtype
((18, 32, 3), dtype('bool'))

Threads: every GPU render goes through one headless OpenGL context per process, created on
first use; :func:`render` serialises its calls on a lock, so it may be called from several
threads. A :class:`Renderer` holds that context too and must be used by one thread at a time.
Scenes are frozen values (change one by ``edit``, not its lists in place) and may be shared
freely; the float64 reference (``reference=True``) uses no GL at all.
"""

from __future__ import annotations

import gc
import os
import threading
from collections.abc import Callable, Mapping
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

import numpy as np

from .files import write_atomic
from .frame import Frame
from .inputs import output_file, scene_of, size_of, switch, whole
from .scene import Render, Scene, SceneError, save_scene
from .scene.edits import still_checked, vouched
from .scene.filetext import read_file_text, saved_text
from .scene.info import SceneInfo, describe
from .scene.motion import check_motion
from .scene.presets import preset_names, resolve
from .scene.render import ignored_by_tracer
from .scene.scene import scene_from_toml
from .scene.schema import COORDINATE_LIMIT, from_dict
from .scene.settings import MAX_SIDE
from .scene.speed import exact_settings, fast_settings, fast_tile

DEFAULT_SIZE = (320, 180)
RENDER_KNOBS = tuple(f.name for f in fields(Render))  # render(**knobs): the [render] fields

_lock = threading.RLock()
_context = None  # the process's headless GL context, made on first use
_context_pid = 0  # the process that made it: a child forked after it cannot draw with it
_hardware: bool | None = None  # whether that context draws on a GPU (on_hardware)
FORKED = (
    "krsview: this process was forked after krsview had drawn in its parent: an OpenGL "
    "context does not survive a fork (and with Mesa the child cannot make its own); start "
    "worker processes with multiprocessing.get_context('spawn') or 'forkserver'"
)


def load(name_or_path: str | Path) -> Scene:
    """A scene from a file (``.toml``) or a shipped preset's name (:func:`presets`).

    >>> load("tree").geometry().depth
    23
    """
    if not isinstance(name_or_path, (str, Path)):
        raise SceneError("name_or_path", name_or_path, "expected a preset's name or a .toml path")
    return scene_of(name_or_path, "name_or_path")


def save(scene: Scene, path: str | Path) -> Path:
    """Write ``scene`` as a scene file (``.toml``), validated first, atomically (a file is
    whole or untouched); over a scene file, only the values that changed are written into
    its text, its comments kept. The path written. :func:`load` reads it back to an equal
    scene.

    >>> import pathlib, tempfile
    >>> out = save(load("rock"), pathlib.Path(tempfile.mkdtemp()) / "rock.toml")
    >>> load(out) == load("rock")
    True
    """
    scene = scene_of(scene)
    out = output_file(path, "path", (".toml",))
    try:  # over a scene file: only what changed is written into its text, comments kept
        text = read_file_text(out)
        write_atomic(out, saved_text(text, scene_from_toml(text, str(out)), scene))
    except (OSError, UnicodeDecodeError, SceneError):
        save_scene(scene, out)
    return out


def load_dict(data: Mapping[str, Any], name: str = "<dict>") -> Scene:
    """A scene from a dict shaped like a scene file's TOML tables, validated the same way
    (``name`` is what errors call the source).

    >>> s = load_dict({"krs": {"levels": [{"kernel": {"type": "sphere", "radius": 0.5}}]}})
    >>> s.geometry().instance_count()
    1
    """
    if not isinstance(data, Mapping):
        raise SceneError(name, data, "expected a dict of a scene file's tables")
    try:
        return vouched(from_dict(Scene, dict(data)))
    except SceneError as e:
        raise e.in_file(name) from None


def presets() -> list[str]:
    """The names of the shipped scenes."""
    return preset_names()


def configure(
    scene: Scene | str | Path,
    *,
    levels: int | None = None,
    effects: list[str] | None = None,
    time: float | None = None,
    **knobs: Any,
) -> Scene:
    """The scene with render knobs (the ``[render]`` fields: ``tracer``, ``epsilon_scale``,
    ``max_iterations``, ``precision``, ``prepass``, ``path``, …), the moment drawn
    (``time``, seconds: :meth:`Scene.at`), an effect set and a level count (of the scene as
    posed at that moment) applied, each checked by the scene schema."""
    scene = scene_of(scene)
    for name, value in knobs.items():
        if name not in RENDER_KNOBS:
            raise SceneError(name, value, "not a render knob; allowed: " + ", ".join(RENDER_KNOBS))
        scene = scene.edit(("render", name), value)
    if ignored := ignored_by_tracer(knobs, scene.render.tracer):  # refused, as the CLI does
        name, needs = ignored
        said = f"applies to tracer={needs!r} (this traces {scene.render.tracer})"
        raise SceneError(name, knobs[name], said)
    if time is not None:
        scene = scene.at(time)
    if effects is not None:
        scene = scene.with_effects(effects)
    return scene if levels is None else scene.with_levels(levels)


def on_hardware() -> bool:
    """Whether this process draws on a GPU rather than a CPU rasteriser such as Mesa's
    llvmpipe: there :func:`fast_settings` trace by the compute path's rounds."""
    global _hardware
    if _hardware is None:
        from .gpu.context import hardware

        ctx = _shared_context()
        with _lock, ctx:
            _hardware = hardware(ctx.info["GL_RENDERER"])
    return _hardware


def _shared_context():
    global _context, _context_pid
    with _lock:
        _not_forked()
        if _context is None:
            from .gpu.context import headless_context

            _context, _context_pid = headless_context(), os.getpid()
        return _context


def _not_forked() -> None:
    """A RuntimeError in a child forked after its parent made the GL context: drawing there
    waits forever on the parent's rasteriser threads, which the fork did not copy."""
    if _context is not None and _context_pid != os.getpid():
        raise RuntimeError(FORKED)


class Renderer:
    """Renders many frames of one size without recompiling: shader variants are compiled
    once per effect set and kept, and geometry edits only re-upload uniforms.

    >>> with Renderer(32, 18) as r:
    ...     a = r.render(load("rock"))
    ...     b = r.render(load("rock"), epsilon_scale=0.5)
    >>> a.size, int(b.iterations.sum()) >= int(a.iterations.sum())
    ((32, 18), True)
    """

    def __init__(self, width: int = DEFAULT_SIZE[0], height: int = DEFAULT_SIZE[1]):
        self.width = whole(width, "width", 1, MAX_SIDE)
        self.height = whole(height, "height", 1, MAX_SIDE)
        self._gpu = None

    @property
    def gpu(self):
        """The GPU renderer underneath (krsview.gpu.renderer.Renderer), made on first use."""
        _not_forked()
        if self._gpu is None:
            from .gpu.renderer import Renderer as GpuRenderer

            _release_dropped()  # what Renderers dropped without close() left behind
            self._gpu = GpuRenderer(_shared_context())
        return self._gpu

    def gpu_shared(self):
        """The process's shared GPU renderer (the one :func:`render` uses)."""
        global _shared_gpu
        with _lock:
            _shared_gpu = _shared_gpu or self.gpu
            self._gpu = _shared_gpu
        return _shared_gpu

    def render(
        self,
        scene: Scene | str | Path,
        *,
        reference: bool = False,
        exact: bool = False,
        progress: Callable[[int, int], None] | None = None,
        **knobs: Any,
    ) -> Frame:
        """One frame of ``scene`` (``knobs``: see :func:`configure`) with the viewer's fast
        settings where neither the file nor ``knobs`` set them (:func:`fast_settings`), or with
        ``exact=True`` every level and no pre-pass (:func:`exact_settings`); ``reference=True``
        traces it with the float64 NumPy reference instead of the GPU; ``progress(done,
        total)`` is called as bands of rows (GPU) or chunks of rays (reference) finish."""
        reference = switch(reference, "reference")
        scene = self._settled(scene, exact, not reference, **knobs)  # the reference: no GL
        if progress is not None and not callable(progress):
            raise SceneError("progress", progress, "expected a function of (done, total)")
        if reference:
            from .reference import render_reference

            return render_reference(scene, self.width, self.height, progress=progress)
        return self.gpu.render(scene, self.width, self.height, progress=progress)

    def time(
        self, scene: Scene | str | Path, repeats: int = 5, *, exact: bool = False, **knobs: Any
    ) -> list[float]:
        """Wall time of ``repeats`` frames in seconds (GPU finished), after a warm-up: the
        frames :meth:`render` draws with the same arguments."""
        scene = self._settled(scene, exact, True, **knobs)
        repeats = whole(repeats, "repeats", 1)
        return self.gpu.time_frame(scene, self.width, self.height, repeats=repeats)

    @staticmethod
    def _settled(scene: Scene | str | Path, exact: bool, gpu: bool, **knobs: Any) -> Scene:
        """``scene`` with the fast or exact settings, then ``knobs`` over them; a pre-pass
        left unset by a knob (``prepass=None``: "not given", as in a file) is the setting's
        own (the fast tile, or none with ``exact``). ``gpu``: drawn by the GPU renderer, so
        the fast settings are those of the device it draws on (else no GL is touched)."""
        scene = scene_of(scene)
        exact = switch(exact, "exact")
        hardware = gpu and not exact and on_hardware()
        scene = configure(
            exact_settings(scene) if exact else fast_settings(scene, hardware), **knobs
        )
        if scene.render.prepass is None:
            tile = 0 if exact else fast_tile(hardware)
            scene = still_checked(scene, replace(scene, render=replace(scene.render, prepass=tile)))
        return scene

    def close(self) -> None:
        """Release the compiled variants and targets (the shared context and the shared
        renderer of :func:`render` stay for others)."""
        own = self._gpu is not None and self._gpu is not _shared_gpu
        self._gpu = None
        if own:  # its GL objects go once Python drops them (the context's gc_mode)
            _release_dropped()

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_shared_gpu = None  # the module-level render()'s GPU renderer: variants kept between calls


def _release_dropped() -> None:
    """Give back the GL objects of renderers Python has dropped: at a Renderer's close(),
    and when a new one starts (one dropped without close() held 11 MB until then)."""
    from .gpu.context import release_dropped

    gc.collect()
    ctx = _shared_context()
    with _lock, ctx:
        release_dropped(ctx)


def render(
    scene: Scene | str | Path,
    size: tuple[int, int] = DEFAULT_SIZE,
    *,
    reference: bool = False,
    exact: bool = False,
    progress: Callable[[int, int], None] | None = None,
    **knobs: Any,
) -> Frame:
    """One frame of a scene (or a preset's name or a file) at ``size`` = (width, height) as
    NumPy arrays: ``color``, ``depth``, ``normal``, ``iterations``, ``hit``. Render knobs
    (``tracer="binary"``, ``epsilon_scale=0.5``, ``levels=8``, ``effects=[…]``, …) are
    applied first (:func:`configure`), over the viewer's fast settings (:func:`fast_settings`), or
    over every level without the pre-pass with ``exact=True``. Variants stay compiled
    between calls."""
    scene = scene_of(scene)
    r = Renderer(*size_of(size))
    with _lock:
        if not reference:
            r.gpu_shared()
        return r.render(scene, reference=reference, exact=exact, progress=progress, **knobs)


def distance(scene: Scene | str | Path, points: Any) -> np.ndarray:
    """Alg. 1's distance from each of ``points`` (an array (..., 3), world units within the
    scene's coordinate limit, ±1e9) to the surface the scene draws at its time, in float64
    by the NumPy reference [KRS17 Alg. 1]: a lower bound of the true distance (equal to it
    where no mirror clips a kernel), negative inside a kernel; the shape of ``points`` less
    its last axis. A MöKRS has no distance function [KRS17 §6] and is refused. (A ray's hit
    from the eye: :func:`render`'s ``depth``.)

    >>> float(distance("rock", [0.0, 100.0, 0.0])) > 90
    True
    """
    from .compile.geometry import compile_geometry
    from .reference.distortion import Distortion
    from .reference.geometry import scene_distance

    scene = scene_of(scene).posed()
    if scene.mokrs is not None:
        raise SceneError("scene", scene.name, "a MöKRS has no distance function [KRS17 §6]")
    try:  # a complex number, text, a ragged list: refused below, as what was given
        if np.iscomplexobj(points):
            raise TypeError
        p = np.asarray(points, dtype=float)
    except (ValueError, TypeError):
        p = None
    if p is None or p.ndim == 0 or p.shape[-1] != 3 or not (np.abs(p) <= COORDINATE_LIMIT).all():
        shown = f"<an array of shape {p.shape}>" if p is not None and p.ndim else points
        raise SceneError(
            "points",
            shown,
            f"expected points of coordinates within ±{COORDINATE_LIMIT:g} (the scene's own "
            "limit), an array of shape (..., 3)",
        )
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    d = scene_distance(c, p.reshape(-1, 3), Distortion.of(scene))
    return d.reshape(p.shape[:-1])


def check(scene: Scene | str | Path) -> SceneInfo:
    """A scene's statistics (geometry, levels, kernel instances, effects, warnings); a
    name or path is loaded and validated first, and a scene with keyframe tracks is posed
    at every moment where a track may break a rule between its keys (scene/animation.py,
    ``moments``): such a value is a SceneError naming the track, the time and the file.

    >>> check("forest").instances
    4194273
    """
    s = scene_of(scene)
    try:
        return describe(s, check_motion(s) if s.animation is not None else 0)
    except SceneError as e:
        named = not isinstance(scene, Scene) and e.file is None
        raise e.in_file(str(resolve(scene))) if named else e from None


def hard_cases() -> dict[str, Scene]:
    """The catalogue of named hard cases (eye on a mirror, grazing rays, 63 levels, deep
    zooms, Möbius poles, …) as scenes, each named after its case."""
    from dataclasses import replace

    from .bench.hard_cases import CASES

    return {name: replace(case.build(), name=name) for name, case in CASES.items()}


def stability(scene: Scene | str | Path, size: tuple[int, int] = (48, 27)):
    """The numerical invariants on one scene (finite pixels, rays within the cap, continuity
    under a 1/100-pixel nudge, GPU = float64 reference, trying double precision where float
    falls short): a :class:`krsview.bench.stability.Outcome` (``.ok``)."""
    from .bench import stability as invariants

    scene, size = scene_of(scene), size_of(size)
    with _lock:
        return invariants.check(scene, Renderer(*size).gpu_shared(), size)


def certify(
    scene: Scene | str | Path,
    size: tuple[int, int] = (48, 27),
    tracer: str | None = None,
    max_segments: int | None = None,
):
    """Certified holes and false hits of the GPU image :func:`render` draws (the viewer's
    fast settings where the scene sets none), by the reliable oracle (interval and revised
    affine arithmetic over ray segments [RAA09]): a :class:`krsview.oracle.certify.Counts`.
    ``tracer`` overrides the scene's."""
    from .oracle.certify import MAX_SEGMENTS, UNCOVERED, count_errors

    scene, size = scene_of(scene), size_of(size)
    if max_segments is not None:
        max_segments = whole(max_segments, "max_segments", 1)
    if UNCOVERED & set(scene.effects):
        raise SceneError(
            scene.name,
            ", ".join(sorted(UNCOVERED & set(scene.effects))),
            "the oracle covers scenes without twist or empty zones "
            "(their distortions are not in it)",
        )
    scene = scene if tracer is None else configure(scene, tracer=tracer)
    scene = fast_settings(scene, on_hardware())
    frame = render(scene, size)
    return count_errors(scene, frame, max_segments=max_segments or MAX_SEGMENTS)
