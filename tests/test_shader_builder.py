"""The program builder: #include resolution, errors mapped to .glsl file:line, variants
specialised by #define and cached."""

from __future__ import annotations

import re
import shutil

import pytest

from krsview.compile.krs import compile_krs
from krsview.gpu.program import SHADER_DIR, ShaderError, Source, build_program
from krsview.gpu.uniforms import variant_defines
from krsview.scene import load_scene
from krsview.scene.presets import resolve

DEFINES = {"KRS_SLOTS": 64, "KRS_KERNEL_TOROIDAL_CAPSULE": None}


@pytest.fixture
def shader_copy(tmp_path):
    d = tmp_path / "shaders"
    shutil.copytree(SHADER_DIR, d)
    return d


def test_compile_error_is_mapped_to_file_and_line(renderer, shader_copy):
    path = shader_copy / "kernels.glsl"
    lines = path.read_text().splitlines()
    target = "return sqrt(w + a.z * a.z) / dot(P, P) - o.w;"
    k = next(i for i, line in enumerate(lines) if target in line)
    lines[k] = lines[k].replace(";", " + undefined_thing;")
    path.write_text("\n".join(lines) + "\n")
    with renderer.current(), pytest.raises(ShaderError) as e:
        build_program(renderer.ctx, "fullscreen.vert", "render.frag", DEFINES, shader_copy)
    text = str(e.value)
    assert f"kernels.glsl:{k + 1}:" in text, text
    assert "| " + target.replace(";", " + undefined_thing;") in text
    assert not re.search(r"\b0:\d+\(\d+\)", text), text  # no raw Mesa offsets left


def test_include_cycle_and_missing_file_are_named(shader_copy):
    (shader_copy / "a.glsl").write_text('#include "b.glsl"\n')
    (shader_copy / "b.glsl").write_text('#include "a.glsl"\n')
    with pytest.raises(ShaderError, match="a.glsl → b.glsl → a.glsl"):
        Source("a.glsl", {}, shader_copy)
    (shader_copy / "c.glsl").write_text('#include "nope.glsl"\n')
    with pytest.raises(ShaderError, match=r"nope.glsl \(included from c.glsl\)"):
        Source("c.glsl", {}, shader_copy)


def test_a_file_edited_is_read_anew_even_at_the_same_size(shader_copy):
    """Each file is parsed once per version (its mtime and size): a shader reload must not be
    served the text parsed before the edit."""
    import os

    f = shader_copy / "one.glsl"
    f.write_text("float one() { return 111.5; }\n")
    assert "111.5" in Source("one.glsl", {}, shader_copy).text
    f.write_text("float one() { return 222.5; }\n")  # the same length
    st = f.stat()
    os.utime(f, ns=(st.st_atime_ns, st.st_mtime_ns + 1))
    again = Source("one.glsl", {}, shader_copy).text
    assert "222.5" in again and "111.5" not in again


def test_source_map_points_every_line_back():
    src = Source("render.frag", DEFINES)
    lines = src.text.splitlines()
    for n, (file, line) in enumerate(src.origin, 1):
        if file != "<defines>":
            assert (SHADER_DIR / file).read_text().splitlines()[line - 1] == lines[n - 1]


def test_variant_contains_only_the_kernels_the_scene_uses(renderer):
    sier = load_scene(resolve("sierpinski"))  # spheres only
    tree = load_scene(resolve("tree"))  # toroidal capsules only
    d_sier = variant_defines(sier, compile_krs(sier.geometry(), (1, 1, 1)))
    d_tree = variant_defines(tree, compile_krs(tree.geometry(), (1, 1, 1)))
    assert "KRS_KERNEL_SPHERE" in d_sier and "KRS_KERNEL_TOROIDAL_CAPSULE" not in d_sier
    assert "KRS_KERNEL_TOROIDAL_CAPSULE" in d_tree and "KRS_KERNEL_SPHERE" not in d_tree
    before = renderer.programs.compiles
    renderer.render(sier, 8, 6)
    renderer.render(sier, 8, 6)  # same define set: cached
    assert renderer.programs.compiles - before <= 1


@pytest.mark.parametrize(
    "defines, emitted",
    [({"A": None}, "a"), ({"B": None}, "b"), ({"A": None, "B": None}, "a"), ({}, "c")],
)
def test_elif_emits_the_first_true_branch_only(tmp_path, defines, emitted):
    (tmp_path / "x.glsl").write_text(
        "#ifdef A\nint a;\n#elif defined(B)\nint b;\n#else\n"
        "int c;\n#endif\n#if defined(B)\nint bb;\n#endif\n"
    )
    body = Source("x.glsl", defines, tmp_path).text.splitlines()
    decl = [line for line in body if line.startswith("int ") and len(line) == 6]
    assert decl == [f"int {emitted};"]
    assert ("int bb;" in body) == ("B" in defines)
