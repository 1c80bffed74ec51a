"""krsview: real-time viewer, editor and benchmark for Kernel–Reflection Sequences [KRS17]."""

from .version import __version__

__all__ = ["__version__"]
