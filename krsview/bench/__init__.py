"""Benchmarks: variants compared side by side in one run, reported as ratios. From Python
each is a function of a scene (a :class:`krsview.Scene`, a preset's name or a file), a
(width, height) and rounds, checked before any work as the API checks its arguments; each
returns a ``Measured``: its ``rows`` (a dict per row) and ``column(name)``; the module's
``table(m)`` is the table the CLI prints:

>>> import krsview
>>> m = krsview.bench.bench_levels("sierpinski", (48, 27), step=8, rounds=1)  # doctest: +SKIP

``bench_levels``, ``bench_tracers``, ``bench_effects``, ``bench_paths``, ``bench_split``,
``bench_zoom``, and against an Embree BVH (with ``krsview[peer]``) ``bench_peer`` and
``bench_peer_zoom``, each from the module of its name (imported on first use)."""

from __future__ import annotations

import importlib

BENCHES = ("levels", "tracers", "effects", "paths", "split", "zoom", "peer", "peer_zoom")
__all__ = [f"bench_{name}" for name in BENCHES]


def __getattr__(name: str):
    """``krsview.bench.bench_levels`` … without importing every benchmark up front."""
    if name in __all__:
        return getattr(importlib.import_module(f".{name[6:]}", __name__), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
