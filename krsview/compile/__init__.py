"""Scene → the flat arrays every tracer reads: kernel records, mirrors, level bounds and
balls (KRS, compound, MöKRS), and the camera's view and rays. Shared by the GPU packer, the
NumPy reference and the oracle, so none of them imports another."""

from .camera import View, pixel_ray, primary_rays, project, view_of
from .geometry import Compiled, compile_geometry, components, scene_ball
from .krs import CompiledCompound, CompiledKRS, compile_krs
from .mokrs import CompiledMoKRS, compile_mokrs

__all__ = [
    "Compiled",
    "CompiledCompound",
    "CompiledKRS",
    "CompiledMoKRS",
    "View",
    "compile_geometry",
    "compile_krs",
    "compile_mokrs",
    "components",
    "pixel_ray",
    "primary_rays",
    "project",
    "scene_ball",
    "view_of",
]
