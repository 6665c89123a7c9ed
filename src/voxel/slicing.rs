//! Tetra slicing (§5.3.2, Table 5-1 as corrected in SPEC §4.2). A tetra with vertices
//! sorted by y (A highest, then B, C, D) meets the slice plane y = s iff A.y > s ≥ D.y;
//! the cross-section points lie on the edges with one end above the plane (y > s) and
//! the other not:
//!
//! | point | A.y > s ≥ B.y | B.y > s ≥ C.y | C.y > s ≥ D.y |
//! |---|---|---|---|
//! | a | AD | AD | AD |
//! | b | AB | BD | BD |
//! | c | AC | AC | CD |
//! | d | –  | BC | –  |
//!
//! Triangle (a, b, c) always, and (c, b, d) in the middle interval: together the convex
//! quad a–b–d–c split along b–c.
//!
//! Every point is computed by [`edge_point`] from its edge alone (upper end first), so
//! two tetras sharing an edge get bit-identical points and their shared cross-section
//! edges cancel exactly under XOR (see `band`).

use glam::DVec3;

/// The cross-section of a tetra with a slice plane, in (x, z) grid units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    /// a, b, c, d (d is meaningful only when `quad`).
    pub points: [[f64; 2]; 4],
    /// Middle interval: the section is the quad a–b–d–c (two triangles).
    pub quad: bool,
}

impl Section {
    /// The one or two triangles to rasterize: (a, b, c) and, for a quad, (c, b, d).
    pub fn triangles(&self) -> impl Iterator<Item = [[f64; 2]; 3]> + '_ {
        let [a, b, c, d] = self.points;
        std::iter::once([a, b, c]).chain(self.quad.then_some([c, b, d]))
    }
}

/// The point where the edge from `upper` (y > s) to `lower` (y ≤ s) crosses y = s:
/// the one formula every method uses (the GPU vertex shader evaluates the same in f32).
pub fn edge_point(upper: DVec3, lower: DVec3, s: f64) -> [f64; 2] {
    let t = (s - upper.y) / (lower.y - upper.y);
    [upper.x + (lower.x - upper.x) * t, upper.z + (lower.z - upper.z) * t]
}

/// Slices j (planes y = j + ½) that cut the sorted tetra `t`: A.y > j + ½ ≥ D.y.
pub fn slice_range(t: &[DVec3; 4], n: usize) -> std::ops::Range<usize> {
    let first = (t[3].y - 0.5).ceil().max(0.0);
    let end = (t[0].y - 0.5).ceil().min(n as f64);
    if first < end { first as usize..end as usize } else { 0..0 }
}

/// Table 5-1: the cross-section of the sorted tetra `t` = [A, B, C, D] with y = s.
pub fn section(t: &[DVec3; 4], s: f64) -> Option<Section> {
    let [a, b, c, d] = *t;
    let above = t.iter().filter(|v| v.y > s).count();
    let (pb, pc) = match above {
        1 => (edge_point(a, b, s), edge_point(a, c, s)),
        2 => (edge_point(b, d, s), edge_point(a, c, s)),
        3 => (edge_point(b, d, s), edge_point(c, d, s)),
        _ => return None,
    };
    let pa = edge_point(a, d, s);
    let pd = if above == 2 { edge_point(b, c, s) } else { pc };
    Some(Section { points: [pa, pb, pc, pd], quad: above == 2 })
}
