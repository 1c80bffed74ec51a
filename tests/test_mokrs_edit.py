"""Editing a MöKRS [KRS17 §7]: handles placed in the world through the Möbius maps above their
frame, drags mapped back (round trip), a drag onto a pole refused, the panel's structural
edits validated and one undo step each, drags and step-list edits keeping the shader variant;
and the editor on palm in a real window under Xvfb, dragged with real pointer events."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from krsview.algebra import mobius
from krsview.document.document import Document
from krsview.editor.handles import handles
from krsview.editor.mokrs_handles import RADIUS_DIRECTION, SCALE_DIRECTION
from krsview.editor.mokrs_levels import changed
from krsview.editor.mokrs_panel import LEVELS, moved, refusal_place, removed
from krsview.scene import SceneError, load_scene
from krsview.scene.edits import apply_edit, get_at
from krsview.scene.mokrs import Rotate, Scale, Translate
from krsview.scene.presets import resolve

PRESETS = ("palm", "shell", "inversion")


@pytest.fixture
def palm_window(display, tmp_path):
    """The editor on a copy of palm in a real window under Xvfb, settled; closed after."""
    from krsview.editor.window import Editor

    from .test_editor import settle

    path = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), path)
    e = Editor(path, size=(800, 500))
    try:
        settle(e)
        yield e
    finally:
        e.close()


@pytest.fixture(scope="module", params=PRESETS)
def scene(request):
    return load_scene(resolve(request.param))


def outward(m, level: int, step: int, q: np.ndarray) -> np.ndarray:
    """A point of the frame after step ``step`` of ``level`` carried into the world one step
    at a time (each step's own map applied to the point, no composed matrices): the rest of
    the level's steps, then every coarser level's."""
    x = np.asarray(q, dtype=np.float64)[None]
    for s in m.levels[level].transform[step + 1 :]:
        x = mobius.apply(s.matrix(), x)
    for lv in m.levels[level + 1 :]:
        for s in lv.transform:
            x = mobius.apply(s.matrix(), x)
    return x[0]


def sample(hs, role: str, count: int = 6):
    """Up to ``count`` handles of a role, spread over the levels (the deepest included)."""
    mine = [h for h in hs if h.role == role]
    if not mine:
        return []
    return [mine[k] for k in sorted({round(t) for t in np.linspace(0, len(mine) - 1, count)})]


def test_every_preset_opens_with_handles_for_each_kind_of_step(scene):
    hs = handles(scene)
    kinds = {s.kind for lv in scene.mokrs.levels for s in lv.transform}
    roles = {h.role for h in hs}
    want = {"translate": {"by"}, "scale": {"factor"}, "rotate": {"degrees", "axis"}}
    want["invert"] = {"center", "radius"}
    for kind in kinds:
        assert want[kind] <= roles, (kind, roles)
    points = {i for i, lv in enumerate(scene.mokrs.levels) if hasattr(lv.kernel, "radius")}
    steps = {i for i, lv in enumerate(scene.mokrs.levels) if lv.transform}
    assert {h.level for h in hs} == points | steps


def test_a_handle_sits_at_its_point_carried_through_every_map_above_it(scene):
    """Kernel points, translate vectors and inversion centres: the handle is the point of its
    frame mapped step by step into the world; read in the level's own space (the negative
    control) it lies elsewhere for a level below a transform."""
    m, hs = scene.mokrs, handles(scene)
    checked = misplaced = 0
    for role in ("point", "by", "center"):
        for h in sample(hs, role):
            i = h.level
            step = h.path[4] if h.path[3] == "transform" else -1  # -1: the level's space
            q = np.array(get_at(m, h.path[1:]))  # the point as the file holds it
            expected = outward(m, i, step, q)
            scale = max(1.0, float(np.linalg.norm(expected)))
            assert np.linalg.norm(h.position - expected) <= 1e-9 * scale, (h.label, expected)
            checked += 1
            misplaced += np.linalg.norm(h.position - q) > 1e-3 * scale
    assert checked >= 4
    assert misplaced >= checked // 2, "the level's own space would have placed them as well"


def _targets(m, h):
    """(a point of the handle's frame, the field's value it stands for) for a drag of ``h``."""
    s = get_at(m, h.owner[1:])
    rho = h.size
    if h.role == "by":
        return np.add(s.by, (0.3, -0.2, 0.1)), None
    if h.role == "center":
        return np.add(s.center, (2.0, -1.0, 0.5)), None
    if h.role == "point":
        return np.add(get_at(m, h.path[1:]), (0.05, 0.02, -0.04)), None
    if h.role == "factor":  # on the 0.0001 a dragged factor lands on (FACTOR_DECIMALS)
        f = round(s.factor * 1.1, 4)
        return f * rho * SCALE_DIRECTION, f
    if h.role == "radius":
        r = s.radius * 1.3
        return np.array(s.center) + r * RADIUS_DIRECTION, r
    if h.role == "degrees":
        deg = s.degrees + 10.0
        return mobius.apply(Rotate(s.axis, deg).matrix(), _zero_dial(s, rho)[None])[0], deg
    axis = np.array(s.axis) + np.array([0.3, 0.2, -0.1])
    axis /= np.linalg.norm(axis)
    return rho * axis, tuple(axis)


def _zero_dial(s: Rotate, rho: float) -> np.ndarray:
    """The dial's 0° point: ρ·v, v the unit vector ⊥ axis from the coordinate axis least
    along it (computed here from the rule, not by the module)."""
    a = np.array(s.axis)
    e = np.eye(3)[int(np.argmin(np.abs(a)))]
    v = e - (e @ a) * a
    return rho * v / np.linalg.norm(v)


def test_a_drag_puts_the_handle_where_it_was_dragged(scene):
    """Handle position → drag to a world point → edit → the new handle is at that point (and
    the field holds the value the point stands for). Negative control: the dragged point
    written as the value, as if the handle's frame were the world, lands elsewhere (where
    the maps above it move the frame's origin)."""
    m, hs = scene.mokrs, handles(scene)
    for h in [h for role in {h.role for h in hs} for h in sample(hs, role, 3)]:
        step = h.path[4] if h.path[3] == "transform" else -1
        q, value = _targets(m, h)
        p = outward(m, h.level, step, q)
        s = apply_edit(scene, *h.edit_to(scene, p))
        new = next(k for k in handles(s) if k.same(h))
        scale = max(1.0, float(np.linalg.norm(p)))
        assert np.linalg.norm(new.position - p) <= 1e-7 * scale, (h.label, new.position, p)
        if value is not None:
            assert np.allclose(get_at(s, h.path), value, rtol=1e-9), (h.label, value)
        if value is None and np.linalg.norm(outward(m, h.level, step, p) - p) > 1e-3 * scale:
            wrong = apply_edit(scene, h.path, tuple(p))  # the world point as the frame's
            moved_to = next(k for k in handles(wrong) if k.same(h)).position
            assert np.linalg.norm(moved_to - p) > 1e-3 * scale, h.label


def test_a_dragged_factor_and_a_typed_number_carry_no_float_noise():
    """A scale handle dragged to a point between the 0.0001 steps sets a factor of four
    decimals (the dial's angles land on 0.01° alike); a number from an ImGui float widget
    (float32) is the decimal typed, and a component the widget left keeps its float64 value
    bit for bit. Negative control: the raw values carry the noise."""
    from krsview.editor.mokrs_handles import FACTOR_DECIMALS
    from krsview.viewer.widgets import as_typed

    scene = load_scene(resolve("palm"))
    m, hs = scene.mokrs, handles(scene)
    h = next(h for h in hs if h.role == "factor")
    s = get_at(m, h.owner[1:])
    raw = s.factor * 1.1 + 1.234567e-6
    p = outward(m, h.level, h.path[4], raw * h.size * SCALE_DIRECTION)
    path, value = h.edit_to(scene, p, carry=False)
    assert value == round(raw, FACTOR_DECIMALS) and repr(value) == repr(round(value, 4))
    assert abs(raw - round(raw, FACTOR_DECIMALS)) > 1e-7  # the raw value had more digits
    typed = float(np.float32(0.09))
    assert typed != 0.09 and as_typed(typed, 0.2) == 0.09
    assert as_typed(float(np.float32(4.254944700928016)), 4.254944700928016) == 4.254944700928016
    assert as_typed(float(np.float32(-0.2)), 1.0) == -0.2


def test_a_vector_field_shows_no_rounding_noise():
    """tree-mokrs's kernels start at x = 4.6e-17 beside y = 6.3 (left by its conversion from
    the tree), and its axes hold −0: the fields show 0 there. Control: a small component
    that is a value (1e-4 beside 6.3) is shown as it is."""
    from krsview.viewer.widgets import shown_vector

    scene = load_scene(resolve("tree-mokrs"))
    start = next(lv.kernel.start for lv in scene.mokrs.levels if lv.kernel is not None)
    assert 0 < abs(start[0]) < 1e-15 and shown_vector(start) == (0.0, start[1], start[2])
    assert repr(shown_vector((-0.0, 0.97, 0.24))[0]) == "0.0"
    assert shown_vector((1e-4, 6.3, 0.5)) == (1e-4, 6.3, 0.5)


def test_a_dial_dragged_past_half_a_turn_keeps_turning():
    """The rotate dial reads the angle nearest the present one: 170° + 20° is 190°, not −170°
    (a monotone response); its negative control, 0° + 20°, is 20°."""
    s0 = load_scene(resolve("shell"))
    h = next(h for h in handles(s0) if h.role == "degrees" and h.level == 10)
    for start, expected in ((170.0, 190.0), (0.0, 20.0), (-350.0, -330.0)):
        sc = apply_edit(s0, h.path, start)
        k = next(k for k in handles(sc) if k.same(h))
        st = get_at(sc, h.owner)
        local = mobius.apply(Rotate(st.axis, expected).matrix(), _zero_dial(st, k.size)[None])[0]
        p = outward(sc.mokrs, h.level, h.path[4], local)
        assert get_at(apply_edit(sc, *k.edit_to(sc, p)), h.path) == pytest.approx(expected)


def test_a_drag_that_puts_the_viewpoint_on_a_pole_is_refused_and_the_scene_stays(tmp_path):
    """inversion's outer step maps its centre to infinity: dragging the centre onto the
    camera is refused with a message naming the viewpoint and the pole, and the document
    keeps its scene and history; the negative control, a drag beside it, lands."""
    path = tmp_path / "inversion.toml"
    shutil.copy(resolve("inversion"), path)
    doc = Document(path)
    before = doc.scene
    h = next(h for h in handles(before) if h.role == "center")
    eye = np.array(before.camera.position)
    with pytest.raises(SceneError, match=r"camera\.position.*infinity"):
        doc.apply(*h.edit_to(before, eye), ("gizmo", 1))
    assert doc.scene is before and not doc.history.steps
    beside = eye + np.array([3.0, 0.0, 0.0])
    doc.apply(*h.edit_to(before, beside), ("gizmo", 2))
    assert np.allclose(next(k for k in handles(doc.scene) if k.same(h)).position, beside)
    assert len(doc.history.steps) == 1


def test_an_inserted_identity_level_can_be_grabbed_and_a_drag_gives_it_a_translate():
    """An identity level without a kernel has its origin as a handle (else nothing selects
    it); dragging it adds a translate step whose handle, on the same path, is where the
    origin was dragged, so the drag goes on. Negative control: a level with steps has none."""

    palm = load_scene(resolve("palm"))
    levels = palm.mokrs.levels
    s = apply_edit(palm, LEVELS, changed(levels, 30, "insert")[0])
    origin = [h for h in handles(s) if h.role == "origin"]
    assert [h.level for h in origin] == [31]
    h = origin[0]
    assert np.allclose(h.position, outward(s.mokrs, 31, -1, np.zeros(3)))
    p = h.position + np.array([0.2, -0.1, 0.3])
    moved_level = apply_edit(s, *h.edit_to(s, p))
    assert [st.kind for st in moved_level.mokrs.levels[31].transform] == ["translate"]
    by = next(k for k in handles(moved_level) if k.same(h))
    assert by.role == "by" and np.allclose(by.position, p, atol=1e-9)
    assert not [k for k in handles(moved_level) if k.role == "origin"]


def test_every_mokrs_handle_drags_through_the_editors_path_carry_on_or_off():
    """The editor's drag (dragging.drag_edits, with "a fork carries its subtree" on by
    default) on every role of handle, an inserted identity level's origin included: a kernel
    point or an origin dragged closed the window (a MöKRS handle had no ``carries``). Each
    drag's edits apply and change the scene; a free point's (a kernel point, an origin, a
    translation, an inversion's centre) puts the handle where it was dragged, where a
    factor or a radius slides along its own line."""
    from krsview.editor.dragging import drag_edits

    tree = load_scene(resolve("tree-mokrs"))
    palm = load_scene(resolve("palm"))
    inserted = apply_edit(palm, LEVELS, changed(palm.mokrs.levels, 30, "insert")[0])
    for scene in (tree, palm, inserted):
        hs = handles(scene)
        for h in [h for role in {h.role for h in hs} for h in sample(hs, role, 2)]:
            if h.kind != "point":
                continue
            p = h.position + 0.01 * np.array([1.0, -0.5, 0.25])
            for carry in (True, False):
                s = scene
                for path, value in drag_edits(scene, h, p, carry, 0.0):
                    s = apply_edit(s, path, value)
                assert s != scene, (h.label, carry)
                if h.role in ("point", "origin", "by", "center"):
                    new = next(k for k in handles(s) if k.same(h))
                    assert np.linalg.norm(new.position - p) < 1e-6, (h.label, carry)


def test_a_linked_step_drag_bends_the_finer_levels_with_the_same_steps_alike():
    """palm's leaflets share their steps: turning level 30's dial (linked, the default)
    turns every finer leaflet level the same and no coarser one, and the dial still lands
    where it was dragged; unlinked (the negative control) only level 30 turns."""
    palm = load_scene(resolve("palm"))
    m = palm.mokrs
    h = next(h for h in handles(palm) if h.role == "degrees" and h.level == 30)
    st = get_at(palm, h.owner)
    local = mobius.apply(Rotate(st.axis, 7.5).matrix(), _zero_dial(st, h.size)[None])[0]
    p = outward(m, 30, h.path[4], local)
    leaflets = [i for i, lv in enumerate(m.levels) if lv.transform == m.levels[30].transform]
    assert len(leaflets) == 30
    for carry, turned in ((True, [i for i in leaflets if i <= 30]), (False, [30])):
        s = apply_edit(palm, *h.edit_to(palm, p, carry))
        now = [i for i, lv in enumerate(s.mokrs.levels) if lv.transform and
               lv.transform[1].degrees == pytest.approx(7.5)]  # fmt: skip
        assert now == turned, (carry, now)
        moved_to = next(k for k in handles(s) if k.same(h)).position
        assert np.linalg.norm(moved_to - p) < 1e-9 * max(1.0, float(np.linalg.norm(p)))


def test_a_refusal_is_shown_under_the_step_or_kernel_it_names():
    assert refusal_place("mokrs.levels[3].transform[1].factor = 0.0: allowed", 3, 3) == "step 1"
    assert refusal_place("mokrs.levels[3].kernel.radius = -1.0: allowed", 3, 3) == "kernel"
    pole = "camera.position = [12.0, 12.0, 12.0]: level 21's transform sends this point"
    assert refusal_place(pole, 3, 3) == "selection"
    assert refusal_place("mokrs.levels = <65 levels>: too many", 3, 3) == "selection"
    # negative controls: another level's step, no error, another part of the scene
    assert refusal_place("mokrs.levels[4].transform[1].factor = 0.0: x", 3, 3) == "selection"
    assert refusal_place("", 3, 3) == ""
    assert refusal_place("render.tracer = 'sphere': this scene is a MöKRS", 3, 3) == ""


def test_a_linked_step_value_refused_is_named_at_the_level_edited():
    """A step's factor typed at palm's level 58 with its 29 linked finer levels: a value the
    level refuses is set there alone, so the refusal names level 58 and lands under its
    step; it used to be the whole level list, refused at level 0 and shown beside another
    step. Negative control: a valid value still goes to every linked level."""
    from krsview.editor.keys import linked_edits

    palm = load_scene(resolve("palm"))
    path = (*LEVELS, 58, "transform", 0, "factor")
    steps = len(palm.mokrs.levels[58].transform)
    edits = linked_edits(palm, path, -1.0, 0.0)
    assert edits == [(path, -1.0)]
    with pytest.raises(SceneError) as refused:
        apply_edit(palm, *edits[0])
    assert str(refused.value).startswith("mokrs.levels[58].transform[0].factor = -1")
    assert refusal_place(str(refused.value), 58, steps) == "step 0"
    [(whole, levels)] = linked_edits(palm, path, 0.9, 0.0)
    assert whole == LEVELS
    s = apply_edit(palm, whole, levels)
    factors = [lv.transform[0].factor for lv in s.mokrs.levels if lv.transform]
    assert factors.count(0.9) == 30, factors


def test_structural_edits_are_validated_and_one_undo_step_each(tmp_path):
    path = tmp_path / "shell.toml"
    shutil.copy(resolve("shell"), path)
    doc = Document(path)
    m = doc.scene.mokrs
    steps = list(m.levels[5].transform)
    assert moved(steps, 0, 1) == [steps[1], steps[0], steps[2]]
    assert moved(steps, 2, 1) == steps  # the outermost stays: nothing to swap with
    doc.apply((*LEVELS, 5, "transform"), moved(steps, 0, 1))
    doc.apply((*LEVELS, 5, "transform"), removed(steps, 1))
    doc.apply((*LEVELS, 5, "transform"), [*steps, Translate((0.0, 0.1, 0.0))])
    assert len(doc.history.steps) == 3
    assert [s.kind for s in doc.scene.mokrs.levels[5].transform] == [
        "scale",
        "rotate",
        "translate",
        "translate",
    ]
    # shell has 64 levels, the most a MöKRS may have: a duplicate is refused with the limit
    with pytest.raises(SceneError, match="at most 64"):
        doc.apply(LEVELS, changed(m.levels, 5, "duplicate")[0])
    doc.apply(LEVELS, removed(m.levels, 0))
    assert doc.scene.mokrs.n == 63 and len(doc.history.steps) == 4
    with pytest.raises(SceneError, match="numerically singular|allowed"):
        doc.apply((*LEVELS, 5, "transform"), [Scale(1e-6), Scale(1e-6), Scale(1e-6)])
    assert doc.scene.mokrs.n == 63 and len(doc.history.steps) == 4
    doc.undo()
    assert doc.scene.mokrs.n == 64


def test_drags_and_step_list_edits_keep_the_shader_variant():
    """What the renderer compiles (its defines) is the same after a step's drag and after a
    level is duplicated (uniforms only); a kernel of a new kind is a new variant."""
    from krsview.compile.geometry import compile_geometry
    from krsview.gpu.uniforms import variant_defines
    from krsview.scene.model import Sphere

    palm = load_scene(resolve("palm"))

    def defines(s):
        return variant_defines(s, compile_geometry(s.geometry(), s.material.albedo))

    base = defines(palm)
    h = next(h for h in handles(palm) if h.role == "degrees" and h.level == 30)
    dragged = apply_edit(palm, h.path, 12.0)
    levels = palm.mokrs.levels
    longer = apply_edit(palm, LEVELS, changed(levels, 30, "duplicate")[0])
    assert defines(dragged) == base and defines(longer) == base
    sphere = apply_edit(palm, (*LEVELS, 30, "kernel"), Sphere((0.0, 0.0, 0.0), 0.1))
    assert defines(sphere) != base


def test_palm_in_a_window_a_step_dragged_by_real_pointer_events_saved(palm_window):
    """palm opens with its levels and handles; clicking a translate step's handle selects it
    (over the kernel point it shares), a 40 px drag moves it in the screen plane as one undo
    step without a recompile; a rotation step turns on its ring, monotone and proportional
    to the pointer each way round; Ctrl+S writes it. A refused value stays beside its step; a
    level count the MöKRS cannot truncate to draws every level and says why."""
    from krsview.scene.model import Empty
    from krsview.viewer.commands import Edit

    from .test_editor import assert_moved_right, click, drag, pump, screen_of, xdo

    e = palm_window
    assert len(e.handles) > 150 and not e.viewer.error
    compiles = e.viewer.renderer.programs.compiles
    by = (*LEVELS, 58, "transform", 2, "by")
    h = next(h for h in e.handles if h.path == by)
    click(e, screen_of(e, h.position))
    assert e.selected is not None and e.selected.path == by, e.selected
    old = np.array(h.position)
    drag(e, screen_of(e, old), (40, 0))
    assert_moved_right(e, old, next(k for k in e.handles if k.path == by).position, 40)
    assert len(e.doc.history.steps) == 1, "the drag was not one undo step"
    assert e.viewer.renderer.programs.compiles == compiles, "a drag recompiled the shader"
    turns = turn_the_dial(e, (*LEVELS, 58, "transform", 1, "degrees"))
    assert len(e.doc.history.steps) == 3, "each way round was not one undo step"
    assert e.viewer.renderer.programs.compiles == compiles, "a turn recompiled the shader"
    forth, back = np.diff(turns[0]), np.diff(turns[1])
    assert (forth > 0).all() and (back < 0).all(), turns  # monotone, each way
    assert forth.max() < 3 * forth.min() and forth.max() < 10.0, forth  # proportional
    xdo("key", "ctrl+s")
    pump(e)
    saved = load_scene(e.path)
    assert get_at(saved, by) == get_at(e.scene, by) != (0.0, 0.34, 0.0)
    # a refused factor: the scene stays; the step's field, drawn in the panel, keeps the
    # refused value and its message (naming that field), not the panel's error line
    factor = (*LEVELS, 58, "transform", 0, "factor")
    e.execute([Edit(factor, 0.0)])
    pump(e)
    assert get_at(e.scene, factor) == 0.93
    refused = e.viewer.interactions.refused.get(factor)
    assert refused is not None and refused.value == 0.0 and not e.viewer.error
    assert refusal_place(refused.message, 58, 3) == "step 0", refused.message
    # the outermost level without a kernel: one level cannot be drawn, two can
    e.execute([Edit((*LEVELS, 59, "kernel"), Empty())])
    e.viewer.drawn.set_levels(1)
    pump(e)
    assert e.viewer.drawn.levels == 0 and "cannot be carried" in e.viewer.error
    assert refusal_place(e.viewer.error, 59, 0) == "selection"  # shown in the panel
    e.viewer.drawn.set_levels(2)
    pump(e)
    assert e.viewer.drawn.levels == 2 and e.viewer.drawn.krs.n == 2


def test_a_dial_turns_by_its_point_as_by_its_ring(palm_window):
    """A rotation step's dial point (on its guide circle, away from the ring) turns the dial
    when pressed and dragged round the axis, selected or not: the angle follows the pointer,
    in one undo step each time, and lands on hundredths of a degree; a click on the point that
    slips 3 px selects the dial, or lands on the selected one, without turning it; a flick,
    pressed, dragged and let go before the editor's next turn, turns it as far as the same
    drag made slowly (platform.Platform.hand). Negative control: the same drag or flick
    pressed beside the point, off the point and the ring, turns nothing."""
    from krsview.editor.dial import GRAB_PIXELS, distance_to, plane_basis
    from krsview.editor.mokrs_handles import DIAL_DECIMALS

    from .test_editor import drag, pump, screen_of, xdo

    e = palm_window
    degrees = (*LEVELS, 58, "transform", 1, "degrees")

    def turned(beside=0.0, arc=0.3, steps=6, quick=False):
        """Press on the dial point (or ``beside`` it, pixels to the right) and drag it
        ``arc`` radians round the axis: the angle before, after each move, the steps.
        ``quick``: pressed, moved and let go before the editor's next turn (a flick on a
        slow frame); the angle after it alone."""
        h = next(h for h in e.handles if h.path == degrees)
        before, steps0 = get_at(e.scene, degrees), e.doc.history.index
        arm = h.position - h.pivot
        y, z = arm / np.linalg.norm(arm), np.cross(h.axis, arm / np.linalg.norm(arm))
        angles = []
        for k in range(steps + 1):
            t = arc * k / steps
            q = h.pivot + np.linalg.norm(arm) * (np.cos(t) * y + np.sin(t) * z)
            x, yy = screen_of(e, q)
            xdo("mousemove", round(x + beside), round(yy))
            if quick:
                if k == 0:
                    xdo("mousedown", 1)
                continue
            pump(e, 2 if k == 0 else 1)
            if k == 0:
                xdo("mousedown", 1)
                pump(e, 2)
            else:
                angles.append(get_at(e.scene, degrees))
        xdo("mouseup", 1)
        pump(e, 4 if quick else 2)
        if quick:
            angles = [get_at(e.scene, degrees)]
        return before, angles, e.doc.history.index - steps0

    def turns(before, angles, steps):
        moved = np.abs(np.diff([before, *angles]))
        assert steps == 1 and (moved > 0).sum() >= 4, (before, angles)
        assert 5.0 < abs(angles[-1] - before) < 40.0, (before, angles)  # 0.3 rad ≈ 17°
        assert all(a == round(a, DIAL_DECIMALS) for a in angles), angles
        label = e.doc.history.labels()[0][-1]  # the undo tooltip names the dial, as
        assert label == f"drag L58 step 1 rotate {before:g} deg", label  # it was pressed

    assert e.selected is None
    h = next(h for h in e.handles if h.path == degrees)
    drag(e, screen_of(e, h.position), (3, 0), steps=3)  # a click that slips: selects it
    assert e.selected is not None and e.selected.path == degrees
    assert get_at(e.scene, degrees) == -2.5 and not e.doc.history.steps
    e.select(None)
    pump(e, 2)
    turns(*turned())  # not selected: the press selects it and turns it
    assert e.selected is not None and e.selected.path == degrees
    h = e.selected
    import glfw

    wx, wy = glfw.get_window_pos(e.viewer.window)
    x, y = screen_of(e, h.position)
    ring = e.gizmo.dial._ring(h, e.window_view(), plane_basis(h.axis))
    assert distance_to(ring, x - wx, y - wy) > 2 * GRAB_PIXELS  # the point is off the ring
    before, angles, steps = turned(beside=3 * GRAB_PIXELS)
    assert angles[-1] == before and steps == 0, angles
    before, steps0 = get_at(e.scene, degrees), len(e.doc.history.steps)
    drag(e, screen_of(e, e.selected.position), (3, 0), steps=3)  # a click's slip on it
    assert get_at(e.scene, degrees) == before and len(e.doc.history.steps) == steps0
    before, slow, _ = turned()  # selected: its point turns it as its ring does
    turns(before, slow, 1)
    e.viewer.undo()
    pump(e, 2)
    for selected in (True, False):  # a flick turns it as far, selected or not
        e.select(e.selected if selected else None)
        pump(e, 2)
        b, fast, steps = turned(quick=True)
        assert b == before and steps == 1 and e.selected.path == degrees, (b, fast, steps)
        assert abs(fast[0] - slow[-1]) < 0.05 * abs(slow[-1] - before), (slow, fast)
        e.viewer.undo()
    b, fast, steps = turned(beside=3 * GRAB_PIXELS, quick=True)  # off the point: nothing
    assert fast == [before] and steps == 0, fast


def turn_the_dial(e, path, steps: int = 6, arc: float = 0.4) -> list[list[float]]:
    """Select the rotation step's dial, find the ImGuizmo ring about its axis by hovering
    (points at growing radii around the pivot, in the plane ⊥ axis), then drag along the
    ring by equal arcs one way and back: the step's angle after each small move."""
    from .test_editor import click, pump, screen_of, xdo

    h = next(h for h in e.handles if h.path == path)
    click(e, screen_of(e, h.position))
    assert e.selected is not None and e.selected.path == path, e.selected
    y = np.cross(h.axis, [0.0, 1.0, 0.0] if abs(h.axis[1]) < 0.9 else [1.0, 0.0, 0.0])
    y /= np.linalg.norm(y)
    z = np.cross(h.axis, y)

    def at(r, t):
        return screen_of(e, h.pivot + r * (np.cos(t) * y + np.sin(t) * z))

    ring = None
    for r in np.linspace(0.05, 1.5, 30):
        for t in np.linspace(0.0, 2.0 * np.pi, 8, endpoint=False):
            xdo("mousemove", *(round(c) for c in at(r, t)))
            pump(e, 1)
            if e.gizmo.claims_mouse():
                ring = (r, t)
                break
        if ring:
            break
    assert ring is not None, "no rotate ring around the dial's pivot"
    r, t0 = ring
    out = []
    for way in (1, -1):
        start = t0 if way == 1 else t0 + arc
        xdo("mousemove", *(round(c) for c in at(r, start)))
        pump(e, 2)
        xdo("mousedown", 1)
        pump(e, 2)
        angles = [get_at(e.scene, path)]
        for k in range(1, steps + 1):
            xdo("mousemove", *(round(c) for c in at(r, start + way * arc * k / steps)))
            pump(e, 1)
            angles.append(get_at(e.scene, path))
        xdo("mouseup", 1)
        pump(e, 2)
        out.append(angles)
    return out


def test_an_edit_that_puts_the_viewpoint_flown_in_the_editor_on_a_pole_is_refused(
    display, tmp_path
):
    """The person has flown to p (the editor's camera, not the file's): moving inversion's
    centre onto p sends the viewpoint to infinity, so the edit is refused with a message
    naming the view, shown in the MöKRS section, and the scene and history stay. Negative
    controls: the file's camera alone accepts that edit (the document's own check), and
    with the view flown elsewhere the editor takes it too."""
    from krsview.editor.window import VIEW, Editor

    path = tmp_path / "inversion.toml"
    shutil.copy(resolve("inversion"), path)
    e = Editor(path, size=(320, 200))
    try:
        before = e.scene
        h = next(h for h in e.handles if h.role == "center")
        p = h.position + np.array([0.4, 0.3, -0.2])
        assert np.linalg.norm(p - np.array(before.camera.position)) > 1.0
        Document(path).apply(*h.edit_to(before, p))  # the file's camera is off that pole
        e.viewer.camera.position = p.copy()
        assert not e.edit(*h.edit_to(before, p), ("gizmo", 1))
        error = e.viewer.error
        assert error.startswith(VIEW + " = [") and "np." not in error and "infinity" in error, error
        assert e.scene is before and not e.doc.history.steps
        assert refusal_place(error, h.level, len(before.mokrs.levels[h.level].transform))
        e.viewer.camera.position = np.array(before.camera.position, dtype=float)
        assert e.edit(*h.edit_to(before, p), ("gizmo", 2)), e.viewer.error
        assert np.allclose(next(k for k in e.handles if k.same(h)).position, p)
    finally:
        e.close()


def test_a_step_removed_from_a_linked_level_goes_from_its_linked_levels_and_keeps_it_selected(
    display, tmp_path
):
    """palm's level 58 with its dial selected and step edits linked: removing that step
    removes it from the 29 linked finer levels too (they stay linked, one undo step), and
    the level stays selected (its dial's handle is gone; the panel used to fall back to
    'select a level'). Unlinked (the control), only level 58 loses it."""
    from krsview.editor.mokrs_panel import _steps
    from krsview.editor.window import Editor

    path = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), path)
    e = Editor(path, size=(640, 400))
    try:
        m = e.scene.mokrs
        leaflets = [i for i, lv in enumerate(m.levels) if lv.transform == m.levels[58].transform]
        assert len(leaflets) == 30
        degrees = (*LEVELS, 58, "transform", 1, "degrees")
        for carry, changed in ((True, leaflets), (False, [58])):
            e.carry = carry
            e.select(next(h for h in e.handles if h.path == degrees))
            before, index = e.scene.mokrs.levels, e.doc.history.index
            e.execute([_steps(e, 58, removed(list(before[58].transform), 1))])
            now = e.scene.mokrs.levels
            assert [i for i in range(len(now)) if now[i] != before[i]] == changed, carry
            assert e.doc.history.index == index + 1
            assert not [h for h in e.handles if h.path == degrees]  # the dial's handle is gone
            assert e.selected is not None and e.selected.level == 58, e.selected
            e.viewer.undo()
    finally:
        e.close()


def test_a_step_added_to_a_level_without_steps_is_its_own():
    """A level without steps (palm has 30, and an inserted level starts so) is linked to no
    other: a step added to it with step edits linked goes to it alone, as its handle's drag
    adds one. It went to all 31 empty levels. The control: a leaflet's added step goes to
    the 30 leaflets."""
    from types import SimpleNamespace

    from krsview.editor.mokrs_panel import _steps
    from krsview.scene.mokrs import MobiusStep, linked_levels

    scene = load_scene(resolve("palm"))
    plain = sum(not lv.transform for lv in scene.mokrs.levels)
    new, i, _ = changed(list(scene.mokrs.levels), 58, "insert")
    scene = scene.edit(LEVELS, new)
    m = scene.mokrs
    empty = [k for k, lv in enumerate(m.levels) if not lv.transform]
    assert len(empty) == plain + 1 > 2 and i in empty and linked_levels(m, i) == [i]
    e = SimpleNamespace(carry=True, scene=scene)
    step = MobiusStep.registry["translate"]()
    edit = _steps(e, i, [step])
    assert edit.path == (*LEVELS, i, "transform") and edit.value == [step]
    leaflet = max(k for k, lv in enumerate(m.levels) if lv.transform)  # its finer ones link
    linked = linked_levels(m, leaflet)
    assert len(linked) > 1 and leaflet in linked
    edit = _steps(e, leaflet, [*m.levels[leaflet].transform, step])
    assert edit.path == LEVELS and [k for k in range(len(new)) if edit.value[k] != new[k]] == (
        linked
    )


def test_level_operations_move_the_selection_with_the_level():
    levels = list("abcde")
    assert changed(levels, 3, "inward")[:2] == (list("abdce"), 2)
    assert changed(levels, 3, "outward")[:2] == (list("abced"), 4)
    assert changed(levels, 0, "inward")[:2] == (levels, 0)  # nothing inside the innermost
    assert changed(levels, 4, "outward")[:2] == (levels, 4)
    assert changed(levels, 1, "duplicate")[:2] == (list("abbcde"), 1)
    assert changed(levels, 4, "remove")[:2] == (list("abcd"), 3)
    new, k, _ = changed(levels, 1, "insert")
    assert k == 2 and len(new) == 6 and new[2].transform == [] and new[:2] == levels[:2]


def test_inward_twice_moves_a_level_two_steps_and_the_keys_act_on_levels(display, tmp_path):
    """ "inward" kept the selection at the index, now the other level: a second click swapped
    them back. And Insert / Delete / Ctrl+D said "select a level first" with one selected:
    they act on the selected MöKRS level now, each one undo step."""
    from krsview.editor.mokrs_levels import level_commands
    from krsview.editor.window import Editor

    from .test_editor import pump, xdo

    path = tmp_path / "tree-mokrs.toml"
    shutil.copy(resolve("tree-mokrs"), path)
    e = Editor(path, size=(640, 400))
    try:
        pump(e)
        start = e.scene.mokrs.levels
        e.select_level(17)
        for _ in range(2):
            e.execute(level_commands(e.selected.level, "inward"))
        assert e.selected.level == 15 and e.scene.mokrs.levels[15] == start[17]
        assert e.scene.mokrs.levels[16:18] == [start[15], start[16]]
        assert len(e.doc.history.steps) == 2
        import glfw

        x, y = glfw.get_window_pos(e.viewer.window)
        xdo("mousemove", x + 620, y + 380)  # over the view
        n = len(e.scene.mokrs.levels)
        for key, change in (("Delete", -1), ("ctrl+d", 1), ("Insert", 1)):
            xdo("key", key)
            pump(e, 2)
            assert len(e.scene.mokrs.levels) == n + change and not e.viewer.error, key
            n = len(e.scene.mokrs.levels)
        assert e.scene.mokrs.levels[e.selected.level].transform == []  # the identity, selected
        assert len(e.doc.history.steps) == 5
        # the linked-levels option stays at a level with none linked (it vanished there)
        from imgui_bundle import imgui

        labels, box = [], imgui.checkbox
        imgui.checkbox = lambda label, on: (labels.append(label), box(label, on))[1]
        try:
            pump(e, 2)
        finally:
            imgui.checkbox = box
        assert "step edits also go to linked levels (none now)" in labels
    finally:
        e.close()


def test_a_scale_that_outgrows_float32_over_linked_levels_is_refused(display, tmp_path):
    """A factor of 50 typed at palm's level 58 goes to its 29 linked levels: the bounds grow
    50× a level, to 1.9e51, and the view was drawn one solid colour with overflow warnings.
    Now the edit is refused, naming the level, and so is a render of such a scene; a factor
    of 2 (2e9: within float32) is taken (the control)."""
    import krsview
    from krsview.editor.keys import linked_edits
    from krsview.editor.window import Editor

    from .test_editor import pump

    path = tmp_path / "palm.toml"
    shutil.copy(resolve("palm"), path)
    factor = (*LEVELS, 58, "transform", 0, "factor")
    palm = load_scene(path)
    [(whole, wide)] = linked_edits(palm, factor, 50.0, 0.0)
    with pytest.raises(SceneError, match=r"mokrs.levels\[21\] = <a bound reaching 1.06e\+19>"):
        krsview.render(apply_edit(palm, whole, wide), (8, 4))
    e = Editor(path, size=(320, 200))
    try:
        pump(e)
        assert not e.edit(whole, wide) and "past what float32 holds" in e.viewer.error
        assert e.scene == palm
        # typed in L58's field: the refusal names that field first and stays at it, red
        # (it named levels[21] alone, beside the selection, and the field showed 0.93)
        e.selected = next(h for h in e.handles if h.path == factor)
        pump(e)
        assert factor in e.viewer.interactions.rects, "control: the field is drawn"
        assert not e.edit(whole, wide, field=(factor, 50.0)) and e.viewer.error == ""
        refused = e.viewer.interactions.refused[factor]
        assert refused.value == 50.0 and refused.message.startswith(
            "mokrs.levels[58].transform[0].factor = 50.0: mokrs.levels[21] = <a bound"
        )
        [(whole, fine)] = linked_edits(palm, factor, 2.0, 0.0)
        assert e.edit(whole, fine) and e.scene.mokrs.levels[58].transform[0].factor == 2.0
    finally:
        e.close()


def test_a_kernel_changed_back_to_its_kind_comes_back_as_it_was():
    """A bent toroidal capsule turned into a capsule and back came back straight [review]:
    the kind change remembers what it left, while nothing was edited since."""
    from dataclasses import replace

    from krsview.editor.mokrs_panel import KindsLeft
    from krsview.scene.model import kernel_as

    bent = load_scene(resolve("palm")).mokrs.levels[0].kernel
    assert bent.kind == "toroidal_capsule"
    where = (*LEVELS, 0)
    kinds = KindsLeft()
    cap = kinds.switch(where, bent, "capsule")
    assert cap == kernel_as(bent, "capsule")
    assert kinds.switch(where, cap, "toroidal_capsule") == bent  # the bend is back
    # through a third kind too, each step undisturbed
    ball = kinds.switch(where, kinds.switch(where, bent, "capsule"), "sphere")
    assert kinds.switch(where, kinds.switch(where, ball, "capsule"), "toroidal_capsule") == bent
    # controls: a capsule edited in between, or another level's, is made afresh
    cap = kinds.switch(where, bent, "capsule")
    thicker = replace(cap, radius=cap.radius * 2)
    assert kinds.switch(where, thicker, "toroidal_capsule") == kernel_as(
        thicker, "toroidal_capsule"
    )
    assert kinds.switch((*LEVELS, 1), cap, "toroidal_capsule") != bent


def test_palm_in_a_window_a_kernel_picked_as_a_capsule_and_back_keeps_its_bend(palm_window):
    """The kernel list of a selected level, clicked in a real window: "capsule" makes the
    bent toroidal capsule a straight capsule; "toroidal_capsule" picked next gives the bend
    back (it came back straight [review]). Negative control: the capsule is not the toroid."""
    from imgui_bundle import imgui

    from krsview.editor.mokrs_panel import KERNEL_KINDS

    from .test_editor import click, screen_of, window_xy

    e = palm_window
    by = (*LEVELS, 58, "transform", 2, "by")
    click(e, screen_of(e, next(h for h in e.handles if h.path == by).position))
    kernel = (*LEVELS, 58, "kernel")
    bent = get_at(e.scene, kernel)
    assert bent.kind == "toroidal_capsule"

    def pick(kind: str) -> None:
        x0, y0, x1, y1 = e.viewer.interactions.rects[(*kernel, "kind")]
        click(e, window_xy(e, (x0 + x1) / 2, (y0 + y1) / 2))
        popup = imgui.internal.find_window_by_name("##Combo_00")
        assert popup is not None and popup.active, "the click opened no list"
        style = imgui.get_style()
        line = imgui.get_text_line_height() + style.item_spacing.y
        y = popup.pos.y + style.window_padding.y + line * KERNEL_KINDS.index(kind) + line / 2
        click(e, window_xy(e, popup.pos.x + 30, y))

    pick("capsule")
    capsule = get_at(e.scene, kernel)
    assert capsule.kind == "capsule" and capsule != bent
    assert (capsule.a, capsule.b) == (bent.start, bent.end)
    pick("toroidal_capsule")
    assert get_at(e.scene, kernel) == bent  # the bend is back
    assert len(e.doc.history.steps) == 2  # one undo step each


def test_palm_curls_tracks_follow_their_levels_and_a_refusal_keeps_the_selection(tmp_path):
    """palm-curl's 30 curls are keyed: removing, duplicating or moving a keyed level was
    refused (its tracks pointed past the list's end) or left a track on another level. Now
    each track follows its level, a removed level's track goes with it and is said, a copy
    gets the track copied, and a swap swaps the tracks. A refused operation (a 65th level)
    changes nothing, the selection included: it used to select the level anyway."""
    from types import SimpleNamespace

    from krsview.document.document import Document
    from krsview.editor.mokrs_levels import apply_op

    path = tmp_path / "palm-curl.toml"
    shutil.copy(resolve("palm-curl"), path)
    chosen, said = [], []
    doc = Document(path)

    class Fake:  # what apply_op reads and calls of the editor
        scene = property(lambda self: doc.scene)

    e = Fake()
    e.doc, e.select_level = doc, chosen.append
    e.viewer = SimpleNamespace(
        camera=doc.scene.camera, sync=lambda: None, error="", message="", say=said.append
    )

    def keyed() -> dict[int, tuple]:
        out = {}
        for t in doc.scene.animation.tracks:
            level = int(t.path.split("[")[1].split("]")[0])
            out[level] = tuple(t.keys)
        return out

    before, n = keyed(), len(doc.scene.mokrs.levels)
    k = min(before)  # a keyed curl; the level after it has no track
    assert k + 1 not in before and len(before) == 30
    apply_op(e, k, "remove")
    after = keyed()
    assert e.viewer.error == "" and len(doc.scene.mokrs.levels) == n - 1
    assert {j - 1 if j > k else j: v for j, v in before.items() if j != k} == after
    assert "its 1 track went with it" in said[-1] and chosen[-1] == k
    doc.undo()
    apply_op(e, k, "duplicate")
    assert keyed() == {**{j + 1 if j > k else j: v for j, v in before.items()}, k + 1: before[k]}
    doc.undo()
    apply_op(e, k, "outward")  # swaps level k and k + 1
    assert keyed() == {**{j: v for j, v in before.items() if j != k}, k + 1: before[k]}
    assert chosen[-1] == k + 1
    doc.undo()
    assert keyed() == before

    full = doc.scene.edit(LEVELS, [*doc.scene.mokrs.levels, *doc.scene.mokrs.levels[-4:]])
    doc.commit(full, "grow to 64 levels")  # control: a refusal
    steps, picks = len(doc.history.steps), len(chosen)
    apply_op(e, k, "insert")
    assert "insert level" in e.viewer.error and "refused" in e.viewer.error
    assert len(chosen) == picks and len(doc.history.steps) == steps and doc.scene == full
