"""`krsview bench effects`: what each effect costs, and what specialising saves [KRS17 §11].

On one scene and view, in one run, frames interleaved round by round (medians):
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
from .harness import Variant, median_times
from .report import write_csv

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


def bench_effects(
    scene: Scene, size: tuple[int, int], rounds: int = 5, csv: str | None = None
) -> list[dict]:
    w, h = size
    runs = runs_of(scene)
    med = median_times(
        Renderer(),
        {name: Variant(s, all_effects=uber) for name, (s, uber) in runs.items()},
        size,
        rounds,
        f"bench effects {scene.name}",
    )
    rows = [
        dict(
            variant=name,
            effects="+".join(s.effects) or "none",
            all_effects_compiled=uber,
            ms=med[name] * 1e3,
            ratio_to_plain=med[name] / med["plain"],
            incremental=med[name] / med["plain"] - 1.0,
        )
        for name, (s, uber) in runs.items()
    ]
    alone = [med[name] for name in runs if name.startswith("component ")]
    if alone:
        rows.append(
            dict(
                variant="components alone, summed",
                effects="none",
                all_effects_compiled=False,
                ms=sum(alone) * 1e3,
                ratio_to_plain=sum(alone) / med["plain"],
                incremental=sum(alone) / med["plain"] - 1.0,
            )
        )
    print(
        f"\nEffect costs — {scene.name}, {w}×{h}, {scene.render.tracer} tracing, median of "
        f"{rounds} interleaved rounds (ratios to plain = no effect, specialised)\n"
    )
    print("| variant | effects | ms/frame | × plain | incremental cost |")
    print("|---|---|---:|---:|---:|")
    for row in rows:
        print(
            f"| {row['variant']} | {row['effects']} | {row['ms']:.1f} | "
            f"{row['ratio_to_plain']:.2f} | {row['incremental']:+.0%} |"
        )
    if scene.effects:
        print(
            f"\nspecialised vs all effects compiled, scene's effects on: "
            f"{med['scene, all compiled'] / med['scene, specialised']:.2f}× slower "
            f"when not specialised"
        )
    print(
        f"all effects compiled, none on, vs plain: "
        f"{med['none on, all compiled'] / med['plain']:.2f}×"
    )
    if csv:
        write_csv(rows, csv)
    return rows
