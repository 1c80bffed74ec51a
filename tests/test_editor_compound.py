"""A compound's component route in the editor (issue 28): once baked, its forks, control
points and normals are handles placed by the component's placement, and a real pointer drag
of a fork edits ``compound[k].route.levels[j].fork`` in the component's own space, with its
subtree; its route line and clipped parts are drawn placed too."""

from __future__ import annotations

import shutil

import numpy as np

from krsview.editor.handles import handles, polylines
from krsview.editor.structure import baked
from krsview.scene.edits import get_at
from krsview.scene.presets import resolve

from .test_editor import click, drag, pump, screen_of

K = 2  # grove's tree turned by -35° about y, at (4.5, 0, 3.5): left in the view
FORK = ("compound", K, "route", "levels", 10, "fork")
FINER = ("compound", K, "route", "levels", 4, "fork")


def test_a_component_routes_handles_sit_on_its_placed_geometry():
    """Each fork handle is the placed route's fork: the component's placed KRS (what the
    tracer draws, ``Component.placed``) has that fork as its capsule ends. Negative control:
    the fork's own (unplaced) value is far from there."""
    from krsview import load

    s, _, _ = baked(load("grove"), K)
    c = s.compound[K]
    placed = c.placed()
    ends = np.array([p for lv in placed.levels for p in (lv.kernel.start, lv.kernel.end)])
    mine = [h for h in handles(s) if h.path[:3] == (*FORK[:3],) and h.path[-1] == "fork"]
    assert len(mine) == len(c.route.levels)
    for h in mine:
        assert np.min(np.linalg.norm(ends - h.position, axis=1)) < 1e-9, h.label
        raw = np.array(get_at(s, h.path))
        assert np.min(np.linalg.norm(ends - raw, axis=1)) > 0.5
    assert len(polylines(s)) == 1 and np.allclose(polylines(s)[0][0], c.position)


def test_a_real_pointer_drag_moves_a_component_fork_by_the_projected_amount(display, tmp_path):
    """Bake grove's component 2, click its fork 10 and drag the gizmo 40 px right: the fork
    in the file moves by the screen-plane move mapped into the component's space (turned
    back by its -35°), its subtree with it. Negative control: the world move written as it
    is (no placement) is off by far more than the tolerance."""
    from krsview.editor import commands as ec
    from krsview.editor.window import Editor
    from krsview.scene.compound import Placement

    path = tmp_path / "grove.toml"
    shutil.copy(resolve("grove"), path)
    e = Editor(path, size=(640, 400))
    try:
        pump(e, 3)
        e.execute([ec.Bake(K)])
        pump(e, 3)
        h = next(h for h in e.handles if h.path == FORK)
        click(e, screen_of(e, h.position))
        assert e.selected is not None and e.selected.path == FORK, e.selected
        before = e.scene.compound[K].route
        drag(e, screen_of(e, h.position), (40, 0))
        after = e.scene.compound[K].route
        v = e.window_view()
        depth = float((h.position - v.origin) @ v.forward)
        world = 40 * 2 * v.tan_half * depth / v.height * v.right  # the screen-plane move
        c = e.scene.compound[K]
        local = np.linalg.solve(Placement(c.position, c.axis, c.angle, c.scale).linear, world)
        moved = np.subtract(after.levels[10].fork, before.levels[10].fork)
        assert np.linalg.norm(moved - local) < 0.1 * np.linalg.norm(local), (moved, local)
        assert np.linalg.norm(moved - world) > 0.3 * np.linalg.norm(world), "placement ignored"
        finer = np.subtract(after.levels[4].fork, before.levels[4].fork)
        assert np.allclose(finer, moved, atol=1e-9), "the subtree stayed behind"
        assert after.levels[11].fork == before.levels[11].fork, "a coarser fork moved"
        assert len(e.doc.history.steps) == 2, "the bake and the drag: one step each"
        now = next(k for k in e.handles if k.path == FORK).position
        assert np.linalg.norm(now - h.position - world) < 0.1 * np.linalg.norm(world)
    finally:
        e.close()


def test_a_component_routes_clipped_part_is_drawn_where_its_placed_mirror_clips():
    """The tree with mirror R20 turned 36° (its branch 20 crosses it, test_handles.py), as a
    component turned by 40°, scaled by 1.3 and moved: its red part lies on the positive side
    of the placed mirror (what Alg. 1 removes there), and its warning names the component.
    Negative controls: the unplaced part does not; the tree as grown warns of nothing."""
    from dataclasses import replace

    from krsview import load
    from krsview.editor.clipped import clipped_parts, scene_clipped
    from krsview.editor.shown import warnings
    from krsview.scene.compound import Component, Placement

    from .test_handles import turned_route

    tree = load("tree")
    route = turned_route(replace(tree, tree=None, route=tree.tree.route())).route
    c = Component(route=route, position=(3.0, 0.5, 1.0), angle=40.0, scale=1.3)
    s = replace(tree, tree=None, compound=[c])
    parts = scene_clipped(s)
    raw = clipped_parts(route)
    assert raw and [k for k, _ in parts] == [0] * len(raw)
    said = warnings(s)  # the panel names the component's level, and selects the component
    assert [k for k, _ in said] == [0, 0]
    assert said[1][1].startswith("compound[0].route.levels[20] (L20): the branch crosses")
    plain = replace(c, route=tree.tree.route())  # negative control: the tree as grown
    assert warnings(replace(s, compound=[plain])) == [] and not scene_clipped(
        replace(s, compound=[plain])
    )
    m = route.mirror(21)
    u, w = Placement(c.position, c.axis, c.angle, c.scale).plane(m.normal, m.offset)
    for (_, line), (_, unplaced) in zip(parts, raw):
        assert (line @ np.array(u) - w > -1e-9).all()
        assert (unplaced @ np.array(u) - w < 0).all()
