"""Boolean operations on solids: operators, named operations and CSG expressions."""
import texgeo

cube = texgeo.load("builtin:cube")
sphere = texgeo.Mesh(texgeo.load("builtin:sphere").vertices * 1.3, texgeo.load("builtin:sphere").polygons())
for name, result in [("cube | sphere", cube | sphere), ("cube & sphere", cube & sphere),
                     ("cube - sphere", cube - sphere), ("cube ^ sphere", cube ^ sphere)]:
    print(f"{name}: {len(result.triangles())} triangles, volume {result.volume:.4f}")
rounded = texgeo.csg("a & b", a=cube, b=sphere)
rounded.save("rounded-cube.off")
