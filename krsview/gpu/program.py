"""Shader program builder: ``#include`` resolution with ``#line`` mapping, one ``#define``
per enabled feature, a variant cache keyed by the define set, and compile errors mapped back
to ``file.glsl:line`` (the moderngl-window habit, DESIGN.md)."""
from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import moderngl

from .context import GL_VERSION

SHADER_DIR = Path(str(resources.files("krsview") / "shaders"))
_INCLUDE = re.compile(r'^\s*#include\s+"([^"]+)"\s*$')
# Mesa: "0:12(5): error"; NVIDIA: "0(12) : error". The line is in the assembled source.
_LOCATION = re.compile(r"\b\d+(?::(\d+)\((\d+)\)|\((\d+)\))")


class ShaderError(RuntimeError):
    """A shader failed to build; ``str()`` names the .glsl file, line and the offending text."""


class Source:
    """A stage assembled from .glsl files. ``origin[k]`` is the (file, line) of assembled line
    k + 1, so compiler messages map back without trusting the driver's ``#line`` handling."""

    def __init__(self, entry: str, defines: dict[str, str | int | float | None],
                 shader_dir: Path = SHADER_DIR):
        self.shader_dir = shader_dir
        head = [f"#version {GL_VERSION} core"]
        head += [f"#define {k}" + ("" if v is None else f" {v}") for k, v in
                 sorted(defines.items())]
        self.origin: list[tuple[str, int]] = [("<defines>", k) for k in range(1, len(head) + 1)]
        lines = head + self._expand(entry, [])
        self.text = "\n".join(lines) + "\n"

    def _expand(self, name: str, stack: list[str]) -> list[str]:
        if name in stack:
            raise ShaderError("#include cycle: " + " → ".join(stack + [name]))
        path = self.shader_dir / name
        try:
            text = path.read_text(encoding="utf-8")
        except OSError:
            where = f" (included from {stack[-1]})" if stack else ""
            raise ShaderError(f"shader file not found: {name}{where}") from None
        # A real header guard, not a textual skip: an #include inside an inactive #ifdef
        # branch must not hide the file from an active branch later.
        guard = "KRS_FILE_" + re.sub(r"\W", "_", name).upper()
        out: list[str] = [f"#ifndef {guard}", f"#define {guard}"]
        self.origin += [("<defines>", 0), ("<defines>", 0)]  # generated, like the defines
        for k, line in enumerate(text.splitlines(), 1):
            m = _INCLUDE.match(line)
            if m:
                out += self._expand(m.group(1), stack + [name])
            else:
                out.append(line)
                self.origin.append((name, k))
        out.append(f"#endif  // {guard}")
        self.origin.append(("<defines>", 0))
        return out

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
                    out.append(raw[:m.start()] + f"{file}:{line}{col}" + raw[m.end():]
                               + f"\n    | {lines[n - 1].strip()}")
                    continue
            if raw.strip():
                out.append(raw)
        return "\n".join(out)


def build_program(ctx: moderngl.Context, vertex: str, fragment: str,
                  defines: dict[str, str | int | float | None],
                  shader_dir: Path = SHADER_DIR) -> moderngl.Program:
    vs, fs = Source(vertex, defines, shader_dir), Source(fragment, defines, shader_dir)
    try:
        return ctx.program(vertex_shader=vs.text, fragment_shader=fs.text)
    except moderngl.Error as e:
        msg = str(e)
        stage = vs if "vertex_shader" in msg and "fragment_shader" not in msg else fs
        raise ShaderError(f"{vertex} + {fragment} failed to compile:\n"
                          + stage.map_log(msg)) from None


class ProgramCache:
    """Compiled variants keyed by their define set: a variant compiles once per context."""

    def __init__(self, ctx: moderngl.Context, shader_dir: Path = SHADER_DIR):
        self.ctx, self.shader_dir = ctx, shader_dir
        self._programs: dict[tuple, moderngl.Program] = {}
        self.compiles = 0

    def get(self, vertex: str, fragment: str,
            defines: dict[str, str | int | float | None]) -> moderngl.Program:
        key = (vertex, fragment, tuple(sorted(defines.items())))
        if key not in self._programs:
            self._programs[key] = build_program(self.ctx, vertex, fragment, defines,
                                                self.shader_dir)
            self.compiles += 1
        return self._programs[key]
