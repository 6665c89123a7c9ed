"""Catmull-Clark subdivision with fragment meshes on the GPU (or method="cpu")."""
import texgeo

cube = texgeo.load("builtin:cube")
smooth = cube.subdivide(4)
sharp = cube.subdivide(4, crease_angle=60)  # every edge of the cube stays sharp
print(smooth, f"volume {smooth.volume:.4f}")
print(sharp, f"volume {sharp.volume:.4f}")
smooth.save("cube-level4.obj")
