//! Boundary decisions do not depend on where the mesh sits: the same
//! solid and the same points, translated far from the origin by an amount that keeps
//! every coordinate exact, get the same label from every method as at the origin —
//! including points a few units in the last place from a face, where "within ε of the
//! surface" must be decided exactly, not by rounding that differs per method.

use glam::DVec3;
use texgeo::gpu::Context;
use texgeo::inclusion::solver::Solver;
use texgeo::inclusion::{Choice, Class, Method, Options};
use texgeo::mesh::{Mesh, procedural};
use texgeo::random::Rng;

/// Translations with the unit in the last place of their coordinates: every test point
/// is a multiple of that unit within 4 of the origin, so it stays exact when translated.
const PLACES: [(f64, f64); 4] = [
    (0.0, 1.0 / (1u64 << 29) as f64),
    (1e7, 1.0 / (1u64 << 29) as f64),
    (3.0e9, 1.0 / (1u64 << 21) as f64),
    (1e12, 1.0 / (1u64 << 13) as f64),
];

/// Points at 0, 1, 2, 3 and 5 units `u` from the surface (both sides) near face points,
/// edges and vertices, plus a few spread points; all multiples of `u`.
fn points(mesh: &Mesh, u: f64, seed: u64) -> Vec<DVec3> {
    let snap = |p: DVec3| (p / u).round() * u;
    let mut rng = Rng::new(seed);
    let pos = mesh.positions();
    let mut out = Vec::new();
    for f in mesh.faces() {
        let corners: Vec<DVec3> = f.iter().map(|&i| pos[i as usize]).collect();
        let n = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
        // The dominant axis of the normal: moving along it changes the distance most.
        let axis = n.abs().max_position();
        let step = DVec3::AXES[axis] * u * n[axis].signum();
        for _ in 0..4 {
            // A point of the face (convex combination), snapped to the lattice.
            let w: Vec<f64> = corners.iter().map(|_| rng.range_f64(0.0, 1.0)).collect();
            let sum: f64 = w.iter().sum();
            let on = snap(corners.iter().zip(&w).map(|(&c, &wi)| c * wi).sum::<DVec3>() / sum);
            for k in [-5.0, -3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0, 5.0] {
                out.push(on + step * k);
            }
        }
        // Along an edge and at a vertex.
        let mid = snap((corners[0] + corners[1]) * 0.5);
        for k in [-2.0, -1.0, 0.0, 1.0, 2.0] {
            out.push(mid + step * k);
            out.push(corners[0] + step * k);
        }
    }
    let (lo, hi) = mesh.bounds();
    out.extend(rng.points_in_box(100, lo - 0.2, hi + 0.2).into_iter().map(snap));
    out
}

fn labels(method: Choice, mesh: &Mesh, pts: &[DVec3], ctx: &Context) -> Vec<Class> {
    let mut solver = Solver::new(method, mesh, &Options::default(), Some(ctx), None)
        .unwrap_or_else(|e| panic!("{method}: {e}"));
    solver.classify_all(pts).unwrap()
}

#[test]
fn every_method_labels_a_translated_solid_as_at_the_origin() {
    let ctx = Context::from_env().expect("a Vulkan device (run tools/setup)");
    // Solids whose vertices (and face centroids) are exact at every placement.
    let solids = [
        ("cube", procedural::cube()),
        ("tetrahedron", procedural::tetrahedron()),
        ("pyramid", procedural::pyramid()),
        ("two-cubes", procedural::two_cubes_sharing_edge()),
        (
            "slanted",
            Mesh::new(
                vec![
                    DVec3::new(-1.0, -1.0, -1.0),
                    DVec3::new(1.0, -1.0, -0.5),
                    DVec3::new(-0.5, 1.0, -1.0),
                    DVec3::new(0.25, 0.5, 1.0),
                ],
                vec![vec![0, 2, 1], vec![0, 1, 3], vec![1, 2, 3], vec![2, 0, 3]],
            )
            .unwrap(),
        ),
    ];
    let mut failures = Vec::new();
    for (name, mesh) in &solids {
        for (place, &(t, u)) in PLACES.iter().enumerate() {
            let pts = points(mesh, u, 7 + place as u64);
            let reference = labels(Choice::Fixed(Method::Cpu), mesh, &pts, &ctx);
            let shift = DVec3::splat(t);
            let moved = mesh.map_positions(|p| p + shift).unwrap();
            let moved_pts: Vec<DVec3> = pts.iter().map(|&p| p + shift).collect();
            assert!(
                moved_pts.iter().zip(&pts).all(|(&m, &p)| m - shift == p),
                "{name}: inexact points at {t}"
            );
            for method in std::iter::once(Choice::Auto).chain(Method::ALL.map(Choice::Fixed)) {
                let got = labels(method, &moved, &moved_pts, &ctx);
                let differ: Vec<_> = (0..pts.len()).filter(|&i| got[i] != reference[i]).collect();
                if let Some(&i) = differ.first() {
                    failures.push(format!(
                        "{name} at {t:e}, {method}: {} of {} points differ, e.g. {} (+{t:e}): {:?} vs {:?} at the origin",
                        differ.len(),
                        pts.len(),
                        pts[i],
                        got[i],
                        reference[i]
                    ));
                }
            }
            // The labels themselves: points a few units away are off the surface once the
            // unit exceeds ε, and on it below.
            assert!(reference.contains(&Class::OnBoundary) && reference.contains(&Class::Inside), "{name}");
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
