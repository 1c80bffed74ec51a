"""krsview: real-time viewer, editor and benchmark for Kernel–Reflection Sequences [KRS17].

The Python API (see the README, "Use it from Python"):

- :func:`load`, :func:`load_dict` → :class:`Scene` (frozen; ``scene.edit(path, value)``
  returns a new, validated scene); :func:`save` writes one; :func:`presets` lists the
  shipped scenes; a scene built from :mod:`krsview.scene`'s classes is validated as a file
  would be wherever the API takes it;
- :func:`render` → :class:`Frame` (NumPy arrays ``color``, ``depth``, ``normal``,
  ``iterations``, ``hit``; ``save``; shown as an image in Jupyter); :class:`Renderer` for many
  frames; ``reference=True`` for the float64 NumPy twin;
- :func:`distance` (Alg. 1's distance at points, float64); :func:`check` (statistics),
  :func:`stability` and :func:`certify` (the numerical invariants and the reliable oracle
  [RAA09]); benchmarks in :mod:`krsview.bench`;
- :mod:`krsview.export`: web page, Shadertoy shader, mesh, camera-path frames and video.
"""

from .api import (
    Renderer,
    certify,
    check,
    configure,
    distance,
    hard_cases,
    load,
    load_dict,
    presets,
    render,
    save,
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
    "distance",
    "export",
    "hard_cases",
    "load",
    "load_dict",
    "presets",
    "render",
    "save",
    "stability",
]


def __getattr__(name: str):
    """``krsview.export`` and ``krsview.bench`` after a plain ``import krsview``, imported on
    first use (they pull in more than rendering needs)."""
    if name in ("export", "bench"):
        import importlib

        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
