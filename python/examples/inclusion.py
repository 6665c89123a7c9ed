"""Point in solid (Feito-Torres): label random points against a torus knot."""
import numpy as np

import texgeo

knot = texgeo.load("builtin:knot")
lo, hi = np.array(knot.stats()["bbox"])
points = lo + (hi - lo) * np.random.default_rng(1).random((100_000, 3))
labels = knot.contains(points)  # 0 outside, 1 inside, 2 on the boundary
print(f"{(labels == 1).sum()} of {len(points)} points inside")
print(f"volume ≈ {(labels == 1).mean() * np.prod(hi - lo):.4f} (exact: {knot.volume:.4f})")
