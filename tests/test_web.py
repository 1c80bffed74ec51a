"""Web page and Shadertoy export [issue 18 §1], checked in a real browser: Debian's chromium,
headless, WebGL2 on its SwiftShader rasteriser (one browser for the module, each page in a
fresh tab: tests/browser.py). Each screenshot is compared with `krsview render` (EGL,
llvmpipe) of the same view; the orbit is checked against cameras computed here
from the orbit formula, and every preset and hard case compiles as GLSL ES 3.00
(glslangValidator)."""

from __future__ import annotations

import functools
import json
import math
import shutil
import subprocess
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from krsview.bench.hard_cases import CASES
from krsview.scene import Camera, SceneError, load_scene, save_scene
from krsview.scene.presets import preset_names, resolve
from krsview.share import web_tracks
from krsview.share.web import export_notes, html_page, page_shader, shadertoy_source, web_shader
from krsview.share.web_tracks import PAGE_DATA_CAP, PAGE_RATE

from .browser import Browser
from .conftest import headless_render, krsview_cli, sweep

# one worker takes the module: one browser, and each moving preset's poses made once
pytestmark = pytest.mark.xdist_group("web")
SIZE = (160, 90)
# Shadertoy's own wrapper, as far as a shader sees it: the version, its uniforms, and a
# main that calls mainImage (iMouse released, iTime 0).
TOY_PAGE_SHADER = (
    "#version 300 es\nprecision highp float;\nprecision highp int;\n"
    "uniform vec3 iResolution;\nuniform float iTime;\nuniform vec4 iMouse;\n"
    "{body}\nout vec4 toy_out;\n"
    "void main() {{ mainImage(toy_out, gl_FragCoord.xy); }}\n"
)


@pytest.fixture(scope="module")
def browser():
    """One headless chromium for the module's screenshots (tests/browser.py)."""
    b = Browser(SIZE)
    yield b
    b.close()


def reference(scene, tmp_path: Path, name: str) -> np.ndarray:
    """`krsview render` of the scene (every level, no pre-pass: as the page draws it)."""
    return headless_render(scene, tmp_path / name, SIZE, "--exact").astype(int)


def agreement(a: np.ndarray, b: np.ndarray, tolerance: int) -> float:
    return float((np.abs(a - b).max(-1) <= tolerance).mean())


def export_page(scene, tmp_path: Path, name: str) -> Path:
    page = tmp_path / f"{name}.html"
    page.write_text(html_page(scene), encoding="utf-8")
    return page


@functools.cache
def preset_scene(name: str):
    """A preset, loaded once for the module: what its page computes is kept on it
    (web.page_shader), so a moving preset's poses (seconds) are made once."""
    return load_scene(resolve(name))


@functools.cache
def preset_html(name: str) -> str:
    return html_page(preset_scene(name))


def preset_page(name: str, tmp_path: Path) -> Path:
    page = tmp_path / f"{name}.html"
    page.write_text(preset_html(name), encoding="utf-8")
    return page


@pytest.mark.parametrize(
    "name", sweep(["tree", "palm", "grove", "sierpinski", "grass"], {"tree", "palm", "grove"})
)
def test_the_page_draws_what_krsview_render_draws(browser, name, tmp_path):
    """Colour within 16 of 255 on ≥ 97 % of pixels and a mean difference ≤ 2: two different
    software rasterisers round differently, which shows on sub-pixel leaves and blades."""
    scene = load_scene(resolve(name))
    shot = browser.shot(export_page(scene, tmp_path, name))
    ref = reference(scene, tmp_path, "ref")
    assert agreement(shot, ref, 16) >= 0.97 and np.abs(shot - ref).max(-1).mean() <= 2.0
    # negative control: the view a little turned is another picture
    turned = browser.shot(tmp_path / f"{name}.html", "bare&orbit=0.1,0,1")
    assert agreement(turned, ref, 16) < 0.95


def silhouette(scene):
    """The scene with flat colours: hits lit by ambient 1 alone (no lights, no effects),
    misses black, so a screenshot is its hit mask."""
    material = replace(scene.material, background=(0.0, 0.0, 0.0), ambient=(1.0, 1.0, 1.0))
    return replace(scene, effects=[], lights=[], material=material)


@pytest.mark.parametrize("name", ["tree", "palm"])
def test_the_page_hits_what_krsview_render_hits(browser, name, tmp_path):
    scene = silhouette(load_scene(resolve(name)))
    shot = browser.shot(export_page(scene, tmp_path, name))
    ref = reference(scene, tmp_path, "ref")
    hit_page, hit_ref = shot.max(-1) > 10, ref.max(-1) > 10
    assert 0.05 < hit_ref.mean() < 0.6
    assert (hit_page == hit_ref).mean() >= 0.99


def orbit_camera(scene, yaw: float, pitch: float, zoom: float) -> Camera:
    """The page's orbit, computed here: around the camera's target, y up, yaw 0 looking
    along +z (towards the target from −z), the distance scaled by zoom."""
    cam = scene.camera
    target, eye = np.array(cam.target), np.array(cam.position)
    away = (eye - target) / np.linalg.norm(eye - target)
    yaw0 = math.atan2(away[0], away[2])
    pitch0 = math.asin(away[1])
    y, p = yaw0 + yaw, pitch0 + pitch
    d = np.linalg.norm(eye - target) * zoom
    new_eye = target + d * np.array(
        [math.cos(p) * math.sin(y), math.sin(p), math.cos(p) * math.cos(y)]
    )
    return Camera(tuple(new_eye), cam.target, cam.up, cam.fov_y)


def test_the_orbit_moves_the_camera_as_the_formula_says(browser, tmp_path):
    scene = load_scene(resolve("tree"))
    assert scene.camera.up == (0.0, 1.0, 0.0)
    page = export_page(scene, tmp_path, "tree")
    shot = browser.shot(page, "bare&orbit=0.7,0.25,0.8")
    ref = reference(replace(scene, camera=orbit_camera(scene, 0.7, 0.25, 0.8)), tmp_path, "r")
    assert agreement(shot, ref, 16) >= 0.97
    assert agreement(shot, reference(scene, tmp_path, "still"), 16) < 0.8


def test_dragging_and_scrolling_orbit_and_zoom(browser, tmp_path):
    """The page's own pointer and wheel handlers, driven by events dispatched in the page:
    a drag of (−50, 20) pixels turns by 0.006 rad per pixel, a wheel of 223 zooms by
    e^(0.001·223) ≈ 1.25."""
    scene = load_scene(resolve("tree"))
    page = export_page(scene, tmp_path, "tree")
    events = """
<script>
const at = (x, y) => ({clientX: x, clientY: y, pointerId: 1, bubbles: true});
canvas.dispatchEvent(new PointerEvent("pointerdown", at(100, 40)));
canvas.dispatchEvent(new PointerEvent("pointermove", at(50, 60)));
canvas.dispatchEvent(new PointerEvent("pointerup", at(50, 60)));
canvas.dispatchEvent(new WheelEvent("wheel", {deltaY: 223, bubbles: true, cancelable: true}));
</script>
</body>"""
    page.write_text(page.read_text(encoding="utf-8").replace("</body>", events), encoding="utf-8")
    shot = browser.shot(page)
    yaw, pitch, zoom = 0.006 * 50, 0.006 * 20, math.exp(0.001 * 223)
    ref = reference(replace(scene, camera=orbit_camera(scene, yaw, pitch, zoom)), tmp_path, "r")
    assert agreement(shot, ref, 16) >= 0.97
    # negative control: the drag without the zoom is another view
    near = reference(replace(scene, camera=orbit_camera(scene, yaw, pitch, 1.0)), tmp_path, "n")
    assert agreement(shot, near, 16) < 0.95


def test_the_shadertoy_shader_draws_the_same_picture(browser, tmp_path):
    """The .glsl file inside Shadertoy's wrapper (version, iResolution, iTime 0, iMouse 0)."""
    scene = load_scene(resolve("palm"))
    page = export_page(scene, tmp_path, "palm")
    body = shadertoy_source(scene)
    assert "void mainImage(out vec4 fragColor, in vec2 fragCoord)" in body
    assert "#version" not in body
    assert not [line for line in body.splitlines() if line.lstrip().startswith("uniform")]
    text = page.read_text(encoding="utf-8")
    start = text.index("const FRAGMENT = ") + len("const FRAGMENT = ")
    end = text.index(";\nconst canvas")
    toy = page.with_name("toy.html")
    toy.write_text(
        text[:start]
        + json.dumps(TOY_PAGE_SHADER.format(body=body))
        + text[end:]
        .replace(
            'gl.getUniformLocation(program, "u_orbit")', 'gl.getUniformLocation(program, "iMouse")'
        )
        .replace(
            'gl.getUniformLocation(program, "u_canvas")',
            'gl.getUniformLocation(program, "iResolution")',
        )
        .replace("gl.uniform3fv(uOrbit, orbit);", "gl.uniform4f(uOrbit, 0, 0, 0, 0);")
        .replace("gl.uniform2f(uCanvas, w, h);", "gl.uniform3f(uCanvas, w, h, 1);"),
        encoding="utf-8",
    )
    shot = browser.shot(toy)
    ref = reference(scene, tmp_path, "ref")
    assert agreement(shot, ref, 16) >= 0.97


def glsl_es_errors(stages: dict[str, str], tmp_path: Path) -> str:
    """glslangValidator's complaints about fragment stages (file name → text), all in one
    run (each file compiled on its own; a complaint names its file); '' if all are valid."""
    for name, text in stages.items():
        (tmp_path / name).write_text(text, encoding="utf-8")
    r = subprocess.run(
        ["glslangValidator", "-S", "frag", *(str(tmp_path / name) for name in stages)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    return "" if r.returncode == 0 else r.stdout + r.stderr


def test_every_preset_and_hard_case_exports_valid_glsl_es(tmp_path):
    assert shutil.which("glslangValidator"), "glslang-tools is missing: `make deps`"
    scenes = [(n, preset_scene(n)) for n in preset_names()]
    scenes += [(f"hard-{c.name}", c.build()) for c in CASES.values()]
    stages, refused = {}, 0
    for name, scene in scenes:
        try:
            page, toy = web_shader(scene), shadertoy_source(scene)
        except SceneError as e:
            assert scene.render.precision == "double" and "no fp64" in str(e), name
            refused += 1
            continue
        stages[f"{name}.page.frag"] = page
        stages[f"{name}.posed.frag"] = page_shader(scene)[0]  # poses live
        stages[f"{name}.toy.frag"] = TOY_PAGE_SHADER.format(body=toy)
    exported = len(stages) // 3
    assert exported == len(scenes) - refused and exported > len(preset_names())
    assert glsl_es_errors(stages, tmp_path) == ""
    # negative control: the validator does reject what GLSL ES forbids, named by its file
    broken = web_shader(load_scene(resolve("tree"))).replace("precision highp float;", "")
    complaints = glsl_es_errors({**stages, "broken.frag": broken + "\ndouble x;"}, tmp_path)
    assert complaints.split("broken.frag\n", 1)[1].startswith("ERROR"), complaints[-2000:]


def test_export_on_the_command_line_and_its_refusals(tmp_path):
    def run(*a):
        return krsview_cli("export", *a, timeout=120)

    r = run("html", "tree", "-o", str(tmp_path / "t.html"), "--levels", "8")
    assert r.returncode == 0 and "wrote" in r.stdout, r.stderr
    r = run("shadertoy", "palm", "-o", str(tmp_path / "p.glsl"))
    assert r.returncode == 0 and (tmp_path / "p.glsl").read_text().count("mainImage") == 1
    r = run("html", "rock", "-o", str(tmp_path / "t.htm"))  # as export.html takes it
    assert r.returncode == 0 and (tmp_path / "t.htm").exists(), r.stderr
    bad = run("html", "tree", "-o", str(tmp_path / "t.txt"))
    assert (
        bad.returncode == 2 and "-o = " in bad.stderr and "must end in .html or .htm" in bad.stderr
    )
    deep = load_scene(resolve("tree"))
    save_scene(
        replace(deep, render=replace(deep.render, precision="double", prepass=8)),
        tmp_path / "deep.toml",
    )
    r = run("html", str(tmp_path / "deep.toml"), "-o", str(tmp_path / "d.html"))
    assert r.returncode == 2 and len(r.stderr.splitlines()) == 1
    assert "render.precision = 'double'" in r.stderr and "no fp64" in r.stderr
    assert not (tmp_path / "d.html").exists()
    save_scene(replace(deep, render=replace(deep.render, prepass=8)), tmp_path / "pre.toml")
    r = run("html", str(tmp_path / "pre.toml"), "-o", str(tmp_path / "p.html"))
    assert r.returncode == 0 and "note: render.prepass = 8" in r.stdout


def test_the_wind_tree_page_plays_and_holds_a_moment_as_render_draws_it(browser, tmp_path):
    """Issue 29: the page keeps the scene's time live (u_time, not baked): held at 1.5 s
    (#time=1.5) it hits what `krsview render --time 1.5` hits; held at 0 s, the crown stands
    elsewhere (the negative control)."""
    scene = silhouette(load_scene(resolve("tree-wind"))).with_effects(["wind"])
    page = export_page(scene, tmp_path, "wind")
    text = page.read_text(encoding="utf-8")
    assert "uniform float u_time;" in text and "const float u_time" not in text
    ref = reference(scene.at(1.5), tmp_path, "ref").max(-1) > 10
    held = browser.shot(page, "bare&time=1.5").max(-1) > 10
    still = browser.shot(page, "bare&time=0").max(-1) > 10
    assert (held == ref).mean() >= 0.99
    assert (still == ref).mean() < (held == ref).mean() - 0.002  # 0.9965 against 0.9999
    toy = shadertoy_source(scene)
    assert "u_time = mod(" in toy and "iTime" in toy


def page_parts(page: Path) -> tuple[str, object]:
    """The page's fragment stage and its poses, read back from the page's text."""
    text = page.read_text(encoding="utf-8")
    start = text.index("const FRAGMENT = ") + len("const FRAGMENT = ")
    fragment = json.loads(text[start : text.index(";\nconst canvas")])
    start = text.index("const POSES = ") + len("const POSES = ")
    return fragment, json.loads(text[start : text.index(";\nlet rows")])


@pytest.mark.parametrize(
    "name, t1, t2",
    [("palm-curl", 1.0, 2.0), ("tree-growing", 3.0, 7.5), ("tree-sway+wind", 1.25, 0.0)],
)
def test_a_moving_page_holds_each_moment_as_render_draws_it(browser, name, t1, t2, tmp_path):
    """Issue 29: the page poses tracks and sway at every 1/24 s (palm-curl: its Möbius steps;
    tree-growing: levels added, so the slots grow, and the camera's tracks moving the orbit;
    tree-sway in the wind: sway and u_time together). Held at T (#time=T) the page draws what
    `krsview render --time T` draws, within the still pages' tolerance, and half a pose
    later it still shows that pose (a whole pose later, the next); held at T1 it is not the
    render at T2 (the negative control)."""
    base, wind = name.split("+") if "+" in name else (name, None)
    scene = load_scene(resolve(base))
    if wind:
        scene = scene.with_effects([*scene.effects, wind])
    page = export_page(scene, tmp_path, base) if wind else preset_page(base, tmp_path)
    fragment, poses = page_parts(page)
    assert poses["rate"] == PAGE_RATE and fragment != web_shader(scene)
    assert ("u_time;" in fragment) == bool(wind)
    shots = {t: browser.shot(page, f"bare&time={t:g}") for t in (t1, t2)}
    refs = {t: reference(scene.at(t), tmp_path, f"ref{t}") for t in (t1, t2)}
    for t in (t1, t2):
        assert agreement(shots[t], refs[t], 16) >= 0.97, t
        assert np.abs(shots[t] - refs[t]).max(-1).mean() <= 2.0, t
    assert agreement(shots[t1], refs[t2], 16) < 0.97
    assert np.abs(shots[t1] - refs[t2]).max(-1).mean() > 2.0
    if base == "palm-curl":  # between two poses the page shows the one before, never a blend
        between = browser.shot(page, f"bare&time={t1 + 0.5 / PAGE_RATE}")
        after = browser.shot(page, f"bare&time={t1 + 1 / PAGE_RATE}")
        assert np.array_equal(between, shots[t1]) and not np.array_equal(after, shots[t1])


def test_the_moving_page_plays(browser, tmp_path):
    """Opened without #time, palm-curl's page plays its loop: after 0.5 s and 2 s of the
    page's clock it shows other poses. Negative control: held (#time=1) it stands."""
    page = preset_page("palm-curl", tmp_path)
    a, b = (browser.shot(page, "bare", ms) for ms in (500, 2000))
    assert agreement(a, b, 16) < 0.97
    c, d = (browser.shot(page, "bare&time=1", ms) for ms in (500, 2000))
    assert np.array_equal(c, d)


@pytest.mark.parametrize("name", ["tree", "tree-wind", "palm"])
def test_a_page_without_tracks_is_the_baked_page(name, tmp_path):
    """A scene without tracks or sway exports the still page's shader, string for string
    (web_shader: every value a constant, the path Shadertoy keeps), no poses and no uniform
    but the page's own and the clock. Negative control: palm-curl's page is not its baked
    shader, and uploads its Möbius records as a uniform block."""
    scene = load_scene(resolve(name))
    fragment, poses = page_parts(export_page(scene, tmp_path, name))
    assert fragment == web_shader(scene) and poses is None
    uniforms = {line.split()[2] for line in fragment.splitlines() if line.startswith("uniform")}
    assert uniforms == {"u_orbit;", "u_canvas;"} | ({"u_time;"} if "wind" in name else set())
    moving = load_scene(resolve("palm-curl"))
    fragment, poses = page_parts(preset_page("palm-curl", tmp_path))
    assert fragment != web_shader(moving) and poses["block"] > 0
    assert "layout(std140) uniform KRSBlock {\n    vec4 u_mobius[" in fragment


def test_every_moving_preset_fits_the_cap_and_a_lower_cap_lowers_the_rate(tmp_path, monkeypatch):
    """Each moving preset's poses stay under PAGE_DATA_CAP at PAGE_RATE a second. Under a cap
    of two thirds of palm-curl's poses (the negative control: they would not fit), the page
    keeps every other pose, 12 a second, under that cap, and its notes say so."""
    moving = [n for n in preset_names() if preset_scene(n).animation is not None]
    moving = [n for n in moving if preset_scene(n).animation.moves]
    assert {"palm-curl", "tree-sway", "tree-growing"} <= set(moving)
    full = {}
    for name in moving:
        full[name] = page_parts(preset_page(name, tmp_path))[1]
        assert full[name]["rate"] == PAGE_RATE and len(full[name]["data"]) <= PAGE_DATA_CAP, name
    cap = len(full["palm-curl"]["data"]) * 2 // 3
    monkeypatch.setattr(web_tracks, "PAGE_DATA_CAP", cap)
    curl = load_scene(resolve("palm-curl"))  # a new scene: nothing of its page cached yet
    poses = page_parts(export_page(curl, tmp_path, "capped"))[1]
    assert poses["rate"] == PAGE_RATE / 2 and poses["count"] == full["palm-curl"]["count"] // 2
    assert len(poses["data"]) <= cap
    assert any("play as 12 poses a second" in n for n in export_notes(curl))


def test_a_track_that_switches_the_variant_is_baked_and_said(tmp_path):
    """A track that changes what is compiled (the tracer) cannot play in one variant: the
    page draws the exported moment, with the still page's shader, and the note says why.
    Negative control: a track on a value (the iteration cap) plays as a live uniform."""
    tree = load_scene(resolve("tree"))
    keyed = tree.edit(
        "animation",
        {
            "duration": 1.0,
            "tracks": [{"path": "render.tracer", "keys": [[0.0, "sphere"], [0.5, "binary"]]}],
        },
    )
    fragment, poses = page_parts(export_page(keyed, tmp_path, "keyed"))
    assert fragment == web_shader(keyed) and poses is None
    (note,) = [n for n in export_notes(keyed) if "tracks" in n]
    assert "drawn as at t = 0 s: the variant changes at t = 0.5 s (KRS_TRACER_BINARY)" in note
    capped = tree.edit(
        "animation",
        {
            "duration": 1.0,
            "tracks": [{"path": "render.max_iterations", "keys": [[0.0, 64], [0.5, 256]]}],
        },
    )
    fragment, poses = page_parts(export_page(capped, tmp_path, "capped"))
    assert "uniform int u_max_iterations;" in fragment and poses["count"] == 24
    assert [u[0] for u in poses["uniforms"]] == ["u_max_iterations"] and poses["block"] == 0
    toy = shadertoy_source(capped)
    assert "// note: keyframe tracks and sway are drawn as at t = 0 s (Shadertoy" in toy


def test_the_page_shows_its_notes_to_the_exporter_not_in_its_caption():
    """The caption carried "render.lod = 0.5: the page draws every level …" over half of
    a small window, for a default nobody set [review]; the notes are the command's output
    and a comment at the top of the page."""
    scene = load_scene(resolve("sierpinski"))
    notes = export_notes(scene)
    page = html_page(scene)
    caption = page[page.index('<div id="help">') : page.index("</div>", page.index('id="help"'))]
    assert notes and all(n not in caption for n in notes) and "drag to orbit" in caption
    head = page[: page.index("-->")]
    assert all(f"Note: {n}" in head for n in notes)
    toy = export_notes(scene, shadertoy=True)  # a shader's notes speak of the shader
    assert toy and all("the page" not in n for n in toy) and "the shader draws" in toy[-1]
    assert any("the page draws every level" in n for n in notes)  # control
