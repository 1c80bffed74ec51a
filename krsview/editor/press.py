"""Whether the left press under way has become a drag: the pointer has left where it was
pressed by more than a click's CLICK_PIXELS at some moment since (ImGui keeps the farthest
distance while the button is held). Below that, the press is a click, as the viewer counts
it (viewer/controls.py), and a click that selects a handle, or lands on the selected one's
point, must not move it by a slip of the hand (grab.py, gizmo.py, dial.py)."""

from __future__ import annotations

from imgui_bundle import imgui

from ..viewer.controls import CLICK_PIXELS


def past_click() -> bool:
    """Inside an ImGui frame: the left press has moved more than CLICK_PIXELS."""
    left = imgui.MouseButton_.left.value
    return imgui.get_io().mouse_drag_max_distance_sqr[left] > CLICK_PIXELS * CLICK_PIXELS
