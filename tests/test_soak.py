"""Soak: a long session in the real viewer — flying (the adaptive resolution visits many image
sizes), variant switches and hot reloads — keeps GL objects and process memory flat
[issue 16]. On llvmpipe textures live in the process, so its resident memory covers them.

CI runs a slice; `KRSVIEW_SOAK=full pytest -m soak -s` runs 3000 frames, 200 variant
switches and 100 hot reloads and prints the figures."""

from __future__ import annotations

import os
import shutil
import time
from dataclasses import replace
from pathlib import Path

import pytest

from krsview.scene import load_scene, save_scene
from krsview.scene.presets import resolve

FULL = os.environ.get("KRSVIEW_SOAK") == "full"
FRAMES, SWITCHES, RELOADS = (3000, 200, 100) if FULL else (300, 12, 2)
pytestmark = pytest.mark.soak


def rss_mb() -> float:
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS")


KEYS = ["W", "A", "S", "D", "Q", "E"]


def fly(v, frames: int, start: int = 0) -> None:
    """Hold each flying key for 25 frames in turn (frame numbers from ``start``)."""
    for k in range(start, start + frames):
        key = KEYS[(k // 25) % len(KEYS)]
        if k % 25 == 0:
            for other in KEYS:
                v.input.key(other, False)
            v.input.key(key, True)
        v.step(0.03)
    for other in KEYS:
        v.input.key(other, False)


@pytest.fixture
def long_viewer(display, tmp_path):
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=(160, 120), hud=False)
    yield v
    v.close()


def test_a_long_session_keeps_gl_objects_and_memory_flat(long_viewer):
    v = long_viewer
    r = v.renderer
    fly(v, 60)  # warm-up: variants and targets exist
    for on in (True, False):
        v.set_effect("fog", on)
        v.step(0.03)
    base, sizes_seen = rss_mb(), set()
    for k in range(FRAMES):
        if k % 100 == 0:  # alternate budgets: the image size keeps changing
            v.set_target_fps(240 if (k // 100) % 2 == 0 else 5)
        fly(v, 1, k)
        sizes_seen.add(v.frames.image[1] if v.frames.image else None)
        if k % max(1, FRAMES // SWITCHES) == 0:
            v.set_effect("fog", (k // max(1, FRAMES // SWITCHES)) % 2 == 0)
            v.set_render(tracer="binary" if k % 2 else "sphere")
        if RELOADS and k % max(1, FRAMES // RELOADS) == 0:
            scene = load_scene(v.path)
            shade = 0.1 + 0.5 * ((k // max(1, FRAMES // RELOADS)) % 2)
            save_scene(
                replace(scene, material=replace(scene.material, background=(shade, shade, shade))),
                v.path,
            )
            time.sleep(0.6)  # the reload watches modification times
            v.step(0.3)
            v.step(0.3)
    grown = rss_mb() - base
    print(
        f"\nsoak: {FRAMES} frames, {len(sizes_seen)} image sizes, {SWITCHES} switches, "
        f"{RELOADS} reloads: RSS {base:.0f} → {base + grown:.0f} MB, "
        f"{len(r._targets)} render targets, {len(r.programs._programs)} programs"
    )
    assert len(sizes_seen) > 8  # flying really visited many sizes
    from krsview.gpu.renderer import MAX_TARGETS

    assert len(r._targets) <= MAX_TARGETS
    # sphere/binary × fog on/off, each: the trace, its pre-pass, the pre-pass's free tiles,
    # the blocks' list and their shadow rays, the hits' depth, the sky's and the hits'
    # shading, the outline pixels; + the display program
    assert len(r.programs._programs) <= 2 * 2 * 9 + 1
    assert grown < 60, f"resident memory grew by {grown:.0f} MB"
    assert not v.error


def test_without_the_target_limit_flying_leaks_render_targets(long_viewer, monkeypatch):
    """Negative control: with no limit on kept sizes, every size flown through stays."""
    from krsview.gpu import renderer

    monkeypatch.setattr(renderer, "MAX_TARGETS", 10**6)
    for fps in (240, 5, 240, 5):  # make the adaptive resolution walk down and up
        long_viewer.set_target_fps(fps)
        fly(long_viewer, 60)
    assert len(long_viewer.renderer._targets) > 8
