"""The shipped scene files (data only; krsview.scene.presets finds them)."""
