"""The render settings `krsview render`, the API and the benches draw with where the scene
file sets none: the fast ones (the viewer's pre-pass, persistent lanes for a deep KRS, the
compute path's rounds on a GPU), and the exact ones the float64 reference matches."""

from __future__ import annotations

from dataclasses import replace

from .edits import still_checked
from .model import KRS
from .render import HARDWARE_PREPASS, LANES_LEVELS, VIEW_PREPASS
from .scene import Scene

# every level, no pre-pass, a shadow ray per pixel from the surface, no walk restart
EXACT = {"prepass": 0, "lod": 0.0, "shadow_block": 1, "shadow_cone": "off", "walk_restart": "off"}


def fast_settings(scene: Scene, hardware: bool = False) -> Scene:
    """The scene with the viewer's fast settings where its file sets none: the pre-pass
    tile VIEW_PREPASS (the level of detail and the shadow rays' pixel blocks are scene
    fields, DEFAULT_LOD and DEFAULT_SHADOW_BLOCK unless the file says otherwise), and for
    a single KRS of LANES_LEVELS levels or more whose file sets no path, persistent lanes
    (``path="compute"``, ``steps=0``: the same image bit for bit; else the fragment path,
    as the viewer draws where the file sets none). On ``hardware`` (a GPU:
    ``krsview.api.on_hardware()``) the pre-pass tile is HARDWARE_PREPASS, and every scene
    whose file sets no path is traced by the compute path's rounds. The oracle certifies both
    geometry settings hole-free; hits may move by up to ε (pre-pass) and a cut ball's
    diameter, 2K·lod·ε (level of detail, compile/lod.py)."""
    r, fast = scene.render, {}
    if r.prepass is None:  # 0 is the file's own "off"
        fast["prepass"] = fast_tile(hardware)
    if r.path is None and hardware:  # rounds of render.steps iterations
        fast["path"] = "compute"
    elif r.path is None:  # "fragment" is the file's own choice
        g = replace(scene, animation=None).geometry()  # the levels, not posed: motion adds none
        deep = isinstance(g, KRS) and g.depth >= LANES_LEVELS
        fast.update({"path": "compute", "steps": 0} if deep else {"path": "fragment"})
    # constants within the schema's ranges: no edit (its validation of a whole animated
    # scene took 0.24 s a call on palm-curl, every frame of render())
    return still_checked(scene, replace(scene, render=replace(r, **fast))) if fast else scene


def fast_tile(hardware: bool) -> int:
    """The pre-pass tile of the fast settings, on a GPU or a CPU rasteriser."""
    return HARDWARE_PREPASS if hardware else VIEW_PREPASS


def exact_settings(scene: Scene) -> Scene:
    """The scene drawn with every level, no pre-pass, a shadow ray per pixel that steps
    every component from the surface (no shadow cone) and no walk restart (a step bounded by
    the levels above moves a grazing ray's hit by up to a step): the image the float64
    reference matches pixel for pixel (``exact=True``, ``krsview render --exact``)."""
    for knob, value in EXACT.items():
        scene = scene.edit(("render", knob), value)
    return scene
