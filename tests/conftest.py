"""Shared fixtures: one headless GL context per session, and the GPU-vs-reference comparison
with the tolerances every pixel test uses."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from krsview.bench import metrics
from krsview.bench.metrics import Agreement
from krsview.frame import Frame
from krsview.scene.presets import PRESET_DIR

TEST_OUTPUT = Path(__file__).resolve().parent.parent / "test-output"

# The GPU-vs-reference tolerances live in krsview.bench.metrics, with why each holds.


@pytest.fixture(scope="session")
def renderer():
    from krsview.gpu.renderer import Renderer

    return Renderer()


@pytest.fixture(scope="module")
def targets(renderer):
    """The passes' targets (gpu/passes.py) on the session's renderer."""
    from krsview.gpu.passes import Targets

    return Targets(renderer.ctx)


def per_pixel(scene):
    """``scene`` with a shadow ray per pixel: as the NumPy reference shades it (the GPU's
    shared shadow rays, ``[render] shadow_block`` > 1, are held to per-pixel ones by
    tests/test_passes.py)."""
    return scene.edit(("render", "shadow_block"), 1)


def preset_paths() -> list[Path]:
    return sorted(PRESET_DIR.glob("*.toml"))


# A sweep runs one check over every preset or hard case. `make test` (CI) runs each sweep's
# slice: a scene of every kind the check treats differently (a grown tree, a compound, a
# plane kernel, no balls, a MöKRS, the hard cases named); `KRSVIEW_SWEEP=full` runs them all.
FULL_SWEEP = os.environ.get("KRSVIEW_SWEEP") == "full"


def sweep(cases: list, slice_: set[str], name=str) -> list:
    """``cases`` as parameters, those whose ``name`` is outside ``slice_`` marked ``sweep``
    (deselected unless KRSVIEW_SWEEP=full). Every name in the slice must be a case."""
    names = {name(c) for c in cases}
    assert slice_ <= names, f"the slice names no case: {sorted(slice_ - names)}"
    return [c if name(c) in slice_ else pytest.param(c, marks=pytest.mark.sweep) for c in cases]


def pytest_collection_modifyitems(config, items):
    """Without KRSVIEW_SWEEP=full, the sweeps' cases outside their slice are deselected."""
    if FULL_SWEEP:
        return
    dropped = [item for item in items if item.get_closest_marker("sweep")]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = [item for item in items if not item.get_closest_marker("sweep")]


# The compute path's deferred shading and the fragment path's shading are separate stages:
# on a CPU rasteriser (llvmpipe, CI) they give the same colours bit for bit, but a GPU's
# compiler contracts their multiply-adds apart. On an H100 the colours differed by up to
# 8.2e-6 (far below 1/255), with hits, depths, normals and iterations bit for bit.
IMAGE_FIELDS = ("color", "depth", "normal", "iterations", "hit")
STAGE_COLOR_TOL = 1e-5


def same_field(a: np.ndarray, b: np.ndarray, name: str) -> bool:
    """Two paths' ``name`` arrays the same: bit for bit, but colours on a GPU within
    STAGE_COLOR_TOL."""
    from krsview.api import on_hardware

    if name == "color" and on_hardware():
        return a.shape == b.shape and bool(np.allclose(a, b, rtol=0, atol=STAGE_COLOR_TOL))
    return np.array_equal(a, b)


def same(a: Frame, b: Frame, fields: tuple[str, ...] = IMAGE_FIELDS) -> bool:
    """Two frames the same image (:func:`same_field`, field by field)."""
    return all(same_field(getattr(a, f), getattr(b, f), f) for f in fields)


failures = metrics.tolerance_failures
agreement = metrics.gpu_reference_agreement


def assert_finite(b: Frame, max_iterations: int, prepass: bool = False) -> None:
    """Finite pixels, and every ray traced within the cap: at least one step, or none where
    the pre-pass found its whole tile free up to the far limit."""
    for name in ("color", "depth", "normal"):
        assert np.isfinite(getattr(b, name)).all(), f"non-finite {name} pixels"
    assert b.iterations.max() <= max_iterations, "a ray exceeded the iteration cap"
    assert b.iterations.min() >= (0 if prepass else 1)


def save_diff(name: str, gpu: Frame, ref: Frame) -> Path:
    """GPU | reference | amplified difference, side by side, for a failing pixel test."""
    from PIL import Image

    TEST_OUTPUT.mkdir(exist_ok=True)
    diff = np.clip(np.abs(gpu.color - ref.color) * 10.0, 0, 1)
    diff[gpu.hit != ref.hit] = (1.0, 0.0, 1.0)
    strip = np.concatenate([gpu.rgb8(), ref.rgb8(), np.round(diff * 255).astype(np.uint8)], 1)
    path = TEST_OUTPUT / f"{name}.png"
    Image.fromarray(strip).save(path)
    return path


def check_against_reference(
    name: str, gpu: Frame, ref: Frame, ties: np.ndarray | None = None
) -> Agreement:
    a = agreement(gpu, ref, ties)
    problems = failures(a)
    if problems:
        path = save_diff(name, gpu, ref)
        pytest.fail(f"{name}: " + "; ".join(problems) + f" (images: {path})")
    return a


def fold_ties(scene, ref: Frame, ulps: float = 4.0) -> np.ndarray:
    """Hit pixels whose reference hit point lies within ``ulps`` float32 roundings (of its
    distance from the eye) of a mirror plane that a component's walk meets: which side the
    GPU's float32 folds it to is chance, and the two sides' normals are each other's mirror
    images (a crease). Left out of the pixel comparison, as outlines are."""
    from krsview.compile.camera import primary_rays, view_of
    from krsview.compile.geometry import compile_geometry
    from krsview.compile.krs import CompiledKRS
    from krsview.reference.distortion import Distortion
    from krsview.reference.krs import fold

    scene = scene.posed()
    h, w = ref.hit.shape
    view = view_of(scene.camera, w, h)
    t = ref.depth.reshape(-1)
    p = view.origin + t[:, None] * primary_rays(view)
    c = compile_geometry(scene.geometry(), scene.material.albedo)
    dist = Distortion.of(scene)
    ties = np.zeros(len(p), dtype=bool)
    for k, part in enumerate(getattr(c, "parts", (c,))):
        if isinstance(part, CompiledKRS):  # a MöKRS has no mirror planes
            x = p if dist is None else dist.undistort(p, k)
            for i in range(part.n - 1, -1, -1):
                x, e = fold(part.mirrors[i, :3], part.bounds[i, :3], x)
                ties |= np.abs(e) < ulps * 2.0**-23 * t
    return ties.reshape(h, w) & ref.hit


@pytest.fixture
def unfolded_hud(monkeypatch):
    """The viewer's HUD opens unfolded in any window (one narrower than two HUD widths opens
    it folded, hud.FOLDED_BELOW): for tests that read or type into it in a small window."""
    monkeypatch.setattr("krsview.viewer.hud.FOLDED_BELOW", 0.0)


@pytest.fixture(scope="session")
def display():
    """An X display: the session's own, or an Xvfb started for the window tests."""
    if os.environ.get("DISPLAY"):
        yield os.environ["DISPLAY"]
        return
    xvfb = shutil.which("Xvfb")
    assert xvfb, "Xvfb is needed for the window tests (`make deps` installs it)"
    # Xvfb picks a free display itself and writes its number once it accepts clients, so
    # test processes running side by side never share or race for one.
    read, write = os.pipe()
    proc = subprocess.Popen(
        [xvfb, "-displayfd", str(write), "-screen", "0", "1920x1200x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        pass_fds=(write,),
    )
    os.close(write)
    with os.fdopen(read) as number:
        n = number.readline().strip()
    assert n.isdigit(), f"Xvfb did not start (exit {proc.poll()})"
    os.environ["DISPLAY"] = f":{n}"
    yield f":{n}"
    del os.environ["DISPLAY"]
    proc.terminate()
    proc.wait(5)


def broken_shaders(tmp_path: Path, name: str, old: str, new: str) -> Path:
    """A copy of the shaders with ``old`` replaced by ``new`` in ``name`` (a negative
    control's deliberately broken shader); the folder to pass as ``shader_dir``."""
    import shutil

    from krsview.gpu.program import SHADER_DIR

    shaders = tmp_path / "shaders"
    shutil.copytree(SHADER_DIR, shaders)
    path = shaders / name
    text = path.read_text()
    assert old in text, f"{name} no longer holds {old!r}"
    path.write_text(text.replace(old, new))
    return shaders


def krsview_cli(
    *args: str, timeout: float = 300, cwd: Path | None = None, **env: str
) -> subprocess.CompletedProcess:
    """`krsview ARGS` in its own process, as a user runs it, headless (DISPLAY empty: EGL, no
    window; ``env``: more variables), its output as text."""
    return subprocess.run(
        [sys.executable, "-m", "krsview", *args],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=cwd,
        env={**os.environ, "DISPLAY": "", **env},
    )


def headless_render(scene, path: Path, size: tuple[int, int], *options: str) -> np.ndarray:
    """`krsview render [options]` in its own process (EGL, no window) of ``scene`` saved at
    ``path``.toml: what a user gets from the command line, for comparing with a window."""
    from PIL import Image

    from krsview.scene import save_scene

    save_scene(scene, path.with_suffix(".toml"))
    out = path.with_suffix(".png")
    r = krsview_cli(
        "render",
        str(path.with_suffix(".toml")),
        "-o",
        str(out),
        "--size",
        f"{size[0]}x{size[1]}",
        "--repeats",
        "1",
        *options,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr
    return np.asarray(Image.open(out).convert("RGB"))
