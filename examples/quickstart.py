"""Load a shipped scene, change it, render it to NumPy arrays and save the image.

Paste into a notebook cell; a Frame shows itself as an image there."""

import os

import numpy as np

import krsview

size = tuple(int(v) for v in os.environ.get("KRSVIEW_EXAMPLE_SIZE", "320x180").split("x"))

scene = krsview.load("tree")  # a preset's name or a path to a .toml file
print(krsview.check(scene))  # levels, kernel instances, effects, …

frame = krsview.render(scene, size=size)  # colour, depth, normal, iterations, hit
print(frame, frame.color.shape, frame.depth.dtype)
print(f"nearest hit at t = {frame.depth[frame.hit].min():.3f}")

# Scenes are values: edit() returns a new scene, checked by the scene-file schema.
closer = scene.edit("camera.position", (0.0, 2.5, -6.0))
coarse = krsview.render(closer, size=size, epsilon_scale=4.0, levels=12)
print(f"iterations per pixel: {frame.iterations.mean():.1f} → {coarse.iterations.mean():.1f}")

frame.save("tree.png")  # .png, or .npz for every array
print(
    "same hits as the float64 reference:",
    np.mean(krsview.render(scene, size=size, reference=True).hit == frame.hit),
)
