//! The solid's boundary as every inclusion method sees it: the covering, the tolerance ε,
//! and the one predicate that decides OnBoundary ("within ε of a face polygon").

use glam::DVec3;

use super::classifier::{BuildStats, vec_bytes};
use super::error::InclusionError;
use crate::exact;
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
    /// Unit normal and a point (the centroid) of every polygon face (degree > 3) that is
    /// planar within ε; `None` for triangles and non-planar faces. Distances are measured
    /// from the point, so they do not lose precision far from the origin.
    face_planes: Vec<Option<(DVec3, DVec3)>>,
    /// Axis along which each polygon face (degree > 3) is projected for its winding test
    /// (the dominant axis of its vector area, decided exactly); `None` for triangles and
    /// faces without area. Both vectors are empty when every face is a triangle.
    face_axes: Vec<Option<usize>>,
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

    /// [`Surface::with_policy`], with its build time and bytes: the whole index of the
    /// classifiers that test every triangle.
    pub fn timed(mesh: &Mesh, allow_open: bool) -> Result<(Surface, BuildStats), InclusionError> {
        let start = std::time::Instant::now();
        let surface = Surface::with_policy(mesh, allow_open)?;
        let stats = BuildStats { build_time: start.elapsed(), bytes: surface.bytes() };
        Ok((surface, stats))
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
        // Only polygons have planes and axes; a triangle mesh allocates none.
        let faces = if covering.triangles.len() == covering.num_faces() { 0 } else { covering.num_faces() };
        let face_planes = (0..faces)
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
                let c = covering.points[covering.triangles[tris.start][0] as usize];
                let planar = covering
                    .polygon(f)
                    .iter()
                    .all(|&i| n.dot(covering.points[i as usize] - c).abs() <= 0.5 * eps);
                planar.then_some((n, c))
            })
            .collect();
        let face_axes = (0..faces)
            .map(|f| {
                let poly = covering.polygon(f);
                if poly.len() > 3 { dominant_axis(poly, &covering.points) } else { None }
            })
            .collect();
        Surface { covering, eps, lo, hi, face_planes, face_axes }
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

    /// Unit normal and a point of the plane of face `f` when it is a polygon of degree > 3
    /// that is planar within ε/2; `None` for triangles and non-planar faces.
    pub fn face_plane(&self, f: usize) -> Option<(DVec3, DVec3)> {
        self.face_planes.get(f).copied().flatten()
    }

    /// The axis face `f` (a polygon with area) is projected along for its winding test.
    fn face_axis(&self, f: usize) -> Option<usize> {
        self.face_axes.get(f).copied().flatten()
    }

    /// Signed distance from `p` to the plane of face `f` (0 when it has none, see [`Self::face_plane`]).
    pub fn face_distance(&self, f: usize, p: DVec3) -> f64 {
        self.face_plane(f).map_or(0.0, |(n, c)| n.dot(p - c))
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

    /// True iff `p` is within ε of face `f`, decided exactly ([`crate::exact`]): the
    /// answer depends on nothing but the covering points, so every method, and the same
    /// solid translated by any amount that keeps its coordinates exact, agree.
    ///
    /// A triangle: Euclidean distance ≤ ε. An n-gon: `p` is within ε of one of its edges,
    /// or within ε of one of its covering triangles at a place the polygon covers —
    /// projected along the dominant axis of the polygon's vector area, `p` lies where the
    /// polygon winds (non-zero rule) — so the parts of the fan that a non-convex face's
    /// negative triangles cancel are *not* boundary.
    pub fn on_face(&self, f: usize, p: DVec3) -> bool {
        let eps = self.eps;
        let tris = self.covering.face_triangles(f);
        let near = |t: usize| {
            let [a, b, c] = self.covering.triangle(t);
            self.near_triangle(t, p) && exact::triangle_within(p, a, b, c, eps)
        };
        if tris.len() == 1 {
            return near(tris.start);
        }
        if !tris.clone().any(near) {
            return false;
        }
        let poly = self.covering.polygon(f);
        let pts = &self.covering.points;
        let on_edge = poly.iter().enumerate().any(|(i, &v)| {
            let (s, e) = (pts[v as usize], pts[poly[(i + 1) % poly.len()] as usize]);
            exact::segment_within(p, s, e, eps)
        });
        on_edge || self.face_axis(f).is_some_and(|axis| polygon_winds_around(poly, pts, axis, p))
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
    /// `None` when `p` lies within ε of one of `triangles` (on the boundary); else `p`,
    /// moved off the plane of a non-convex face among them ([`Self::off_polygon_planes`]).
    pub fn off_boundary<I: IntoIterator<Item = usize> + Clone>(
        &self,
        p: DVec3,
        triangles: I,
    ) -> Option<DVec3> {
        if triangles.clone().into_iter().any(|t| self.on_boundary_near(t, p)) {
            return None;
        }
        Some(self.off_polygon_planes(p, triangles))
    }

    pub fn off_polygon_planes(&self, p: DVec3, triangles: impl IntoIterator<Item = usize>) -> DVec3 {
        let c = &self.covering;
        if self.face_planes.is_empty() {
            return p; // every face is a triangle
        }
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
            + vec_bytes(&self.face_axes)
    }
}

/// Whether the polygon `poly` (indices into `pts`), projected along coordinate axis `axis`,
/// winds around the projection of `x` (Sunday's crossing rule with exact orientation tests;
/// a point on an edge is left to the edge test).
fn polygon_winds_around(poly: &[u32], pts: &[DVec3], axis: usize, x: DVec3) -> bool {
    let (u, v) = [(1, 2), (2, 0), (0, 1)][axis];
    let q = [x[u], x[v]];
    let mut wn = 0i32;
    for (i, &s) in poly.iter().enumerate() {
        let (s, e) = (pts[s as usize], pts[poly[(i + 1) % poly.len()] as usize]);
        let (s, e) = ([s[u], s[v]], [e[u], e[v]]);
        if s[1] <= q[1] {
            if e[1] > q[1] && exact::orient2d(s, e, q) > 0 {
                wn += 1;
            }
        } else if e[1] <= q[1] && exact::orient2d(s, e, q) < 0 {
            wn -= 1;
        }
    }
    wn != 0
}

/// The coordinate axis along which the polygon's vector area Σ (Pᵢ − P₀) × (Pᵢ₊₁ − P₀) is
/// largest in absolute value (ties: the lower axis), decided exactly; `None` when the
/// vector area is zero.
fn dominant_axis(poly: &[u32], pts: &[DVec3]) -> Option<usize> {
    let p0 = pts[poly[0] as usize];
    let (mut n, mut bound) = (DVec3::ZERO, DVec3::ZERO);
    for w in poly.windows(2).skip(1) {
        let (a, b) = (pts[w[0] as usize] - p0, pts[w[1] as usize] - p0);
        n += a.cross(b);
        bound += DVec3::new(
            (a.y * b.z).abs() + (a.z * b.y).abs(),
            (a.z * b.x).abs() + (a.x * b.z).abs(),
            (a.x * b.y).abs() + (a.y * b.x).abs(),
        );
    }
    // Rounding of the differences, products and sums: far below this bound.
    let bound = bound * (8.0 * (poly.len() as f64 + 2.0) * f64::EPSILON);
    let m = n.abs();
    let best = if m.x >= m.y && m.x >= m.z {
        0
    } else if m.y >= m.z {
        1
    } else {
        2
    };
    let clear = (0..3).all(|k| k == best || m[best] - m[k] > bound[best] + bound[k]);
    if clear && m[best] > bound[best] {
        return Some(best);
    }
    // In doubt: the vector area in exact arithmetic.
    let mut e = exact::Exact3::default();
    for w in poly.windows(2).skip(1) {
        let a = exact::Exact3::diff(pts[w[0] as usize], p0);
        let b = exact::Exact3::diff(pts[w[1] as usize], p0);
        let c = a.cross(&b);
        e = exact::Exact3(std::array::from_fn(|k| &e.0[k] + &c.0[k]));
    }
    let abs = |x: &exact::Exact| if x.sign() < 0 { -x } else { x.clone() };
    let a: [exact::Exact; 3] = std::array::from_fn(|k| abs(&e.0[k]));
    let mut best = 0;
    for k in 1..3 {
        if (&a[k] - &a[best]).sign() > 0 {
            best = k;
        }
    }
    (a[best].sign() != 0).then_some(best)
}
