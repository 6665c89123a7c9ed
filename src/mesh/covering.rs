//! Simplicial coverings (SPEC §2, thesis §3.4–3.6).
//!
//! A polygon face P0…Pn−1 (n > 3) is covered by the n triangles (C, Pi, Pi+1), C its
//! vertex centroid; a triangle face covers itself. The triangles keep the face's
//! orientation, so on a non-convex face some of them are negative and the signed sum
//! still covers the face exactly — no tessellation. Joining every covering triangle to a
//! common apex O gives the covering tetrahedra of the solid; their signed volumes add up
//! to the solid's volume (Alg. 3-1).
//!
//! Everything is index based: covering point `i < mesh.num_vertices()` is mesh vertex
//! `i`, the rest are face centroids, so the identity of every covering vertex is known
//! (the vertex-set rule of Alg. 4-1 and the GPU upload need it).

use glam::DVec3;

use super::Mesh;
use super::disjoint_sets::UnionFind;
use super::frame::Frame;
use crate::exact::rounding::Ball;

/// A shell whose volume is less than this share of the sum of its tetrahedra's absolute
/// volumes is measured again in double-double ([`Covering::shell_measures`]): 2⁻²⁰.
const SLIVER: f64 = 1.0 / 1048576.0;

/// What [`Covering::shell_measures`] finds for one shell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShellMeasures {
    /// The apex of its tetras: the centre of its bounding box.
    pub apex: DVec3,
    /// Signed volume (Alg. 3-1).
    pub volume: f64,
    /// First moment Σ Vᵢ·(A+B+C−3·apex)/4 about the apex.
    pub moment: DVec3,
    /// Σ |Vᵢ|: the size the volume is small or large against.
    pub magnitude: f64,
}

/// Neumaier's compensated sum: the rounding error of each addition is kept and added
/// back at the end, so the result is as if summed in twice the precision.
#[derive(Clone, Copy, Debug, Default)]
struct Compensated {
    sum: f64,
    error: f64,
}

impl Compensated {
    fn add(&mut self, x: f64) {
        let t = self.sum + x;
        self.error += if self.sum.abs() >= x.abs() { (self.sum - t) + x } else { (x - t) + self.sum };
        self.sum = t;
    }

    fn value(self) -> f64 {
        self.sum + self.error
    }
}

/// Volume and area of `mesh` in its units, measured in its [`Frame`] (no product
/// underflows or overflows at any size): what commands report for a mesh they hold.
pub fn measures(mesh: &Mesh) -> (f64, f64) {
    if mesh.num_faces() == 0 {
        return (0.0, 0.0);
    }
    let frame = Frame::of(&[mesh]);
    let c = Covering::new(&frame.mesh_in_ref(mesh));
    (frame.volume_out(c.volume()), frame.area_out(c.area()))
}

/// The sum of `values`, compensated ([`Compensated`]): how shell volumes are added up.
pub fn compensated_sum(values: impl IntoIterator<Item = f64>) -> f64 {
    let mut sum = Compensated::default();
    for x in values {
        sum.add(x);
    }
    sum.value()
}

/// The simplicial covering of a polygon mesh's faces.
#[derive(Clone, Debug, PartialEq)]
pub struct Covering {
    /// Mesh vertices, then one centroid per face of degree > 3 (in face order).
    pub points: Vec<DVec3>,
    /// Covering triangles as indices into `points`, oriented like their face.
    pub triangles: Vec<[u32; 3]>,
    /// The mesh face each covering triangle comes from.
    pub face_of: Vec<u32>,
    /// Covering triangles of face `f` are `face_start[f]..face_start[f + 1]`.
    pub face_start: Vec<u32>,
    /// Number of mesh vertices (the first points).
    pub num_mesh_vertices: usize,
    polygon_offsets: Vec<usize>,
    polygon_indices: Vec<u32>,
}

/// A directed edge whose reverse is not used as often as it is: the surface is open or
/// inconsistently oriented there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnbalancedEdge {
    pub a: u32,
    pub b: u32,
    /// Times the edge is used as a→b.
    pub forward: u32,
    /// Times the edge is used as b→a.
    pub backward: u32,
}

/// An edge of more than two faces (balanced in direction) around which the faces, in
/// their order about the edge, do not alternate in direction: the winding number beside
/// it takes three values, so it is −1 or 2 somewhere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FoldedEdge {
    pub a: u32,
    pub b: u32,
    /// How many faces use it.
    pub faces: u32,
}

impl std::fmt::Display for UnbalancedEdge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (a, b) = (self.a, self.b);
        write!(
            f,
            "edge {a}–{b} is used {} time(s) as {a}→{b} but {} time(s) as {b}→{a}",
            self.forward, self.backward
        )
    }
}

/// The vertex centroid of a polygon face, rounded to f64 once: the centre of its covering
/// fan, and of every other use of a face's fan ([`super::triangulate::fan_centre`]), so
/// all of them cover the same surface.
pub fn face_centroid(positions: &[DVec3], face: &[u32]) -> DVec3 {
    let sum = face.iter().fold(DVec3::ZERO, |s, &i| s + positions[i as usize]);
    sum / face.len() as f64
}

/// Signed volume of the tetrahedron (O, A, B, C): det(A−O, B−O, C−O) / 6 (Def. 3.21).
pub fn signed_tetra_volume(o: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (a - o).dot((b - o).cross(c - o)) / 6.0
}

/// Signed solid angle of triangle (a, b, c) seen from the origin (corners relative to the
/// viewer): positive when the origin is behind the triangle, i.e. on the side opposite to
/// its normal (b−a)×(c−a) — so the winding number is +1 inside an outward-oriented closed
/// surface (Van Oosterom & Strackee 1983).
pub fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * num.atan2(den)
}

impl Covering {
    /// Covers every face: triangles as they are, n-gons by the fan from their centroid.
    pub fn new(mesh: &Mesh) -> Covering {
        let nv = mesh.num_vertices();
        let (offsets, indices) = mesh.face_parts();
        let mut points = mesh.positions().to_vec();
        let mut triangles =
            Vec::with_capacity(mesh.faces().map(|f| if f.len() == 3 { 1 } else { f.len() }).sum());
        let mut face_of = Vec::with_capacity(triangles.capacity());
        let mut face_start = Vec::with_capacity(mesh.num_faces() + 1);
        face_start.push(0);
        for (f, face) in mesh.faces().enumerate() {
            if face.len() == 3 {
                triangles.push([face[0], face[1], face[2]]);
                face_of.push(f as u32);
            } else {
                let c = points.len() as u32;
                points.push(face_centroid(mesh.positions(), face));
                for (i, &p) in face.iter().enumerate() {
                    triangles.push([c, p, face[(i + 1) % face.len()]]);
                    face_of.push(f as u32);
                }
            }
            face_start.push(triangles.len() as u32);
        }
        Covering {
            points,
            triangles,
            face_of,
            face_start,
            num_mesh_vertices: nv,
            polygon_offsets: offsets.to_vec(),
            polygon_indices: indices.to_vec(),
        }
    }

    pub fn num_faces(&self) -> usize {
        self.face_start.len() - 1
    }

    /// The vertex indices (= covering point indices) of mesh face `f`, in order.
    pub fn polygon(&self, f: usize) -> &[u32] {
        &self.polygon_indices[self.polygon_offsets[f]..self.polygon_offsets[f + 1]]
    }

    /// Indices of the covering triangles of face `f`.
    pub fn face_triangles(&self, f: usize) -> std::ops::Range<usize> {
        self.face_start[f] as usize..self.face_start[f + 1] as usize
    }

    /// The three corners of covering triangle `t`.
    #[inline]
    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.points[a as usize], self.points[b as usize], self.points[c as usize]]
    }

    /// Axis-aligned bounds of the covering points (both zero when there are none).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        if self.points.is_empty() {
            return (DVec3::ZERO, DVec3::ZERO);
        }
        self.points.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// Generalized winding number about `p` of the covering triangles `triangles`:
    /// Σ Ω(t) / 4π ([`solid_angle`]). Negative triangles of non-convex faces subtract what
    /// their positive partners add. For a closed, consistently oriented set of faces it is
    /// an integer (up to rounding) away from their surface: 1 inside an outward solid.
    pub fn winding_number(&self, triangles: impl IntoIterator<Item = usize>, p: DVec3) -> f64 {
        let sum: f64 = triangles
            .into_iter()
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                solid_angle(a - p, b - p, c - p)
            })
            .sum();
        sum / (4.0 * std::f64::consts::PI)
    }

    /// Sum of the signed covering-tetra volumes with apex `o` (Alg. 3-1, §3.6.3), summed
    /// with compensation.
    ///
    /// For a closed, consistently oriented mesh the result does not depend on `o`.
    pub fn signed_volume_about(&self, o: DVec3) -> f64 {
        compensated_sum((0..self.triangles.len()).map(|t| {
            let [a, b, c] = self.triangle(t);
            signed_tetra_volume(o, a, b, c)
        }))
    }

    /// The faces of each shell (a connected component: faces sharing a vertex are
    /// connected), ordered by first face. Every edge's twin lies in the same shell, so
    /// each shell of a closed surface is closed.
    pub fn shells(&self) -> Vec<Vec<u32>> {
        let mut sets = UnionFind::new(self.num_mesh_vertices);
        for f in 0..self.num_faces() {
            let face = self.polygon(f);
            for &v in &face[1..] {
                sets.union(face[0], v);
            }
        }
        let mut shell_of_root = vec![u32::MAX; self.num_mesh_vertices];
        let mut shells: Vec<Vec<u32>> = Vec::new();
        for f in 0..self.num_faces() {
            let r = sets.find(self.polygon(f)[0]) as usize;
            if shell_of_root[r] == u32::MAX {
                shell_of_root[r] = shells.len() as u32;
                shells.push(Vec::new());
            }
            shells[shell_of_root[r] as usize].push(f as u32);
        }
        shells
    }

    /// Signed volume and first moment of the faces `faces` (a closed shell), with the apex
    /// at the centre of their bounding box: the differences to the apex are then (nearly)
    /// exact however far the shell lies from the origin, and the determinants small. The
    /// moment Σ Vᵢ·(A+B+C−3O)/4 is taken about that apex, which is returned too.
    ///
    /// The volume is summed in f64; when it is less than 2⁻²⁰ of the sum of the tetrahedra's
    /// absolute volumes (a thin sliver, whose volume is what is left of large cancelling
    /// tetrahedra, and whose f64 sum can be off by 10⁻⁸ of it), it is summed again in
    /// double-double ([`crate::exact::volume`], within about 10⁻¹⁶ of it, certified).
    pub fn shell_measures(&self, faces: &[u32]) -> ShellMeasures {
        let (lo, hi) = faces.iter().flat_map(|&f| self.polygon(f as usize)).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), &v| {
                let p = self.points[v as usize];
                (lo.min(p), hi.max(p))
            },
        );
        let apex = if lo.cmple(hi).all() { (lo + hi) * 0.5 } else { DVec3::ZERO };
        let mut volume = Compensated::default();
        let mut magnitude = 0.0;
        let mut moment = [Compensated::default(), Compensated::default(), Compensated::default()];
        for t in faces.iter().flat_map(|&f| self.face_triangles(f as usize)) {
            let [a, b, c] = self.triangle(t);
            let (a, b, c) = (a - apex, b - apex, c - apex);
            let v = a.dot(b.cross(c)) / 6.0;
            volume.add(v);
            magnitude += v.abs();
            let m = v * (a + b + c) * 0.25;
            for (k, sum) in moment.iter_mut().enumerate() {
                sum.add(m[k]);
            }
        }
        let mut volume = volume.value();
        if volume.abs() < magnitude * SLIVER {
            volume = self.shell_volume_double_double(faces, apex);
        }
        ShellMeasures {
            apex,
            volume,
            moment: DVec3::new(moment[0].value(), moment[1].value(), moment[2].value()),
            magnitude,
        }
    }

    /// The volume of the shell `faces` about `apex` in double-double, certified
    /// ([`crate::exact::volume`]: the differences to the apex are taken there too).
    fn shell_volume_double_double(&self, faces: &[u32], apex: DVec3) -> f64 {
        let triangles: Vec<[u32; 3]> =
            faces.iter().flat_map(|&f| self.face_triangles(f as usize)).map(|t| self.triangles[t]).collect();
        let apex = apex.to_array().map(Ball::of);
        crate::exact::volume::signed_volume(&triangles, |i| {
            let p = self.points[i as usize].to_array();
            (std::array::from_fn(|k| Ball::of(p[k]).sub(&apex[k])), false)
        })
        .value
    }

    /// Signed volume (Alg. 3-1), positive for outward-facing orientation: each shell's
    /// volume about the centre of its own bounding box ([`Covering::shell_measures`]),
    /// summed with compensation. Every command's volume is this one.
    pub fn volume(&self) -> f64 {
        compensated_sum(self.shells().iter().map(|s| self.shell_measures(s).volume))
    }

    /// Signed area of every covering triangle, measured along its face's vector area: a
    /// triangle turning against its face (on a non-convex face) is negative (§3.6.2).
    pub fn triangle_signed_areas(&self) -> Vec<f64> {
        let face_dirs: Vec<DVec3> = self.face_vector_areas().iter().map(|v| v.normalize_or_zero()).collect();
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                0.5 * (b - a).cross(c - a).dot(face_dirs[self.face_of[t] as usize])
            })
            .collect()
    }

    /// Vector area of every face: the sum of its covering triangles' vector areas (for a
    /// planar polygon, its normal times its area).
    pub fn face_vector_areas(&self) -> Vec<DVec3> {
        (0..self.num_faces())
            .map(|f| {
                self.face_triangles(f).fold(DVec3::ZERO, |s, t| {
                    let [a, b, c] = self.triangle(t);
                    s + 0.5 * (b - a).cross(c - a)
                })
            })
            .collect()
    }

    /// Area of every face: the signed areas of its covering triangles summed (§3.6.2).
    pub fn face_areas(&self) -> Vec<f64> {
        self.face_vector_areas().iter().map(|v| v.length()).collect()
    }

    /// Total surface area, summed with compensation.
    pub fn area(&self) -> f64 {
        compensated_sum(self.face_areas())
    }

    /// The volume centroid Σ Vᵢ·(O+A+B+C)/4 / V over the covering tetras, each shell's
    /// moment taken about its own apex ([`Covering::shell_measures`]); `None` when the
    /// volume is zero (relative to Σ |Vᵢ|).
    pub fn centroid(&self) -> Option<DVec3> {
        let shells: Vec<ShellMeasures> = self.shells().iter().map(|s| self.shell_measures(s)).collect();
        let v = compensated_sum(shells.iter().map(|s| s.volume));
        let magnitude: f64 = shells.iter().map(|s| s.magnitude).sum();
        // Σ (Vₛ·Oₛ + Mₛ) / V, as Σ Vₛ/V·Oₛ + Mₛ/V: no product of a volume and a far apex.
        (v.abs() > 1e-12 * magnitude)
            .then(|| shells.iter().fold(DVec3::ZERO, |g, s| g + s.apex * (s.volume / v) + s.moment / v))
    }

    /// The thesis' centroid (§3.6.1): face centroids weighted by their vertex counts,
    /// Σ CGᵢ·Kᵢ / Σ Kᵢ — the mean of the face corners, not the volume centroid.
    pub fn face_weighted_centroid(&self) -> Option<DVec3> {
        let sum = self.polygon_indices.iter().fold(DVec3::ZERO, |s, &i| s + self.points[i as usize]);
        (!self.polygon_indices.is_empty()).then(|| sum / self.polygon_indices.len() as f64)
    }

    /// The first mesh edge (in vertex order) used a different number of times in each
    /// direction, if any. `None` means the faces form a closed, consistently oriented
    /// surface (a 2-cycle), which is what the covering methods need; non-manifold edges
    /// (used twice each way) are fine.
    pub fn unbalanced_edge(&self) -> Option<UnbalancedEdge> {
        self.edge_faults().0
    }

    /// The smallest edge whose uses do not pair up ([`Self::unbalanced_edge`]), and the
    /// smallest balanced edge of more than two faces around which the faces do not
    /// alternate in direction ([`FoldedEdge`]), from one walk over the edges.
    pub fn edge_faults(&self) -> (Option<UnbalancedEdge>, Option<FoldedEdge>) {
        // The uses of each edge are adjacent in its lower vertex's bucket, edges in
        // increasing order: the first unbalanced one is the smallest.
        let half_edges = super::validate::HalfEdges::of_faces(
            &self.polygon_offsets,
            &self.polygon_indices,
            self.points.len(),
        );
        let (mut unbalanced, mut folded) = (None, None);
        for (lo, hi, run) in half_edges.edges() {
            let forward = half_edges.forward(lo, run);
            let backward = run.len() - forward;
            if forward != backward {
                unbalanced.get_or_insert(UnbalancedEdge {
                    a: lo as u32,
                    b: hi,
                    forward: forward as u32,
                    backward: backward as u32,
                });
            } else if run.len() > 2 && folded.is_none() && self.folds(lo as u32, hi, run) {
                folded = Some(FoldedEdge { a: lo as u32, b: hi, faces: run.len() as u32 });
            }
            if unbalanced.is_some() && folded.is_some() {
                break;
            }
        }
        (unbalanced, folded)
    }

    /// Whether the faces around edge lo–hi (its uses `run`, balanced, more than two) fail
    /// to alternate in direction: [`folds`] of their covering triangles' third corners.
    fn folds(&self, lo: u32, hi: u32, run: &[u64]) -> bool {
        let (a, b) = (self.points[lo as usize], self.points[hi as usize]);
        // Per use: the third corner of the covering triangle on the edge, and whether the
        // face runs lo → hi.
        let uses: Vec<(DVec3, bool)> = run
            .iter()
            .map(|&item| {
                let corner = super::validate::corner(item);
                let f = self.polygon_offsets.partition_point(|&o| o <= corner) - 1;
                let face = self.polygon(f);
                let forward = self.polygon_indices[corner] == lo;
                let third = if face.len() == 3 {
                    let k = corner - self.polygon_offsets[f];
                    face[(k + 2) % 3]
                } else {
                    self.triangles[self.face_start[f] as usize][0]
                };
                (self.points[third as usize], forward)
            })
            .collect();
        folds(a, b, &uses)
    }
}

/// Whether faces around the edge a–b, given by their third corners and whether they run
/// a → b, fail to alternate in direction when taken in their exact order around the edge.
/// Passing a face changes the winding number by one, up or down with the face's direction
/// along the edge: faces that alternate leave two values beside the edge, two neighbours
/// of one direction leave three, so −1 or 2 somewhere (a piece hanging on the edge turned
/// inside out, or inside a part facing its way). Faces at one angle (overlapping) are left
/// to the self-intersection test.
pub(crate) fn folds(a: DVec3, b: DVec3, uses: &[(DVec3, bool)]) -> bool {
    order_about(a, b, uses).is_some_and(|order| {
        (0..order.len()).any(|i| uses[order[i]].1 == uses[order[(i + 1) % order.len()]].1)
    })
}

/// The faces around the edge a–b, given by their third corners (and whether they run
/// a → b, unused here), in their exact order about the axis a → b: by increasing angle in
/// the right-hand sense, from the first. Going that way, a face that runs a → b is passed
/// from the side its normal points away from to the side it points to (the winding number
/// goes down by one), one that runs b → a the other way (up by one). `None` where every
/// corner lies in one plane with the edge or two lie at one angle (overlapping faces).
pub(crate) fn order_about(a: DVec3, b: DVec3, uses: &[(DVec3, bool)]) -> Option<Vec<usize>> {
    use crate::exact::orient3d;
    // Angles about the axis a→b from the first use's half-plane: (half, position),
    // half 0 for [0, π), 1 for [π, 2π); a point off the common plane tells the two
    // sides of the axis apart for corners in the first use's plane.
    // Each sign is taken once (the reference's own is 0): on a result's cut curve every
    // edge has four faces, and a sign of coinciding points is one the filter cannot give.
    let reference = uses[0].0;
    let signs: Vec<_> = uses
        .iter()
        .enumerate()
        .map(|(i, u)| if i == 0 { 0 } else { orient3d(a, b, reference, u.0) })
        .collect();
    let k = signs.iter().position(|&s| s != 0)?;
    let off = uses[k].0;
    let side_of_reference = orient3d(a, b, off, reference);
    let half = |i: usize| match signs[i] {
        0 if i == 0 || orient3d(a, b, off, uses[i].0) == side_of_reference => 0u8,
        0 => 1,
        s if s > 0 => 0,
        _ => 1,
    };
    let halves: Vec<u8> = (0..uses.len()).map(half).collect();
    let mut order: Vec<usize> = (0..uses.len()).collect();
    let mut tie = false;
    order.sort_by(|&x, &y| {
        halves[x].cmp(&halves[y]).then_with(|| match orient3d(a, b, uses[x].0, uses[y].0) {
            0 => {
                tie = true;
                std::cmp::Ordering::Equal
            }
            s if s > 0 => std::cmp::Ordering::Less,
            _ => std::cmp::Ordering::Greater,
        })
    });
    (!tie).then_some(order)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::TAU;

    use super::*;

    fn quad_box(lo: DVec3, hi: DVec3) -> Mesh {
        crate::mesh::procedural::box_between(lo, hi)
    }

    fn prism(xy: &[(f64, f64)], h: f64) -> Mesh {
        crate::mesh::procedural::prism(xy, h).unwrap()
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    #[test]
    fn cube_volume_area_centroid() {
        let c = Covering::new(&quad_box(DVec3::splat(-1.0), DVec3::splat(1.0)));
        assert_eq!(c.triangles.len(), 24);
        assert_eq!(c.points.len(), 8 + 6);
        assert!(close(c.volume(), 8.0, 1e-14));
        assert!(close(c.signed_volume_about(DVec3::new(5.0, -3.0, 7.0)), 8.0, 1e-13));
        assert!(close(c.area(), 24.0, 1e-14));
        assert!(c.centroid().unwrap().length() < 1e-14);
        assert!(c.face_weighted_centroid().unwrap().length() < 1e-14);
        assert!(c.triangle_signed_areas().iter().all(|&a| close(a, 1.0, 1e-14)));
        assert_eq!(c.unbalanced_edge(), None);
    }

    #[test]
    fn offset_box_centroids_differ_from_origin() {
        let c = Covering::new(&quad_box(DVec3::new(1.0, 2.0, 3.0), DVec3::new(3.0, 3.0, 7.0)));
        assert!(close(c.volume(), 8.0, 1e-13));
        assert!((c.centroid().unwrap() - DVec3::new(2.0, 2.5, 5.0)).length() < 1e-13);
        assert!((c.face_weighted_centroid().unwrap() - DVec3::new(2.0, 2.5, 5.0)).length() < 1e-13);
    }

    #[test]
    fn shells_far_apart_measure_exactly() {
        // Two unit-size boxes 10⁷ apart: about one apex between them the tetras reach 10¹³
        // and the volume loses 10⁻⁴; each about its own box centre it is exact.
        let a = quad_box(DVec3::new(1e7 - 1.0, -1.0, -1.0), DVec3::new(1e7 + 1.0, 1.0, 1.0));
        let b = quad_box(DVec3::new(-1.0, 1e7 - 1.0, -1.0), DVec3::new(1.0, 1e7 + 1.0, 1.0));
        let mut positions = a.positions().to_vec();
        positions.extend_from_slice(b.positions());
        let faces =
            a.faces().map(<[u32]>::to_vec).chain(b.faces().map(|f| f.iter().map(|&i| i + 8).collect()));
        let c = Covering::new(&Mesh::new(positions, faces.collect()).unwrap());
        assert_eq!(c.shells().len(), 2);
        assert_eq!(c.volume(), 16.0);
        assert_eq!(c.area(), 48.0);
        assert_eq!(c.centroid().unwrap(), DVec3::new(5e6, 5e6, 0.0));
    }

    #[test]
    fn non_convex_l_prism() {
        // L = [0,4]x[0,1] ∪ [0,1]x[1,3]: area 6, perimeter 14. Its vertex centroid (5/3, 4/3)
        // lies in the notch, outside the L, so two cap triangles are negative.
        let l = [(0.0, 0.0), (4.0, 0.0), (4.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)];
        let h = 0.5;
        let c = Covering::new(&prism(&l, h));
        assert_eq!(c.unbalanced_edge(), None);
        assert!(close(c.volume(), 6.0 * h, 1e-14));
        assert!(close(c.area(), 2.0 * 6.0 + 14.0 * h, 1e-14));
        let areas = c.triangle_signed_areas();
        let caps: Vec<f64> = c.face_triangles(1).map(|t| areas[t]).collect();
        assert_eq!(caps.iter().filter(|&&a| a < 0.0).count(), 2, "{caps:?}");
        assert!(close(caps.iter().sum::<f64>(), 6.0, 1e-14));
        // Volume centroid: bar (area 4, centre (2, 1/2)) + arm (area 2, centre (1/2, 2)).
        let want = DVec3::new((4.0 * 2.0 + 2.0 * 0.5) / 6.0, (4.0 * 0.5 + 2.0 * 2.0) / 6.0, h / 2.0);
        assert!((c.centroid().unwrap() - want).length() < 1e-14);
        // Corner-weighted centroid: every vertex is a corner of exactly 3 faces (its cap and
        // two side quads), so it is the mean of the 12 vertices.
        let fw = c.face_weighted_centroid().unwrap();
        assert!((fw - DVec3::new(10.0 / 6.0, 8.0 / 6.0, h / 2.0)).length() < 1e-14, "{fw}");
    }

    #[test]
    fn centroid_on_a_corner_gives_degenerate_triangles_but_right_sums() {
        // Symmetric L: the vertex centroid (1,1) is the reflex corner itself.
        let l = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
        let c = Covering::new(&prism(&l, 1.0));
        let areas = c.triangle_signed_areas();
        assert_eq!(c.face_triangles(1).filter(|&t| areas[t] == 0.0).count(), 2);
        assert!(close(c.volume(), 3.0, 1e-14));
        assert!(close(c.area(), 6.0 + 8.0, 1e-14));
    }

    #[test]
    fn torus_volume_matches_the_polyhedron() {
        // Each of the nu slices is swept by a regular nv-gon of area A = nv/2 r² sin(2π/nv)
        // whose centroid is at distance R from the axis; the slice's volume is
        // sin(2π/nu) · R · A (its planar trapezoid faces interpolate linearly).
        let (big, small, nu, nv) = (2.0, 0.5, 24, 12);
        let c = Covering::new(&crate::mesh::procedural::torus(big, small, nu, nv));
        assert_eq!(c.unbalanced_edge(), None);
        let a = nv as f64 / 2.0 * small * small * (TAU / nv as f64).sin();
        let want = nu as f64 * (TAU / nu as f64).sin() * big * a;
        assert!(close(c.volume(), want, 1e-13), "{} vs {want}", c.volume());
        assert!(c.centroid().unwrap().length() < 1e-12);
    }

    /// A thin triangular prism (height 1e-9 along its base's normal, tilted vertices that
    /// round): the f64 sum of its tetrahedra is off by far more than 1e-13 (relative), the
    /// volume is not.
    #[test]
    fn a_thin_sliver_keeps_its_relative_accuracy() {
        use crate::exact::Exact;
        use crate::exact::rounding::quotient_exact;
        let base = [DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.9, 0.15, 0.35), DVec3::new(0.4, 0.85, 0.1)];
        let n = (base[1] - base[0]).cross(base[2] - base[0]).normalize();
        let mut positions = base.to_vec();
        positions.extend(base.map(|p| p + n * 1e-9));
        let mut faces = vec![vec![0, 2, 1], vec![3, 4, 5]];
        for i in 0..3u32 {
            let j = (i + 1) % 3;
            faces.push(vec![i, j, j + 3]);
            faces.push(vec![i, j + 3, i + 3]);
        }
        let m = Mesh::new(positions, faces).unwrap();
        let c = Covering::new(&m);
        // Exactly: Σ det(a, b, c) / 6 with the origin as apex, in expansions.
        let e = |x: f64| Exact::from_f64(x);
        let six = c.triangles.iter().fold(Exact::default(), |sum, t| {
            let [a, b, cc] = t.map(|i| c.points[i as usize].to_array().map(e));
            let cross = |i: usize| {
                let (j, k) = ((i + 1) % 3, (i + 2) % 3);
                &(&b[j] * &cc[k]) - &(&b[k] * &cc[j])
            };
            &sum + &(&(&(&a[0] * &cross(0)) + &(&a[1] * &cross(1))) + &(&a[2] * &cross(2)))
        });
        let want = quotient_exact(&six, &e(6.0));
        assert!(want > 1e-10 && want < 1e-9, "{want}");
        let naive = compensated_sum((0..c.triangles.len()).map(|t| {
            let [a, b, cc] = c.triangle(t);
            a.dot(b.cross(cc)) / 6.0
        }));
        assert!((naive - want).abs() > 1e-12 * want, "{naive} vs {want}: not a hard case");
        let got = c.volume();
        assert!((got - want).abs() <= 1e-15 * want, "{got} vs {want}");
    }

    #[test]
    fn open_or_flipped_meshes_have_unbalanced_edges() {
        let cube = quad_box(DVec3::ZERO, DVec3::ONE);
        let mut faces: Vec<Vec<u32>> = cube.faces().map(<[u32]>::to_vec).collect();
        let open = Mesh::new(cube.positions().to_vec(), faces[1..].to_vec()).unwrap();
        let e = Covering::new(&open).unbalanced_edge().unwrap();
        assert_eq!(e.forward + e.backward, 1);
        faces[2].reverse();
        let flipped = Mesh::new(cube.positions().to_vec(), faces).unwrap();
        let e = Covering::new(&flipped).unbalanced_edge().unwrap();
        assert!(e.forward == 2 || e.backward == 2, "{e:?}");
    }
}
