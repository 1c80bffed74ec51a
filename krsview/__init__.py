"""krsview: real-time viewer, editor and benchmark for Kernel–Reflection Sequences [KRS17]."""

__version__ = "0.1.0"
