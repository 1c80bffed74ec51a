"""The viewer's clock (issue 29): playing advances the moment shown by wall time × speed round
the loop; paused, nothing moves."""

import pytest

from krsview.viewer.playback import SPEED_RANGE, Playback


def test_playing_advances_by_wall_time_times_speed_round_the_loop():
    p = Playback(time=9.0, duration=10.0, playing=True, speed=2.0)
    assert p.advance(0.25) and p.time == pytest.approx(9.5)
    assert p.advance(0.5) and p.time == pytest.approx(0.5)  # 10.5 wraps to 0.5
    p.playing = False  # the negative control: paused, the clock stands
    assert not p.advance(1.0) and p.time == pytest.approx(0.5)


@pytest.mark.parametrize("t, shown", [(-3.0, 0.0), (4.0, 4.0), (99.0, 10.0)])
def test_seek_stays_in_the_loop(t, shown):
    p = Playback(duration=10.0)
    p.seek(t)
    assert p.time == shown


def test_speed_stays_in_the_sliders_range():
    p = Playback()
    p.set_speed(100.0)
    assert p.speed == SPEED_RANGE[1]
    p.set_speed(0.0)
    assert p.speed == SPEED_RANGE[0]
    p.set_speed(1.5)
    assert p.speed == 1.5
