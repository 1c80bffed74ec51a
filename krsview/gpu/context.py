"""OpenGL contexts: headless through EGL (tests, CI, `krsview render`)."""

from __future__ import annotations

import moderngl

GL_VERSION = 430  # compute + std140 + explicit locations; llvmpipe offers 4.5 core


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
    ctx.__exit__(None, None, None)  # release it: nothing is current on this thread now
    return ctx
