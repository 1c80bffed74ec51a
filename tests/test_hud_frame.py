"""The HUD built while the frame is traced [issue 27 §4]: its parts that read nothing of the
new frame are built once that frame's first pass is issued, its numbers once the frame is on
screen, so the HUD drawn over a frame describes that frame; and the numbers fill exactly the
slot left for them, so the HUD's layout is the one drawn at once."""

from __future__ import annotations

import shutil

import pytest
from imgui_bundle import imgui

from krsview.scene.presets import resolve

SIZE = (640, 360)  # the HUD is 440 px wide


@pytest.fixture
def flying(display, tmp_path, monkeypatch, unfolded_hud):
    """A viewer with its HUD on, recording per turn: the image handed to the display pass,
    the image on screen as the HUD's numbers and its other part read it, and the passes
    issued by then."""
    from krsview.gpu.passes import PassImage
    from krsview.viewer import hud, hudframe
    from krsview.viewer.window import Viewer

    path = tmp_path / "tree.toml"
    shutil.copy(resolve("tree"), path)
    v = Viewer(path, size=SIZE, hud=True)
    seen: dict[str, list] = {"shown": [], "numbers": [], "begun": [], "passes": [], "slot": []}
    draws = [0]
    draw, show, numbers, begin, finish = (
        PassImage.draw,
        v.frames.show,
        hud._numbers,
        hudframe.begin_hud,
        hudframe.finish_hud,
    )

    def counted(self, *a, **k):
        draws[0] += 1
        return draw(self, *a, **k)

    def shown(*a, **k):
        seen["shown"].append(v.frames.image[1])
        return show(*a, **k)

    def numbers_(viewer):
        seen["numbers"].append(viewer.frames.frame_state())
        return numbers(viewer)

    def begun(viewer, interactions, foot=0.0):
        seen["begun"].append((viewer.frames.frame_state(), draws[0]))
        out, slot = begin(viewer, interactions, foot)
        spacing = imgui.get_style().item_spacing.y
        seen["slot"].append([slot.y + hud.numbers_height() + spacing])  # where the slot ends
        return out, slot

    def finished(viewer, slot):
        end = finish(viewer, slot)
        seen["slot"][-1].append(end)
        return end

    monkeypatch.setattr(PassImage, "draw", counted)
    monkeypatch.setattr(v.frames, "show", shown)
    monkeypatch.setattr(hud, "_numbers", numbers_)
    monkeypatch.setattr(hudframe, "begin_hud", begun)
    monkeypatch.setattr(hudframe, "finish_hud", finished)
    v.draws, v.seen = draws, seen
    yield v
    v.close()


def fly(v, turns: int) -> list[tuple]:
    """``turns`` turns with W held: per turn the image on screen after it, the image shown,
    the state the numbers and the rest of the HUD read, and the passes drawn before the
    rest of the HUD was built and in the whole turn."""
    out = []
    v.input.key("W", True)
    for _ in range(turns):
        for key in v.seen:
            v.seen[key].clear()
        v.draws[0] = 0
        v.step(1 / 30)
        ((begun, before),) = v.seen["begun"]
        out.append(
            (
                v.frames.frame_state(),
                *v.seen["shown"],
                *v.seen["numbers"],
                begun,
                before,
                v.draws[0],
            )
        )
    v.input.key("W", False)
    return out


def test_the_hud_over_a_frame_shows_that_frame_though_built_while_it_is_traced(flying, monkeypatch):
    v = flying
    a, scales = v.frames.adaptive, iter([0.3, 0.4] * 8)
    # a new size each turn, whatever the machine's load (the frame rate's own changes were
    # too few on a busy machine for the control below)
    monkeypatch.setattr(a, "frame_done", lambda *_, **__: setattr(a, "scale", next(scales)))
    monkeypatch.setattr(a, "predict", lambda *_, **__: None)
    turns = fly(v, 8)
    for after, shown, numbers, _, before, drawn in turns:
        # the numbers describe the image the display pass drew under them, the one on screen
        assert numbers is after and numbers.size == shown and after.state == "moving"
        # the rest of the HUD was built after the first pass was issued, before the last
        assert 1 <= before < drawn
    # negative control: what the HUD's other part saw is the frame before, a size off in
    # some turns: numbers read then would have been one frame late
    stale = [begun.size != shown for _, shown, _, begun, *_ in turns[1:]]
    assert sum(stale) >= 5, stale


def test_the_numbers_fill_the_slot_left_for_them(flying, monkeypatch):
    from krsview.viewer import hud, hudframe

    v = flying
    fly(v, 2)
    ((slot_end, end),) = v.seen["slot"]
    assert end == pytest.approx(slot_end)
    # negative control: a plot taller than the slot was made for ends past it
    begin = hudframe.begin_hud  # the fixture's recorder

    def taller_after(viewer, interactions, foot=0.0):
        out = begin(viewer, interactions, foot)
        monkeypatch.setattr(hud, "PLOT_HEIGHT", hud.PLOT_HEIGHT + 10)
        return out

    monkeypatch.setattr(hudframe, "begin_hud", taller_after)
    fly(v, 1)
    ((slot_end, end),) = v.seen["slot"]
    assert end - slot_end == pytest.approx(10)
