//! Ray crossings, the Jordan-curve baseline (§4.2.2), with Möller–Trumbore intersection.
//!
//! The thesis counts crossings mod 2. On a covering that is not enough: the triangles of a
//! non-convex face overlap with opposite signs, so a ray through the overlap crosses the
//! fan three times (or twice where it is outside the face) and parity would be wrong.
//! Counting *signed* crossings instead (+1 leaving through a triangle, −1 entering, by
//! the side of its normal the ray goes) gives the winding number, which the overlaps
//! leave unchanged. Inside iff it is non-zero, as for every method here.
//!
//! A ray that hits within 1e-9 (barycentric) of a triangle's edge or vertex, or grazes a
//! triangle's plane (|cos| < 1e-7), is cast again in another direction from a fixed
//! pseudo-random sequence. A point within ε of a face is OnBoundary before any ray is cast;
//! a point in the plane of a non-convex face, over its cancelled part, casts its rays from
//! ε/2 off that plane ([`Surface::off_polygon_planes`]).

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier};
use super::error::Result;
use super::surface::Surface;
use super::winding;
use crate::mesh::Mesh;
use crate::random::Rng;

/// Barycentric margin under which a hit counts as on an edge or vertex.
pub const EDGE_MARGIN: f64 = 1e-9;
/// |cos(ray, normal)| under which a ray counts as running along a triangle.
pub const GRAZING: f64 = 1e-7;
/// Directions tried before giving up (then the winding number decides).
pub const MAX_CASTS: usize = 32;
const RAY_SEED: u64 = 0x3a7_0d4e;

/// One ray against one triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hit {
    Miss,
    /// A clean crossing at `x`: +1 leaving (along the normal), −1 entering.
    Cross {
        sign: i32,
        x: DVec3,
    },
    /// Too close to an edge, a vertex, or the triangle's plane to trust: cast again.
    Degenerate,
}

/// Möller–Trumbore: the ray p + t·d (t > 0, |d| = 1, t ≤ `reach`) against triangle (a, b, c).
#[inline]
pub fn ray_hit(p: DVec3, d: DVec3, a: DVec3, b: DVec3, c: DVec3, reach: f64) -> Hit {
    let (e1, e2) = (b - a, c - a);
    let pvec = d.cross(e2);
    let det = e1.dot(pvec); // = −d·n, n = e1×e2
    let s = p - a;
    let n = e1.cross(e2);
    let n_len = n.length();
    if n_len == 0.0 {
        // No area: its edges belong to its neighbours, which report hits near them.
        return Hit::Miss;
    }
    if det.abs() < GRAZING * n_len {
        // Running along the plane: only a problem if the ray comes close to the triangle.
        let dist = n.dot(s) / n_len;
        let cos = det.abs() / n_len;
        let near_plane = dist.abs() <= cos * reach + 1e-12 * reach;
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        return if near_plane && segment_meets_box(p, d, reach, lo, hi) {
            Hit::Degenerate
        } else {
            Hit::Miss
        };
    }
    let inv = 1.0 / det;
    let u = s.dot(pvec) * inv;
    if !(-EDGE_MARGIN..=1.0 + EDGE_MARGIN).contains(&u) {
        return Hit::Miss;
    }
    let qvec = s.cross(e1);
    let v = d.dot(qvec) * inv;
    if v < -EDGE_MARGIN || u + v > 1.0 + EDGE_MARGIN {
        return Hit::Miss;
    }
    let t = e2.dot(qvec) * inv;
    if t <= 0.0 || t > reach {
        return Hit::Miss;
    }
    if u <= EDGE_MARGIN || v <= EDGE_MARGIN || u + v >= 1.0 - EDGE_MARGIN {
        return Hit::Degenerate;
    }
    Hit::Cross { sign: if det < 0.0 { 1 } else { -1 }, x: p + d * t }
}

/// Whether the segment p + t·d, t ∈ [0, reach], meets the box [lo, hi] (slab test).
pub fn segment_meets_box(p: DVec3, d: DVec3, reach: f64, lo: DVec3, hi: DVec3) -> bool {
    let (mut t0, mut t1) = (0.0f64, reach);
    for axis in 0..3 {
        if d[axis] == 0.0 {
            if p[axis] < lo[axis] || p[axis] > hi[axis] {
                return false;
            }
            continue;
        }
        let inv = 1.0 / d[axis];
        let (mut a, mut b) = ((lo[axis] - p[axis]) * inv, (hi[axis] - p[axis]) * inv);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// The ray directions, in order: a fixed generic one, then pseudo-random unit vectors.
pub fn directions() -> impl Iterator<Item = DVec3> {
    let mut rng = Rng::new(RAY_SEED);
    let first = DVec3::new(0.577_215_664_9, 0.298_142_396_9, 0.751_646_028_5).normalize();
    std::iter::once(first).chain(std::iter::from_fn(move || {
        loop {
            let v = rng.point_in_box(DVec3::NEG_ONE, DVec3::ONE);
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return Some(v / l);
            }
        }
    }))
}

/// Casts rays from `p` in the fixed directions until one hits no edge, vertex or face
/// plane (`crossings(p, d, reach)` returns its signed crossing count, `None` to re-cast),
/// and answers by that count; after [`MAX_CASTS`] failures the winding number decides.
pub(crate) fn cast(
    surface: &Surface,
    p: DVec3,
    crossings: impl Fn(DVec3, DVec3, f64) -> Option<i32>,
) -> Class {
    // Any ray from inside the box leaves it within two diagonals.
    let reach = 2.0 * surface.scale() + surface.eps();
    for d in directions().take(MAX_CASTS) {
        if let Some(w) = crossings(p, d, reach) {
            return if w != 0 { Class::Inside } else { Class::Outside };
        }
    }
    winding::classify_nonzero(surface, p)
}

/// Ray crossings over every covering triangle.
#[derive(Clone, Debug)]
pub struct Jordan {
    surface: Surface,
    stats: BuildStats,
}

impl Jordan {
    pub fn new(mesh: &Mesh) -> Result<Jordan> {
        Jordan::with_policy(mesh, false)
    }

    /// `allow_open` accepts open surfaces (see [`Surface::with_policy`]).
    pub fn with_policy(mesh: &Mesh, allow_open: bool) -> Result<Jordan> {
        let (surface, stats) = Surface::timed(mesh, allow_open)?;
        Ok(Jordan { surface, stats })
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    /// Signed crossings along `d`, or `None` when the ray must be cast again.
    fn crossings(&self, p: DVec3, d: DVec3, reach: f64) -> Option<i32> {
        let covering = self.surface.covering();
        let mut w = 0;
        for t in 0..covering.triangles.len() {
            let [a, b, c] = covering.triangle(t);
            match ray_hit(p, d, a, b, c, reach) {
                Hit::Miss => {}
                Hit::Cross { sign, .. } => w += sign,
                Hit::Degenerate => return None,
            }
        }
        Some(w)
    }
}

impl Classifier for Jordan {
    fn name(&self) -> &str {
        "jordan"
    }

    fn classify(&self, p: DVec3) -> Class {
        let surface = &self.surface;
        if !surface.in_bounds(p) {
            return Class::Outside;
        }
        match surface.off_boundary(p, 0..surface.covering().triangles.len()) {
            Some(p) => cast(surface, p, |p, d, reach| self.crossings(p, d, reach)),
            None => Class::OnBoundary,
        }
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_and_degenerate_hits() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let p = DVec3::new(0.2, 0.3, -1.0);
        // Along +z the ray leaves through the triangle's side its normal (+z) points to.
        assert_eq!(ray_hit(p, DVec3::Z, a, b, c, 10.0), Hit::Cross { sign: 1, x: DVec3::new(0.2, 0.3, 0.0) });
        assert_eq!(ray_hit(p, -DVec3::Z, a, b, c, 10.0), Hit::Miss);
        let down = ray_hit(DVec3::new(0.2, 0.3, 1.0), -DVec3::Z, a, b, c, 10.0);
        assert_eq!(down, Hit::Cross { sign: -1, x: DVec3::new(0.2, 0.3, 0.0) });
        assert_eq!(ray_hit(DVec3::new(0.5, 0.0, -1.0), DVec3::Z, a, b, c, 10.0), Hit::Degenerate);
        assert_eq!(ray_hit(DVec3::new(0.5, 0.5, -1.0), DVec3::Z, a, b, c, 10.0), Hit::Degenerate);
        assert_eq!(ray_hit(DVec3::new(-0.5, 0.1, 0.0), DVec3::X, a, b, c, 10.0), Hit::Degenerate);
        assert_eq!(ray_hit(DVec3::new(-0.5, 0.1, 1.0), DVec3::X, a, b, c, 10.0), Hit::Miss);
        assert_eq!(ray_hit(p, DVec3::Z, a, b, c, 0.5), Hit::Miss);
    }

    #[test]
    fn directions_are_unit_and_fixed() {
        let a: Vec<DVec3> = directions().take(5).collect();
        assert_eq!(a, directions().take(5).collect::<Vec<_>>());
        assert!(a.iter().all(|d| (d.length() - 1.0).abs() < 1e-15));
    }
}
