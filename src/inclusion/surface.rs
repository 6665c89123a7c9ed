//! The solid's boundary as every inclusion method sees it: the covering, the tolerance ε,
//! and the one predicate that decides OnBoundary ("within ε of a face polygon").

use glam::DVec3;

use super::{InclusionError, vec_bytes};
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;

/// ε = `REL_TOL` × (bounding-box diagonal): the distance under which a point is on a
/// plane, a face or the boundary. See the module docs of [`crate::inclusion`].
pub const REL_TOL: f64 = 1e-9;

/// A closed, consistently oriented boundary with its covering and tolerance.
#[derive(Clone, Debug)]
pub struct Surface {
    covering: Covering,
    eps: f64,
    lo: DVec3,
    hi: DVec3,
    /// Unit normal and offset of every polygon face (degree > 3) that is planar within ε;
    /// `None` for triangles and non-planar faces.
    face_planes: Vec<Option<(DVec3, f64)>>,
}

impl Surface {
    /// Covers `mesh` and checks that its faces form a closed, consistently oriented surface.
    pub fn new(mesh: &Mesh) -> Result<Surface, InclusionError> {
        Surface::from_covering(Covering::new(mesh))
    }

    /// Like [`Surface::new`], but with `allow_open` an open or inconsistently oriented
    /// surface is accepted as it is (`texgeo inclusion --allow-open`): the covering still
    /// sums to the generalized winding number, which is no longer 0 or 1.
    pub fn with_policy(mesh: &Mesh, allow_open: bool) -> Result<Surface, InclusionError> {
        if allow_open { Ok(Surface::unchecked(Covering::new(mesh))) } else { Surface::new(mesh) }
    }

    pub fn from_covering(covering: Covering) -> Result<Surface, InclusionError> {
        if let Some(e) = covering.unbalanced_edge() {
            return Err(e.into());
        }
        Ok(Surface::unchecked(covering))
    }

    fn unchecked(covering: Covering) -> Surface {
        let (lo, hi) = covering.bounds();
        let eps = REL_TOL * (hi - lo).length();
        let face_planes = (0..covering.num_faces())
            .map(|f| {
                let tris = covering.face_triangles(f);
                if tris.len() < 2 {
                    return None;
                }
                let n = tris.clone().fold(DVec3::ZERO, |s, t| {
                    let [a, b, c] = covering.triangle(t);
                    s + (b - a).cross(c - a)
                });
                let n = n.try_normalize()?;
                // The centroid is the first corner of every covering triangle of an n-gon.
                let off = n.dot(covering.points[covering.triangles[tris.start][0] as usize]);
                let planar = covering
                    .polygon(f)
                    .iter()
                    .all(|&i| (n.dot(covering.points[i as usize]) - off).abs() <= 0.5 * eps);
                planar.then_some((n, off))
            })
            .collect();
        Surface { covering, eps, lo, hi, face_planes }
    }

    pub fn covering(&self) -> &Covering {
        &self.covering
    }

    /// The tolerance ε (see [`REL_TOL`]).
    pub fn eps(&self) -> f64 {
        self.eps
    }

    /// Bounding box of the boundary.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.lo, self.hi)
    }

    /// Length of the bounding-box diagonal.
    pub fn scale(&self) -> f64 {
        (self.hi - self.lo).length()
    }

    /// True when `p` is inside the bounding box grown by ε (false for NaN): nothing outside
    /// it can be inside or on the boundary.
    pub fn in_bounds(&self, p: DVec3) -> bool {
        let (lo, hi) = (self.lo - self.eps, self.hi + self.eps);
        p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z
    }

    /// Unit normal and offset (n·x = offset) of face `f` when it is a polygon of degree > 3
    /// that is planar within ε/2; `None` for triangles and non-planar faces.
    pub fn face_plane(&self, f: usize) -> Option<(DVec3, f64)> {
        self.face_planes[f]
    }

    /// Signed distance from `p` to the plane of face `f` (0 when it has none, see [`Self::face_plane`]).
    pub fn face_distance(&self, f: usize, p: DVec3) -> f64 {
        self.face_planes[f].map_or(0.0, |(n, off)| n.dot(p) - off)
    }

    /// Cheap filter: `p` is inside the bounding box of covering triangle `t` grown by ε.
    pub fn near_triangle(&self, t: usize, p: DVec3) -> bool {
        let [a, b, c] = self.covering.triangle(t);
        let lo = a.min(b).min(c) - self.eps;
        let hi = a.max(b).max(c) + self.eps;
        p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z
    }

    /// `p` is on the boundary through covering triangle `t`'s face (filtered by [`Self::near_triangle`]).
    pub fn on_boundary_near(&self, t: usize, p: DVec3) -> bool {
        self.near_triangle(t, p) && self.on_face(self.covering.face_of[t] as usize, p)
    }

    /// True iff `p` is within ε of face `f`.
    ///
    /// A triangle: Euclidean distance ≤ ε. An n-gon: `p` is within ε of one of its edges,
    /// or within ε of a covering triangle at a point X around which the polygon (projected
    /// on that triangle's plane) winds — so the parts of the fan that a non-convex face's
    /// negative triangles cancel are *not* boundary.
    pub fn on_face(&self, f: usize, p: DVec3) -> bool {
        let eps = self.eps;
        let tris = self.covering.face_triangles(f);
        if tris.len() == 1 {
            let [a, b, c] = self.covering.triangle(tris.start);
            return closest_point_on_triangle(p, a, b, c).distance(p) <= eps;
        }
        let poly = self.covering.polygon(f);
        let pts = &self.covering.points;
        let mut edges_checked = false;
        for t in tris {
            let [a, b, c] = self.covering.triangle(t);
            let x = closest_point_on_triangle(p, a, b, c);
            if x.distance(p) > eps {
                continue;
            }
            if !edges_checked {
                edges_checked = true;
                let near_edge = poly.iter().enumerate().any(|(i, &v)| {
                    let (s, e) = (pts[v as usize], pts[poly[(i + 1) % poly.len()] as usize]);
                    closest_point_on_segment(p, s, e).distance(p) <= eps
                });
                if near_edge {
                    return true;
                }
            }
            let n = (b - a).cross(c - a);
            if n != DVec3::ZERO && polygon_winds_around(poly, pts, n, x) {
                return true;
            }
        }
        false
    }

    /// `p`, or `p` moved ε/2 away from the plane of the first covering triangle of an n-gon
    /// among `triangles` whose plane passes within ε of it (inside its grown box).
    ///
    /// For ray crossings and solid angles, a point lying in the plane of a non-convex
    /// face, over its cancelled part, is ambiguous: the overlapping positive and negative
    /// triangles each see it on a side decided by rounding. Off the boundary (> ε from every
    /// face) nothing changes within ε/2, so classifying the moved point is exact and makes
    /// those triangles agree. Triangle faces need no such care: within rounding of their
    /// plane and over them, a point is on the boundary.
    pub fn off_polygon_planes(&self, p: DVec3, triangles: impl IntoIterator<Item = usize>) -> DVec3 {
        let c = &self.covering;
        for t in triangles {
            if c.face_triangles(c.face_of[t] as usize).len() < 2 || !self.near_triangle(t, p) {
                continue;
            }
            let [a, b, cc] = c.triangle(t);
            let Some(n) = (b - a).cross(cc - a).try_normalize() else { continue };
            let d = n.dot(p - a);
            if d.abs() <= self.eps {
                return p + n * if d >= 0.0 { 0.5 * self.eps } else { -0.5 * self.eps };
            }
        }
        p
    }

    /// Heap bytes held.
    pub fn bytes(&self) -> usize {
        let c = &self.covering;
        vec_bytes(&c.points)
            + vec_bytes(&c.triangles)
            + vec_bytes(&c.face_of)
            + vec_bytes(&c.face_start)
            + c.num_faces() * std::mem::size_of::<usize>()
            + (0..c.num_faces()).map(|f| c.polygon(f).len() * 4).sum::<usize>()
            + vec_bytes(&self.face_planes)
    }
}

/// Whether the polygon `poly` (indices into `pts`), projected along the dominant axis of
/// `n`, has a non-zero winding number around the projection of `x` (Sunday's crossing rule).
fn polygon_winds_around(poly: &[u32], pts: &[DVec3], n: DVec3, x: DVec3) -> bool {
    let a = n.abs();
    let (u, v) = if a.x >= a.y && a.x >= a.z {
        (1, 2)
    } else if a.y >= a.z {
        (2, 0)
    } else {
        (0, 1)
    };
    let (xu, xv) = (x[u], x[v]);
    let mut wn = 0i32;
    for (i, &s) in poly.iter().enumerate() {
        let (s, e) = (pts[s as usize], pts[poly[(i + 1) % poly.len()] as usize]);
        let left = (e[u] - s[u]) * (xv - s[v]) - (xu - s[u]) * (e[v] - s[v]);
        if s[v] <= xv {
            if e[v] > xv && left > 0.0 {
                wn += 1;
            }
        } else if e[v] <= xv && left < 0.0 {
            wn -= 1;
        }
    }
    wn != 0
}

/// The point of segment [a, b] closest to `p` (a when the segment is a point).
pub fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// The point of triangle (a, b, c) closest to `p`, by Voronoi regions; degenerate
/// (zero-area) triangles fall back to their edges.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vc = d1 * d4 - d3 * d2;
    let vb = d5 * d2 - d1 * d6;
    let va = d3 * d6 - d5 * d4;
    let sum = va + vb + vc;
    if sum <= 0.0 || ab.cross(ac) == DVec3::ZERO {
        return [
            closest_point_on_segment(p, a, b),
            closest_point_on_segment(p, b, c),
            closest_point_on_segment(p, c, a),
        ]
        .into_iter()
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(a);
    }
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    a + ab * (vb / sum) + ac * (vc / sum)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closest_points() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let at = |p: DVec3, want: DVec3| {
            let q = closest_point_on_triangle(p, a, b, c);
            assert!(q.distance(want) < 1e-15, "{p} -> {q}, want {want}");
        };
        at(DVec3::new(0.2, 0.3, 5.0), DVec3::new(0.2, 0.3, 0.0));
        at(DVec3::new(-1.0, -1.0, 0.0), a);
        at(DVec3::new(2.0, -0.5, 1.0), b);
        at(DVec3::new(-0.5, 3.0, 1.0), c);
        at(DVec3::new(0.5, -3.0, 0.0), DVec3::new(0.5, 0.0, 0.0));
        at(DVec3::new(-3.0, 0.25, 2.0), DVec3::new(0.0, 0.25, 0.0));
        at(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0));
        // Collinear corners: the closest point of the segment they span.
        let q = closest_point_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, DVec3::X, DVec3::X * 2.0);
        assert_eq!(q, DVec3::new(0.5, 0.0, 0.0));
        assert_eq!(closest_point_on_segment(DVec3::ONE, DVec3::X, DVec3::X), DVec3::X);
    }
}
