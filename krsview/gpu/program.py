"""Shader program builder: ``#include`` resolution with ``#line`` mapping, the constants shared
with Python (compile/constants.py) and one ``#define`` per enabled feature, a variant cache
keyed by the define set, and compile errors mapped back to ``file.glsl:line`` (the
moderngl-window habit, docs/architecture.md)."""

from __future__ import annotations

import functools
import re
from importlib import resources
from pathlib import Path

import moderngl

from ..compile.constants import glsl_defines
from .context import GL_VERSION

SHADER_DIR = Path(str(resources.files("krsview") / "shaders"))
CORE_HEADER = (f"#version {GL_VERSION} core",)
# WebGL2 (share/web.py): GLSL ES 3.00 has no default float precision in fragment shaders
ES_HEADER = ("#version 300 es", "precision highp float;", "precision highp int;")
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
# Mesa: "0:12(5): error"; NVIDIA: "0(12) : error". The line is in the assembled source.
_LOCATION = re.compile(r"\b\d+(?::(\d+)\((\d+)\)|\((\d+)\))")
SHARED = glsl_defines()  # every program's first defines: the constants shared with Python


class ShaderError(RuntimeError):
    """A shader failed to build; ``str()`` names the .glsl file, line and the offending text."""


_DIRECTIVE = re.compile(
    r"^\s*#\s*(ifdef|ifndef|if|elif|else|endif|define|undef)\b\s*(.*?)\s*(//.*)?$"
)
_DEFINED = re.compile(r"defined\s*\(?\s*(\w+)\s*\)?")
_CONDITIONALS = ("ifdef", "ifndef", "if", "elif", "else", "endif")


@functools.lru_cache(maxsize=512)
def _parsed(path: Path, stamp: tuple[int, int]) -> tuple[tuple[str, str, str | None, str], ...]:
    """Each line of a shader file as (directive or "", its argument, the file it includes or
    None, the line), read and matched once per version of the file (``stamp``: its mtime and
    size, so a shader reload reads an edited file anew): a variant's source is assembled from
    these without a regular expression per line."""
    out = []
    for line in path.read_text(encoding="utf-8").splitlines():
        d, m = _DIRECTIVE.match(line), _INCLUDE.match(line)
        out.append((d.group(1) if d else "", d.group(2) if d else "", m and m.group(1), line))
    return tuple(out)


class Source:
    """A stage assembled from .glsl files. ``origin[k]`` is the (file, line) of assembled line
    k + 1, so compiler messages map back without trusting the driver's ``#line`` handling.

    Conditionals are resolved here, against the variant's defines: an inactive ``#ifdef``
    block, and any file it includes, never reaches the driver, so a scene without an effect
    compiles none of that effect's code (docs/architecture.md, Specialise, don't branch)."""

    def __init__(
        self,
        entry: str,
        defines: dict[str, str | int | float | None],
        shader_dir: Path = SHADER_DIR,
        header: tuple[str, ...] = CORE_HEADER,
    ):
        self.shader_dir = shader_dir
        clash = sorted(set(defines) & set(SHARED))
        if clash:
            raise ShaderError(f"{entry}: {', '.join(clash)} shared with Python, not a variant's")
        head = list(header) + [f"#define {k} {v}" for k, v in SHARED.items()]
        head += [
            f"#define {k}" + ("" if v is None else f" {v}") for k, v in sorted(defines.items())
        ]
        self.origin: list[tuple[str, int]] = [("<defines>", k) for k in range(1, len(head) + 1)]
        self.defined = set(defines) | set(SHARED)
        self.included: set[str] = set()
        lines = head + self._expand(entry, [])
        self.text = "\n".join(lines) + "\n"

    def _expand(self, name: str, stack: list[str]) -> list[str]:
        if name in stack:
            raise ShaderError("#include cycle: " + " → ".join(stack + [name]))
        if name in self.included:
            return []  # once per stage: inactive branches are gone, so a plain skip is safe
        self.included.add(name)
        path = self.shader_dir / name
        try:
            stat = path.stat()
            parsed = _parsed(path, (stat.st_mtime_ns, stat.st_size))
        except OSError:
            where = f" (included from {stack[-1]})" if stack else ""
            raise ShaderError(f"shader file not found: {name}{where}") from None
        out: list[str] = []
        # One entry per open conditional: [is this branch emitted, was any branch taken].
        active, emitting = [[True, True]], True
        for k, (kind, arg, include, line) in enumerate(parsed, 1):
            if kind in _CONDITIONALS:
                self._conditional(kind, arg, active, name, k)
                emitting = all(on for on, _ in active)
                continue
            if not emitting:
                continue
            if kind == "define":
                defined = arg.split("(")[0].split()[0]
                if defined in SHARED:
                    raise ShaderError(
                        f"{name}:{k}: #define {defined}: shared with Python, so defined once "
                        "in compile/constants.py and given to every program"
                    )
                self.defined.add(defined)
            elif kind == "undef":
                self.defined.discard(arg)
            if include is not None:
                out += self._expand(include, stack + [name])
            else:
                out.append(line)
                self.origin.append((name, k))
        if len(active) != 1:
            raise ShaderError(f"{name}: #if without #endif")
        return out

    def _conditional(
        self, kind: str, arg: str, active: list[list[bool]], name: str, k: int
    ) -> None:
        if kind in ("ifdef", "ifndef", "if"):
            on = (
                arg in self.defined
                if kind == "ifdef"
                else arg not in self.defined
                if kind == "ifndef"
                else self._evaluate(arg, name, k)
            )
            active.append([on, on])
        elif len(active) == 1:
            raise ShaderError(f"{name}:{k}: #{kind} without #if")
        elif kind == "endif":
            active.pop()
        else:  # elif / else: the first true branch only
            taken = active[-1][1]
            on = not taken and (kind == "else" or self._evaluate(arg, name, k))
            active[-1] = [on, taken or on]

    def _evaluate(self, expr: str, name: str, k: int) -> bool:
        """``#if`` over ``defined(NAME)``, ``!``, ``&&``, ``||`` and parentheses only."""
        py = _DEFINED.sub(lambda m: str(m.group(1) in self.defined), expr)
        py = py.replace("&&", " and ").replace("||", " or ").replace("!", " not ")
        if re.fullmatch(r"[\s()]*((True|False|and|or|not)[\s()]*)*", py) is None:
            raise ShaderError(
                f"{name}:{k}: #if {expr}: only defined(), !, && and || are supported by the builder"
            )
        return bool(eval(py))  # noqa: S307 - the expression holds only booleans and operators

    def map_log(self, log: str) -> str:
        """Rewrite each compiler location as ``file.glsl:line[:col]``, followed by that line."""
        out = []
        lines = self.text.splitlines()
        for raw in log.splitlines():
            m = _LOCATION.search(raw)
            if m:
                n = int(m.group(1) or m.group(3))
                if 0 < n <= len(self.origin):
                    file, line = self.origin[n - 1]
                    col = f":{m.group(2)}" if m.group(2) else ""
                    out.append(
                        raw[: m.start()]
                        + f"{file}:{line}{col}"
                        + raw[m.end() :]
                        + f"\n    | {lines[n - 1].strip()}"
                    )
                    continue
            if raw.strip():
                out.append(raw)
        return "\n".join(out)


def build_program(
    ctx: moderngl.Context,
    vertex: str,
    fragment: str,
    defines: dict[str, str | int | float | None],
    shader_dir: Path = SHADER_DIR,
) -> moderngl.Program:
    vs, fs = Source(vertex, defines, shader_dir), Source(fragment, defines, shader_dir)
    try:
        return ctx.program(vertex_shader=vs.text, fragment_shader=fs.text)
    except moderngl.Error as e:
        msg = str(e)
        stage = vs if "vertex_shader" in msg and "fragment_shader" not in msg else fs
        raise ShaderError(
            f"{vertex} + {fragment} failed to compile:\n" + stage.map_log(msg)
        ) from None


def build_compute(
    ctx: moderngl.Context,
    entry: str,
    defines: dict[str, str | int | float | None],
    shader_dir: Path = SHADER_DIR,
) -> moderngl.ComputeShader:
    cs = Source(entry, defines, shader_dir)
    try:
        return ctx.compute_shader(cs.text)
    except moderngl.Error as e:
        raise ShaderError(f"{entry} failed to compile:\n" + cs.map_log(str(e))) from None


class ProgramCache:
    """Compiled variants keyed by their define set: a variant compiles once per context."""

    def __init__(self, ctx: moderngl.Context, shader_dir: Path = SHADER_DIR):
        self.ctx, self.shader_dir = ctx, shader_dir
        self._programs: dict[tuple, moderngl.Program] = {}
        self.compiles = 0

    def get(
        self, vertex: str, fragment: str, defines: dict[str, str | int | float | None]
    ) -> moderngl.Program:
        key = (vertex, fragment, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = build_program(
                self.ctx, vertex, fragment, defines, self.shader_dir
            )
            self.compiles += 1
        return self._programs[key]

    def compute(
        self, entry: str, defines: dict[str, str | int | float | None]
    ) -> moderngl.ComputeShader:
        key = (entry, None, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = build_compute(self.ctx, entry, defines, self.shader_dir)
            self.compiles += 1
        return self._programs[key]
