"""Time in a scene: the [animation] table and Scene.at (issue 29)."""

import math

import pytest

from krsview import load
from krsview.scene import SceneError
from krsview.scene.scene import scene_from_toml, scene_to_toml


def test_a_scene_without_the_table_is_at_time_zero_and_at_moves_it():
    s = load("tree")
    assert s.animation is None and s.time == 0.0
    later = s.at(2.5)
    assert later.time == 2.5 and s.time == 0.0, "at() changed the scene it was asked of"
    assert later.at(1.0).time == 1.0
    assert scene_from_toml(scene_to_toml(later)).time == 2.5  # saved and read back
    assert "[animation]" not in scene_to_toml(s)  # a static scene's file does not grow


@pytest.mark.parametrize("bad", [-1.0, math.nan, math.inf, "2", True, 2e6])
def test_a_bad_time_is_a_one_line_error_naming_it(bad):
    with pytest.raises(SceneError) as e:
        load("tree").at(bad)
    assert str(e.value).startswith("time = ") and "\n" not in str(e.value)


def test_a_bad_time_in_a_file_names_the_file_and_field():
    text = scene_to_toml(load("tree").at(1.0)).replace("time = 1.0", "time = -3.0")
    assert "time = -3.0" in text  # the negative control: the edit above took
    with pytest.raises(SceneError, match=r"scene\.toml.*animation\.time"):
        scene_from_toml(text, "scene.toml")


def test_the_api_takes_time_as_a_knob():
    from krsview import api

    assert api.configure(load("tree"), time=2.5).time == 2.5
    assert api.configure(load("tree")).time == 0.0
    with pytest.raises(SceneError, match="time = -1"):
        api.configure(load("tree"), time=-1)


def test_animated_is_tracks_sway_or_an_effect_that_reads_time():
    s = load("tree")
    assert not s.animated and not s.at(3.0).animated  # time alone moves nothing
    assert s.edit("animation", {"sway": {}}).animated
    assert s.edit("animation", {"tracks": [{"path": "tree.bend", "keys": [[0, 0.1]]}]}).animated
    assert s.with_effects([*s.effects, "wind"]).animated and load("tree-wind").animated
    assert not s.with_effects([*s.effects, "twist"]).animated  # the twist does not move


def test_truncating_a_moving_scene_truncates_it_as_posed():
    """The levels slider and --levels on a tree whose tracks address [tree]: the truncated
    scene is the pose's (the tracks cannot address the [krs] that replaces the tree)."""
    s = load("tree").edit(
        "animation", {"time": 2.0, "tracks": [{"path": "tree.trunk_length", "keys": [[2.0, 0.7]]}]}
    )
    cut = s.with_levels(4)
    assert cut.krs.levels[-1].kernel.end[1] == pytest.approx(0.7) and not cut.animated
    assert load("tree").with_levels(4).krs.levels[-1].kernel.end[1] == pytest.approx(1.6)


def test_equal_geometry_compiles_once_and_a_change_compiles_anew():
    """Posed frames whose tracks move only the camera give new but equal geometry: the
    compile cache answers by value with what compiling it gives."""
    import numpy as np

    from krsview.compile.geometry import compile_geometry
    from krsview.compile.krs import compile_krs

    s = load("tree").edit(
        "animation", {"tracks": [{"path": "camera.fov_y", "keys": [[0, 40.0], [1, 50.0]]}]}
    )
    a, b = (s.at(t).posed() for t in (0.2, 0.7))
    assert a.geometry() is not b.geometry() and a.camera != b.camera
    ca = compile_geometry(a.geometry(), a.material.albedo)
    assert compile_geometry(b.geometry(), b.material.albedo) is ca
    fresh = compile_krs(a.geometry(), a.material.albedo)
    assert all(np.array_equal(getattr(ca, f), getattr(fresh, f)) for f in ("mirrors", "records"))
    moved = a.edit("tree.bend", 0.1)  # negative control: another geometry, another compile
    assert compile_geometry(moved.geometry(), moved.material.albedo) is not ca


def turning(keys: str, interpolation: str = "linear") -> str:
    return (
        'name = "turning"\n[tree]\nlevels = 6\nup = [1.0, 0.0, 0.0]\n[[animation.tracks]]\n'
        f'path = "tree.up"\ninterpolation = "{interpolation}"\nkeys = {keys}\n'
    )


def test_check_poses_tracks_between_keys_and_warns_where_a_vector_flips(tmp_path):
    """`krsview check` said "ok" for a direction keyed through the zero vector half way
    between two valid keys; a render then stopped at that moment [review]. It poses the
    scene between keys, and warns where a vector track passes (almost) through what it must
    keep away from, where the view or direction flips in an instant."""
    from krsview import check

    f = tmp_path / "t.toml"
    f.write_text(turning("[[0.0, [1.0, 0.0, 0.0]], [3.0, [-1.0, 0.0, 0.0]]]"))
    with pytest.raises(SceneError) as e:  # exactly zero at the keys' middle, 1.5 s
        check(f)
    assert str(e.value).startswith(f"{f}: animation.tracks[0] at t = 1.5 s = [0.0, 0.0, 0.0]")
    # the zero at 2/3 of the way, smooth: no time drawn is exactly zero, but it flips there
    flips = check(scene_from_toml(turning("[[0.0, [2.0, 0.0, 0.0]], [3.0, [-1.0, 0.0, 0.0]]]",
                                          "smooth")))  # fmt: skip
    (w,) = flips.warnings
    assert w.startswith("animation.tracks[0]: tree.up passes through the zero vector at t ≈ ")
    t = float(w.split("≈ ")[1].split(" s")[0])
    s = t / 3.0  # eased: 2 − 3 (3s² − 2s³) = 0 there
    assert abs(2 - 3 * (3 * s**2 - 2 * s**3)) < 1e-3 and "posed at 3 moments" in flips.moves
    # control: a key off the line, the path passes 0.1 from zero: no warning
    off = "[[0.0, [2.0, 0.0, 0.0]], [3.0, [-1.0, 0.1, 0.0]]]"
    assert check(scene_from_toml(turning(off, "smooth"))).warnings == ()
    # a point through the origin is no flip: only directions and the camera are warned of
    base = "[[0.0, [1.0, 0.0, 0.0]], [2.0, [-1.0, 0.0, 0.0]]]"
    moved = turning(base).replace('path = "tree.up"', 'path = "tree.base"')
    assert check(scene_from_toml(moved)).warnings == ()
    # the camera keyed through what it looks at (its target stays at the preset's)
    tree = load("tree")
    p, q = list(tree.camera.position), tree.camera.target
    beyond = [2 * b - a for a, b in zip(p, q)]
    track = {"path": "camera.position", "interpolation": "linear"}
    through = tree.edit("animation", {"tracks": [{**track, "keys": [[0.0, p], [3.0, beyond]]}]})
    with pytest.raises(SceneError, match=r"between its keys: camera\.target: must be at least"):
        check(through)
