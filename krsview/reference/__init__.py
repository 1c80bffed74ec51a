"""NumPy float64 reference, vectorised over rays: the oracle every shader is tested against."""

from .compiled import CompiledKRS, compile_krs
from .krs import distance, nearest
from .render import render_reference

__all__ = ["CompiledKRS", "compile_krs", "distance", "nearest", "render_reference"]
