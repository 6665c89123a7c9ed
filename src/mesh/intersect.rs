//! Exact triangle–triangle intersection and self-intersection detection.
//!
//! Every decision is a sign of an exact predicate on the f64 input coordinates
//! ([`crate::exact`]): `orient3d` in space, and `orient2d` for coplanar pairs, projected
//! along an axis the triangle's exact normal does not vanish on (projection keeps
//! coordinates as they are, so it adds no rounding).
//! No point is constructed, so nothing here depends on a tolerance.
//!
//! [`self_intersections`] finds the face pairs of a mesh whose intersection is more than
//! what they are entitled to: nothing for faces with no common vertex, the vertex for
//! faces sharing one, the edge for faces sharing an edge. Vertices are identified by
//! position, so a mesh whose shells touch at duplicated vertices counts as touching,
//! not crossing. Polygon faces are tessellated as every command sees them
//! ([`super::triangulate::fan_centre`]): a non-planar face whose centroid fan does not
//! fold as the fan from its centroid, any other in its plane ([`super::triangulate`]).
//! Either way no two triangles of a face overlap, so they are not tested against each
//! other; a face whose outline crosses itself is reported paired with itself.
//!
//! A face with no area plugs a T-junction: its corners lie on one line, and its middle
//! corner lies on the segment between the two others, where the faces on one side have
//! that whole segment as an edge and those on the other side have its pieces. Those
//! faces only touch; to tell that from crossing, the triangles with the whole segment
//! are split at the middle corner before the pair tests ([`split_at_t_junctions`]).
//! Candidate pairs come from a uniform grid over the triangles' boxes
//! ([`super::boxgrid`]) when its cells hold few boxes each, as on ordinary meshes, where
//! it is the cheapest search; when boxes pile up in its cells (fans, long slivers,
//! high-valence vertices: counted from the cells' occupancy before any pair is compared),
//! from an octree over the triangles and their edges that leaves out pairs which cannot
//! count ([`super::crosstree`]). Restricted to marked triangles, they are the marked
//! triangles' boxes against all others in the grid.
//!
//! Big strictly convex faces (a cone's or a cylinder's one-polygon base) are first tiled
//! for the search alone ([`triangulate::convex_tiling`]: a fan from a point inside, or
//! short chords): a Delaunay triangulation of corners on a circle draws long triangles
//! across the whole face, which the octree must follow through every cell on their way.
//! Whether faces cross does not depend on how such a face is tiled (see
//! [`search_soup`]), so a mesh found clean that way is clean; one that does cross is
//! answered again from the triangles every command sees, because which crossing comes
//! first may depend on the tiling.

use glam::DVec3;
use rayon::prelude::*;

use super::Mesh;
use super::boxgrid::{box_pairs, box_pairs_near, box_pairs_within};
use super::crosstree::candidate_pairs;
use super::triangulate::{self, ConvexTiling, Projection, TriangulateError};
use crate::exact::{Sign, orient2d, orient2d_approx, orient3d};

/// An exact projection for the plane of triangle (a, b, c): along the axis where its
/// normal is largest, judged by exact 2D orientations, so the chosen component is
/// non-zero. `None` when the three points are collinear.
pub fn triangle_projection(a: DVec3, b: DVec3, c: DVec3) -> Option<Projection> {
    let n = exact_normal_signs(a, b, c);
    Projection::along(n)
}

/// The normal's components as 2D determinants in the yz, zx and xy planes (their signs
/// are exact; their sizes are the determinants' approximate values).
fn exact_normal_signs(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let o = |u: usize, v: usize| {
        let q = |p: DVec3| glam::DVec2::new(p[u], p[v]);
        orient2d_approx(q(a), q(b), q(c))
    };
    DVec3::new(o(1, 2), o(2, 0), o(0, 1))
}

/// True when a, b, c are exactly collinear (or coincide).
pub fn is_degenerate(t: [DVec3; 3]) -> bool {
    exact_normal_signs(t[0], t[1], t[2]) == DVec3::ZERO
}

/// All of `points` lie exactly on one line (or coincide).
fn all_collinear(points: &[DVec3]) -> bool {
    let Some(&a) = points.first() else { return true };
    let Some(&b) = points.iter().find(|&&p| p != a) else { return true };
    points.iter().all(|&c| is_degenerate([a, b, c]))
}

/// Closed 2D segments [p, q] and [r, s] share a point.
fn segments_meet_2d(p: glam::DVec2, q: glam::DVec2, r: glam::DVec2, s: glam::DVec2) -> bool {
    let d1 = orient2d(r, s, p);
    let d2 = orient2d(r, s, q);
    let d3 = orient2d(p, q, r);
    let d4 = orient2d(p, q, s);
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let within = |a: glam::DVec2, b: glam::DVec2, x: glam::DVec2| {
        x.x >= a.x.min(b.x) && x.x <= a.x.max(b.x) && x.y >= a.y.min(b.y) && x.y <= a.y.max(b.y)
    };
    (d1 == 0 && within(r, s, p))
        || (d2 == 0 && within(r, s, q))
        || (d3 == 0 && within(p, q, r))
        || (d4 == 0 && within(p, q, s))
}

/// Closed 2D triangle (any orientation, non-degenerate) holds x.
fn triangle_holds_2d(t: [glam::DVec2; 3], x: glam::DVec2) -> bool {
    let s = [0, 1, 2].map(|k| orient2d(t[k], t[(k + 1) % 3], x));
    !(s.contains(&1) && s.contains(&-1))
}

/// The closed segment [p, q] and the closed, non-degenerate triangle t share a point.
pub fn segment_meets_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let [a, b, c] = t;
    let sp = orient3d(a, b, c, p);
    let sq = orient3d(a, b, c, q);
    if sp * sq > 0 {
        return false;
    }
    if sp == 0 && sq == 0 {
        let Some(proj) = triangle_projection(a, b, c) else { return false };
        let t2 = t.map(|v| proj.apply(v));
        let (p2, q2) = (proj.apply(p), proj.apply(q));
        return triangle_holds_2d(t2, p2)
            || triangle_holds_2d(t2, q2)
            || (0..3).any(|k| segments_meet_2d(p2, q2, t2[k], t2[(k + 1) % 3]));
    }
    // The segment reaches the plane at one point; the line pq passes through the closed
    // triangle iff the three edge orientations do not disagree.
    let s = [orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a)];
    !(s.contains(&1) && s.contains(&-1))
}

/// The closed, non-degenerate triangles t and u share a point.
///
/// Two closed triangles meet iff an edge of one meets the other (the ends of their
/// common segment, or of their common polygon's edges, lie on edges), after a quick
/// rejection when one lies strictly on one side of the other's plane.
pub fn triangles_meet(t: [DVec3; 3], u: [DVec3; 3]) -> bool {
    let side = |plane: [DVec3; 3], pts: [DVec3; 3]| {
        let s = pts.map(|p| orient3d(plane[0], plane[1], plane[2], p));
        s == [1, 1, 1] || s == [-1, -1, -1]
    };
    if side(u, t) || side(t, u) {
        return false;
    }
    (0..3).any(|k| segment_meets_triangle(t[k], t[(k + 1) % 3], u))
        || (0..3).any(|k| segment_meets_triangle(u[k], u[(k + 1) % 3], t))
}

/// The ray from a through x (x coplanar with triangle (a, d, e)) lies in the closed
/// angle of that triangle at a.
fn ray_in_angle(a: DVec3, d: DVec3, e: DVec3, x: DVec3) -> bool {
    let Some(proj) = triangle_projection(a, d, e) else { return false };
    let [a2, d2, e2, x2] = [a, d, e, x].map(|p| proj.apply(p));
    let s: Sign = orient2d(a2, d2, e2);
    s * orient2d(a2, d2, x2) >= 0 && s * orient2d(a2, x2, e2) >= 0
}

/// Triangles (a, b, c) and (a, d, e), sharing only the vertex a, meet elsewhere too.
pub fn meet_beyond_vertex(a: DVec3, [b, c]: [DVec3; 2], [d, e]: [DVec3; 2]) -> bool {
    let t = [a, b, c];
    let u = [a, d, e];
    if segment_meets_triangle(b, c, u) || segment_meets_triangle(d, e, t) {
        return true;
    }
    // What is left: the common part runs from a along an edge at a of one triangle that
    // lies in the other's plane, inside the other's angle at a (this also covers
    // coplanar pairs, whose angles at a overlap iff a side of one lies in the other).
    let in_plane = |plane: [DVec3; 3], x: DVec3| orient3d(plane[0], plane[1], plane[2], x) == 0;
    [b, c].into_iter().any(|x| in_plane(u, x) && ray_in_angle(a, d, e, x))
        || [d, e].into_iter().any(|x| in_plane(t, x) && ray_in_angle(a, b, c, x))
}

/// Triangles (a, b, c) and (a, b, d), sharing the edge ab, meet beyond it: they are
/// coplanar and fold onto the same side of ab.
pub fn meet_beyond_edge(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    if orient3d(a, b, c, d) != 0 {
        return false;
    }
    let Some(proj) = triangle_projection(a, b, c) else { return false };
    let [a2, b2, c2, d2] = [a, b, c, d].map(|p| proj.apply(p));
    orient2d(a2, b2, c2) * orient2d(a2, b2, d2) > 0
}

/// The faces of a mesh as non-overlapping triangles over position-welded vertices.
#[derive(Clone, Debug)]
pub struct TriangleSoup {
    /// The mesh's positions (unchanged).
    pub positions: Vec<DVec3>,
    /// Triangles as indices into `positions`, each vertex replaced by the first vertex at
    /// its exact position; oriented like their face.
    pub triangles: Vec<[u32; 3]>,
    /// The mesh face of each triangle.
    pub face_of: Vec<u32>,
    /// Faces that could not be tessellated, with the reason (self-crossing outline, no
    /// vector area without lying on one line).
    pub failed: Vec<(u32, TriangulateError)>,
}

impl TriangleSoup {
    /// Tessellates every face of `mesh` and welds vertices at equal positions: a face with
    /// a [`triangulate::fan_centre`] as the fan from it (the centres are added to
    /// `positions`, after the mesh's vertices, in face order), any other polygon in its
    /// plane ([`triangulate::polygon`]).
    pub fn new(mesh: &Mesh) -> TriangleSoup {
        Self::build(mesh, false).0
    }

    /// [`TriangleSoup::new`], or with `for_search` every strictly convex face of at least
    /// [`SEARCH_TILING_FROM`] corners tiled by [`triangulate::convex_tiling`] instead
    /// (its centre, if any, added like a non-planar face's); also which faces were, and
    /// the weld ([`weld_by_position`]).
    fn build(mesh: &Mesh, for_search: bool) -> (TriangleSoup, Vec<bool>, Vec<u32>) {
        // A triangle face needs no allocation.
        enum Tess {
            One([u32; 3]),
            Many(Vec<[u32; 3]>),
            Short(Vec<[u32; 3]>),
            Fan(DVec3),
            ShortFan(DVec3),
            Failed(TriangulateError),
        }
        let per_face: Vec<Tess> = (0..mesh.num_faces())
            .into_par_iter()
            .with_min_len(1024)
            .map(|f| {
                let face = mesh.face(f);
                if face.len() == 3 {
                    return Tess::One([face[0], face[1], face[2]]);
                }
                if for_search && face.len() >= SEARCH_TILING_FROM {
                    let corners: Vec<DVec3> = face.iter().map(|&v| mesh.positions()[v as usize]).collect();
                    match triangulate::convex_tiling(&corners) {
                        Some(ConvexTiling::Centre(c)) => return Tess::ShortFan(c),
                        Some(ConvexTiling::Corners(tris)) => {
                            return Tess::Short(
                                tris.into_iter().map(|t| t.map(|k| face[k as usize])).collect(),
                            );
                        }
                        None => {}
                    }
                }
                if let Some(c) = triangulate::fan_centre(mesh.positions(), face) {
                    return Tess::Fan(c);
                }
                let corners: Vec<DVec3> = face.iter().map(|&v| mesh.positions()[v as usize]).collect();
                match triangulate::polygon(&corners) {
                    Ok(tris) => Tess::Many(tris.into_iter().map(|t| t.map(|k| face[k as usize])).collect()),
                    // Corners on one line: the fan of triangles of no area, like a triangle
                    // face of no area (it may plug a T-junction, [`split_at_t_junctions`]).
                    Err(TriangulateError::Degenerate) if all_collinear(&corners) => {
                        Tess::Many((1..face.len() - 1).map(|i| [face[0], face[i], face[i + 1]]).collect())
                    }
                    Err(e) => Tess::Failed(e),
                }
            })
            .collect();
        let short: Vec<bool> =
            per_face.iter().map(|r| matches!(r, Tess::Short(_) | Tess::ShortFan(_))).collect();
        let mut positions = mesh.positions().to_vec();
        positions.extend(per_face.iter().filter_map(|r| match r {
            Tess::Fan(c) | Tess::ShortFan(c) => Some(*c),
            _ => None,
        }));
        let weld = weld_by_position(&positions);
        let mut soup = TriangleSoup {
            triangles: Vec::with_capacity(mesh.num_faces()),
            face_of: Vec::with_capacity(mesh.num_faces()),
            failed: Vec::new(),
            positions,
        };
        let mut next_centre = mesh.num_vertices() as u32;
        for (f, r) in per_face.into_iter().enumerate() {
            let mut push = |t: [u32; 3]| {
                soup.triangles.push(t.map(|v| weld[v as usize]));
                soup.face_of.push(f as u32);
            };
            match r {
                Tess::One(t) => push(t),
                Tess::Many(tris) | Tess::Short(tris) => tris.into_iter().for_each(push),
                Tess::Fan(_) | Tess::ShortFan(_) => {
                    let face = mesh.face(f);
                    for (i, &v) in face.iter().enumerate() {
                        push([next_centre, v, face[(i + 1) % face.len()]]);
                    }
                    next_centre += 1;
                }
                Tess::Failed(e) => soup.failed.push((f as u32, e)),
            }
        }
        (soup, short, weld)
    }

    /// The same surface without its triangles of no area (exactly collinear or coinciding
    /// corners), which carry neither area nor volume: every triangle with the whole segment
    /// of such a triangle as an edge is split at the segment's middle corner, which lies
    /// exactly on it ([`split_at_t_junctions`]), then the triangles of no area are dropped.
    /// Exact (no point is made, no tolerance) and the faces keep their names. A closed soup
    /// stays closed; `Err(face)` names a face of no area whose removal would leave edges
    /// unmatched (such triangles stacked along one line in a way the split does not
    /// resolve).
    pub fn without_zero_area(&self) -> Result<std::borrow::Cow<'_, TriangleSoup>, u32> {
        let degenerate: Vec<bool> = (0..self.triangles.len())
            .into_par_iter()
            .with_min_len(4096)
            .map(|t| is_degenerate(self.triangle(t)))
            .collect();
        let Some(first) = degenerate.iter().position(|&d| d) else {
            return Ok(std::borrow::Cow::Borrowed(self));
        };
        let split = split_at_t_junctions(self);
        let split = split.as_ref().unwrap_or(self);
        let mut out = TriangleSoup {
            positions: self.positions.clone(),
            triangles: Vec::with_capacity(split.triangles.len()),
            face_of: Vec::with_capacity(split.triangles.len()),
            failed: self.failed.clone(),
        };
        for (t, (&tri, &f)) in split.triangles.iter().zip(&split.face_of).enumerate() {
            if !is_degenerate(split.triangle(t)) {
                out.triangles.push(tri);
                out.face_of.push(f);
            }
        }
        if !edges_balanced(&out.triangles) && edges_balanced(&self.triangles) {
            return Err(self.face_of[first]);
        }
        Ok(std::borrow::Cow::Owned(out))
    }

    /// The triangles as a mesh over `positions` (unused ones included).
    pub fn to_mesh(&self) -> super::Result<Mesh> {
        let offsets = (0..=self.triangles.len()).map(|t| 3 * t).collect();
        Mesh::from_parts(self.positions.clone(), offsets, self.triangles.as_flattened().to_vec())
    }

    /// The corners of triangle `t`.
    #[inline]
    pub fn triangle(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// Axis-aligned box of every triangle.
    pub fn boxes(&self) -> Vec<(DVec3, DVec3)> {
        self.triangles
            .par_iter()
            .with_min_len(4096)
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect()
    }
}

/// For every vertex, the first vertex with exactly the same position (−0 equals +0).
pub fn weld_by_position(positions: &[DVec3]) -> Vec<u32> {
    use super::hash::{HashMap, HashMapExt};
    let key = |p: DVec3| (p + DVec3::ZERO).to_array().map(f64::to_bits);
    // Each position's bits to the first id seen with them, ids in increasing order.
    let mut first: HashMap<[u64; 3], u32> = HashMap::with_capacity(positions.len());
    positions.iter().enumerate().map(|(i, &p)| *first.entry(key(p)).or_insert(i as u32)).collect()
}

/// Every directed edge a→b of `triangles` is matched by a use b→a (edges from a vertex to
/// itself aside).
fn edges_balanced(triangles: &[[u32; 3]]) -> bool {
    let mut uses: Vec<(u64, i32)> = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|(a, b)| a != b)
        .map(|(a, b)| ((a.min(b) as u64) << 32 | a.max(b) as u64, if a < b { 1 } else { -1 }))
        .collect();
    uses.par_sort_unstable();
    uses.chunk_by(|x, y| x.0 == y.0).all(|run| run.iter().map(|x| x.1).sum::<i32>() == 0)
}

/// Whether each triangle of `soup` has no area.
fn degenerate_flags(soup: &TriangleSoup) -> Vec<bool> {
    (0..soup.triangles.len())
        .into_par_iter()
        .with_min_len(1024)
        .map(|t| is_degenerate(soup.triangle(t)))
        .collect()
}

/// How two triangles of one mesh meet, judged by the vertices they share.
fn soup_pair_meets(soup: &TriangleSoup, i: usize, j: usize) -> bool {
    let (ti, tj) = (soup.triangles[i], soup.triangles[j]);
    // Shared corners as (corner of i, corner of j), without allocating.
    let mut shared = [(0usize, 0usize); 3];
    let mut k = 0;
    for (a, va) in ti.iter().enumerate() {
        for (b, vb) in tj.iter().enumerate() {
            if va == vb {
                shared[k] = (a, b);
                k += 1;
            }
        }
    }
    let (p, q) = (soup.triangle(i), soup.triangle(j));
    match k {
        0 => triangles_meet(p, q),
        1 => {
            let (a, b) = shared[0];
            let (pb, pc) = (p[(a + 1) % 3], p[(a + 2) % 3]);
            let (qd, qe) = (q[(b + 1) % 3], q[(b + 2) % 3]);
            // Quick exit: one triangle's free corners strictly on one side of the other's
            // plane, so it touches that plane at the shared corner only.
            let side = |plane: [DVec3; 3], x: DVec3, y: DVec3| {
                let (sx, sy) =
                    (orient3d(plane[0], plane[1], plane[2], x), orient3d(plane[0], plane[1], plane[2], y));
                sx * sy > 0
            };
            if side(q, pb, pc) || side(p, qd, qe) {
                return false;
            }
            meet_beyond_vertex(p[a], [pb, pc], [qd, qe])
        }
        2 => {
            let c = (0..3).find(|&x| shared[0].0 != x && shared[1].0 != x).unwrap_or(0);
            let d = (0..3).find(|&x| shared[0].1 != x && shared[1].1 != x).unwrap_or(0);
            meet_beyond_edge(p[shared[0].0], p[shared[1].0], p[c], q[d])
        }
        // The same three corners: the faces coincide there.
        _ => true,
    }
}

/// `soup` with its T-junctions made explicit (see the module docs): a triangle with no
/// area and three distinct corners puts its middle corner on the segment between the two
/// others, and every triangle with that segment as an edge is split there (again and
/// again, until no edge carries such a point). The pieces keep their face and cover the
/// same region. `None` when there is nothing to split.
fn split_at_t_junctions(soup: &TriangleSoup) -> Option<TriangleSoup> {
    let pos = |v: u32| soup.positions[v as usize].to_array();
    // Exactly collinear points are in line order when ordered lexicographically.
    let order = |x: &u32, y: &u32| pos(*x).partial_cmp(&pos(*y)).unwrap_or(std::cmp::Ordering::Equal);
    let flat = |t: [u32; 3]| t[0] != t[1] && t[1] != t[2] && t[0] != t[2];
    let mut on_edge: super::hash::HashMap<(u32, u32), Vec<u32>> = super::hash::HashMap::default();
    let mut degenerate = vec![false; soup.triangles.len()];
    for (t, &tri) in soup.triangles.iter().enumerate() {
        if !is_degenerate(soup.triangle(t)) {
            continue;
        }
        degenerate[t] = true;
        if flat(tri) {
            let mut s = tri;
            s.sort_by(order);
            on_edge.entry((s[0].min(s[2]), s[0].max(s[2]))).or_default().push(s[1]);
        }
    }
    if on_edge.is_empty() {
        return None;
    }
    let mut out = TriangleSoup {
        positions: soup.positions.clone(),
        triangles: Vec::with_capacity(soup.triangles.len()),
        face_of: Vec::with_capacity(soup.triangles.len()),
        failed: soup.failed.clone(),
    };
    let mut stack = Vec::new();
    for (t, &tri) in soup.triangles.iter().enumerate() {
        stack.push(tri);
        while let Some(tri) = stack.pop() {
            let split = (0..3).find_map(|k| {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                on_edge.get(&(a.min(b), a.max(b))).map(|points| (k, points))
            });
            match split {
                Some((k, points)) if !degenerate[t] => {
                    // Pieces (a, m1, c), (m1, m2, c), …, (mk, b, c): oriented like (a, b, c).
                    let (a, b, c) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
                    let mut chain = points.clone();
                    chain.sort_by(order);
                    chain.dedup();
                    if order(&a, &b) == std::cmp::Ordering::Greater {
                        chain.reverse();
                    }
                    chain.push(b);
                    let mut prev = a;
                    for m in chain {
                        stack.push([prev, m, c]);
                        prev = m;
                    }
                }
                _ => {
                    out.triangles.push(tri);
                    out.face_of.push(soup.face_of[t]);
                }
            }
        }
    }
    Some(out)
}

/// Face pairs `(f, g)`, f ≤ g, of `mesh` that intersect more than they may (see the
/// module docs), at most `limit` of them: the first ones in triangle order, so the
/// answer is the same on every run. A face whose outline crosses itself is
/// reported as `(f, f)`. Faces with no area (exactly collinear corners) are skipped:
/// [`super::validate::Report::degenerate_faces`] counts them.
pub fn self_intersections(mesh: &Mesh, limit: usize) -> Vec<(usize, usize)> {
    if let Some(soup) = search_soup(mesh) {
        if soup_self_intersections(&soup, limit).is_empty() {
            return Vec::new();
        }
    }
    soup_self_intersections(&TriangleSoup::new(mesh), limit)
}

/// Faces with fewer corners have few chords however they are triangulated.
const SEARCH_TILING_FROM: usize = 16;

/// The faces of `mesh` as triangles ([`TriangleSoup::build`]) with every strictly convex
/// face of [`SEARCH_TILING_FROM`] corners or more tiled for the search, when that tiling
/// finds a crossing exactly when the tiling every command sees does: no triangle is
/// without area (nothing to split at T-junctions), no centre of a fan is at any other
/// vertex, and each such face F shares with every other face G at most one corner, or
/// the two ends of a side of F that is also a side of G where G is such a face too.
/// `None` otherwise, or when no face is such.
///
/// Why: F is a convex region R tiled by triangles whose corners are F's corners and at
/// most a point inside R that no other face has. A corner
/// of F, an extreme point of R, lies in a triangle of F only as its corner; a point inside
/// a side of F lies only in the triangle on that side. Let a triangle t of F and u of
/// another face meet at x beyond their common corners (or coincide, which needs three
/// common corners). With the corners common to F and u at most one corner or a side's
/// two ends, x is then none of them and not inside that side (else t would have them as
/// corners too), so x ∈ R ∩ u lies beyond what F and u share, and the triangle of any
/// other tiling of R that holds x meets u beyond their common corners. Two such faces:
/// the same, from both sides. Triangles of other faces are the same in both soups.
fn search_soup(mesh: &Mesh) -> Option<TriangleSoup> {
    if !mesh.faces().any(|f| f.len() >= SEARCH_TILING_FROM) {
        return None;
    }
    let (soup, short, weld) = TriangleSoup::build(mesh, true);
    if !short.contains(&true) {
        return None;
    }
    let n = soup.triangles.len();
    if (0..n).into_par_iter().with_min_len(4096).any(|t| is_degenerate(soup.triangle(t))) {
        return None;
    }
    // Fan centres (added after the mesh's vertices) welded to nothing else.
    let mut welded = vec![0u32; weld.len()];
    weld.iter().for_each(|&w| welded[w as usize] += 1);
    if (mesh.num_vertices()..weld.len()).any(|c| weld[c] as usize != c || welded[c] != 1) {
        return None;
    }
    // (welded corner, face, position in the face) for the short-chord faces' corners.
    let mut corners: Vec<(u32, u32, u32)> = Vec::new();
    for (f, _) in short.iter().enumerate().filter(|(_, s)| **s) {
        corners.extend(mesh.face(f).iter().enumerate().map(|(k, &v)| (weld[v as usize], f as u32, k as u32)));
    }
    corners.sort_unstable();
    let (mut vertices, mut common) = (Vec::new(), Vec::new());
    // A face's triangles are consecutive in the soup.
    let mut start = 0;
    for run in soup.face_of.chunk_by(|a, b| a == b) {
        let (g, triangles) = (run[0], &soup.triangles[start..start + run.len()]);
        start += run.len();
        vertices.clear();
        vertices.extend(triangles.iter().flatten().copied());
        vertices.sort_unstable();
        vertices.dedup();
        common.clear();
        for &w in &vertices {
            let from = corners.partition_point(|c| c.0 < w);
            common.extend(
                corners[from..].iter().take_while(|c| c.0 == w).filter(|c| c.1 != g).map(|c| (c.1, c.2)),
            );
        }
        common.sort_unstable();
        for shared in common.chunk_by(|a, b| a.0 == b.0) {
            let sides = mesh.face(shared[0].0 as usize).len() as u32;
            let side = |a: u32, b: u32| b - a == 1 || b - a == sides - 1;
            if shared.len() > 2 || (shared.len() == 2 && !side(shared[0].1, shared[1].1)) {
                return None;
            }
        }
    }
    Some(soup)
}

/// [`self_intersections`] of a mesh already tessellated (`soup.face_of` names the faces).
pub fn soup_self_intersections(soup: &TriangleSoup, limit: usize) -> Vec<(usize, usize)> {
    crossings(soup, None, limit, Search::Auto)
}

/// [`soup_self_intersections`] restricted to the pairs with at least one triangle marked
/// in `near` (one flag per triangle): when the unmarked triangles are known not to cross
/// each other, the same answer for a fraction of the work.
pub fn soup_self_intersections_near(soup: &TriangleSoup, near: &[bool], limit: usize) -> Vec<(usize, usize)> {
    crossings(soup, Some(near), limit, Search::Auto)
}

/// Box pairs sharing a grid cell the grid may compare per triangle (plus a floor for
/// small meshes) before the octree is used instead. Ordinary meshes compare 15–30.
const GRID_TESTS_PER_TRIANGLE: u64 = 128;
const GRID_TESTS_FLOOR: u64 = 1 << 16;

/// Where the candidate pairs of a whole soup come from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Search {
    /// The grid unless it would compare too many boxes, then the octree.
    Auto,
    #[cfg(test)]
    Grid,
    #[cfg(test)]
    Tree,
}

/// Faces whose own triangulation failed because their edges cross or corners coincide,
/// as (f, f) pairs.
fn self_crossing_faces(soup: &TriangleSoup) -> Vec<(usize, usize)> {
    soup.failed
        .iter()
        .filter(|(_, e)| *e == TriangulateError::Crossing || *e == TriangulateError::Duplicate)
        .map(|&(f, _)| (f as usize, f as usize))
        .collect()
}

fn crossings(
    soup: &TriangleSoup,
    near: Option<&[bool]>,
    limit: usize,
    search: Search,
) -> Vec<(usize, usize)> {
    let mut found = self_crossing_faces(soup);
    if found.len() >= limit {
        found.truncate(limit);
        return found;
    }
    let flags = degenerate_flags(soup);
    let split = if flags.contains(&true) { split_at_t_junctions(soup) } else { None };
    // The split soup has more triangles: a piece is marked when its face has a marked one.
    let split_near: Option<Vec<bool>> = match (&split, near) {
        (Some(s), Some(near)) => {
            let faces = soup.face_of.iter().chain(&s.face_of).map(|&f| f as usize + 1).max().unwrap_or(0);
            let mut marked = vec![false; faces];
            for (t, &f) in soup.face_of.iter().enumerate() {
                marked[f as usize] |= near[t];
            }
            Some(s.face_of.iter().map(|&f| marked[f as usize]).collect())
        }
        _ => None,
    };
    let near = split_near.as_deref().or(near);
    let soup = split.as_ref().unwrap_or(soup);
    let n = soup.triangles.len();
    let degenerate = if split.is_some() { degenerate_flags(soup) } else { flags };
    let candidates = match near {
        None => {
            let budget = match search {
                Search::Auto => {
                    GRID_TESTS_PER_TRIANGLE.saturating_mul(n as u64).saturating_add(GRID_TESTS_FLOOR)
                }
                #[cfg(test)]
                Search::Grid => u64::MAX,
                #[cfg(test)]
                Search::Tree => 0,
            };
            box_pairs_within(&soup.boxes(), None, budget).unwrap_or_else(|| {
                candidate_pairs(&soup.positions, &soup.triangles, &soup.face_of, &degenerate)
            })
        }
        Some(near) => {
            // Marked boxes among themselves, then against the unmarked ones near them.
            let boxes = soup.boxes();
            let (marked, others): (Vec<u32>, Vec<u32>) = (0..n as u32).partition(|&t| near[t as usize]);
            let of = |ids: &[u32]| -> Vec<_> { ids.iter().map(|&t| boxes[t as usize]).collect() };
            let (marked_boxes, other_boxes) = (of(&marked), of(&others));
            let (within, across) = rayon::join(
                || box_pairs(&marked_boxes, None),
                || box_pairs_near(&marked_boxes, &other_boxes),
            );
            let within = within.into_iter().map(|(k, l)| (marked[k as usize], marked[l as usize]));
            let across = across.into_iter().map(|(k, j)| {
                let (i, j) = (marked[k as usize], others[j as usize]);
                (i.min(j), i.max(j))
            });
            within.chain(across).collect()
        }
    };
    let mut pairs: Vec<(u32, u32)> = candidates
        .into_par_iter()
        .with_min_len(1024)
        .filter(|&(i, j)| {
            let (i, j) = (i as usize, j as usize);
            !degenerate[i]
                && !degenerate[j]
                && soup.face_of[i] != soup.face_of[j]
                && soup_pair_meets(soup, i, j)
        })
        .collect();
    // Triangle-pair order, so the pairs kept under the limit do not depend on timing.
    pairs.par_sort_unstable();
    let mut faces: Vec<(usize, usize)> = pairs
        .into_iter()
        .map(|(i, j)| {
            let (f, g) = (soup.face_of[i as usize] as usize, soup.face_of[j as usize] as usize);
            (f.min(g), f.max(g))
        })
        .collect();
    // Keep the first occurrence of each face pair, in discovery order.
    let mut seen = super::hash::HashSet::default();
    faces.retain(|p| seen.insert(*p));
    found.extend(faces);
    found.truncate(limit);
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn crossing_touching_and_apart() {
        let t = [v(0.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(0.0, 2.0, 0.0)];
        // Pierces t's interior.
        assert!(triangles_meet(t, [v(0.5, 0.5, -1.0), v(0.5, 0.5, 1.0), v(3.0, 3.0, 0.5)]));
        // Above t, nearly touching: apart.
        assert!(!triangles_meet(t, [v(0.5, 0.5, 1e-300), v(1.0, 0.5, 1.0), v(0.5, 1.0, 1.0)]));
        // A vertex exactly on t's edge: they meet (closed triangles).
        assert!(triangles_meet(t, [v(1.0, 0.0, 0.0), v(1.0, -1.0, 1.0), v(1.0, -1.0, -1.0)]));
        // Coplanar, overlapping and disjoint.
        assert!(triangles_meet(t, [v(0.5, 0.5, 0.0), v(3.0, 0.5, 0.0), v(0.5, 3.0, 0.0)]));
        assert!(!triangles_meet(t, [v(1.5, 1.5, 0.0), v(3.0, 1.5, 0.0), v(1.5, 3.0, 0.0)]));
        // Coplanar, one inside the other (no edges cross).
        assert!(triangles_meet(t, [v(0.1, 0.1, 0.0), v(0.5, 0.1, 0.0), v(0.1, 0.5, 0.0)]));
    }

    #[test]
    fn shared_vertex_and_edge_rules() {
        let a = DVec3::ZERO;
        // Two fan triangles around a, side by side in a plane: fine.
        assert!(!meet_beyond_vertex(
            a,
            [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [v(-1.0, 0.0, 0.0), v(0.0, -1.0, 0.0)]
        ));
        // Coplanar, overlapping sectors: fold.
        assert!(meet_beyond_vertex(
            a,
            [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [v(1.0, 1.0, 0.0), v(-1.0, 2.0, 0.0)]
        ));
        // Not coplanar; the second's edge ad lies in the first's plane, inside its angle.
        assert!(meet_beyond_vertex(
            a,
            [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [v(0.3, 0.3, 0.0), v(0.0, 0.0, 1.0)]
        ));
        // Not coplanar, only the apex in common.
        assert!(!meet_beyond_vertex(
            a,
            [v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [v(-0.3, -0.3, 0.0), v(0.0, 0.0, 1.0)]
        ));
        // Crossing through each other's interior at the shared vertex.
        assert!(meet_beyond_vertex(
            a,
            [v(1.0, 0.0, -1.0), v(1.0, 0.0, 1.0)],
            [v(1.0, -1.0, 0.0), v(1.0, 1.0, 0.0)]
        ));
        // Edge sharing: folded flat onto each other vs. opened or bent.
        let (p, q) = (DVec3::ZERO, DVec3::X);
        assert!(meet_beyond_edge(p, q, v(0.5, 1.0, 0.0), v(0.2, 3.0, 0.0)));
        assert!(!meet_beyond_edge(p, q, v(0.5, 1.0, 0.0), v(0.2, -3.0, 0.0)));
        assert!(!meet_beyond_edge(p, q, v(0.5, 1.0, 0.0), v(0.2, 3.0, 1e-300)));
    }

    /// [`self_intersections`] with every triangle pair tested, no candidate search.
    fn all_pairs(mesh: &Mesh) -> Vec<(usize, usize)> {
        all_pairs_marked(mesh, None)
    }

    /// [`all_pairs`] of the pairs with a face marked in `marked` (all when `None`).
    fn all_pairs_marked(mesh: &Mesh, marked: Option<&[bool]>) -> Vec<(usize, usize)> {
        let soup = TriangleSoup::new(mesh);
        let mut found = self_crossing_faces(&soup);
        let soup = split_at_t_junctions(&soup).unwrap_or(soup);
        let n = soup.triangles.len();
        let flat: Vec<bool> = (0..n).map(|t| is_degenerate(soup.triangle(t))).collect();
        let counts = |t: usize| marked.is_none_or(|m| m[soup.face_of[t] as usize]);
        for i in 0..n {
            for j in i + 1..n {
                if !flat[i]
                    && !flat[j]
                    && soup.face_of[i] != soup.face_of[j]
                    && (counts(i) || counts(j))
                    && soup_pair_meets(&soup, i, j)
                {
                    let (f, g) = (soup.face_of[i] as usize, soup.face_of[j] as usize);
                    if !found.contains(&(f.min(g), f.max(g))) {
                        found.push((f.min(g), f.max(g)));
                    }
                }
            }
        }
        found
    }

    /// Triangles between points of the grid {0, 1, 2}³ (many coplanar, collinear and
    /// shared corners, so every sharing and touching case comes up), some of them moved
    /// off the grid.
    fn grid_soup(seed: u64, triangles: usize) -> Mesh {
        let mut rng = crate::random::Rng::new(seed);
        let mut positions: Vec<DVec3> =
            (0..27).map(|i| DVec3::new(f64::from(i % 3), f64::from(i / 3 % 3), f64::from(i / 9))).collect();
        positions.extend((0..10).map(|_| rng.point_in_box(DVec3::ZERO, DVec3::splat(2.0))));
        let faces = (0..triangles)
            .map(|_| {
                loop {
                    let f: Vec<u32> = (0..3).map(|_| rng.below(positions.len() as u64) as u32).collect();
                    if f[0] != f[1] && f[1] != f[2] && f[0] != f[2] {
                        break f;
                    }
                }
            })
            .collect();
        Mesh::new(positions, faces).unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn candidate_search_finds_what_testing_every_pair_finds() {
        use super::super::procedural::{bicone, cone, cube_with_cavity, sliver_cylinder, sphere};
        // The bicone with its first top triangle replaced by a spike through the bottom cap.
        let spiked = {
            let b = bicone(40, 1.0, 1.0);
            let mut positions = b.positions().to_vec();
            positions.push(DVec3::new(0.6, 0.05, -0.5));
            let mut faces: Vec<Vec<u32>> = b.faces().map(<[u32]>::to_vec).collect();
            faces[0] = vec![0, 1, 42];
            faces.extend([vec![1, 40, 42], vec![40, 0, 42]]);
            Mesh::new(positions, faces).unwrap_or_else(|e| panic!("{e}"))
        };
        // The sliver cylinder with one side triangle's top corner pulled inwards past the
        // far side: that long sliver crosses the opposite side and the caps.
        let pierced = {
            let c = sliver_cylinder(60, 10.0);
            let mut positions = c.positions().to_vec();
            positions.push(DVec3::new(-1.5, 0.02, 9.0));
            let mut faces: Vec<Vec<u32>> = c.faces().map(<[u32]>::to_vec).collect();
            faces[0][2] = 2 * 60 + 2;
            Mesh::new(positions, faces).unwrap_or_else(|e| panic!("{e}"))
        };
        let mut meshes = vec![
            spiked,
            pierced,
            bicone(40, 1.0, 1.0),
            bicone(40, 5.0, 0.0),
            cone(40),
            cube_with_cavity(),
            sliver_cylinder(60, 10.0),
        ];
        // A sphere crossed by a shifted copy of itself, in one mesh.
        let s = sphere(6, 10);
        let mut positions = s.positions().to_vec();
        positions.extend(s.positions().iter().map(|p| *p + DVec3::new(0.5, 0.25, 0.125)));
        let k = s.num_vertices() as u32;
        let faces =
            s.faces().map(<[u32]>::to_vec).chain(s.faces().map(|f| f.iter().map(|v| v + k).collect()));
        meshes.push(Mesh::new(positions, faces.collect()).unwrap_or_else(|e| panic!("{e}")));
        meshes.extend((0..6).map(|seed| grid_soup(seed, 60)));
        for (i, m) in meshes.iter().enumerate() {
            let expected = all_pairs(m);
            let soup = TriangleSoup::new(m);
            for search in [Search::Auto, Search::Grid, Search::Tree] {
                assert_eq!(crossings(&soup, None, usize::MAX, search), expected, "mesh {i}, {search:?}");
            }
            if i <= 1 || i >= 7 {
                assert!(!expected.is_empty(), "mesh {i} has no crossing to find");
            }
            // Restricted to the triangles of marked faces (every third, and a few), as the
            // check of a Boolean result is: the same as testing every such pair.
            for every in [3, 17] {
                let marked: Vec<bool> = (0..m.num_faces()).map(|f| f % every == 1).collect();
                let near: Vec<bool> = soup.face_of.iter().map(|&f| marked[f as usize]).collect();
                let want = all_pairs_marked(m, Some(&marked));
                assert_eq!(
                    crossings(&soup, Some(&near), usize::MAX, Search::Auto),
                    want,
                    "mesh {i}, 1/{every}"
                );
            }
        }
    }

    #[test]
    fn search_tiling_changes_no_answer() {
        use super::super::procedural::cone;
        // A cone over one 40-gon in the plane z = tilt · x: faces 0..40 the sides, 40 the
        // base; vertices 0..40 the base's corners, 40 the apex, then the extra ones.
        let (n, base) = (40u32, 40usize);
        let with = |tilt: f64, extra: &[DVec3], faces: &[[u32; 3]]| {
            let c = cone(n);
            let mut positions: Vec<DVec3> =
                c.positions().iter().map(|p| if p.z == 0.0 { v(p.x, p.y, tilt * p.x) } else { *p }).collect();
            positions.extend_from_slice(extra);
            let all = c.faces().map(<[u32]>::to_vec).chain(faces.iter().map(|f| f.to_vec())).collect();
            Mesh::new(positions, all).unwrap_or_else(|e| panic!("{e}"))
        };
        let k = n + 1;
        for tilt in [0.0, 0.5] {
            let clean = with(tilt, &[], &[]);
            assert!(search_soup(&clean).is_some());
            assert_eq!(self_intersections(&clean, 10), vec![]);
        }
        // A triangle through the base's interior, below the sides.
        let pierced =
            with(0.0, &[v(0.3, 0.2, -0.5), v(0.35, 0.2, 0.5), v(0.3, 0.3, 0.5)], &[[k, k + 1, k + 2]]);
        assert!(search_soup(&pierced).is_some());
        assert_eq!(self_intersections(&pierced, 10), vec![(base, base + 1)]);
        // A triangle through the fan of sides and the base: the same face pairs, in the
        // same order, as testing every pair of the triangles every command sees.
        for tilt in [0.0, 0.5] {
            let through =
                with(tilt, &[v(0.2, 0.1, -0.5), v(0.25, 0.1, 1.5), v(0.9, -0.6, 0.7)], &[[k, k + 1, k + 2]]);
            let expected = all_pairs(&through);
            assert!(expected.len() > 2 && expected.iter().all(|&(_, g)| g == base + 1), "{expected:?}");
            assert_eq!(self_intersections(&through, usize::MAX), expected);
            assert_eq!(self_intersections(&through, 1), expected[..1]);
        }
        // A triangle hanging below the tilted base from one of its diagonals touches it
        // only along that diagonal in a tiling that has it as a chord, and crosses the
        // triangles it passes through in one that does not: such a face is tiled as every
        // command tiles it. Without that rule some diagonal would be missed.
        let mut missed = 0;
        for i in 0..n {
            for j in i + 2..n {
                if j - i == n - 1 {
                    continue;
                }
                let m = with(0.5, &[v(0.0, 0.0, -1.0)], &[[i, j, k]]);
                assert!(search_soup(&m).is_none());
                let expected = all_pairs(&m);
                assert_eq!(self_intersections(&m, 10), expected, "diagonal {i}–{j}");
                let short = TriangleSoup::build(&m, true).0;
                missed += usize::from(!expected.is_empty() && soup_self_intersections(&short, 10).is_empty());
            }
        }
        assert!(missed > 0);
        // A face without area (three corners on a line) anywhere, or a vertex at the
        // base's centre (the base's fan, as the face is listed): the tiling every command
        // sees.
        let plugged =
            with(0.0, &[v(2.0, 0.0, 0.0), v(3.0, 0.0, 0.0), v(4.0, 0.0, 0.0)], &[[k, k + 1, k + 2]]);
        assert!(search_soup(&plugged).is_none());
        assert_eq!(self_intersections(&plugged, 10), all_pairs(&plugged));
        let Some(ConvexTiling::Centre(centre)) =
            triangulate::convex_tiling(&cone(n).positions()[..40].iter().rev().copied().collect::<Vec<_>>())
        else {
            panic!("the base is fanned from its centre")
        };
        let touched = with(0.0, &[centre, v(0.0, 0.1, -1.0), v(0.1, 0.0, -1.0)], &[[k, k + 1, k + 2]]);
        assert!(search_soup(&touched).is_none());
        assert_eq!(self_intersections(&touched, 10), all_pairs(&touched));
    }

    #[test]
    fn welding_treats_negative_zero_as_zero() {
        let w = weld_by_position(&[v(0.0, 1.0, 2.0), v(5.0, 5.0, 5.0), v(-0.0, 1.0, 2.0)]);
        assert_eq!(w, vec![0, 1, 0]);
    }
}
