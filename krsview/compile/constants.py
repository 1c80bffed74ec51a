"""Every number the GLSL in ``shaders/`` shares with Python, declared here once (or in its
home, imported here) and handed to every shader program as a ``#define`` of the same name
(:func:`glsl_defines`, added by ``gpu/program.py``'s builder). A shader never defines one of
these itself (the builder refuses, ``tests/test_constants.py`` scans every file); the buffer
layouts shared with the GPU are declared in ``compile/std430.py``."""

from __future__ import annotations

from ..scene import MAX_COMPONENTS
from ..scene.effects import MAX_EMPTY_ZONES
from ..scene.render import PREPASS_RATIO
from ..scene.scene import MAX_LIGHTS
from .krs import KERNEL_CODES, RECORD_VEC4

# Tracing [KRS17 Alg. 2] (reference/trace.py, trace.glsl, shadows.glsl, prepass.glsl)
INITIAL_PROBE = 1.0  # first probe radius of binary tracing, scene units [KRS17 Alg. 2 line 2]
# A blocked probe this small has converged even where ε(t) = 0 (an eye inside a solid): in
# exact arithmetic it would shrink forever; in float32 it underflowed to 0 within 100 probes.
MIN_PROBE = 1e-30
# A pre-pass cone stops once a blocked probe is no larger than this fraction of the cone's own
# width there (prepass.glsl): one cone's further probes spare its tile's 16 rays their first
# steps, so it pays to get closer than the width (docs/speed.md: 1 → 1/8 took the 16-level
# tree's primary rays from 1.89 to 1.45 iterations per pixel).
PREPASS_STOP = 0.125
# The walk restart's anchor sits at the deepest level whose fold margin and distance above are
# this many last steps' lengths: the next few steps fit under it (krs.glsl, krs_restart).
RESTART_KEEP = 8.0

# Shading (reference/occlusion.py, shade.py, atmosphere.py, texture.py and their shaders)
SHADOW_OFFSET = 2.0  # a shadow ray starts this many ε off the surface, along the normal
AO_SAMPLES = 5  # ambient occlusion's distance samples along the normal
GAMMA = 2.2
SUN_SHARPNESS = 600.0  # cosine power of the sky's glow towards the first light
TEXTURE_OCTAVES = 5
TEXTURE_OCTAVE_SHIFT = (17.0, 31.0)  # decorrelates the octaves
BARK_STRETCH = (0.25, 2.0)  # kernel texture: streaks long along a branch, fine around
GROUND_STRETCH = (0.25, 0.25)  # ... and a plane's patches as wide as a streak is long (the
# bark's streaks on a ground plane read as motion blur)

# The GPU's own (gpu/uniforms.py, gpu/renderer.py, gpu/display.py and their shaders)
MOBIUS_RECORD = 6  # vec4s per MöKRS level: a, b, c, d of H_i, its pole record, its bound
COMPUTE_GROUP = 64  # compute.comp's local size
# display.frag's views, in order (KRS_VIEW = VIEW_<MODE>; shaded: no define)
VIEW_MODES = ("shaded", "iterations", "depth", "normals")
PREPASS_TARGETS = -(-MAX_COMPONENTS // 4)  # RGBA32F targets of a coarse pass: 4 components each
# A coarse pass stores its tiles in four quarter images, blocks of PREPASS_BLOCK × PREPASS_BLOCK
# tiles alternating between them (prepass.glsl, coarse_texel; gpu/coarse.py), so
# that llvmpipe's threads share the cones and a SIMD group's tiles stay neighbours.
PREPASS_BLOCK = 8
# Storage buffer bindings: the scene block (KRS_DOUBLE) and the compute path's buffers.
BINDING_KRS_BLOCK = 0  # also the uniform block binding of KRSBlock in float
BINDING_RAYS = 1  # rays.glsl's Ray per pixel
BINDING_QUEUES = 2  # two queues of ray (or task) indices
BINDING_COUNTS = 3  # compute.comp's Counts: live rays per queue, the next dispatch's size
BINDING_SHADOWS = 4  # shadows.glsl's Shadow per pixel and light (KRS_SHADOW_TASKS)
BINDING_TASKS = 5  # a Ray per pixel and component (KRS_COMPONENT_TASKS)
BINDING_OUTLINE = 6  # upsampled.frag's list of outline pixels (gpu/passes.py)
BINDING_BLOCK_LIST = 7  # coarse_visibility.frag's list of blocks with shadow rays to trace
# compute.comp's u_phase: what one dispatch does
PHASE_START = 0  # start the rays (or component tasks) of the tile
PHASE_ROUND = 1  # a round of the rays
PHASE_SIZE = 2  # size the next round from the rays the last one left live
PHASE_SHADOW_START = 3  # start the shadow tasks
PHASE_SHADOW_ROUND = 4  # a round of the shadow tasks
PHASE_NEAREST = 5  # each pixel's nearest component task (KRS_COMPONENT_TASKS)
PHASE_LANES = 6  # persistent lanes: each takes the next pixel when its ray is done

GlslValue = int | float | tuple[float, ...]


def shared() -> dict[str, GlslValue]:
    """Name → value of every constant the shaders share with Python, each under its Python
    name; the kernel codes as ``KERNEL_<KIND>`` and the view modes as ``VIEW_<MODE>``."""
    return {
        **{f"KERNEL_{kind.upper()}": code for kind, code in KERNEL_CODES.items()},
        **{f"VIEW_{mode.upper()}": k for k, mode in enumerate(VIEW_MODES)},
        "RECORD_VEC4": RECORD_VEC4,
        "MOBIUS_RECORD": MOBIUS_RECORD,
        "MAX_COMPONENTS": MAX_COMPONENTS,
        "MAX_LIGHTS": MAX_LIGHTS,
        "MAX_EMPTY_ZONES": MAX_EMPTY_ZONES,
        "INITIAL_PROBE": INITIAL_PROBE,
        "MIN_PROBE": MIN_PROBE,
        "PREPASS_STOP": PREPASS_STOP,
        "RESTART_KEEP": RESTART_KEEP,
        "SHADOW_OFFSET": SHADOW_OFFSET,
        "AO_SAMPLES": AO_SAMPLES,
        "GAMMA": GAMMA,
        "SUN_SHARPNESS": SUN_SHARPNESS,
        "TEXTURE_OCTAVES": TEXTURE_OCTAVES,
        "TEXTURE_OCTAVE_SHIFT": TEXTURE_OCTAVE_SHIFT,
        "BARK_STRETCH": BARK_STRETCH,
        "GROUND_STRETCH": GROUND_STRETCH,
        "COMPUTE_GROUP": COMPUTE_GROUP,
        "PREPASS_TARGETS": PREPASS_TARGETS,
        "PREPASS_RATIO": PREPASS_RATIO,
        "PREPASS_BLOCK": PREPASS_BLOCK,
        "BINDING_KRS_BLOCK": BINDING_KRS_BLOCK,
        "BINDING_RAYS": BINDING_RAYS,
        "BINDING_QUEUES": BINDING_QUEUES,
        "BINDING_COUNTS": BINDING_COUNTS,
        "BINDING_SHADOWS": BINDING_SHADOWS,
        "BINDING_TASKS": BINDING_TASKS,
        "BINDING_OUTLINE": BINDING_OUTLINE,
        "BINDING_BLOCK_LIST": BINDING_BLOCK_LIST,
        "PHASE_START": PHASE_START,
        "PHASE_ROUND": PHASE_ROUND,
        "PHASE_SIZE": PHASE_SIZE,
        "PHASE_SHADOW_START": PHASE_SHADOW_START,
        "PHASE_SHADOW_ROUND": PHASE_SHADOW_ROUND,
        "PHASE_NEAREST": PHASE_NEAREST,
        "PHASE_LANES": PHASE_LANES,
    }


def glsl_literal(name: str, value: GlslValue) -> str:
    """``value`` as GLSL source: an int, a float that reads back the same (always with a
    point or an exponent, so GLSL sees a float), a tuple of 2–4 floats as a vecN."""
    if isinstance(value, bool) or not isinstance(value, (int, float, tuple)):
        raise TypeError(f"compile/constants.py: {name} = {value!r}: allowed: int, float, tuple")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        text = repr(value)
        return text if ("." in text or "e" in text) else text + ".0"
    if not 2 <= len(value) <= 4:
        raise TypeError(f"compile/constants.py: {name} = {value!r}: allowed: 2 to 4 floats")
    return f"vec{len(value)}({', '.join(glsl_literal(name, float(v)) for v in value)})"


def glsl_defines() -> dict[str, str]:
    """The shared constants as ``#define`` values, for every shader program."""
    return {name: glsl_literal(name, value) for name, value in shared().items()}
