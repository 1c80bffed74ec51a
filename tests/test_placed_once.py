"""A compound's components are placed once each (scene/compound.py ``placed``): a drag's edit
keeps the unchanged components, which would otherwise grow their trees again every frame."""

from __future__ import annotations

import krsview


def test_an_edit_places_only_the_component_it_changed():
    grove = krsview.load("grove")
    parts = grove.geometry().parts
    assert all(a is b for a, b in zip(parts, grove.geometry().parts))  # made once
    moved = grove.edit(("compound", 2, "position"), (-4.0, 0.0, 3.0))
    after = moved.geometry().parts
    kept = [a is b for a, b in zip(parts, after)]
    assert kept == [k != 2 for k in range(len(parts))]
    # negative control: the changed one is placed anew, where the edit put it
    grown = moved.compound[2]._place()
    assert after[2] is not grown and repr(after[2]) == repr(grown) != repr(parts[2])
