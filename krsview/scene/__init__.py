"""Scene model: validated dataclasses, TOML load/save, tree → KRS. Imports nothing from GL."""

from ..messages import SceneError
from .compound import MAX_COMPONENTS, Component, Compound
from .effects import EFFECTS, EffectSettings, EmptyZone
from .model import (
    KRS,
    MAX_LEVELS,
    Arc,
    Capsule,
    Empty,
    Kernel,
    Level,
    Mirror,
    Plane,
    Sphere,
    ToroidalCapsule,
    arc_of,
    arcs_of,
)
from .mokrs import Invert, MobiusLevel, MobiusStep, MoKRS, Rotate, Scale, Translate
from .render import TRACERS, Camera, Light, Material, Render
from .route import Route, RouteLevel
from .scene import Bookmark, Geometry, Scene, load_scene, save_scene, scene_from_toml, scene_to_toml
from .tree import Tree

__all__ = [
    "Bookmark",
    "Component",
    "Compound",
    "Geometry",
    "MAX_COMPONENTS",
    "EFFECTS",
    "EffectSettings",
    "EmptyZone",
    "KRS",
    "MAX_LEVELS",
    "Arc",
    "Camera",
    "Capsule",
    "Empty",
    "Kernel",
    "Level",
    "Light",
    "Material",
    "Mirror",
    "MobiusLevel",
    "MobiusStep",
    "MoKRS",
    "Invert",
    "Rotate",
    "Scale",
    "Translate",
    "TRACERS",
    "Plane",
    "Render",
    "Scene",
    "SceneError",
    "Sphere",
    "ToroidalCapsule",
    "Route",
    "RouteLevel",
    "Tree",
    "arc_of",
    "arcs_of",
    "load_scene",
    "save_scene",
    "scene_from_toml",
    "scene_to_toml",
]
