"""A quick click (the pointer moved and pressed before the window drew a frame with it there,
a touchpad's tap) in the editor's real window under Xvfb: on the panel it is the panel's
alone, in the view it picks, on the gizmo it is the gizmo's (no pick, no orbit), and a wheel
notch scrolls the side under the pointer; a hidden panel takes nothing, and a field held
takes the other buttons too; a tap-drag whose first motion comes with its press (one
poll) moves either the gizmo or, orbiting, the camera, never both. ImGui's own
``want_capture_mouse`` and the gizmo's hover answer for where the pointer was at the last
frame, so each went to the wrong side."""

from __future__ import annotations

import numpy as np
import pytest

from krsview.editor.commands import Bake
from krsview.viewer.commands import ToggleHud, ToggleOrbit, Undo

from .test_editor import (
    LEVEL,
    SIZE,
    click,
    editor_on_a_copy,
    handle,
    pump,
    screen_of,
    settle,
    window_xy,
    xdo,
)

FORK = ("route", "levels", LEVEL, "fork")
RADIUS = ("route", "levels", LEVEL, "radius")


@pytest.fixture
def baked(display, tmp_path):
    """The tree baked, its fork LEVEL selected by a click (its fields shown in the panel)."""
    for e in editor_on_a_copy(tmp_path, "tree", SIZE):
        settle(e)
        e.execute([Bake()])
        settle(e)
        click(e, screen_of(e, handle(e, FORK).position))
        assert e.selected is not None and e.selected.path == FORK
        yield e


def quick_click(e, at) -> None:
    """Move to ``at`` and click in one go: no frame sees the pointer there before the press."""
    xdo("mousemove", round(at[0]), round(at[1]), "click", 1)
    pump(e, 3)


def rest(e, at) -> None:
    """The pointer at ``at`` for two frames: ImGui knows where it is."""
    xdo("mousemove", round(at[0]), round(at[1]))
    pump(e, 2)


def middle(rect) -> tuple[float, float]:
    x0, y0, x1, y1 = rect
    return (x0 + x1) / 2, (y0 + y1) / 2


def test_a_quick_click_on_the_panel_keeps_the_selection(baked):
    """From the view straight onto the fork's radius field: the field takes the click (a new
    interaction; a click without a drag keeps its value) and the selection stays."""
    e = baked
    radius = e.scene.route.levels[LEVEL].radius
    field = window_xy(e, *middle(e.viewer.interactions.rects[RADIUS]))
    off_tree = window_xy(e, 30, 480)  # the view, off the tree and its handles
    rest(e, off_tree)
    count = e.viewer.interactions.count
    quick_click(e, field)
    assert e.selected is not None and e.selected.path == FORK, "the click picked in the view"
    assert e.viewer.interactions.count == count + 1, "the panel's field missed the click"
    assert e.scene.route.levels[LEVEL].radius == radius
    # negative control: the same quick click off the tree in the view clears the selection
    rest(e, field)
    quick_click(e, off_tree)
    assert e.selected is None


def test_a_quick_click_in_the_view_from_the_panel_still_picks(baked):
    """From the panel straight onto the trunk: the trunk's level is picked, and the panel's
    fields take nothing."""
    e = baked
    depth = e.viewer.drawn.geometry.depth
    rest(e, window_xy(e, *middle(e.viewer.interactions.rects[RADIUS])))
    count = e.viewer.interactions.count
    quick_click(e, screen_of(e, (0.0, 0.4, -0.2)))
    assert e.selected is not None and e.selected.level == depth - 1
    assert e.viewer.interactions.count == count


def x_arrow(e) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Screen points 30 pixels from the selected fork: on its gizmo's X arrow, and away from
    it where there is no gizmo nor a handle, which a press would grab (the first such point
    from the opposite way round); the arrow's unit direction on screen."""
    import glfw

    from krsview.compile.camera import project
    from krsview.editor.picking import PICK_PIXELS

    def free(window_point) -> bool:  # no shown handle within 1.5 times the pick radius
        v = e.window_view()
        return all(
            np.hypot(*(np.array(project(v, h.position)[:2]) - window_point)) > 1.5 * PICK_PIXELS
            for h in e.shown()
        )

    at = np.array(screen_of(e, handle(e, FORK).position))
    along = np.array(screen_of(e, handle(e, FORK).position + np.array([0.01, 0.0, 0.0]))) - at
    along /= np.linalg.norm(along)
    corner = np.array(glfw.get_window_pos(e.viewer.window))
    for turn in np.radians([180, 195, 165, 210, 150, 225, 135, 240, 120, 255, 105]):
        c, s_ = np.cos(turn), np.sin(turn)
        off = at + 30 * np.array([c * along[0] - s_ * along[1], s_ * along[0] + c * along[1]])
        if free(off - corner):
            return at + 30 * along, off, along
    raise AssertionError("no free point 30 px from the fork")


def test_a_quick_tap_on_the_gizmo_keeps_the_selection(baked):
    """From the view straight onto the gizmo's X arrow: the gizmo's, not a pick of what lies
    under the arrow."""
    e = baked
    arrow, off, _ = x_arrow(e)
    rest(e, window_xy(e, 30, 480))
    quick_click(e, arrow)
    assert e.selected is not None and e.selected.path == FORK
    # negative control: as far off the other way, no gizmo there, the tap picks
    rest(e, window_xy(e, 30, 480))
    quick_click(e, off)
    assert e.selected is None or e.selected.path != FORK


def pose(e) -> tuple[np.ndarray, np.ndarray]:
    """The camera's position and the watched fork's, as they are now."""
    return e.viewer.camera.position.copy(), np.array(e.scene.route.levels[LEVEL].fork)


def moved(e, before: tuple[np.ndarray, np.ndarray]) -> tuple[float, float]:
    """How far the camera and the fork moved since ``before`` (:func:`pose`)."""
    (eye, fork), (eye2, fork2) = before, pose(e)
    return float(np.linalg.norm(eye2 - eye)), float(np.linalg.norm(fork2 - fork))


def press_and_drag(e, start, along) -> tuple[float, float]:
    """From the view, a press straight at ``start`` and a 30-pixel drag along ``along``; how
    far the camera and the fork moved."""
    before = pose(e)
    rest(e, window_xy(e, 30, 480))
    xdo("mousemove", *map(round, start), "mousedown", 1)
    pump(e, 2)
    for k in range(1, 7):
        xdo("mousemove", *map(round, start + 5 * k * along))
        pump(e, 1)
    xdo("mouseup", 1)
    pump(e, 2)
    return moved(e, before)


def test_a_quick_press_and_drag_on_the_gizmo_moves_the_fork_not_the_orbiting_camera(baked):
    """Orbiting (a left drag turns the camera): a press straight onto the gizmo's X arrow
    and a drag move the fork and leave the camera; the same press off the gizmo orbits."""
    e = baked
    e.execute([ToggleOrbit()])
    arrow, off, along = x_arrow(e)
    eye_moved, fork_moved = press_and_drag(e, arrow, along)
    assert eye_moved == 0.0 and fork_moved > 0.0, (eye_moved, fork_moved)
    eye_moved, fork_moved = press_and_drag(e, off, along)  # negative control
    assert eye_moved > 0.0 and fork_moved == 0.0, (eye_moved, fork_moved)


def test_with_the_hud_hidden_a_drag_where_the_panel_was_orbits(baked):
    """F1 hides the panel, whose windows stay in ImGui's context: a press where it was is the
    view's (orbiting, the camera turns); shown again, the same press is the panel's."""
    e = baked
    e.execute([ToggleOrbit(), ToggleHud()])
    pump(e, 2)
    field = np.array(window_xy(e, *middle(e.viewer.interactions.rects[RADIUS])))
    down = np.array([0.0, 1.0])
    assert press_and_drag(e, field, down)[0] > 0.0
    e.execute([ToggleHud()])  # negative control
    pump(e, 2)
    assert press_and_drag(e, field, down)[0] == 0.0


def test_a_quick_wheel_turn_on_the_panel_scrolls_it_and_not_the_flying_speed(baked):
    """From the view straight onto the panel, a wheel notch: the panel scrolls (its fields
    move up), the flying speed stays; the same notch straight into the view changes the
    speed and scrolls nothing."""
    e = baked
    speed = e.viewer.nav.speed_factor
    field = window_xy(e, *middle(e.viewer.interactions.rects[RADIUS]))
    rest(e, window_xy(e, 30, 480))
    y = e.viewer.interactions.rects[RADIUS][1]
    xdo("mousemove", *map(round, field), "click", 5)
    pump(e, 3)
    assert e.viewer.interactions.rects[RADIUS][1] < y and e.viewer.nav.speed_factor == speed
    y = e.viewer.interactions.rects[RADIUS][1]
    xdo("mousemove", *map(round, window_xy(e, 30, 480)), "click", 5)  # negative control
    pump(e, 3)
    assert e.viewer.interactions.rects[RADIUS][1] == y and e.viewer.nav.speed_factor != speed


def test_while_a_panel_field_is_dragged_a_right_press_in_the_view_does_not_look(baked):
    """ImGui holds the pointer while it holds a button pressed on it: a right press in the
    view then is not the look button's; with no field held, it is."""
    e = baked
    field = window_xy(e, *middle(e.viewer.interactions.rects[RADIUS]))
    view = window_xy(e, 30, 480)
    rest(e, field)
    xdo("mousedown", 1)
    pump(e, 2)
    xdo("mousemove", *map(round, view), "mousedown", 3)
    pump(e, 2)
    assert "right" not in e.viewer.input.buttons
    xdo("mouseup", 3, "mouseup", 1)
    pump(e, 2)
    rest(e, view)  # negative control
    xdo("mousedown", 3)
    pump(e, 2)
    assert "right" in e.viewer.input.buttons
    xdo("mouseup", 3)
    pump(e, 2)


def in_one_poll(e, rest_at, *events) -> tuple[float, float]:
    """The pointer resting at ``rest_at`` (frames see it there), then ``events`` (a move,
    a press and a move) delivered together, before any frame; how far the camera and the
    fork moved once the button is up."""
    rest(e, rest_at)
    before = pose(e)
    xdo(*events)
    pump(e, 2)
    xdo("mouseup", 1)
    pump(e, 2)
    return moved(e, before)


def xy(p) -> tuple[int, int]:
    return round(p[0]), round(p[1])


def test_a_tap_drag_in_one_poll_onto_the_gizmo_never_orbits_by_its_motion(baked):
    """Orbiting: a press onto the gizmo's X arrow with the drag's first motion in the same
    poll is the gizmo's alone (the view used to orbit by that motion before the frame found
    the gizmo). A press in the view whose motion reaches the gizmo in that poll orbits, and
    the gizmo, moved under the pointer by that orbit, used to take the press too."""
    e = baked
    e.execute([ToggleOrbit()])
    arrow, off, along = x_arrow(e)
    view = window_xy(e, 30, 480)
    press = ("mousemove", *xy(arrow), "mousedown", 1, "mousemove", *xy(arrow + 30 * along))
    eye_moved, fork_moved = in_one_poll(e, view, *press)
    assert eye_moved == 0.0 and fork_moved > 0.0, (eye_moved, fork_moved)
    e.execute([Undo()])
    eye_moved, fork_moved = in_one_poll(e, off, "mousedown", 1, "mousemove", *xy(arrow))
    assert eye_moved > 0.0 and fork_moved == 0.0, (eye_moved, fork_moved)


def test_a_tap_drag_in_one_poll_off_the_gizmo_orbits(baked):
    """Orbiting, the pointer resting on the gizmo: moved off it, pressed and dragged in one
    poll, the press is the view's and orbits (it used to be nobody's: the gizmo had been
    under the pointer at the last frame); pressed and dragged where it rests, it is the
    gizmo's (the control)."""
    e = baked
    e.execute([ToggleOrbit()])
    arrow, off, along = x_arrow(e)
    away = ("mousemove", *xy(off), "mousedown", 1, "mousemove", *xy(off - 30 * along))
    eye_moved, fork_moved = in_one_poll(e, arrow, *away)
    assert eye_moved > 0.0 and fork_moved == 0.0, (eye_moved, fork_moved)
    arrow, off, along = x_arrow(e)  # where the orbit put them
    on = ("mousedown", 1, "mousemove", *xy(arrow + 30 * along))
    eye_moved, fork_moved = in_one_poll(e, arrow, *on)
    assert eye_moved == 0.0 and fork_moved > 0.0, (eye_moved, fork_moved)


def test_the_motion_of_a_press_a_frame_judges_waits_for_the_frame():
    """Input alone: with ``judged_by_frame`` a left press's motion reaches the drag only once
    judged, and none of it once let go (a gizmo's press); without it (the viewer, whose
    presses are judged as they come) the motion is the drag at once."""
    from krsview.viewer.controls import Input

    for judged in (True, False):
        i = Input(judged_by_frame=True)
        i.move_cursor(10.0, 10.0)
        i.button("left", True)
        i.move_cursor(13.0, 14.0)
        assert i.take_drag() == (0.0, 0.0)
        if judged:
            i.judged()
        else:
            i.let_go("left")
        i.move_cursor(15.0, 14.0)
        assert i.take_drag() == ((5.0, 4.0) if judged else (0.0, 0.0))
    i = Input()  # the control: no frame judges
    i.button("left", True)
    i.move_cursor(3.0, 4.0)
    assert i.take_drag() == (3.0, 4.0)
