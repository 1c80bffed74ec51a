"""NumPy float64 reference, vectorised over rays: the oracle every shader is tested against."""

from .krs import distance, nearest
from .render import render_reference

__all__ = ["distance", "nearest", "render_reference"]
