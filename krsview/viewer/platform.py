"""The platform layer: a GLFW window with an OpenGL 4.3+ core context, Dear ImGui's GLFW and
OpenGL3 backends, and the routing of GLFW events to ImGui first, then to the window's own
input (keys, buttons, cursor, wheel) unless ImGui or a gizmo wants them.

A press or a wheel turn is ImGui's when ImGui's windows, as the last frame drew them, lie
under the pointer where the event happened (``imgui_under``). ImGui's own
``want_capture_mouse`` answers for the pointer where its last frame saw it, so a pointer
moved and pressed before the next frame (a touchpad's tap) went to the wrong side.

A release reaches ImGui only once a frame has read every event before it (``Platform.hand``):
a quick drag, pressed, moved and let go between two frames, is then seen by one frame with
the pointer where it was let go and the button still down, and by the next as let go.
ImGui's own trickling reads the last motion and the release in one frame, and ImGuizmo (or
the dial, or a slider) ends a drag there before it moves it: a flick on a slow frame was
lost."""

from __future__ import annotations

import ctypes
import string
from collections.abc import Callable

import glfw  # noqa: E402  (order matters)
from imgui_bundle import imgui, implot  # imgui before glfw (docs/architecture.md, stack facts)

from .controls import LOOK_BUTTON, Input
from .fonts import load_font

GLFW_KEYS = (
    {getattr(glfw, f"KEY_{c}"): c for c in string.ascii_uppercase}
    | {getattr(glfw, f"KEY_F{i}"): f"F{i}" for i in range(1, 13)}
    | {glfw.KEY_INSERT: "Insert", glfw.KEY_DELETE: "Delete", glfw.KEY_SPACE: "Space"}
)
GLFW_BUTTONS = {glfw.MOUSE_BUTTON_LEFT: "left", glfw.MOUSE_BUTTON_RIGHT: "right"}
GL_VOID = ctypes.CFUNCTYPE(None)  # glFlush's signature


class WindowError(RuntimeError):
    """No window could be opened (no display, or no OpenGL 4.3+ there)."""


class Platform:
    def __init__(self, size: tuple[int, int], title: str, visible: bool):
        self.window = open_window(size, title, visible)
        imgui.create_context()
        implot.create_context()
        imgui.get_io().set_ini_filename("")
        opaque_popups()
        load_font()
        self.addr = ctypes.cast(self.window, ctypes.c_void_p).value
        imgui.backends.glfw_init_for_opengl(self.addr, False)
        imgui.backends.opengl3_init("#version 430")
        self.drawn = False  # this turn drew an ImGui frame: its windows are on screen
        # ImGui's events from a held-back release on, (event, is a release), in their order
        self.later: list[tuple[Callable[[], None], bool]] = []
        self._gl_flush = GL_VOID(glfw.get_proc_address("glFlush"))

    def begin_turn(self) -> None:
        """A turn of the event loop begins: ImGui's windows are on screen for the events
        after it only if it draws a frame (a hidden HUD draws none; its windows stay in
        ImGui's context, not on screen)."""
        self.drawn = False

    def close(self) -> None:
        imgui.backends.opengl3_shutdown()
        imgui.backends.glfw_shutdown()
        implot.destroy_context()
        imgui.destroy_context()
        glfw.destroy_window(self.window)

    def hand(self, event: Callable[[], None], release: bool = False) -> None:
        """Give ImGui an event (a call of its GLFW backend), in order: a release waits while
        ImGui holds events that no frame has read yet, and so does every event after a
        waiting one (module docstring)."""
        if self.later or (release and unread()):
            self.later.append((event, release))
        else:
            event()

    def hand_on(self) -> None:
        """After a frame has read ImGui's events: the waiting ones, up to the next release
        that must wait in turn."""
        while self.later and not (self.later[0][1] and unread()):
            self.later.pop(0)[0]()

    def route_events(self, to: Input) -> None:
        """GLFW events go to ImGui first (``hand``), then to ``to`` unless ImGui or a gizmo
        takes them."""
        b, a, window, hand = imgui.backends, self.addr, self.window, self.hand
        taken: set[int] = set()  # the buttons whose press was not the view's, until released

        def ui() -> bool:
            return self.drawn and imgui_under(to, taken)

        def on_key(_w, key, scancode, action, mods):
            hand(lambda: b.glfw_key_callback(a, key, scancode, action, mods))
            if key not in GLFW_KEYS:
                return
            if action == glfw.RELEASE:  # let go, whoever has the keyboard: a flight key held
                to.key(GLFW_KEYS[key], False)  # into a field or a slider's drag would fly on
                return
            if imgui.get_io().want_capture_keyboard:
                return  # typing in a field
            if action == glfw.PRESS and mods & glfw.MOD_CONTROL:
                shift = "shift+" if mods & glfw.MOD_SHIFT else ""
                to.chord(f"ctrl+{shift}{GLFW_KEYS[key]}")
            elif action == glfw.PRESS:
                to.key(GLFW_KEYS[key], True)

        def on_button(_w, button, action, mods):
            release = action == glfw.RELEASE
            hand(lambda: b.glfw_mouse_button_callback(a, button, action, mods), release)
            if action == glfw.PRESS and (ui() or to.claimed):
                taken.add(button)
                return  # the HUD's or a gizmo's press, not the camera's
            taken.discard(button)
            if button in GLFW_BUTTONS:
                to.button(GLFW_BUTTONS[button], action == glfw.PRESS)
                look = GLFW_BUTTONS[button] == LOOK_BUTTON
                if look and to.look_hides_cursor:
                    mode = glfw.CURSOR_DISABLED if action == glfw.PRESS else glfw.CURSOR_NORMAL
                    glfw.set_input_mode(window, glfw.CURSOR, mode)

        def on_cursor(_w, x, y):
            hand(lambda: b.glfw_cursor_pos_callback(a, x, y))
            to.move_cursor(x, y)

        def on_scroll(_w, dx, dy):
            hand(lambda: b.glfw_scroll_callback(a, dx, dy))
            if not ui():
                to.wheel(dy)

        def on_char(_w, c):
            hand(lambda: b.glfw_char_callback(a, c))

        self._callbacks = (on_key, on_button, on_cursor, on_scroll, on_char)  # keep alive
        glfw.set_key_callback(window, on_key)
        glfw.set_mouse_button_callback(window, on_button)
        glfw.set_cursor_pos_callback(window, on_cursor)
        glfw.set_scroll_callback(window, on_scroll)
        glfw.set_char_callback(window, on_char)

    def flush(self) -> None:
        """Start the GL commands issued so far without waiting for them (glFlush): on
        llvmpipe its threads draw them while this thread goes on."""
        self._gl_flush()

    def new_frame(self) -> None:
        imgui.backends.opengl3_new_frame()
        imgui.backends.glfw_new_frame()
        imgui.new_frame()
        self.hand_on()
        close_on_escape()

    def render(self) -> None:
        self.drawn = True
        imgui.render()
        imgui.backends.opengl3_render_draw_data(imgui.get_draw_data())


def close_on_escape() -> None:
    """Inside a frame: Esc closes an open drop-down list or menu, as in any application.
    ImGui's keyboard navigation would, but it is off: it would take the flight keys."""
    if imgui.is_key_pressed(imgui.Key.escape, False) and imgui.is_popup_open(
        "", imgui.PopupFlags_.any_popup
    ):
        imgui.internal.close_popup_to_level(0, True)


def unread() -> bool:
    """ImGui holds input events that no frame has read yet."""
    return imgui.get_current_context().input_events_queue.size() > 0


def opaque_popups() -> None:
    """Drop-down lists and menus drawn opaque: ImGui's default lets 6 % of the text behind a
    HUD combo's list through, which reads as clutter over its entries."""
    style = imgui.get_style()
    c = style.color_(imgui.Col_.popup_bg.value)
    style.set_color_(imgui.Col_.popup_bg.value, imgui.ImVec4(c.x, c.y, c.z, 1.0))


def imgui_under(to: Input, taken: set[int]) -> bool:
    """Whether ImGui takes a press or a wheel turn of the pointer at ``to.cursor``, between
    two frames: ImGui's rule (``UpdateHoveredWindowAndCaptureFlags``) for the pointer there,
    not where its last frame saw it. A button the view holds keeps the pointer the view's;
    else ImGui takes it while it holds a button (``taken``, in the events' order: its own
    state lags a frame) or a popup is open (a click anywhere closes it), or where a window
    of its last frame lies."""
    if to.buttons:
        return False
    if taken or imgui.is_popup_open("", imgui.PopupFlags_.any_popup):
        return True
    return window_at(*to.cursor)


def window_at(x: float, y: float) -> bool:
    """An ImGui window drawn in the last frame covers window point (x, y), as ImGui's next
    frame finds it (``FindHoveredWindowEx``: windows taking mouse input, each grown by its
    hover padding, more where it can be resized by its border)."""
    style = imgui.get_style()
    touch = style.touch_extra_padding
    border = style.window_border_hover_padding
    fixed = imgui.WindowFlags_.no_resize | imgui.WindowFlags_.always_auto_resize
    point = imgui.ImVec2(x, y)
    for w in imgui.get_current_context().windows:
        if not w.active or w.hidden or w.flags & imgui.WindowFlags_.no_mouse_inputs:
            continue
        pad = touch if w.flags & fixed else imgui.ImVec2(max(touch.x, border), max(touch.y, border))
        if w.outer_rect_clipped.contains_with_pad(point, pad):
            return True
    return False


def open_window(size: tuple[int, int], title: str, visible: bool):
    glfw.ERROR_REPORTING = "ignore"  # failures are reported below, as a WindowError
    if not glfw.init():
        raise WindowError(
            "cannot open a window: GLFW found no display (is DISPLAY set? "
            "use `krsview render` to render headless)"
        )
    size = fitted(size, _screen())
    for minor in (5, 3):  # 4.6 fails on llvmpipe (docs/architecture.md)
        glfw.default_window_hints()
        glfw.window_hint(glfw.CONTEXT_VERSION_MAJOR, 4)
        glfw.window_hint(glfw.CONTEXT_VERSION_MINOR, minor)
        glfw.window_hint(glfw.OPENGL_PROFILE, glfw.OPENGL_CORE_PROFILE)
        glfw.window_hint(glfw.OPENGL_FORWARD_COMPAT, True)
        glfw.window_hint(glfw.VISIBLE, visible)
        window = glfw.create_window(size[0], size[1], title, None, None)
        if window:
            glfw.make_context_current(window)
            glfw.swap_interval(0)
            return window
    raise WindowError("cannot open an OpenGL 4.3+ core window on this display")


def _screen() -> tuple[int, int] | None:
    """The primary monitor's work area (less task bars), or None where GLFW knows none."""
    monitor = glfw.get_primary_monitor()
    if not monitor:
        return None
    _, _, w, h = glfw.get_monitor_workarea(monitor)
    return (w, h) if w > 0 and h > 0 else None


def fitted(size: tuple[int, int], screen: tuple[int, int] | None) -> tuple[int, int]:
    """``size``, or where it is larger than the ``screen``'s work area, the largest size of
    its shape that fits, said once: a window past the screen's edge traced pixels nobody
    saw (4000×3000 took 6.5 s a still frame)."""
    if screen is None:
        return size
    scale = min(1.0, screen[0] / size[0], screen[1] / size[1])
    if scale >= 1.0:
        return size
    out = (max(1, int(size[0] * scale)), max(1, int(size[1] * scale)))
    print(
        f"krsview: a window of {size[0]}×{size[1]} does not fit the screen "
        f"({screen[0]}×{screen[1]}): it opens at {out[0]}×{out[1]}",
        flush=True,
    )
    return out
