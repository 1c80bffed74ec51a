"""Vectors, quaternions and quaternion Möbius maps [KRS17 §6, App. A–C]: NumPy only, used by the
scene model (to validate and compose MöKRS levels), the compiler and the reference tracer."""
