//! Point in solid on the GPU (Alg. 4-2, 4-3): phase 1 (one point-vertex per batch of
//! tetrahedra classifying a group of points), phase 2 on the GPU (tiled reduction) and
//! the grid variant, each against the exact CPU test point by point. The special cases
//! (points on faces, edges and vertices, at the apex, on apex edges, in the plane of flat
//! tetrahedra) must be flagged and decided exactly; random points must be decided by the
//! GPU itself, not handed to the CPU.

use glam::DVec3;

use super::{Check, Needs, Step, Stop, first_difference};
use crate::gpu::Context;
use crate::inclusion::gpu::{GpuInclusion, GpuOptions, GpuStats, Phase2};
use crate::inclusion::gpu_grid::GpuGridInclusion;
use crate::inclusion::tetragrid::GridClassifier;
use crate::inclusion::{Class, Classifier, EdgeRule, FeitoTorres};
use crate::mesh::{Mesh, procedural};
use crate::random::Rng;

pub(super) fn checks() -> Vec<Check> {
    // The phase-1 target: 32 points per group in tiles of up to 64 texels a side.
    let needs = Needs { texture: 256, ..Needs::default() };
    vec![
        Check {
            name: "inclusion-phase1",
            what: "phase 1 (one point-vertex per tetrahedron, sums read back) vs the exact test",
            needs,
            run: phase1,
        },
        Check {
            name: "inclusion-phase2",
            what: "phase 1 batched + phase 2 reduced on the GPU vs the exact test",
            needs,
            run: phase2,
        },
        Check {
            name: "inclusion-grid",
            what: "the tetra-grid variant (each point against its cell's tetrahedra) vs the exact test",
            needs,
            run: grid,
        },
        Check {
            name: "inclusion-flags",
            what: "special cases flagged and decided exactly: surface points, apex, flat tetrahedra",
            needs,
            run: flags,
        },
    ]
}

/// The cases: solids with triangles, polygons (non-convex caps), a cavity, a hole.
fn models() -> Vec<(&'static str, Mesh)> {
    vec![
        ("cube", procedural::cube()),
        ("torus", procedural::torus(1.0, 0.4, 16, 8)),
        ("l-prism", procedural::l_prism()),
        ("cavity", procedural::cube_with_cavity()),
    ]
}

fn exact(mesh: &Mesh) -> Result<GridClassifier, Stop> {
    Ok(GridClassifier::new(FeitoTorres::new(mesh)?, 8)?)
}

/// Random points in the grown bounding box.
fn random_points(mesh: &Mesh, n: usize, seed: u64) -> Vec<DVec3> {
    let (lo, hi) = mesh.bounds();
    let pad = (hi - lo) * 0.1;
    Rng::new(seed).points_in_box(n, lo - pad, hi + pad)
}

/// Points on the surface (vertices, face centroids, edge midpoints), the apex and
/// points on apex edges: every one a special case.
fn special_points(mesh: &Mesh) -> Result<Vec<DVec3>, Stop> {
    let p = mesh.positions();
    let mut pts = p.to_vec();
    for f in mesh.faces() {
        pts.push(f.iter().map(|&i| p[i as usize]).sum::<DVec3>() / f.len() as f64);
        pts.push((p[f[0] as usize] + p[f[1] as usize]) * 0.5);
    }
    let ft = FeitoTorres::new(mesh)?;
    let o = ft.apex();
    pts.push(o);
    for t in 0..ft.tetras().len().min(20) {
        pts.push(o + (ft.tetra_vertices(t)[0] - o) * 0.5);
    }
    Ok(pts)
}

/// A GPU classifier of either kind.
trait Gpu {
    fn classify(&mut self, points: &[DVec3]) -> Result<Vec<Class>, Stop>;
    fn stats(&self) -> &GpuStats;
}

impl Gpu for GpuInclusion {
    fn classify(&mut self, points: &[DVec3]) -> Result<Vec<Class>, Stop> {
        Ok(self.classify_all(points)?)
    }
    fn stats(&self) -> &GpuStats {
        GpuInclusion::stats(self)
    }
}

impl Gpu for GpuGridInclusion {
    fn classify(&mut self, points: &[DVec3]) -> Result<Vec<Class>, Stop> {
        Ok(self.classify_all(points)?)
    }
    fn stats(&self) -> &GpuStats {
        GpuGridInclusion::stats(self)
    }
}

/// Classifies random points and special points of every model with the classifier
/// `make` builds, against the exact test. Random points must be decided on the GPU (at
/// most 2% flagged: a pass that computes nothing useful flags everything and would
/// otherwise pass on the CPU's answers); special points on the surface must be flagged.
fn against_exact<G: Gpu>(
    ctx: &Context,
    label: &str,
    make: impl Fn(&Context, GridClassifier) -> Result<G, Stop>,
) -> Step {
    for (name, mesh) in models() {
        let reference = exact(&mesh)?;
        let random = random_points(&mesh, 1500, 11);
        let mut gpu = make(ctx, exact(&mesh)?)?;
        let got = gpu.classify(&random)?;
        let want = reference.classify_all(&random);
        first_difference(&want, &got, |i| format!("{name} ({label}), random point {i} {:?}", random[i]))?;
        let (flagged, drawn) = (gpu.stats().flagged, gpu.stats().gpu_points);
        if drawn == 0 || flagged * 50 > random.len() {
            return Err(Stop::error(format!(
                "{name} ({label}): of {} random points, {drawn} went to the GPU and {flagged} were flagged \
                 for the CPU; the GPU decided too few",
                random.len()
            )));
        }
        let special = special_points(&mesh)?;
        let got = gpu.classify(&special)?;
        let want = reference.classify_all(&special);
        first_difference(&want, &got, |i| format!("{name} ({label}), special point {i} {:?}", special[i]))?;
        let on_surface = want.iter().filter(|&&c| c == Class::OnBoundary).count();
        if gpu.stats().flagged < on_surface {
            return Err(Stop::mismatch(
                format!("{name} ({label}): points flagged among {} special points", special.len()),
                format!("≥ {on_surface} (those on the surface)"),
                gpu.stats().flagged,
            ));
        }
    }
    Ok(())
}

fn phase1(ctx: &Context) -> Step {
    // The thesis' layout: one tetrahedron per point-vertex, the sums on the host.
    let options = GpuOptions { batch: 1, groups_per_draw: 2, phase2: Phase2::Host };
    against_exact(ctx, "batch 1, host sums", |ctx, g| Ok(GpuInclusion::new(ctx, g, options)?))
}

fn phase2(ctx: &Context) -> Step {
    against_exact(ctx, "batched, GPU reduction", |ctx, g| {
        Ok(GpuInclusion::new(ctx, g, GpuOptions::default())?)
    })?;
    let odd = GpuOptions { batch: 7, groups_per_draw: 3, phase2: Phase2::Gpu };
    against_exact(ctx, "batch 7, 3 groups per draw", |ctx, g| Ok(GpuInclusion::new(ctx, g, odd)?))
}

fn grid(ctx: &Context) -> Step {
    for batch in [1, 16] {
        against_exact(ctx, &format!("grid, batch {batch}"), |ctx, g| {
            Ok(GpuGridInclusion::new(ctx, g, batch)?)
        })?;
    }
    Ok(())
}

fn flags(ctx: &Context) -> Step {
    // The apex on the cube's x = 1 face plane: that face's tetrahedra are flat. Points in
    // their plane, inside and outside the face, must all be decided exactly.
    let mesh = procedural::cube();
    let apex = DVec3::new(1.0, 0.3, -0.2);
    let make = || -> Result<GridClassifier, Stop> {
        Ok(GridClassifier::new(FeitoTorres::with_options(&mesh, Some(apex), EdgeRule::Rerun)?, 8)?)
    };
    let mut rng = Rng::new(2);
    let plane: Vec<DVec3> =
        (0..200).map(|_| DVec3::new(1.0, rng.range_f64(-1.5, 1.5), rng.range_f64(-1.5, 1.5))).collect();
    let on_face = plane.iter().filter(|p| p.y.abs() <= 1.0 && p.z.abs() <= 1.0).count();
    let want = make()?.classify_all(&plane);
    let mut gpu = GpuInclusion::new(ctx, make()?, GpuOptions::default())?;
    let got = gpu.classify_all(&plane)?;
    first_difference(&want, &got, |i| format!("cube, apex on a face plane, point {i} {:?}", plane[i]))?;
    if gpu.stats().flagged < on_face {
        return Err(Stop::mismatch(
            "cube, apex on a face plane: points flagged in the flat tetrahedra's plane",
            format!("≥ {on_face}"),
            gpu.stats().flagged,
        ));
    }
    let mut grid = GpuGridInclusion::new(ctx, make()?, 4)?;
    let got = grid.classify_all(&plane)?;
    first_difference(&want, &got, |i| format!("cube, apex on a face plane (grid), point {i} {:?}", plane[i]))
}
