//! Voxelization by slicing tetrahedra with XOR (Ch. 5): `fgpu` (CPU slices, GPU
//! rasterizes), `pgpu` (the vertex shader slices, Alg. 5-2) and `zoned` (PGPU-MP), bit
//! for bit against the exact CPU references. On a box whose faces lie on voxel-centre
//! planes the raw GPU output, without the exact fallback near the surface, must already
//! follow the tie rule; on solids with slanted faces and edges through centres, and on
//! a curved solid, the finished volume must equal the exact one.

use glam::DVec3;

use super::{Check, Needs, Step, Stop};
use crate::gpu::Context;
use crate::mesh::{Mesh, procedural};
use crate::voxel::{Grid, Method, Solid, Volume, Voxelizer, Zone, exact, scanline};

/// Every case is voxelized at this resolution.
const N: usize = 32;

pub(super) fn checks() -> Vec<Check> {
    // The presence buffer has a margin of one texel on each side.
    let needs = Needs { logic_op: true, texture: N as u32 + 2, ..Needs::default() };
    vec![
        Check {
            name: "voxel-fgpu",
            what: "fgpu: CPU-sliced cross-sections XOR-rasterized, 32³, bit for bit",
            needs,
            run: |ctx| method(ctx, Method::Fgpu, Zone::Auto),
        },
        Check {
            name: "voxel-pgpu",
            what: "pgpu: tetrahedra sliced in the vertex shader (Alg. 5-2), 32³, bit for bit",
            needs,
            run: |ctx| method(ctx, Method::Pgpu, Zone::Auto),
        },
        Check {
            name: "voxel-zoned",
            what: "zoned (PGPU-MP): zones of 5 slices (a partial last zone), 32³, bit for bit",
            needs,
            run: |ctx| {
                method(ctx, Method::Zoned, Zone::Slices(std::num::NonZeroUsize::MIN.saturating_add(4)))
            },
        },
    ]
}

/// Disjoint closed meshes as one (vertices renumbered).
fn union(parts: &[Mesh]) -> Result<Mesh, Stop> {
    let (mut p, mut f) = (Vec::new(), Vec::new());
    for m in parts {
        let base = p.len() as u32;
        p.extend_from_slice(m.positions());
        f.extend(m.faces().map(|face| face.iter().map(|&i| i + base).collect::<Vec<_>>()));
    }
    Ok(Mesh::new(p, f)?)
}

/// `inner` plus unit cubes in opposite corners of [0, 32]³: the grid at N = 32 then has
/// voxel side 1 and centres at exact half-integers.
fn on_lattice(inner: Mesh) -> Result<Mesh, Stop> {
    let cube = |lo: f64| procedural::box_between(DVec3::splat(lo), DVec3::splat(lo + 1.0));
    union(&[inner, cube(0.0), cube(31.0)])
}

/// The exact occupancy of every voxel centre by ray parity (the tie rule of `exact`).
fn exact_volume(solid: &Solid, grid: &Grid) -> Result<Volume, Stop> {
    let mut v = Volume::new(grid.n)?;
    for j in 0..grid.n {
        for k in 0..grid.n {
            for i in 0..grid.n {
                if exact::inside_by_ray(&solid.triangles, grid.centre(i, j, k)) {
                    v.set(i, j, k, true);
                }
            }
        }
    }
    Ok(v)
}

/// `got` equals `expected`, or the first differing voxel.
fn same_bits(case: &str, expected: &Volume, got: &Volume) -> Step {
    match got.differences(expected, 1)?.first() {
        None => Ok(()),
        Some(&[i, j, k]) => Err(Stop::mismatch(
            format!("{case}, voxel ({i}, {j}, {k})"),
            expected.get(i, j, k),
            got.get(i, j, k),
        )),
    }
}

fn method(ctx: &Context, method: Method, zone: Zone) -> Step {
    let mut v = Voxelizer::new(Some(ctx.clone()));
    v.zone = zone;
    // Faces on centre planes x = 2.5, 9.5; y = 2.5, 7.5; z = 3.5, 20.5: the raw raster.
    let mesh = on_lattice(procedural::box_between(DVec3::new(2.5, 2.5, 3.5), DVec3::new(9.5, 7.5, 20.5)))?;
    let (grid, solid) = (Grid::for_mesh(&mesh, N)?, Solid::new(&mesh)?);
    let expected = exact_volume(&solid, &grid)?;
    v.fallback = false;
    same_bits(
        "box with faces on centre planes, no fallback",
        &expected,
        &v.run(&solid, &grid, method)?.volume,
    )?;
    v.fallback = true;
    // Slanted faces, edges and vertices through centres; then a curved solid.
    for (o, r) in [(16.0, 10.5), (15.0, 6.5)] {
        let mesh = on_lattice(procedural::octahedron(DVec3::splat(o), r))?;
        let (grid, solid) = (Grid::for_mesh(&mesh, N)?, Solid::new(&mesh)?);
        let expected = exact_volume(&solid, &grid)?;
        let case = format!("octahedron at {o} of radius {r}");
        same_bits(&case, &expected, &v.run(&solid, &grid, method)?.volume)?;
    }
    let mesh = procedural::torus_knot();
    let (grid, solid) = (Grid::for_mesh(&mesh, N)?, Solid::new(&mesh)?);
    let expected = scanline::voxelize(&solid, &grid)?;
    same_bits("torus knot", &expected, &v.run(&solid, &grid, method)?.volume)
}
