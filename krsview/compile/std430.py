"""The storage buffers' structs, declared once: field names and GLSL types, from which the
std430 offsets and sizes follow (OpenGL 4.6 §7.6.2.2). The GLSL declares the same fields
(``tests/test_constants.py`` compares them, and the sizes with the driver's own report);
``gpu/renderer.py`` sizes its buffers from these.

A type may be ``real`` (float, or double in a KRS_DOUBLE variant) and an array's length the
name of a define (``COMPONENT_SLOTS``), both given when the layout is computed."""

from __future__ import annotations

from dataclasses import dataclass

# GLSL scalar → bytes; a vector of n of them aligns to 2 (n = 2) or 4 (n = 3, 4) scalars.
SCALARS = {"float": 4, "int": 4, "uint": 4, "double": 8}
VECTORS = {"vec": "float", "ivec": "int", "uvec": "uint", "dvec": "double"}


@dataclass(frozen=True)
class Field:
    type: str  # GLSL type; a trailing "r" (vec4r) or "real" follows the precision
    name: str
    count: int | str | None = None  # array length: a number or a define's name


@dataclass(frozen=True)
class Struct:
    name: str
    fields: tuple[Field, ...]

    def offsets(self, real: str = "float", **counts: int) -> dict[str, int]:
        """Byte offset of each field; ``real``: "float" or "double", ``counts``: the arrays'
        named lengths."""
        return self._layout(real, counts)[0]

    def size(self, real: str = "float", **counts: int) -> int:
        """Bytes per element of an array of this struct (std430: the size rounded up to the
        largest member alignment)."""
        return self._layout(real, counts)[1]

    def _layout(self, real: str, counts: dict[str, int]) -> tuple[dict[str, int], int]:
        offsets, end, align = {}, 0, 1
        for f in self.fields:
            size, a = base_type(f.type, real)
            if f.count is not None:
                n = f.count if isinstance(f.count, int) else counts.get(f.count)
                if n is None:
                    raise KeyError(f"{self.name}.{f.name}: no length given for {f.count}")
                size = -(-size // a) * a * n  # std430: element stride = size rounded to align
            end = -(-end // a) * a
            offsets[f.name] = end
            end += size
            align = max(align, a)
        return offsets, -(-end // align) * align


def base_type(glsl: str, real: str = "float") -> tuple[int, int]:
    """(size, alignment) in bytes of a scalar or vector type under std430."""
    if real not in ("float", "double"):
        raise ValueError(f"precision {real!r}: allowed: float, double")
    if glsl == "real":
        glsl = real
    elif glsl.endswith("r") and glsl[:-1] in ("vec2", "vec3", "vec4"):
        glsl = ("d" if real == "double" else "") + glsl[:-1]
    if glsl in SCALARS:
        return SCALARS[glsl], SCALARS[glsl]
    for prefix, scalar in VECTORS.items():
        n = glsl.removeprefix(prefix)
        if glsl.startswith(prefix) and n in ("2", "3", "4"):
            s = SCALARS[scalar]
            return s * int(n), s * (2 if n == "2" else 4)
    raise ValueError(f"std430: type {glsl!r}: allowed: real, {', '.join(SCALARS)} and vectors")


# trace.glsl's Ray: a primary ray (or a component task) between the compute path's rounds.
RAY = Struct(
    "Ray",
    (
        Field("real", "tc", "COMPONENT_SLOTS"),
        Field("real", "sc", "COMPONENT_SLOTS"),
        Field("real", "ts"),
        Field("real", "ds"),
        Field("real", "w"),
        Field("real", "t"),
        Field("int", "iterations"),
        Field("int", "state"),
        Field("vec3r", "wx"),
        Field("int", "slots"),
        Field("vec3r", "wdir"),
        Field("real", "wt"),
        Field("real", "wm"),
        Field("real", "wd"),
        Field("int", "wj"),
    ),
)
# shadows.glsl's Shadow: a shadow ray between rounds (KRS_SHADOW_TASKS).
SHADOW = Struct(
    "Shadow",
    (
        Field("vec4r", "o"),
        Field("vec4", "l"),
        Field("real", "tc", "COMPONENT_SLOTS"),
        Field("real", "s"),
        Field("float", "vis"),
        Field("int", "iterations"),
        Field("int", "state"),
    ),
)
# compute.comp's Counts: live rays per queue, the next dispatch's size (indirect), and the
# persistent lanes that have finished (PHASE_LANES).
COUNTS = Struct(
    "Counts",
    (
        Field("uint", "count", 2),
        Field("uint", "groups", 3),
        Field("uint", "taken"),
        Field("uint", "lanes_done"),
    ),
)
