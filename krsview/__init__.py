"""krsview: real-time viewer, editor and benchmark for Kernel–Reflection Sequences [KRS17].

The Python API (see the README, "Use it from Python"):

- :func:`load`, :func:`load_dict` → :class:`Scene` (immutable; ``scene.edit(path, value)``
  returns a new, validated scene); :func:`presets` lists the shipped scenes;
- :func:`render` → :class:`Frame` (NumPy arrays ``color``, ``depth``, ``normal``,
  ``iterations``, ``hit``; ``save``; shown as an image in Jupyter); :class:`Renderer` for many
  frames; ``reference=True`` for the float64 NumPy twin;
- :func:`check` (statistics), :func:`stability` and :func:`certify` (the numerical
  invariants and the reliable oracle [RAA09]); benchmarks in :mod:`krsview.bench`;
- :mod:`krsview.export`: web page, Shadertoy shader, mesh, camera-path frames and video.
"""

from .api import (
    Renderer,
    certify,
    check,
    configure,
    hard_cases,
    load,
    load_dict,
    presets,
    render,
    stability,
)
from .frame import Frame
from .scene import Scene, SceneError
from .scene.info import SceneInfo
from .version import __version__

__all__ = [
    "Frame",
    "Renderer",
    "Scene",
    "SceneError",
    "SceneInfo",
    "__version__",
    "certify",
    "check",
    "configure",
    "hard_cases",
    "load",
    "load_dict",
    "presets",
    "render",
    "stability",
]
