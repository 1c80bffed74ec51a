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
