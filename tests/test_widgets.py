"""A field's tooltip states its range in the words its errors use (one schema for file, panels
and CLI): an open bound reads <, not the closed interval the old tooltip drew."""

from __future__ import annotations

from dataclasses import fields

import pytest

from krsview.scene.render import Render
from krsview.scene.route import RouteLevel
from krsview.scene.schema import SceneError, describe_range, from_dict
from krsview.viewer.widgets import tooltip_text


def meta_of(cls: type, name: str) -> dict:
    return dict(next(f for f in fields(cls) if f.name == name).metadata)


def test_an_open_bound_reads_as_the_error_for_a_refused_value_says():
    radius = meta_of(RouteLevel, "radius")
    text = tooltip_text(radius, float)
    with pytest.raises(SceneError) as refused:
        from_dict(RouteLevel, {"fork": [0.0, 1.0, 0.0], "control": [0.0, 0.5, 0.0], "radius": -5.0})
    allowed = describe_range(radius)
    assert allowed == "allowed: 0 < value ≤ 1e+06"
    assert allowed in text and allowed in str(refused.value)
    assert "ctrl+click or double-click to type a value" in text
    # negative control: the same bound closed reads ≤
    assert "allowed: 0 ≤ value ≤ 1e+06" in tooltip_text({**radius, "lo_open": False}, float)


def test_whole_numbers_switches_and_fields_without_a_range():
    steps = meta_of(Render, "steps")
    assert describe_range(steps, int) in tooltip_text(steps, int)
    assert "type a value" not in tooltip_text({"help": "on or off"}, bool)
    assert tooltip_text({"help": "a name"}, str) == "a name"
    assert tooltip_text({}, bool) == ""
