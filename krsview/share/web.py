"""`krsview export html|shadertoy`: the scene's own specialised tracer in GLSL ES 3.00 for
WebGL2 [issue 18 §1]. The fragment stage is assembled from the app's shader files
(``web.frag`` includes the same tracer and shading as ``render.frag``) with the scene's
defines; then every uniform the renderer would upload is baked into a constant, relative to
the exported camera's eye O, and the camera's uniforms become globals that
``orbit_camera`` sets from the mouse. The page is one file with no server or network; the
Shadertoy file is one ``mainImage``. Time: ``u_time`` stays live (the wind plays); keyframe
tracks and sway play on the page as poses sampled over the loop (``web_tracks.py``), and
Shadertoy, which runs no script, draws them as at the exported moment.

What cannot be exported: double precision (GLSL ES has no fp64). The compute path and the
pre-pass are speed-ups of the desktop renderer (a storage buffer, float render targets): the
page traces every pixel in one fragment pass, the same surfaces."""

from __future__ import annotations

import html
import json
import re
from importlib import resources

import numpy as np

from ..gpu.program import ES_HEADER, Source
from ..gpu.uniforms import block_arrays
from ..scene import Scene, SceneError
from ..scene.edits import parse_path
from ..scene.schema import cached
from .web_tracks import live_names, moment, page_poses, sample

# Set per pixel by orbit_camera (web.frag): declared as plain globals.
CAMERA = (
    "u_eye_shift",
    "u_forward",
    "u_right",
    "u_up",
    "u_resolution",
    "u_footprint",
    "u_detail_footprint",
    "u_eps_per_t",
)
PAGE = ("u_orbit", "u_canvas")  # the page's own uniforms (Shadertoy has iMouse instead)
CLOCK = "u_time"  # the moment drawn: live on the page, Shadertoy's iTime in mainImage
_UNIFORM = re.compile(r"^\s*uniform\s+(\w+)\s+(\w+)\s*(\[\s*(\w+)\s*\])?\s*;.*$", re.M)
_BLOCK = re.compile(r"layout\(std140\) uniform KRSBlock \{.*?\};", re.S)
_REAL = {"real": "float", "vec2r": "vec2", "vec3r": "vec3", "vec4r": "vec4", "mat3r": "mat3"}


def refuse(scene: Scene) -> None:
    """A scene that cannot be exported at all is a SceneError naming the field."""
    if scene.render.precision == "double":
        raise SceneError(
            "render.precision",
            "double",
            "a web page or Shadertoy cannot draw "
            "it: GLSL ES 3.00 (WebGL2) has no fp64; export with precision = "
            '"float"',
        )


def export_notes(scene: Scene, shadertoy: bool = False) -> list[str]:
    """What the page (or, ``shadertoy``, the Shadertoy file) leaves out, one line each; a
    scene that cannot be exported at all is a SceneError naming the field."""
    refuse(scene)
    r, it = scene.render, "the shader" if shadertoy else "the page"
    notes = []
    if r.path == "compute":
        notes.append(
            f'render.path = "compute": {it} traces in one fragment pass '
            "(WebGL2 has no compute shaders; the same image)"
        )
    if r.prepass:
        notes.append(
            f"render.prepass = {r.prepass}: {it} traces without the pre-pass "
            "(the same surfaces, a slower frame)"
        )
    if r.lod:
        notes.append(
            f"render.lod = {r.lod:g}: {it} draws every level (its orbiting eye moves "
            "away from the origin the level of detail is measured from)"
        )
    a = scene.animation
    if a is not None and a.moves:
        notes += _moving_notes(scene, shadertoy)
    return notes


def _moving_notes(scene: Scene, shadertoy: bool) -> list[str]:
    """How the export carries keyframe tracks and sway (export_notes)."""
    at = f"keyframe tracks and sway are drawn as at t = {scene.time:g} s"
    if shadertoy:
        return [
            f"{at} (Shadertoy runs no script to change the baked geometry; only effects "
            "that read time play)"
        ]
    poses = page_shader(scene)[1]
    notes = []
    if isinstance(poses, str):
        notes.append(
            f"{at}: {poses} (the page bakes the geometry; only effects that read time play)"
        )
    elif poses is not None:
        notes.append(
            f"keyframe tracks and sway play as {poses['rate']:g} poses a second, each shown "
            "until the next (exact poses, never blended)"
        )
    if isinstance(poses, str) and any(
        parse_path(tr.path)[0] == "camera" for tr in scene.animation.tracks
    ):
        notes.append(f"the camera stays where its tracks put it at t = {scene.time:g} s")
    return notes


def web_shader(scene: Scene, shadertoy: bool = False) -> str:
    """The fragment stage of the page (``#version 300 es``), or Shadertoy's body (Shadertoy
    adds the version, precision and its uniforms), with tracks and sway baked as at the
    scene's time: a still scene's page, and Shadertoy's."""
    refuse(scene)
    m = moment(scene, np.array(scene.posed().camera.position, dtype=np.float64))
    if shadertoy:
        m.defines["KRS_SHADERTOY"] = None
    text = Source("web.frag", m.defines, header=() if shadertoy else ES_HEADER).text
    blocks = block_arrays(m.compiled, "float", len(m.compiled.records))
    return _specialise(text, m.values, blocks, shadertoy)


def page_shader(scene: Scene) -> tuple[str, dict | str | None]:
    """The page's fragment stage and its poses: the page's POSES (web_tracks.page_poses),
    or why the page draws tracks and sway as at the scene's time, or None where nothing
    moves. Made once per scene (html_page and export_notes both ask)."""
    return cached(scene, "_web_page", lambda: _page_shader(scene))


def _page_shader(scene: Scene) -> tuple[str, dict | str | None]:
    refuse(scene)
    if scene.animation is None or not scene.animation.moves:
        return web_shader(scene), None
    poses = sample(scene)
    if isinstance(poses, str):
        return web_shader(scene), poses
    text = Source("web.frag", poses.defines, header=ES_HEADER).text
    declared = {
        m.group(2): _REAL.get(m.group(1), m.group(1))
        for m in _UNIFORM.finditer(text)
        if m.group(2) in poses.values[0] and m.group(2) not in (*CAMERA, CLOCK, *PAGE)
    }
    block, live = live_names(poses, declared)
    if not block and not live:
        return web_shader(scene), None
    data = page_poses(poses, block, {n: declared[n] for n in live})
    if isinstance(data, str):
        return web_shader(scene), data
    return _specialise(text, poses.values[0], poses.blocks[0], False, block, live), data


def _specialise(text: str, values: dict, blocks: dict, shadertoy: bool, block=(), live=()) -> str:
    """``text`` with every uniform and KRSBlock array baked into a constant, but the
    camera's (globals), the clock and the page's own, and the ``block`` arrays and ``live``
    uniforms the page uploads at each pose."""

    def krs_block(m: re.Match) -> str:
        out = [const_array("vec4", k, v) for k, v in blocks.items() if k not in block]
        if block:
            members = "".join(f"    vec4 {k}[{len(blocks[k])}];\n" for k in block)
            out.append(f"layout(std140) uniform KRSBlock {{\n{members}}};")
        return "\n".join(out)

    text = _BLOCK.sub(krs_block, text)
    return _UNIFORM.sub(lambda m: _bake(m, values, shadertoy, live), text)


def _bake(m: re.Match, values: dict, shadertoy: bool, live=()) -> str:
    kind, name, count = _REAL.get(m.group(1), m.group(1)), m.group(2), m.group(4)
    if name in live:
        return f"uniform {kind} {name}{m.group(3) or ''};"
    if name in CAMERA or (name == CLOCK and shadertoy):
        return f"{kind} {name}{m.group(3) or ''};"
    if name == CLOCK:
        return m.group(0)
    if name in PAGE and not shadertoy:
        return m.group(0)
    if name not in values:
        raise RuntimeError(f"web export: no value for uniform {name} (web.py, values)")
    if count is None:
        return f"const {kind} {name} = {literal(kind, values[name])};"
    return const_array(kind, name, values[name])


def const_array(kind: str, name: str, rows) -> str:
    rows = list(rows)
    if kind.startswith("vec") and rows and np.ndim(rows[0]) == 0:
        rows = [rows]  # an array of one vector, uploaded as the vector (u_wind_base of a KRS)
    items = ",\n    ".join(literal(kind, r) for r in rows)
    return f"const {kind} {name}[{len(rows)}] = {kind}[{len(rows)}](\n    {items});"


def literal(kind: str, value) -> str:
    """A GLSL ES constant of type ``kind`` (float32 values written to round-trip)."""
    flat = np.atleast_1d(np.asarray(value, dtype=np.float64)).ravel()
    if not np.isfinite(flat).all():
        raise RuntimeError(f"web export: a {kind} constant is not finite: {value!r}")
    if kind in ("int", "ivec2", "ivec3", "ivec4", "bool"):
        parts = [str(int(v)) for v in flat] if kind != "bool" else [str(bool(flat[0])).lower()]
    else:
        parts = [_float(v) for v in flat]
    return parts[0] if kind in ("int", "float", "bool") else f"{kind}({', '.join(parts)})"


def _float(v: float) -> str:
    text = format(float(np.float32(v)), ".9g")
    return text if ("." in text or "e" in text) else text + ".0"


def vertex_shader() -> str:
    """The app's full-screen triangle, in GLSL ES."""
    return Source("fullscreen.vert", {}, header=ES_HEADER).text


def html_page(scene: Scene) -> str:
    """One self-contained page: canvas, the two shaders, the poses of its tracks and sway
    (page_shader), and a few lines of WebGL2."""
    template = resources.files("krsview.share").joinpath("page.html").read_text("utf-8")
    notes = export_notes(scene)
    fragment, poses = page_shader(scene)
    return (
        template.replace("{{TITLE}}", html.escape(f"krsview — {scene.name}"))
        .replace("{{NOTES}}", "\n".join(f"Note: {n}" for n in notes).replace("--", "- -"))
        .replace("{{TIME}}", json.dumps(scene.time))
        .replace("{{DURATION}}", json.dumps(scene.duration))
        .replace("{{VERTEX}}", json.dumps(vertex_shader()))
        .replace("{{FRAGMENT}}", json.dumps(fragment))
        .replace("{{POSES}}", json.dumps(poses if isinstance(poses, dict) else None))
    )


def shadertoy_source(scene: Scene) -> str:
    """The scene as one Shadertoy ``mainImage``: drag the mouse to orbit (x: around, y: up
    and down), and the view turns slowly with time."""
    head = (
        f"// krsview — {scene.name}: a Kernel–Reflection Sequence scene exported by "
        "`krsview export shadertoy` [KRS17].\n// Drag to orbit; the view turns slowly "
        "with time.\n"
    )
    notes = "".join(f"// note: {n}\n" for n in export_notes(scene, shadertoy=True))
    body = web_shader(scene, shadertoy=True)
    clock = f"mod({_float(scene.time)} + iTime, {_float(scene.duration)})"
    plays = f"    {CLOCK} = {clock};  // the scene's time, round its loop\n"
    main = SHADERTOY_MAIN.replace("    PLAYS\n", plays if CLOCK in body else "")
    return head + notes + body + main


SHADERTOY_MAIN = """
void mainImage(out vec4 fragColor, in vec2 fragCoord) {
    PLAYS
    vec3 orbit = vec3(0.05 * iTime, 0.0, 1.0);
    if (iMouse.z > 0.0) orbit.xy += vec2(-6.0, 3.0) * (iMouse.xy / iResolution.xy - 0.5);
    orbit_camera(iResolution.xy, orbit);
    fragColor = krs_image(fragCoord);
}
"""
