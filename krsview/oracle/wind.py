"""The wind in the oracle (issue 29): component c of a windy scene is drawn where its
world→rest map g_c(p) = p + turn(p − b_c, −a_c·max(h, 0)) (``reference/wind.py``: the axis A,
the rates a_c at the scene's time and the feet b_c are read from there) takes p into its rest
geometry. The oracle's unknown is the sign of the rest value at g_c(X), so it needs no
Lipschitz bound: it evaluates g_c itself over a box or segment X, in interval or affine
arithmetic (sin and cos enclosed in ``numbers.py``), and walks the component from there
(``distance.Moved``); its culling and level-of-detail balls are in rest space, where the
walk meets them. A component that stands (a_c = 0: a ground plane) is looked up where it is.

How near a hit lies: the tracer stops where its stepped distance D/(1 + |a|(ρ' + D)) is below
ε/(1 + M) (ε shrunk by the largest shear M = most·reach, ``Wind.lod_scale``), and |a|ρ' ≤ M
near the component, so its rest point is within about ε of the rest geometry. Back in the
world that length stretches by ‖Dg⁻¹‖ = ‖I − x upᵀ/(1 + α)‖ ≤ 1 + β/(1 − β) = 1/(1 − β),
β = |x| = |a|ρ the shear and |α| ≤ β (``reference/wind.py``, Tighter), ρ the distance to the
axis line at the points between; so a hit's reach s widens by 1/(1 − |a|(ρ + 2s)) where that
is at most 2, over the components whose swept ball (``Wind.balls``) lies within 2s of it
(``hit_stretch``).
"""

from __future__ import annotations

import numpy as np

from ..algebra.vectors import cross
from ..compile.geometry import Compiled
from ..reference.wind import Wind
from ..scene import Scene
from .distance import Moved, Vec, dot, minus


def turn(r: Vec, axis: np.ndarray, sin, half_sin) -> Vec:
    """How far the vector r moves when turned about the unit ``axis`` by the angle whose sine
    is ``sin`` and half-angle's sine ``half_sin`` (Numbers): Rodrigues' formula less r, with
    1 − cos = 2 sin²(angle/2), as ``reference/wind.py``'s wind_turn."""
    ax = [float(v) for v in axis]
    axr = (  # axis × r
        r[2] * ax[1] - r[1] * ax[2],
        r[0] * ax[2] - r[2] * ax[0],
        r[1] * ax[0] - r[0] * ax[1],
    )
    along, chord = dot(axis, r), half_sin.sqr() * 2.0
    return tuple(axr[k] * sin + (along * ax[k] - r[k]) * chord for k in range(3))


def unwind(wind: Wind, c: int):
    """g_c over Numbers: where component c's rest geometry is looked up for world points."""
    rate, base = float(wind.rates[c]), wind.bases[c]

    def g(x: Vec) -> Vec:
        r = minus(x, base)
        theta = r[1].relu() * -rate  # the turn back: −a·max(h, 0), h = r·up, up = +y
        move = turn(r, wind.axis, theta.sin(), (theta * 0.5).sin())
        return tuple(x[k] + move[k] for k in range(3))

    return g


def wind_moved(wind: Wind, c: Compiled) -> Moved:
    """The compiled geometry ``c`` with each component the ``wind`` bends looked up through
    g_c; those that stand, where they are."""
    maps = (unwind(wind, i) if wind.rates[i] != 0.0 else None for i in range(len(wind.rates)))
    return Moved(c, tuple(maps))


def hit_stretch(scene: Scene, wind: Wind, p: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Per hit point p (N, 3) with reach s (N,) in the world: how much farther it may lie
    from the bent surface, 1/(1 − β), β = max_c |a_c|(ρ_c(p) + 2s) over the components c
    that may lie within 2s of p (module docstring)."""
    beta = np.zeros(len(p))
    for c, (a, b) in enumerate(zip(np.abs(wind.rates), wind.bases)):
        rho = np.linalg.norm(cross(wind.axis, p - b), axis=-1)
        near = wind.wind_ball_distance(c, p) <= 2.0 * s
        beta = np.where(near, np.maximum(beta, a * (rho + 2.0 * s)), beta)
    if (beta > 0.5).any():
        raise ValueError(
            f"{scene.name}: effect_settings.wind_strength = {scene.effect_settings.wind_strength}"
            f" shears the geometry by {beta.max():.2f} (|a| × distance from the foot's axis);"
            " the oracle judges hits where it is at most 0.5"
        )
    return 1.0 / (1.0 - beta)
