"""OpenGL contexts: headless through EGL (tests, CI, `krsview render`); what the passes do
on one: give a program its uniforms, draw a pass behind a mark of the pixels it has nothing
to do on, make a texture's sides no powers of two."""

from __future__ import annotations

from collections.abc import Callable

import moderngl

GL_VERSION = 430  # compute + std140 + explicit locations; llvmpipe offers 4.5 core


# GL_RENDERER of the rasterisers that run on the CPU (Mesa's, Google's): every other is a GPU
SOFTWARE_RASTERISERS = ("llvmpipe", "softpipe", "lavapipe", "swiftshader")


def hardware(renderer: str) -> bool:
    """Whether a context whose GL_RENDERER is ``renderer`` draws on a GPU, not the CPU."""
    return not any(name in renderer.lower() for name in SOFTWARE_RASTERISERS)


class ContextError(RuntimeError):
    """No usable OpenGL context; the message says what to install."""


def headless_context() -> moderngl.Context:
    """An EGL context that is current only inside ``with ctx:`` blocks (the renderer's entry
    points), so it never steals the thread from a window's GLX context: an EGL context left
    current makes a later glXMakeCurrent fail with BadAccess, which kills the process."""
    try:
        # Versioned names: the runtime packages (libgl1, libegl1) ship only these.
        ctx = moderngl.create_standalone_context(
            backend="egl", require=GL_VERSION, libgl="libGL.so.1", libegl="libEGL.so.1"
        )
    except Exception as e:  # moderngl raises plain Exception subclasses from glcontext
        raise ContextError(
            f"cannot create a headless OpenGL {GL_VERSION // 100}.{GL_VERSION % 100 // 10} "
            f"context through EGL ({e}). On Debian install libegl1 libegl-mesa0 libgl1 "
            "libgl1-mesa-dri (`make deps` does it)."
        ) from None
    ctx.gc_mode = "context_gc"  # objects dropped by Python wait for release_dropped()
    ctx.__exit__(None, None, None)  # release it: nothing is current on this thread now
    return ctx


def release_dropped(ctx: moderngl.Context) -> int:
    """Release the GL objects Python has dropped (the headless context's gc_mode is
    "context_gc", so they wait in ``ctx.objects`` until here); how many. moderngl 5.13
    also queues objects released before they were dropped: those hold nothing and are
    skipped (its own ``ctx.gc()`` fails on them). The context must be current."""
    count = 0
    while ctx.objects:
        obj = ctx.objects.popleft()
        if not isinstance(obj, moderngl.InvalidObject):
            obj.release()
            count += 1
    return count


def texture_side(n: int) -> int:
    """The side a texture of ``n`` texels is made with: ``n``, or the next side that is no
    power of two. llvmpipe compiles a shader variant for each pattern of power-of-two sides
    among the textures it samples, so an image whose size passes 128 or 64 (the viewer's
    adaptive resolution) stalled its turn for 0.4–0.6 s while the tracer compiled anew; a
    texel more on such sides keeps every texture of one pattern (docs/speed.md)."""
    while n & (n - 1) == 0:  # 1, 2, 4, 8, …
        n += 1
    return n


def behind_mark(
    ctx: moderngl.Context,
    mark: Callable[[], None],
    draw: Callable[[], None],
    marked: Callable[[], None] | None = None,
) -> None:
    """Draw ``mark``, whose shader writes depth 0 on the pixels ``draw`` has nothing to do on
    and 1 elsewhere, then ``draw`` (fragments at depth 0.5, writing no depth) behind a
    less-than test, which llvmpipe makes before the fragment shader, and ``marked``, if given,
    on the pixels marked 0 (a greater-than test): llvmpipe runs every branch's code for every
    pixel it shades, so a sky pixel otherwise costs as much as a traced one. A shader that
    writes memory declares ``early_fragment_tests``."""
    ctx.enable(moderngl.DEPTH_TEST)
    try:
        for part, test in ((mark, "1"), (draw, "<"), (marked, ">")):  # "1": always
            if part is not None:
                ctx.depth_func = test
                part()
    finally:
        ctx.disable(moderngl.DEPTH_TEST)


def set_uniforms(prog: moderngl.Program, uniforms: dict[str, object]) -> None:
    """Give ``prog`` the values of ``uniforms`` it declares; of an array, only the first
    elements that it uses (the compiler drops the rest: a pass that reads only the first
    light's colour declares an array of one)."""
    for name, value in uniforms.items():
        uniform = prog.get(name, None)  # not `name in prog`, which walks all its members
        if uniform is not None:
            n = uniform.array_length
            if isinstance(value, list) and n < len(value):
                value = value[0] if n == 1 else value[:n]
            uniform.value = value


def image_uniforms(
    prog: moderngl.Program,
    source: moderngl.Framebuffer,
    window: tuple[int, int],
    image: tuple[int, int],
) -> None:
    """The sizes a pass that draws a traced image over a window reads (window_image.glsl,
    in display.frag and overlay.frag): the window's, the image's, and the texture's that holds
    it (texture_side: no larger than the image by more than a texel a side)."""
    prog["u_window"].value = (float(window[0]), float(window[1]))
    prog["u_image"].value = (float(image[0]), float(image[1]))
    prog["u_texture"].value = tuple(map(float, source.color_attachments[0].size))
