"""Solid voxelization by tetra slicing: a 64³ torus, saved for other tools."""
import texgeo

v = texgeo.load("builtin:torus").voxelize(64)
print(v, "origin", v.origin, "pitch", v.pitch)
print("occupied fraction of the middle z slice:", v.occupied[:, :, 32].mean())
v.save("torus.npy")  # and torus.json with the grid; or "torus.binvox"
