"""Where the HUD's parts go: the status line at the window's foot where no other window covers
it, and the measured-accuracy plot's room around its points."""

import math

from krsview.viewer.status import MARGIN, MIN_ROOM, status_spot

DISPLAY = (960.0, 540.0)
FOOT = DISPLAY[1] - MARGIN
HUD = (8.0, 8.0, 448.0, 536.0)  # reaches the foot


def line(length: float, height: float = 24.0):
    """A text ``length`` px long on one line; wrapped at a width, as many lines as it takes."""
    return lambda width: (
        (length, height) if length <= width else (width, height * math.ceil(length / width))
    )


def meets(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def box(spot, measure):
    x, foot, room = spot
    w, h = measure(room)
    return (x, foot - h, x + w, foot)


def test_alone_it_sits_at_the_foot_on_the_left():
    assert status_spot(DISPLAY, line(300), []) == (MARGIN, FOOT, DISPLAY[0] - 2 * MARGIN)


def test_beside_a_hud_that_reaches_the_foot():
    spot = status_spot(DISPLAY, line(300), [HUD])
    assert spot == (HUD[2] + MARGIN, FOOT, 496.0) and not meets(box(spot, line(300)), HUD)
    # control: at the foot's left, where it used to be, it covers the HUD's last lines
    assert meets(box((MARGIN, FOOT, 944.0), line(300)), HUD)
    # a short HUD leaves the foot free
    assert status_spot(DISPLAY, line(300), [(8.0, 8.0, 448.0, 300.0)])[0] == MARGIN


def test_between_windows_or_above_a_timeline():
    panel = (660.0, 0.0, 960.0, 540.0)
    assert status_spot(DISPLAY, line(150), [HUD, panel]) == (456.0, FOOT, 196.0)
    timeline = (8.0, 470.0, 952.0, 532.0)  # the editor's strip across the foot
    spot = status_spot(DISPLAY, line(300), [timeline])
    assert spot[:2] == (MARGIN, timeline[1] - MARGIN)
    assert not meets(box(spot, line(300)), timeline)


def test_too_long_for_one_line_it_is_wrapped_into_a_gap():
    long = line(700)
    spot = status_spot(DISPLAY, long, [HUD])
    assert spot == (456.0, FOOT, 496.0) and not meets(box(spot, long), HUD)
    assert box(spot, long)[1] == FOOT - 48, "two lines"
    # a gap under MIN_ROOM is none: then the foot's left, over the HUD
    narrow = (456.0 + MIN_ROOM, 0.0, 960.0, 540.0)
    assert status_spot(DISPLAY, long, [HUD, narrow])[:2] == (MARGIN, FOOT)
    # a gap whose column is taken higher up (a window right of the HUD, above the foot)
    above = (456.0, 0.0, 960.0, FOOT - 30)
    assert status_spot(DISPLAY, long, [HUD, above])[:2] == (MARGIN, FOOT)


def test_the_measured_plot_leaves_room_around_its_points():
    import numpy as np

    from krsview.viewer.hud import padded

    lo, hi = padded(np.array([10.0, 30.0, 20.0]))
    assert lo < 10.0 and hi > 30.0 and np.isclose(10.0 - lo, hi - 30.0)
    one = padded(np.array([5.0]))  # one point: still a span around it
    assert one[0] < 5.0 < one[1]


def test_a_window_larger_than_the_screen_opens_at_the_largest_size_that_fits(capsys):
    from krsview.viewer.platform import fitted

    assert fitted((960, 540), (1600, 1000)) == (960, 540) and capsys.readouterr().out == ""
    w, h = fitted((4000, 3000), (1600, 1000))
    assert (w, h) == (1333, 1000)
    assert "4000×3000 does not fit the screen (1600×1000)" in capsys.readouterr().out
    assert fitted((4000, 3000), None) == (4000, 3000)  # no monitor known: as asked


def test_the_hud_opened_over_the_edit_panel_moves_beside_it():
    from krsview.editor.layout import MARGIN as GAP
    from krsview.editor.layout import hud_clear_of

    hud = (8.0, 8.0, 448.0, 408.0)
    left = (8.0, 36.0, 348.0, 612.0)  # docked left, below the HUD's title bar
    x = hud_clear_of(hud, left, "left", 1100.0)
    assert x == left[2] + GAP and not meets((x, 8.0, x + 440.0, 408.0), left)
    right = (752.0, 8.0, 1092.0, 612.0)
    # control: the HUD at its own place beside a panel docked right is left where it is
    assert hud_clear_of(hud, right, "right", 1100.0) is None
    dragged = (700.0, 100.0, 1140.0, 500.0)  # dragged onto the right panel: back beside it
    assert hud_clear_of(dragged, right, "right", 1100.0) == right[0] - GAP - 440.0
    # a window too narrow for both: as far from the panel as the window lets it go, once
    narrow = (8.0, 36.0, 328.0, 392.0)
    x = hud_clear_of(hud, narrow, "left", 640.0)
    assert x == 640.0 - GAP - 440.0
    assert hud_clear_of((x, 8.0, x + 440.0, 408.0), narrow, "left", 640.0) is None


def test_above_a_timeline_beside_a_panel_that_reaches_the_top():
    """The editor's timeline across the foot up to a panel docked right that spans the whole
    height: the line goes just above the timeline. It went over the strip's start: the next
    band tried was above the panel's top, off the window [a real-window review]."""
    display = (900.0, 560.0)
    timeline, panel = (8.0, 488.0, 536.0, 552.0), (552.0, 8.0, 892.0, 552.0)
    spot = status_spot(display, line(237, 30), [timeline, panel])
    assert spot[:2] == (MARGIN, timeline[1] - MARGIN)
    drawn = box(spot, line(237, 30))
    assert not meets(drawn, timeline) and not meets(drawn, panel)
    # control: at the foot, where no gap holds it, it covers the strip
    assert meets(box((MARGIN, display[1] - MARGIN, 884.0), line(237, 30)), timeline)


def test_a_long_line_is_wrapped_above_the_timeline_beside_the_panel():
    """A refusal too long for one line where the editor's timeline spans the foot and its
    panel the right: wrapped in the gap above the strip, left of the panel. It was drawn at
    the foot's left across the strip and the panel [a real-window review]. Control: no
    band above holds MIN_ROOM (a panel docked over nearly all the width): the foot's left."""
    display = (800.0, 500.0)
    timeline, panel = (8.0, 428.0, 452.0, 492.0), (460.0, 8.0, 792.0, 492.0)
    long = line(900, 20)
    spot = status_spot(display, long, [timeline, panel])
    assert spot == (MARGIN, timeline[1] - MARGIN, panel[0] - 2 * MARGIN)
    drawn = box(spot, long)
    assert not meets(drawn, timeline) and not meets(drawn, panel) and drawn[1] >= 0
    assert box(spot, long)[1] == spot[1] - 3 * 20, "three lines"
    wide = (8.0 + MIN_ROOM, 8.0, 792.0, 492.0)
    assert status_spot(display, long, [timeline, wide])[:2] == (MARGIN, display[1] - MARGIN)
