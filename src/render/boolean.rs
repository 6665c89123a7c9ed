//! Pictures of a Boolean operation in the style of the 2006 thesis' Figs. 6-9 … 6-12: the
//! two refined operands in their two colours with the cut curve drawn over them, and beside
//! them the result, each face in the colour of the operand it comes from, with the same
//! curve.

use glam::DVec3;

use super::colour::{self, Rgba};
use super::{Content, Polyline};
use crate::boolean::{Evaluation, Operation, Result};
use crate::mesh::Mesh;

/// Width of the cut curve, in pixels.
const CURVE_WIDTH: f32 = 2.5;

/// What a Boolean picture shows: the operands (A in [`colour::FIRST`], B in
/// [`colour::SECOND`]) and, moved to their right by 1.25 times the operands' width along
/// x, the result of `op` with its faces coloured by operand; the cut curve in
/// [`colour::CURVE`] on both.
pub fn content(ev: &Evaluation, op: Operation, regularized: bool) -> Result<Content> {
    let (result, from_a) = ev.result_by_operand(op, regularized)?;
    let a = ev.refined_operand(false);
    let b = ev.refined_operand(true);
    let (lo, hi) = bounds(&[&a, &b]);
    let shift = DVec3::new(1.25 * (hi.x - lo.x).max(f64::MIN_POSITIVE), 0.0, 0.0);
    let (part_a, part_b) = split(&result, from_a);
    let moved = |m: Mesh| m.map_positions(|p| p + shift);
    let mut meshes: Vec<(Mesh, Rgba)> = vec![(a, colour::FIRST), (b, colour::SECOND)];
    for (part, rgba) in [(part_a, colour::FIRST), (part_b, colour::SECOND)] {
        if part.num_faces() > 0 {
            meshes.push((moved(part)?, rgba));
        }
    }
    let curve = ev.cut_curve();
    let lines = curve
        .iter()
        .flat_map(|&[p, q]| {
            [
                Polyline::new(vec![p, q], colour::CURVE, CURVE_WIDTH),
                Polyline::new(vec![p + shift, q + shift], colour::CURVE, CURVE_WIDTH),
            ]
        })
        .collect();
    Ok(Content::Meshes(meshes, lines))
}

fn bounds(meshes: &[&Mesh]) -> (DVec3, DVec3) {
    meshes
        .iter()
        .filter(|m| m.num_vertices() > 0)
        .map(|m| m.bounds())
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), (l, h)| (lo.min(l), hi.max(h)))
}

/// The first `from_a` faces of `mesh` and the rest, each as a mesh of its own.
fn split(mesh: &Mesh, from_a: usize) -> (Mesh, Mesh) {
    let part = |faces: std::ops::Range<usize>| {
        let faces: Vec<Vec<u32>> = faces.map(|f| mesh.face(f).to_vec()).collect();
        Mesh::new(mesh.positions().to_vec(), faces)
            .unwrap_or_else(|e| unreachable!("faces of a valid mesh form a valid mesh: {e}"))
    };
    (part(0..from_a), part(from_a..mesh.num_faces()))
}
