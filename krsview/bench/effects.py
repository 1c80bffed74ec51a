"""`krsview bench effects`: what each effect costs, and what specialising saves [KRS17 §11].

On one scene and view, in one run, frames interleaved round by round (fastest rounds):
- ``plain``: the geometry with no effect, the cheap path every ratio is taken against;
- each effect alone, specialised (its #define only): its incremental cost;
- the scene's own effect set, specialised, against the same set in the variant that compiles
  every effect and switches them by a bit of ``u_effects`` (the "uber-shader"), and that
  variant with every bit off against ``plain``;
- the compound [KRS17 §5.1]: a KRS scene drawn as a compound of one (what the compound
  variant's per-component bookkeeping costs); a compound scene against each of its components
  drawn alone, and their sum (what drawing them separately and composing by depth would cost).
The paper reports soft shadows at quarter resolution ≈ 25 % of the primary cost, ambient
occlusion ≈ one extra level and a compound of eight ≈ a single KRS of similar kernel count;
we trace shadows at full resolution.
"""

from __future__ import annotations

from dataclasses import replace

from ..gpu.renderer import Renderer
from ..scene import Compound, EmptyZone, Scene
from ..scene.effects import allowed_effects
from .harness import Variant, bench_inputs, fastest, round_times, time_columns
from .report import TIME_SPREAD, Measured, markdown, ms_spread

TWIST_FALLBACK = 10.0  # degrees per unit, when the scene sets no twist of its own


def with_settings_for(scene: Scene, effect: str) -> Scene:
    """Give an effect something to do when the scene leaves it idle (twist 0, no zones)."""
    fx = scene.effect_settings
    if effect == "twist" and fx.twist == 0.0:
        fx = replace(fx, twist=TWIST_FALLBACK)
    if effect == "empty_zones" and not fx.empty_zones:
        fx = replace(fx, empty_zones=[EmptyZone(scene.camera.target, 0.5)])
    return replace(scene, effects=[effect], effect_settings=fx)


def runs_of(scene: Scene) -> dict[str, tuple[Scene, bool]]:
    """name → (scene, all_effects variant?)."""
    plain = replace(scene, effects=[])
    runs = {"plain": (plain, False)}
    for e in allowed_effects(scene.mokrs is not None):
        runs[e] = (with_settings_for(scene, e), False)
    if scene.effects:
        runs["scene, specialised"] = (scene, False)
        runs["scene, all compiled"] = (scene, True)
    runs["none on, all compiled"] = (plain, True)
    geometry = scene.geometry()
    if isinstance(geometry, Compound):
        for k, part in enumerate(geometry.parts, 1):
            runs[f"component {k} alone"] = (plain.with_geometry(part), False)
    elif scene.mokrs is None:
        runs["compound of 1"] = (plain.with_geometry(Compound((geometry,))), False)
    return runs


def bench_effects(scene: Scene, size: tuple[int, int], rounds: int = 5) -> Measured:
    """One row per variant (:func:`runs_of`, then the components' sum for a compound): its
    effects, ms per frame, ratio to the plain render and incremental cost."""
    scene, size, rounds = bench_inputs(scene, size, rounds)
    runs = runs_of(scene)
    times = round_times(
        Renderer(),
        {name: Variant(s, all_effects=uber) for name, (s, uber) in runs.items()},
        size,
        rounds,
        f"bench effects {scene.name}",
    )
    best = fastest(times)

    def each(name: str) -> list[float]:  # its cost over plain's, round by round
        return [a / b - 1.0 for a, b in zip(times[name], times["plain"])]

    rows = [
        dict(
            variant=name,
            effects="+".join(s.effects) or "none",
            all_effects_compiled=uber,
            **time_columns(times[name]),
            ratio_to_plain=best[name] / best["plain"],
            incremental=best[name] / best["plain"] - 1.0,
            low=min(each(name)),
            high=max(each(name)),
        )
        for name, (s, uber) in runs.items()
    ]
    alone = [best[name] for name in runs if name.startswith("component ")]
    if alone:
        rows.append(
            dict(
                variant="components alone, summed",
                effects="none",
                all_effects_compiled=False,
                ms=sum(alone) * 1e3,
                ms_median="",  # a sum of fastest rounds, not a frame drawn in rounds
                ms_max="",
                ratio_to_plain=sum(alone) / best["plain"],
                incremental=sum(alone) / best["plain"] - 1.0,
                low="",
                high="",
            )
        )
    return Measured(scene, size, rounds, rows)


def _noise(r: dict) -> str:
    """ " (within noise)" where the rounds disagree on the cost's sign (not for plain)."""
    within = r["low"] != "" and r["variant"] != "plain" and r["low"] <= 0.0 <= r["high"]
    return " (within noise)" if within else ""


def table(m: Measured) -> str:
    ms = {row["variant"]: row["ms"] for row in m.rows}
    text = (
        f"\nEffect costs — {m.scene.name}, {m.size[0]}×{m.size[1]}, {m.scene.render.tracer} "
        f"tracing, ms {TIME_SPREAD} of {m.rounds} interleaved rounds (ratios to plain = no effect, "
        "specialised; a cost whose rounds disagree on its sign is within noise)\n\n"
    )
    text += markdown(
        ("variant", "effects", "ms/frame", "× plain", "incremental cost", "rounds [min–max]"),
        "llrrrr",
        (
            (
                r["variant"],
                r["effects"],
                f"{r['ms']:.1f}" if r["ms_median"] == "" else ms_spread(r),
                f"{r['ratio_to_plain']:.2f}",
                f"{r['incremental']:+.0%}" + _noise(r),
                "" if r["low"] == "" else f"{r['low']:+.0%} … {r['high']:+.0%}",
            )
            for r in m.rows
        ),
    )
    if "scene, specialised" in ms:
        text += (
            f"\n\nspecialised vs all effects compiled, scene's effects on: "
            f"{ms['scene, all compiled'] / ms['scene, specialised']:.2f}× slower "
            f"when not specialised"
        )
    return text + (
        f"\nall effects compiled, none on, vs plain: "
        f"{ms['none on, all compiled'] / ms['plain']:.2f}×"
    )
