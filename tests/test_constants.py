"""What GLSL and Python share is declared once: the constants (compile/constants.py, given to
every program as defines), the storage buffers' structs (compile/std430.py, their std430
sizes checked against the driver's), the twin pointers in comments, and the twin functions'
names (the table below maps those that differ)."""

from __future__ import annotations

import ast
import ctypes
import re
from dataclasses import replace
from pathlib import Path

import pytest

from krsview.compile import constants
from krsview.compile.std430 import COUNTS, RAY, SHADOW, Field, Struct, base_type
from krsview.gpu.program import SHADER_DIR, SHARED, ShaderError, Source
from krsview.scene import load_scene
from krsview.scene.presets import resolve

PACKAGE = SHADER_DIR.parent
SHADERS = sorted(
    p for p in SHADER_DIR.iterdir() if p.suffix in (".glsl", ".frag", ".comp", ".vert")
)
_DEFINE = re.compile(r"^\s*#\s*define\s+(\w+)", re.M)


def own_defines(text: str) -> set[str]:
    """The shared names a shader source defines itself."""
    return set(_DEFINE.findall(text)) & set(SHARED)


def test_no_shader_defines_a_shared_constant():
    found = {p.name: own_defines(p.read_text()) for p in SHADERS}
    assert {k: v for k, v in found.items() if v} == {}
    # negative control: a copy typed into a shader is found, and the builder refuses it
    assert own_defines("// ao\n  #define AO_SAMPLES 5\n#define LOCAL 1\n") == {"AO_SAMPLES"}


def test_builder_refuses_a_shared_constant_defined_again(tmp_path):
    (tmp_path / "a.frag").write_text('#include "b.glsl"\nvoid main() {}\n')
    (tmp_path / "b.glsl").write_text("#define LOCAL 2\n#  define MAX_LIGHTS 4\n")
    with pytest.raises(ShaderError, match=r"b\.glsl:2: #define MAX_LIGHTS"):
        Source("a.frag", {}, tmp_path)
    with pytest.raises(ShaderError, match="GAMMA shared with Python"):
        Source("a.frag", {"GAMMA": 2.0}, tmp_path)
    (tmp_path / "b.glsl").write_text("#define LOCAL 2\n")
    text = Source("a.frag", {}, tmp_path).text  # control: the same file without the copy
    assert "#define MAX_LIGHTS 4\n" in text and "#define AO_SAMPLES 5\n" in text


def test_every_shared_constant_is_used_by_a_shader():
    """A name in the table is shared: some shader reads it (an enumeration: some member)."""
    words = set(re.findall(r"\w+", " ".join(p.read_text() for p in SHADERS)))
    families = ("KERNEL_", "VIEW_", "PHASE_", "BINDING_")
    unused = {
        name
        for name in SHARED
        if not (name.startswith(families) and any(n in words for n in SHARED if n[:5] == name[:5]))
        and name not in words
    }
    assert unused == set()
    assert "NOT_IN_A_SHADER" not in words  # control: an unused name would be found


def test_glsl_values_are_the_python_values():
    """Each define reads back as its Python value (floats as floats, pairs as vec2)."""
    for name, value in constants.shared().items():
        text = SHARED[name]
        if isinstance(value, tuple):
            assert text == f"vec{len(value)}({', '.join(repr(float(v)) for v in value)})"
        else:
            assert type(value)(text) == value and (
                isinstance(value, int) or "." in text or "e" in text
            )
    assert SHARED["KERNEL_TOROIDAL_CAPSULE"] == "3" and SHARED["VIEW_DEPTH"] == "2"
    with pytest.raises(TypeError, match="X = 'a'"):
        constants.glsl_literal("X", "a")  # control: a value GLSL cannot take


def module_constants(path: Path) -> set[str]:
    """Upper-case names a Python module assigns at its top level."""
    out = set()
    for node in ast.parse(path.read_text()).body:
        targets = node.targets if isinstance(node, ast.Assign) else [getattr(node, "target", None)]
        out |= {t.id for t in targets if isinstance(t, ast.Name) and t.id.isupper()}
    return out


# The one home of each shared name declared outside compile/constants.py.
HOMES = {
    "RECORD_VEC4": "compile/krs.py",
    "KERNEL_CODES": "compile/krs.py",
    "MAX_COMPONENTS": "scene/compound.py",
    "MAX_LIGHTS": "scene/scene.py",
    "MAX_EMPTY_ZONES": "scene/effects.py",
    "PREPASS_RATIO": "scene/render.py",
}


def test_python_declares_each_shared_constant_once():
    names = set(SHARED) | {"KERNEL_CODES", "VIEW_MODES"}
    where: dict[str, list[str]] = {}
    for path in PACKAGE.rglob("*.py"):
        for name in module_constants(path) & names:
            where.setdefault(name, []).append(path.relative_to(PACKAGE).as_posix())
    homes = {name: [HOMES.get(name, "compile/constants.py")] for name in where}
    assert where == homes
    assert module_constants(Path(constants.__file__)) >= {"AO_SAMPLES", "MIN_PROBE"}  # control


# --- twin pointers -------------------------------------------------------------------------

_POINTER = re.compile(r"(?<![\w/.])([\w/]+\.(?:py|glsl|frag|comp|vert))(?:'s |, )?(\w+)?")


def comments(text: str) -> str:
    """A shader's comments, joined into one text (a pointer may wrap onto the next line)."""
    return " ".join(m.group(1) for m in re.finditer(r"//\s?(.*)", text))


def dangling(text: str) -> list[str]:
    """Pointers to files that do not exist (.py under krsview/, shaders in shaders/), or to a
    name (``file.py's name``, ``file.py, name``) that the file does not define."""
    out = []
    for m in _POINTER.finditer(text):
        rel, name = m.group(1), m.group(2)
        path = PACKAGE / rel if rel.endswith(".py") else SHADER_DIR / Path(rel).name
        if not path.is_file():
            out.append(rel)
        elif name and rel.endswith(".py") and name not in defined_names(path):
            out.append(f"{rel}'s {name}")
    return out


def defined_names(path: Path) -> set[str]:
    """Functions, classes and upper-case constants a module defines, or imports."""
    tree = ast.parse(path.read_text())
    out = module_constants(path)
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            out.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            out |= {a.asname or a.name for a in node.names}
    return out


def test_twin_pointers_name_files_that_exist():
    bad = {p.name: dangling(comments(p.read_text())) for p in SHADERS}
    for path in (PACKAGE / "reference").glob("*.py"):  # the NumPy side's pointers back
        docs = " ".join(re.findall(r"``(shaders/[\w.]+)``", path.read_text()))
        bad[path.name] = dangling(docs)
    assert {k: v for k, v in bad.items() if v} == {}
    # negative controls: a moved file, a misspelt shader, a name the module lacks
    assert dangling(comments("// twin of reference/effects.py and trace.glsl.")) == [
        "reference/effects.py"
    ]
    assert dangling("shaders/trace.glsl shaders/traces.glsl") == ["shaders/traces.glsl"]
    assert dangling("(reference/mokrs.py, level_bounds) compile/mokrs.py's level_bounds") == [
        "reference/mokrs.py's level_bounds"
    ]


# --- twin names ----------------------------------------------------------------------------

# GLSL functions (``file.glsl:name`` for one file's only) whose NumPy twin has another name,
# in the modules the shader's "twin of" names or ("module.py:name") elsewhere, and those
# with no twin (None), with why.
TWIN_NAMES: dict[str, str | None] = {
    "mokrs.glsl:lod_scale": None,  # 1, or the wind's one factor (wind_lod_scale)
    "wind_lod_scale": "lod_scale",  # reference/wind.py, Wind.lod_scale
    "capsule_core": "core_point",  # one core_point for every kind
    "toroidal_capsule_core": "core_point",
    "toroidal_capsule_distance": "kernel_distance",  # one kernel_distance for every kind
    "kernel_distance_of": "kernel_distance",  # the same, for the kinds of a bit mask
    "kernel_rec": None,  # reads the uniform block: NumPy indexes the records
    "kernel_rec_float": None,
    "krs_distance": "distance",  # reference/krs.py is the KRS's module: no prefix
    "krs_nearest": "nearest",
    "fold_frame": "nearest",  # one level of nearest's loop
    "krs_level": "distance",  # one level of distance's loop
    "krs_lod_cut": "distance",  # the level-of-detail ball of distance's loop, after the walk
    "krs_restart": "restart",
    "restart_distance": "restart_trace",  # a restarted step, inside the tracer's loop
    "distort_distance": "distance",  # Distortion.distance
    "undistorted_distance": "reference/geometry.py:component_distances",
    "component_distance_at": "component_distance",  # ρ given: component_distance's lod, reach
    "lod_radius": "reference/geometry.py:Lod",  # Lod.radius
    "krs_lod": "compile/lod.py:krs_lod",  # ρ → the cut's depth and culling's reach
    "component": None,  # a compound's slot range from the uniforms
    "nearest_component": "nearest",  # geometry.nearest picks the component
    "scene_nearest": "nearest",
    "is_unbounding": "component_tests",  # the KRS family's ball test
    "mobius_rec": None,  # reads the uniform block
    "mobius_apply": "apply",
    "mobius_jacobian": "jacobian",
    "reflects": None,  # a flag of the record: CompiledMoKRS.reflects
    "exterior_is_free": "is_unbounding",  # a branch of Alg. 3, inline in NumPy
    "mokrs_nearest": "nearest",
    "qpure": "pure",
    "qmul": "mul",
    "qinv": "inv",
    "soft_shadows_on": None,  # effect switches (effects.glsl): NumPy reads scene.effects
    "shadows_on": None,
    "shadow_begin": "shadow_by_distance",  # a shadow ray's steps, one function in NumPy
    "shadow_step": "shadow_by_distance",
    "shadow_visibility": "shadow_by_distance",
    "light_visibility": "reference/shade.py:shade",
    "lattice_hash": "lattice",
    "texture_fbm": "fbm",
    "texture_modulation": "modulation",
    "perpendicular": "scene/tree.py:perpendicular",
    "next_step": "front",  # a tracer's steps: one loop per tracer in NumPy
    "ray_begin": "sphere_trace",
    "ray_step": "sphere_trace",
    "ray_starts_live": "sphere_trace",
    "trace_ray": "sphere_trace",
    "bound_ahead": None,  # the balls' exits change no value: compared without them instead
    "leave": None,
    "packed_index": None,  # where a packed pass reads its list (gpu/passes.py, packed)
    "nearest_kernel": "reference/geometry.py:nearest",
    "packed_slots": None,  # what a hit's walk hands the shading: NumPy's nearest walks all
    "turn": "untwist",  # the rotation, inline in NumPy
}
_FUNCTION = re.compile(r"^(?!uniform|layout|struct|return|else)\w+ (\w+)\(", re.M)
_TWIN_OF = re.compile(r"twin of (.*?)(?:\.\s|\.$)", re.I)


def twin_modules(text: str) -> list[Path]:
    """The Python modules a shader's "twin of …" sentences name."""
    return [
        PACKAGE / rel
        for sentence in _TWIN_OF.findall(comments(text))
        for rel in re.findall(r"[\w/]+\.py", sentence)
    ]


def missing_twins(text: str, file: str = "") -> list[str]:
    """GLSL functions of a twinned shader (``file``) with no NumPy function of the same name
    in its twin modules, nor the one TWIN_NAMES gives; ``main`` is no function of a twin."""
    modules = twin_modules(text)
    if not modules:
        return []
    names = set().union(*(defined_names(m) for m in modules))
    out = []
    for fn in dict.fromkeys(f for f in _FUNCTION.findall(text) if f != "main"):
        key = f"{file}:{fn}"
        twin = TWIN_NAMES[key] if key in TWIN_NAMES else TWIN_NAMES.get(fn, fn)
        if twin is None or (key not in TWIN_NAMES and fn in names):
            continue  # no twin, or one of the same name
        if ":" in twin:
            rel, twin = twin.split(":")
            found = twin in defined_names(PACKAGE / rel)
        else:
            found = twin in names
        if not found:
            out.append(f"{fn} → {twin}")
    return out


def test_twin_functions_have_their_twins():
    twinned = [p for p in SHADERS if twin_modules(p.read_text())]
    assert len(twinned) >= 14  # every geometry, tracing and shading file names its twin
    assert {p.name: missing_twins(p.read_text(), p.name) for p in twinned} == dict.fromkeys(
        (p.name for p in twinned), []
    )
    stale = {
        key
        for key in TWIN_NAMES
        if not any(
            re.search(rf"^\w+ {key.split(':')[-1]}\(", p.read_text(), re.M)
            and (":" not in key or key.startswith(p.name + ":"))
            for p in SHADERS
        )
    }
    assert stale == set()
    # negative control: a function with no twin and no entry in the table
    synthetic = (
        "// twin of reference/occlusion.py.\nfloat ambient_occlusion() {}\nint glow(int k) {}\n"
    )
    assert missing_twins(synthetic) == ["glow → glow"]


# --- std430 layouts ------------------------------------------------------------------------


def glsl_fields(text: str, name: str) -> tuple[Field, ...]:
    """The fields of ``struct name`` or ``buffer name`` in GLSL source, as declared there."""
    body = re.search(rf"(?:struct|buffer) {name} \{{(.*?)\}}", text, re.S)
    assert body, f"no struct or buffer {name}"
    out = []
    for decl in re.sub(r"//[^\n]*", "", body.group(1)).split(";"):
        if decl.strip():
            kind, names = decl.split(None, 1)
            for item in names.split(","):
                m = re.fullmatch(r"(\w+)(?:\[(\w+)\])?", item.strip())
                count = m.group(2)
                out.append(
                    Field(kind, m.group(1), int(count) if count and count.isdigit() else count)
                )
    return tuple(out)


def test_glsl_structs_match_their_declarations():
    source = {p.name: p.read_text() for p in SHADERS}
    assert glsl_fields(source["trace.glsl"], "Ray") == RAY.fields
    assert glsl_fields(source["shadows.glsl"], "Shadow") == SHADOW.fields
    assert glsl_fields(source["compute.comp"], "Counts") == COUNTS.fields
    # negative control: a field typed differently in the shader is seen
    changed = source["trace.glsl"].replace("real ts, ds, w;", "real ts, ds;\n    vec3r w;")
    assert glsl_fields(changed, "Ray") != RAY.fields


def test_std430_rules():
    """Sizes and offsets by hand from OpenGL 4.6 §7.6.2.2, against the declared layouts."""
    assert base_type("vec3r", "double") == (24, 32) and base_type("vec2") == (8, 8)
    assert RAY.offsets("double", COMPONENT_SLOTS=2)["ts"] == 32
    # 6 floats + 2 ints (32), two vec3 aligned to 16 (32 → 44, 48 → 60), 4 floats + 1 int → 80
    assert RAY.size("float", COMPONENT_SLOTS=1) == 80
    assert SHADOW.size("float", COMPONENT_SLOTS=1) == 64  # 16 + 16 + 4 × 4 + 12 → 60 → 64
    assert SHADOW.size("double", COMPONENT_SLOTS=8) == 160  # 32 + 16 + 72 + 4 + 8 → 132 → 160
    assert COUNTS.offsets() == {"count": 0, "groups": 8, "taken": 20, "lanes_done": 24}
    assert COUNTS.size() == 28
    with pytest.raises(KeyError, match="COMPONENT_SLOTS"):
        RAY.size("float")


# A struct's size is the stride of an array of it (a block's GL_BUFFER_DATA_SIZE: padded by Mesa).
GL_BUFFER_VARIABLE, GL_OFFSET, GL_TOP_LEVEL_ARRAY_STRIDE = 0x92E5, 0x92FC, 0x930D


def resource(program: int, name: str, prop: int) -> int:
    """One property of a buffer variable of ``program``, as the driver reports it
    (glGetProgramResourceiv; the context must be current)."""
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]

    def gl(fn: str, *types):
        return ctypes.CFUNCTYPE(*types)(egl.eglGetProcAddress(fn.encode()))

    u, i = ctypes.c_uint, ctypes.c_int
    index = gl("glGetProgramResourceIndex", u, u, u, ctypes.c_char_p)(
        program, GL_BUFFER_VARIABLE, name.encode()
    )
    assert index != 0xFFFFFFFF, f"{name}: not an active buffer variable"
    out, props = i(-1), (u * 1)(prop)
    query = gl(
        "glGetProgramResourceiv",
        None,
        u,
        u,
        u,
        i,
        ctypes.POINTER(u),
        i,
        ctypes.c_void_p,
        ctypes.c_void_p,
    )
    query(program, GL_BUFFER_VARIABLE, index, 1, props, 1, None, ctypes.byref(out))
    return out.value


def driver_layout(program: int, array: str, struct: Struct) -> tuple[dict[str, int], int]:
    """Offsets of ``struct``'s fields in the buffer array ``array`` and its stride, from the
    driver."""
    names = {f.name: f"{array}[0].{f.name}" + ("[0]" if f.count else "") for f in struct.fields}
    offsets = {f: resource(program, n, GL_OFFSET) for f, n in names.items()}
    stride = resource(program, names[struct.fields[0].name], GL_TOP_LEVEL_ARRAY_STRIDE)
    return offsets, stride


@pytest.mark.parametrize("precision", ["float", "double"])
@pytest.mark.parametrize("preset", ["tree", "grove"])
def test_std430_sizes_are_the_drivers(renderer, preset, precision):
    """compute.comp's buffers as the driver lays them out: a single KRS (COMPONENT_SLOTS 1)
    and a compound with component tasks (MAX_COMPONENTS), both with shadow tasks."""
    from krsview.compile.geometry import compile_geometry
    from krsview.gpu.uniforms import variant_defines

    scene = load_scene(resolve(preset))
    render = replace(
        scene.render, path="compute", precision=precision, shadow_tasks="on", component_tasks="on"
    )
    scene = replace(scene, render=render)
    defines = variant_defines(scene, compile_geometry(scene.geometry(), scene.material.albedo))
    assert "KRS_SHADOW_TASKS" in defines
    slots = constants.MAX_COMPONENTS if "KRS_COMPOUND" in defines else 1
    assert (slots > 1) == (preset == "grove")
    with renderer.current():
        glo = renderer.programs.compute("compute.comp", defines).glo
        for array, struct in (("rays", RAY), ("shadows", SHADOW), ("tasks", RAY)):
            if array == "tasks" and slots == 1:
                continue  # component tasks: compounds only
            want = (struct.offsets(precision, COMPONENT_SLOTS=slots),)
            want += (struct.size(precision, COMPONENT_SLOTS=slots),)
            assert driver_layout(glo, array, struct) == want, (array, struct.name)
        counts = ("count", "groups")  # the lanes' fields: tests/test_lanes.py
        assert {f: resource(glo, f"{f}[0]", GL_OFFSET) for f in counts} == {
            f: COUNTS.offsets()[f] for f in counts
        }
        # negative control: a declaration that forgot the probe radii is caught
        wrong = Struct("Ray", tuple(f for f in RAY.fields if f.name != "sc"))
        offsets, _ = driver_layout(glo, "rays", RAY)
        assert wrong.offsets(precision, COMPONENT_SLOTS=slots)["ts"] != offsets["ts"]
