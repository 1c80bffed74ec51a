"""Ground truth for the accuracy benchmark: the float64 NumPy reference with a tight LOD
threshold (ε at 1/8 of the pixel footprint) and a generous iteration cap, computed once per
scene, view and size and cached on disk under a key made from the scene's content."""

from __future__ import annotations

import hashlib
import os
from dataclasses import replace
from pathlib import Path

from ..frame import Frame
from ..reference import render_reference
from ..scene import Scene, scene_to_toml
from ..version import __version__

TRUTH_EPSILON_SCALE = 0.125  # × the pixel footprint
TRUTH_ITERATIONS = 4096


def truth_scene(scene: Scene) -> Scene:
    """The scene at ground-truth accuracy: tight ε, generous cap, every level (no level of
    detail), a shadow ray per pixel stepping every component from the surface (no shadow
    cone), its own tracer (a MöKRS keeps binary tracing: it has no distance)."""
    return replace(
        scene,
        render=replace(
            scene.render,
            epsilon_scale=TRUTH_EPSILON_SCALE,
            max_iterations=TRUTH_ITERATIONS,
            lod=0.0,
            shadow_block=1,
            shadow_cone="off",
        ),
    )


def default_cache() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "krsview" / "truth"


# Bumped whenever the reference draws differently, so no cache outlives its images
# (2: a MöKRS probe holding a pole is free when the level's bound lies outside it).
REFERENCE_REVISION = 2


def cache_key(scene: Scene, size: tuple[int, int]) -> str:
    text = f"{__version__}.{REFERENCE_REVISION}\n{size}\n{scene_to_toml(truth_scene(scene))}"
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def ground_truth(scene: Scene, size: tuple[int, int], cache: Path | None = None) -> Frame:
    """The reference image at ground-truth accuracy, from the cache when it holds one."""
    path = (cache or default_cache()) / f"{cache_key(scene, size)}.npz"
    if path.exists():
        return Frame.load(path)
    b = render_reference(truth_scene(scene), *size)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp.npz")
    b.save(tmp)
    tmp.replace(path)
    return b
