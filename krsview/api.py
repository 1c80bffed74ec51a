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
Scenes are immutable values and may be shared freely; the float64 reference
(``reference=True``) uses no GL at all.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from dataclasses import fields, replace
from pathlib import Path
from typing import Any

from .frame import Frame
from .scene import Render, Scene, SceneError, load_scene
from .scene.info import SceneInfo, describe
from .scene.model import KRS
from .scene.presets import preset_names, resolve
from .scene.render import LANES_LEVELS, VIEW_PREPASS
from .scene.schema import from_dict
from .scene.settings import MAX_SIDE

DEFAULT_SIZE = (320, 180)
RENDER_KNOBS = tuple(f.name for f in fields(Render))  # render(**knobs): the [render] fields

_lock = threading.RLock()
_context = None  # the process's headless GL context, made on first use


def load(name_or_path: str | Path) -> Scene:
    """A scene from a file (``.toml``) or a shipped preset's name (:func:`presets`).

    >>> load("tree").geometry().depth
    23
    """
    return load_scene(resolve(str(name_or_path)))


def load_dict(data: Mapping[str, Any], name: str = "<dict>") -> Scene:
    """A scene from a dict shaped like a scene file's TOML tables, validated the same way
    (``name`` is what errors call the source).

    >>> s = load_dict({"krs": {"levels": [{"kernel": {"type": "sphere", "radius": 0.5}}]}})
    >>> s.geometry().instance_count()
    1
    """
    try:
        return from_dict(Scene, dict(data))
    except SceneError as e:
        raise e.in_file(name) from None


def presets() -> list[str]:
    """The names of the shipped scenes."""
    return preset_names()


def configure(
    scene: Scene,
    *,
    levels: int | None = None,
    effects: list[str] | None = None,
    time: float | None = None,
    **knobs: Any,
) -> Scene:
    """The scene with render knobs (the ``[render]`` fields: ``tracer``, ``epsilon_scale``,
    ``max_iterations``, ``precision``, ``prepass``, ``path``, …), an effect set, a level
    count and the moment drawn (``time``, seconds: :meth:`Scene.at`) applied, each checked by
    the scene schema."""
    for name, value in knobs.items():
        if name not in RENDER_KNOBS:
            raise SceneError(name, value, "not a render knob; allowed: " + ", ".join(RENDER_KNOBS))
        scene = scene.edit(("render", name), value)
    if effects is not None:
        scene = scene.with_effects(effects)
    if levels is not None:
        scene = scene.with_levels(levels)
    return scene if time is None else scene.at(time)


def fast_settings(scene: Scene) -> Scene:
    """The scene with the viewer's fast settings where its file sets none: the pre-pass
    tile VIEW_PREPASS (the level of detail and the shadow rays' pixel blocks are scene
    fields, DEFAULT_LOD and DEFAULT_SHADOW_BLOCK unless the file says otherwise), and for
    a single KRS of LANES_LEVELS levels or more on the fragment path, persistent lanes
    (``path="compute"``, ``steps=0``: the same image bit for bit). The oracle certifies both
    geometry settings hole-free; hits may move by up to ε (pre-pass) and 2·lod·ε (level of
    detail)."""
    r, fast = scene.render, {}
    if not r.prepass:
        fast["prepass"] = VIEW_PREPASS
    g = replace(scene, animation=None).geometry()  # the levels, not posed: motion adds none
    if r.path == "fragment" and isinstance(g, KRS) and g.depth >= LANES_LEVELS:
        fast.update(path="compute", steps=0)
    # constants within the schema's ranges: no edit (its validation of a whole animated
    # scene took 0.24 s a call on palm-curl, every frame of render())
    return replace(scene, render=replace(r, **fast)) if fast else scene


def exact_settings(scene: Scene) -> Scene:
    """The scene drawn with every level, no pre-pass, a shadow ray per pixel that steps
    every component from the surface (no shadow cone) and no walk restart (a step bounded by
    the levels above moves a grazing ray's hit by up to a step): the image the float64
    reference matches pixel for pixel (``exact=True``, ``krsview render --exact``)."""
    return configure(
        scene, prepass=0, lod=0.0, shadow_block=1, shadow_cone="off", walk_restart="off"
    )


def _shared_context():
    global _context
    with _lock:
        if _context is None:
            from .gpu.context import headless_context

            _context = headless_context()
        return _context


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
        for axis, v in (("width", width), ("height", height)):
            if not (isinstance(v, int) and 1 <= v <= MAX_SIDE):
                raise SceneError(axis, v, f"allowed: a whole number of pixels, 1..{MAX_SIDE}")
        self.width, self.height = width, height
        self._gpu = None

    @property
    def gpu(self):
        """The GPU renderer underneath (krsview.gpu.renderer.Renderer), made on first use."""
        if self._gpu is None:
            from .gpu.renderer import Renderer as GpuRenderer

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
        scene: Scene,
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
        scene = configure(exact_settings(scene) if exact else fast_settings(scene), **knobs)
        if reference:
            from .reference import render_reference

            return render_reference(scene, self.width, self.height, progress=progress)
        return self.gpu.render(scene, self.width, self.height, progress=progress)

    def time(self, scene: Scene, repeats: int = 5, **knobs: Any) -> list[float]:
        """Wall time of ``repeats`` frames in seconds (GPU finished), after a warm-up."""
        return self.gpu.time_frame(
            configure(scene, **knobs), self.width, self.height, repeats=repeats
        )

    def close(self) -> None:
        """Drop the compiled variants and targets (the shared context stays for others)."""
        self._gpu = None

    def __enter__(self) -> Renderer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


_shared_gpu = None  # the module-level render()'s GPU renderer: variants kept between calls


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
    if not isinstance(scene, Scene):
        scene = load(scene)
    r = Renderer(*size)
    with _lock:
        if not reference:
            r.gpu_shared()
        return r.render(scene, reference=reference, exact=exact, progress=progress, **knobs)


def check(scene: Scene | str | Path) -> SceneInfo:
    """A scene's statistics (geometry, levels, kernel instances, effects, warnings); a
    name or path is loaded and validated first.

    >>> check("forest").instances
    4194273
    """
    return describe(scene if isinstance(scene, Scene) else load(scene))


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

    scene = scene if isinstance(scene, Scene) else load(scene)
    with _lock:
        return invariants.check(scene, Renderer(*size).gpu_shared(), tuple(size))


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

    scene = scene if isinstance(scene, Scene) else load(scene)
    if UNCOVERED & set(scene.effects):
        raise SceneError(
            scene.name,
            ", ".join(sorted(UNCOVERED & set(scene.effects))),
            "the oracle covers scenes without twist or empty zones "
            "(their distortions are not in it)",
        )
    scene = fast_settings(scene if tracer is None else configure(scene, tracer=tracer))
    frame = render(scene, size)
    return count_errors(scene, frame, max_segments=max_segments or MAX_SEGMENTS)
