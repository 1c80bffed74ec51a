"""The growth parameters of a KRS tree: ratios and angles from the trunk to the twig.

They are the fields of a ``[tree]`` table (:class:`krsview.scene.tree.Tree` grows them) and of a
baked route's ``[route.growth]``, kept so that the route can be grown again after its growth
parameters change (``scene/restructure.py``'s ``rebake``).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..messages import SceneError
from .model import Mirror
from .schema import COLOR, Vec3, param


@dataclass(frozen=True)
class Growth:
    """Growth parameters of a KRS tree [KRS17 §9.2]: a ``[tree]`` table, and a baked
    route's ``[route.growth]``, from which it can be grown again."""

    levels: int = param(
        20,
        lo=1,
        hi=63,
        help="forks from trunk to twig (2^levels twigs; drawn as levels + 1 KRS levels)",
    )
    base: Vec3 = param((0.0, 0.0, 0.0), help="foot of the trunk")
    up: Vec3 = param((0.0, 1.0, 0.0), unit_vector="normalise", help="trunk direction")
    trunk_length: float = param(1.5, lo=0.0, lo_open=True, help="length of the trunk")
    trunk_radius: float = param(0.12, lo=0.0, lo_open=True, help="section radius of the trunk")
    length_ratio: float = param(0.8, lo=0.05, hi=1.0, help="child / parent branch length")
    radius_ratio: float = param(0.72, lo=0.05, hi=1.0, help="child / parent branch radius")
    branch_angle: float = param(
        32.0, lo=0.0, hi=89.0, unit="degrees", help="angle between a branch and each child"
    )
    divergence: float = param(
        90.0,
        lo=0.0,
        hi=180.0,
        unit="degrees",
        help="turn of successive fork planes around the branch",
    )
    bend: float = param(0.08, lo=-0.5, hi=0.5, help="upward bow of a branch, × its length")
    bark: Vec3 = param((0.30, 0.20, 0.12), **COLOR)
    leaf: Vec3 = param((0.20, 0.45, 0.10), **COLOR)
    leaf_levels: int = param(5, lo=0, hi=63, help="finest levels coloured as leaves")
    forest: list[Mirror] = param(
        [],
        help="extra reflections above the trunk, with empty "
        "kernels: 2^k trees from one [KRS17 §9.2]",
    )
    ground: Vec3 | None = param(
        None,
        lo=0.0,
        hi=1.0,
        help="colour of a ground plane through the base (kernel of the last forest level)",
    )

    def validate(self, path: str) -> None:
        if self.levels + 1 + len(self.forest) > 64:
            raise SceneError(
                f"{path}.forest",
                f"<{len(self.forest)} mirrors>",
                f"levels + 1 + forest mirrors must be ≤ 64; allowed: at most "
                f"{63 - self.levels} forest mirrors with {self.levels} levels",
            )
        if self.ground is not None and not self.forest:
            raise SceneError(
                f"{path}.ground",
                list(self.ground),
                "the ground is the kernel of the last forest level: add at least one forest mirror",
            )


def growth_of(g: Growth) -> Growth:
    """The plain growth parameters of ``g`` (a Tree is one too): what a route keeps."""
    return Growth(**{f.name: getattr(g, f.name) for f in fields(Growth)})
