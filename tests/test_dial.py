"""The dial ring's geometry (editor/dial.py), without a window: the pointer's angle about the
axis is read back on the whole ring, its far half included (ImGuizmo's ring takes a press only
on the nearer half), the rotation is right-handed, and the ring is found near the pointer."""

from __future__ import annotations

import math

import numpy as np

from krsview.compile.camera import project, view_of
from krsview.editor.dial import distance_to, plane_basis, pointer_angle, rotation
from krsview.scene.render import Camera


class Dial:
    """A stand-in for a dial handle: what the ring reads of it."""

    def __init__(self, pivot, axis):
        self.pivot, self.axis = np.array(pivot, float), np.array(axis, float)


def test_the_pointer_angle_is_read_all_round_the_ring_far_half_too():
    v = view_of(Camera(position=(3.0, 2.0, 4.0), target=(0.0, 0.0, 0.0)), 400, 300)
    h = Dial((0.2, -0.1, 0.0), np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2]))
    e0, e1 = plane_basis(h.axis)
    assert abs(np.cross(e0, e1) @ h.axis - 1.0) < 1e-12  # right-handed with the axis
    far = 0
    for t in np.linspace(-math.pi, math.pi, 37)[1:]:
        p = h.pivot + 0.5 * (math.cos(t) * e0 + math.sin(t) * e1)
        x, y, z = project(v, p)
        far += z > float((h.pivot - v.origin) @ v.forward)
        assert abs(math.remainder(pointer_angle(h, v, (e0, e1), x, y) - t, 2 * math.pi)) < 1e-9
    assert far >= 10, "no point of the far half was tried"
    # negative control: the plane seen edge-on reads no angle
    edge = Dial((0.0, 0.0, 0.0), np.cross(v.forward, v.up))
    assert pointer_angle(edge, v, plane_basis(edge.axis), 200.0, 150.0) is None


def test_rotation_is_right_handed_and_turns_the_dial_point_about_the_axis():
    axis = np.array([0.0, 0.0, 1.0])
    assert np.allclose(rotation(axis, math.pi / 2) @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    a = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
    r = rotation(a, 0.7)
    assert np.allclose(r @ r.T, np.eye(3)) and np.allclose(r @ a, a)
    assert abs(np.trace(r) - (1 + 2 * math.cos(0.7))) < 1e-12
    assert not np.allclose(rotation(a, -0.7), r)  # negative control: the sense matters


def test_the_ring_is_near_a_pointer_on_it_and_far_from_its_centre():
    ring = [
        (100 + 60 * math.cos(t), 80 + 60 * math.sin(t)) for t in np.linspace(0, 2 * math.pi, 65)
    ]
    assert distance_to(ring, 160.0, 80.0) < 1e-9
    assert abs(distance_to(ring, 100.0, 146.0) - 6.0) < 0.1
    assert distance_to(ring, 100.0, 80.0) > 50.0  # the centre is not on the ring
    assert distance_to([], 0.0, 0.0) == math.inf
