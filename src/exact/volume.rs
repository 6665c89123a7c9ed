//! The volume of a closed, oriented triangle surface whose vertices are known as
//! double-double balls ([`Ball`]: exact f64 input vertices, or implicit intersection points
//! divided out to at most 2⁻⁸⁴ of |x| + 1), with a certified error bound: Alg. 3-1's signed
//! tetrahedra with apex at the origin, each determinant and their sum in double-double.
//!
//! Accuracy: [`Volume::error`] bounds |value − exact volume| rigorously (every rounding of
//! the double-double arithmetic and the width of every vertex ball are carried as ball
//! radii, and the last rounding to f64 is added). It is of the order of the vertex balls'
//! widths (2⁻⁸⁴ at most) times the sum of the determinants' absolute products, plus half an
//! ulp of the value: for a sliver whose volume is 10⁻⁸ of the big cancelling terms, still
//! below 10⁻¹⁵ relative (e.g. 1e-16 for a cube minus its copy turned 1e-6°), where an f64
//! sum of the same terms (or of the vertices rounded to f64) can be off by 10⁻⁸ relative.
//!
//! [`Volume::rounding`] bounds how far the volume of the same triangles moves when the
//! vertices given as implicit are rounded to their nearest f64 (nothing else changed):
//! each coordinate moves by at most u = 2⁻⁵³ of itself, so each product of three
//! coordinates by at most (1 + u)³ − 1 < 3.0001·u of itself, and each tetrahedron by at
//! most 3.0001·u/6 times the sum of its determinant's six absolute products.
//!
//! The sum runs over fixed chunks of triangles in parallel and adds the chunks in order:
//! the value does not depend on thread timing.

use rayon::prelude::*;

use super::rounding::Ball;

/// u = 2⁻⁵³.
const U: f64 = 1.0 / 9007199254740992.0;

/// Triangles per parallel chunk.
const CHUNK: usize = 4096;

/// A signed volume, certified: the exact volume lies within `error` of `value`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Volume {
    pub value: f64,
    /// An upper bound of |value − exact volume|.
    pub error: f64,
    /// An upper bound of how far the volume moves when the vertices marked rounded are
    /// rounded to their nearest f64 (see the module docs).
    pub rounding: f64,
}

impl Volume {
    /// This volume scaled by `factor` (a power of two: the frame's scale, exact).
    pub fn scaled(self, factor: impl Fn(f64) -> f64) -> Volume {
        Volume { value: factor(self.value), error: factor(self.error), rounding: factor(self.rounding) }
    }
}

/// A vertex for [`signed_volume`]: its coordinates and whether it is rounded when written
/// (an implicit point) or written as it is (an f64 input vertex).
pub type Vertex = ([Ball; 3], bool);

/// The signed volume of `triangles` over `vertex(id)` (positive for an outward-oriented
/// closed surface); see the module docs for its accuracy.
pub fn signed_volume(triangles: &[[u32; 3]], vertex: impl Fn(u32) -> Vertex + Sync) -> Volume {
    let chunks: Vec<(Ball, f64)> = triangles
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut sum = Ball::of(0.0);
            let mut moved = 0.0;
            for t in chunk {
                let ((a, ra), (b, rb), (c, rc)) = (vertex(t[0]), vertex(t[1]), vertex(t[2]));
                // a · (b × c): six times the signed tetrahedron (origin, a, b, c).
                let cross = |i: usize| {
                    let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                    b[j].mul(&c[k]).sub(&b[k].mul(&c[j]))
                };
                let det = a[0].mul(&cross(0)).add(&a[1].mul(&cross(1))).add(&a[2].mul(&cross(2)));
                sum = sum.add(&det);
                if ra || rb || rc {
                    moved += products(&a, &b, &c);
                }
            }
            (sum, moved)
        })
        .collect();
    let (six, moved) = chunks.iter().fold((Ball::of(0.0), 0.0), |(s, m), (x, y)| (s.add(x), m + y));
    let v = six.div(&Ball::of(6.0)).unwrap_or_else(|| unreachable!("a finite sum divides by 6"));
    // 3.0001·u/6 per unit of the products; the f64 sums of non-negative terms above are
    // within a factor 1 + n·u of the exact ones (n < 2⁴⁰), well inside the margin.
    Volume { value: v.value(), error: v.error(), rounding: moved * (3.0001 * U / 6.0) * (1.0 + 1e-3) }
}

/// Σ |a_i·b_j·c_k| over the six terms of det(a, b, c), from the balls' values widened by
/// their errors (an upper bound).
fn products(a: &[Ball; 3], b: &[Ball; 3], c: &[Ball; 3]) -> f64 {
    let m = |x: &[Ball; 3]| x.each_ref().map(|v| v.value().abs() + v.error());
    let (a, b, c) = (m(a), m(b), m(c));
    let cross = |i: usize| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        b[j] * c[k] + b[k] * c[j]
    };
    a[0] * cross(0) + a[1] * cross(1) + a[2] * cross(2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::Exact;
    use crate::exact::rounding::quotient_exact;

    /// The unit cube's twelve triangles (outward), corners at 0 and 1 shifted by `o`.
    fn cube(o: f64) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
        let p =
            (0..8).map(|i| [(i & 1) as f64 + o, ((i >> 1) & 1) as f64 + o, (i >> 2) as f64 + o]).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let t = quads.iter().flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        (p, t)
    }

    #[test]
    fn exact_vertices_give_the_exact_volume_within_the_bound() {
        // Offsets whose sums with 0 and 1 are exact, so that the cube is exactly a unit cube.
        for o in [0.0, -0.5, 0.375, 1024.25] {
            let (p, t) = cube(o);
            let v = signed_volume(&t, |i| (p[i as usize].map(Ball::of), false));
            assert!((v.value - 1.0).abs() <= v.error, "{v:?}");
            assert!(v.error < 1e-15, "{v:?}");
            assert_eq!(v.rounding, 0.0);
        }
    }

    /// A sliver: the box [7, 8]² × [7, 7 + h] with h = 2⁻²⁵/3 (not an f64), its top corners
    /// given as balls of X/W quotients; the volume h comes out of cancelling terms of size
    /// 7³ (the box sits far from the origin).
    #[test]
    fn a_sliver_far_from_the_origin_keeps_its_relative_accuracy() {
        let (p, t) = cube(0.0);
        let o = 7.0;
        // Heights as exact quotients X/W: 1/3 · 2⁻²⁵, not an f64.
        let (x, w) = (Exact::from_f64(2f64.powi(-25)), Exact::from_f64(3.0));
        let h = Ball::of_exact(&x).div(&Ball::of_exact(&w)).unwrap();
        let vertex = |i: u32| {
            let q = p[i as usize];
            let shift = |c: f64| Ball::of(c + o);
            let z = if q[2] == 1.0 { Ball::of(o).add(&h) } else { Ball::of(o) };
            ([shift(q[0]), shift(q[1]), z], q[2] == 1.0)
        };
        let v = signed_volume(&t, vertex);
        let want = quotient_exact(&x, &w);
        assert!((v.value - want).abs() <= v.error + want * U, "{v:?} vs {want}");
        assert!(v.error <= 1e-15 * want, "{v:?}");
        // Rounding the top corners moves them by about 7·u: the bound covers it and is of
        // the size of the terms' products, not of the sliver.
        assert!(v.rounding > 0.0 && v.rounding < 1e-11, "{v:?}");
    }
}
