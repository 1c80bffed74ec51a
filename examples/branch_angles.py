"""The tree at 40 branch angles, as arrays: one Renderer, one shader variant, 40 frames.
Writes a contact sheet and prints how the crown's covered area grows with the angle."""

import os

import numpy as np
from PIL import Image

import krsview

w, h = (int(v) for v in os.environ.get("KRSVIEW_EXAMPLE_SIZE", "160x90").split("x"))
tree = krsview.load("tree")
angles = np.linspace(10.0, 70.0, 40)

with krsview.Renderer(w, h) as renderer:
    frames = [renderer.render(tree.edit("tree.branch_angle", float(a)), levels=14) for a in angles]

covered = np.array([f.hit.mean() for f in frames])
for a, c in zip(angles[::8], covered[::8]):
    print(f"branch angle {a:5.1f}°: {c:6.1%} of the pixels hit")

rows = [np.concatenate([f.rgb8() for f in frames[r : r + 8]], axis=1) for r in range(0, 40, 8)]
sheet = np.concatenate(rows, axis=0)  # 5 rows of 8, the angle growing along each row
Image.fromarray(sheet).save("branch-angles.png")
print(f"wrote branch-angles.png ({sheet.shape[1]}×{sheet.shape[0]})")
