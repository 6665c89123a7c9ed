//! Triangulating polygons in their own plane: constrained Delaunay (spade) over the
//! polygon's corners projected along its dominant normal axis, keeping the triangles
//! inside the polygon's outline. Formats and renderers that only know triangles (STL, the
//! offscreen renderer) use [`face_triangles`] / [`triangulated`] on top of it.
//!
//! This is a real tessellation, unlike the simplicial covering's centroid fan
//! ([`super::covering`]), whose triangles overlap on non-convex faces: intersection tests
//! and Booleans need triangles that do not overlap. The same routine also re-triangulates
//! the cut triangles of a Boolean refinement, whose intersection segments are extra
//! constraints ([`cdt`]).
//!
//! Projection drops the coordinate axis along which the face's normal is largest and
//! keeps the other two *as they are* (no rotation), so points exactly in the plane keep
//! their exact f64 coordinates and spade's exact orientation predicates decide on the
//! input values ([`crate::exact`]). The two kept axes are ordered so that the face's own orientation is
//! counter-clockwise in 2D.

use glam::{DVec2, DVec3};

use super::Mesh;
use super::covering::face_centroid;
use crate::exact::{orient2d, orient3d};
use spade::{ConstrainedDelaunayTriangulation, HasPosition, Point2, Triangulation};

/// Why a polygon or a constrained point set could not be triangulated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TriangulateError {
    /// The polygon's vector area is zero: no plane to triangulate in.
    #[error("the face has no area (its corners are collinear or coincide)")]
    Degenerate,
    /// Two outline or constraint segments cross (after projection): the polygon overlaps
    /// itself, or rounding put two intersection segments across each other.
    #[error("its edges cross each other in its plane")]
    Crossing,
    /// Two corners project to the same point.
    #[error("two of its corners coincide in its plane")]
    Duplicate,
    /// A coordinate is outside what the exact predicates accept (|x| < 1e-154 but not 0,
    /// or > 1e150).
    #[error("a coordinate is out of the range the exact predicates accept")]
    Range,
}

/// Projection of 3D points onto the axis plane most orthogonal to `normal`,
/// orientation-preserving (a polygon counter-clockwise about `normal` stays so in 2D).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Projection {
    u: usize,
    v: usize,
}

impl Projection {
    /// The projection for a plane with normal `normal`; `None` for a zero normal.
    pub fn along(normal: DVec3) -> Option<Projection> {
        let a = normal.abs();
        let k = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        if normal[k] == 0.0 || !normal[k].is_finite() {
            return None;
        }
        // (x, y, z) → drop k; (k+1, k+2) is right-handed about +axis k.
        let (u, v) = ((k + 1) % 3, (k + 2) % 3);
        Some(if normal[k] > 0.0 { Projection { u, v } } else { Projection { u: v, v: u } })
    }

    #[inline]
    pub fn apply(&self, p: DVec3) -> DVec2 {
        DVec2::new(p[self.u], p[self.v])
    }
}

/// Newell's vector area of a polygon (twice its area along its normal for a planar one).
pub fn newell_normal(points: impl Iterator<Item = DVec3> + Clone) -> DVec3 {
    let first = points.clone().next().unwrap_or(DVec3::ZERO);
    let mut prev = first;
    let mut n = DVec3::ZERO;
    for p in points.skip(1).chain(std::iter::once(first)) {
        n += (prev - first).cross(p - first);
        prev = p;
    }
    n
}

/// Triangulates one polygon face (corners in order, counter-clockwise about its normal):
/// triangles as index triples into `corners`, oriented like the face. Triangles and
/// convex or simply non-convex quads are split directly; larger polygons and awkward
/// quads go through a constrained Delaunay triangulation of the outline.
pub fn polygon(corners: &[DVec3]) -> Result<Vec<[u32; 3]>, TriangulateError> {
    let n = corners.len();
    if n == 3 {
        return Ok(vec![[0, 1, 2]]);
    }
    let normal = newell_normal(corners.iter().copied());
    let proj = Projection::along(normal).ok_or(TriangulateError::Degenerate)?;
    let p: Vec<DVec2> = corners.iter().map(|&c| proj.apply(c)).collect();
    if n == 4 {
        let ccw = |a: usize, b: usize, c: usize| orient2d(p[a], p[b], p[c]) > 0;
        if ccw(0, 1, 2) && ccw(0, 2, 3) {
            return Ok(vec![[0, 1, 2], [0, 2, 3]]);
        }
        if ccw(1, 2, 3) && ccw(1, 3, 0) {
            return Ok(vec![[1, 2, 3], [1, 3, 0]]);
        }
    }
    let outline: Vec<u32> = (0..n as u32).collect();
    let tris = cdt(&p, &outline, &[])?.triangles;
    if tris.is_empty() {
        return Err(TriangulateError::Degenerate);
    }
    Ok(tris)
}

/// Triangles tiling the polygon `corners` (indices into `corners`, oriented like it):
/// the fan (0, i, i + 1) for a convex polygon, [`polygon`] for a non-convex one, and the
/// fan again for a polygon that cannot be triangulated in its plane (its outline crosses
/// itself, or it is degenerate) — the fan keeps its signed area, which is all such a
/// polygon has.
pub fn polygon_or_fan(corners: &[DVec3]) -> Vec<[u32; 3]> {
    let n = corners.len() as u32;
    let fan = || (1..n.saturating_sub(1)).map(|i| [0, i, i + 1]).collect();
    if n <= 3 {
        return fan();
    }
    let Some(proj) = Projection::along(newell_normal(corners.iter().copied())) else {
        return fan();
    };
    let p: Vec<DVec2> = corners.iter().map(|&c| proj.apply(c)).collect();
    let m = p.len();
    if (0..m).all(|i| orient2d(p[i], p[(i + 1) % m], p[(i + 2) % m]) >= 0) {
        return fan();
    }
    polygon(corners).unwrap_or_else(|_| fan())
}

/// A tiling of a strictly convex face for the crossing search ([`convex_tiling`]).
#[derive(Clone, Debug, PartialEq)]
pub enum ConvexTiling {
    /// The fan from this point: the corners' mean, strictly inside the face and exactly
    /// in its plane (a plane of constant coordinate, which the mean keeps).
    Centre(DVec3),
    /// Triangles over the corners (index triples into them).
    Corners(Vec<[u32; 3]>),
}

/// A tiling for the crossing search of a polygon whose corners lie exactly in one plane
/// and turn strictly left all the way round, once (a strictly convex face; the outline's
/// edges change the sign of their first projected coordinate exactly twice): in a plane
/// of constant coordinate the fan from the corners' mean (every triangle at that point,
/// where the search stops splitting), elsewhere the triangle of three corners a third of
/// the way apart, then over each arc's chord the triangle to the arc's middle corner
/// (chords about the perimeter times log n long in all). A Delaunay triangulation of
/// corners on a circle, or a fan from one corner, draws chords across the whole face
/// instead. Oriented like the face, none without area. `None` for any other polygon.
pub fn convex_tiling(corners: &[DVec3]) -> Option<ConvexTiling> {
    let n = corners.len();
    if n < 4 || !is_planar(corners) {
        return None;
    }
    let proj = Projection::along(newell_normal(corners.iter().copied()))?;
    let p: Vec<DVec2> = corners.iter().map(|&c| proj.apply(c)).collect();
    if !(0..n).all(|i| orient2d(p[i], p[(i + 1) % n], p[(i + 2) % n]) > 0) {
        return None;
    }
    // Left turns only: the outline is simple (not a star wound twice) iff its direction
    // turns round once. A difference of f64 has the exact difference's sign.
    let signs: Vec<bool> =
        (0..n).map(|i| p[(i + 1) % n].x - p[i].x).filter(|&d| d != 0.0).map(|d| d > 0.0).collect();
    let changes = (0..signs.len()).filter(|&i| signs[i] != signs[(i + 1) % signs.len()]).count();
    if changes != 2 {
        return None;
    }
    if let Some(k) = (0..3).find(|&k| corners.iter().all(|c| c[k] == corners[0][k])) {
        let mut centre = corners.iter().sum::<DVec3>() / n as f64;
        centre[k] = corners[0][k];
        let c = proj.apply(centre);
        if (0..n).all(|i| orient2d(c, p[i], p[(i + 1) % n]) > 0) {
            return Some(ConvexTiling::Centre(centre));
        }
    }
    let (b, c) = (n / 3, 2 * n / 3);
    let mut triangles = vec![[0, b as u32, c as u32]];
    let mut arcs = vec![(0, b), (b, c), (c, n)];
    while let Some((i, j)) = arcs.pop() {
        if j - i >= 2 {
            let m = (i + j) / 2;
            triangles.push([i as u32, m as u32, (j % n) as u32]);
            arcs.extend([(i, m), (m, j)]);
        }
    }
    Some(ConvexTiling::Corners(triangles))
}

/// The corners lie in one plane, decided exactly: every corner is coplanar (`orient3d`)
/// with three of them that are not collinear. Corners that are all collinear count as
/// planar (they have no area to place anywhere).
pub fn is_planar(corners: &[DVec3]) -> bool {
    let Some(&a) = corners.first() else { return true };
    let Some(&b) = corners.iter().find(|&&p| p != a) else { return true };
    let collinear = |c: DVec3| {
        let o = |u: usize, v: usize| {
            let q = |p: DVec3| DVec2::new(p[u], p[v]);
            orient2d(q(a), q(b), q(c))
        };
        o(1, 2) == 0 && o(2, 0) == 0 && o(0, 1) == 0
    };
    let Some(&c) = corners.iter().find(|&&c| !collinear(c)) else { return true };
    corners.iter().all(|&d| orient3d(a, b, c, d) == 0)
}

/// The point a polygon face's surface is fanned from: what a face *is* when its corners
/// do not lie in one plane. texgeo takes the thesis' covering ([`super::covering`]): such
/// a face is the fan of triangles (C, Pi, Pi+1) from its centroid C ([`face_centroid`],
/// the same rounded point everywhere), in every command, export and check.
///
/// `None` for a triangle, a planar face (any triangulation in its plane covers the same
/// region as the fan), and a non-planar face whose fan folds (some triangle turns against
/// the face seen along its normal, as on a non-convex face whose centroid lies outside
/// it): that fan's triangles overlap each other and reach past the face's outline, where
/// they would cross its neighbours as soon as rounding lifts the face out of its plane
/// (a turned L-shaped prism), so such a face is triangulated in its projection plane; only
/// for those faces do the covering's volume and the triangles differ, by about the face's
/// distance from a plane times its area.
pub fn fan_centre(positions: &[DVec3], face: &[u32]) -> Option<DVec3> {
    if face.len() <= 3 {
        return None;
    }
    let corners: Vec<DVec3> = face.iter().map(|&v| positions[v as usize]).collect();
    if is_planar(&corners) {
        return None;
    }
    let c = face_centroid(positions, face);
    let proj = Projection::along(newell_normal(corners.iter().copied()))?;
    let (c2, p): (DVec2, Vec<DVec2>) = (proj.apply(c), corners.iter().map(|&x| proj.apply(x)).collect());
    (0..p.len()).all(|i| orient2d(c2, p[i], p[(i + 1) % p.len()]) > 0).then_some(c)
}

/// The triangles of face `face` of a mesh with `positions` (vertex indices, oriented like
/// the face), for a planar face: n − 2 triangles that tile it exactly, non-convex faces
/// included (a fan from the first vertex folds over a non-convex polygon, keeping its
/// signed area but not its area). Non-planar faces are fanned from their centroid
/// ([`fan_centre`], [`triangulated`]).
pub fn face_triangles(positions: &[DVec3], face: &[u32]) -> Vec<[u32; 3]> {
    if face.len() == 3 {
        return vec![[face[0], face[1], face[2]]];
    }
    let corners: Vec<DVec3> = face.iter().map(|&v| positions[v as usize]).collect();
    polygon_or_fan(&corners).into_iter().map(|t| t.map(|i| face[i as usize])).collect()
}

/// `mesh` with every face triangulated: planar faces in their plane over the same
/// vertices, non-planar ones as the fan from their centroid, which is added as a vertex
/// (after the mesh's own). The triangles cover exactly the surface every command uses.
pub fn triangulated(mesh: &Mesh) -> Mesh {
    let mut positions = mesh.positions().to_vec();
    let mut faces: Vec<Vec<u32>> = Vec::with_capacity(mesh.num_faces());
    for face in mesh.faces() {
        match fan_centre(mesh.positions(), face) {
            Some(c) => {
                let ci = positions.len() as u32;
                positions.push(c);
                faces.extend((0..face.len()).map(|i| vec![ci, face[i], face[(i + 1) % face.len()]]));
            }
            None => faces.extend(face_triangles(mesh.positions(), face).into_iter().map(|t| t.to_vec())),
        }
    }
    Mesh::new(positions, faces)
        .unwrap_or_else(|e| unreachable!("triangles of a valid mesh form a valid mesh: {e}"))
}

#[derive(Clone, Copy, Debug)]
struct Vertex2 {
    position: Point2<f64>,
    id: u32,
}

impl HasPosition for Vertex2 {
    type Scalar = f64;
    fn position(&self) -> Point2<f64> {
        self.position
    }
}

/// A constrained triangulation of a region.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Cdt {
    /// Triangles inside the outline, as index triples, counter-clockwise.
    pub triangles: Vec<[u32; 3]>,
    /// The constraint edges inside the region (not on the outline), as index pairs: the
    /// given constraints, split where a point lies exactly on one.
    pub constraint_edges: Vec<[u32; 2]>,
}

/// Constrained Delaunay triangulation of the region bounded by the closed loop
/// `outline` (indices into `points`, counter-clockwise), with the extra segments
/// `constraints` (index pairs) as edges. Returns the triangles inside the outline as
/// index triples into `points`, counter-clockwise, and the constraint edges inside it.
/// Points not on the outline are inserted too (they must lie inside it). An empty outline
/// keeps every triangle of the points' convex hull.
///
/// Fails when segments cross or two points coincide: both mean the input was not a
/// planar straight-line graph (a self-overlapping polygon, or intersection segments
/// that rounding put across each other).
pub fn cdt(points: &[DVec2], outline: &[u32], constraints: &[[u32; 2]]) -> Result<Cdt, TriangulateError> {
    let vertices: Vec<Vertex2> = points
        .iter()
        .enumerate()
        .map(|(i, p)| Vertex2 { position: Point2::new(p.x, p.y), id: i as u32 })
        .collect();
    let n = outline.len();
    let mut edges: Vec<[usize; 2]> = Vec::with_capacity(n + constraints.len());
    for k in 0..n {
        edges.push([outline[k] as usize, outline[(k + 1) % n] as usize]);
    }
    edges.extend(constraints.iter().map(|c| [c[0] as usize, c[1] as usize]));
    let mut conflict = false;
    let cdt: ConstrainedDelaunayTriangulation<Vertex2> =
        ConstrainedDelaunayTriangulation::try_bulk_load_cdt(vertices, edges, |_| conflict = true)
            .map_err(|_| TriangulateError::Range)?;
    if cdt.num_vertices() != points.len() {
        return Err(TriangulateError::Duplicate);
    }
    if conflict {
        return Err(TriangulateError::Crossing);
    }
    // Outline edges as (min, max) id pairs: the walls the outside flood fill stops at.
    let mut walls: Vec<(u32, u32)> = (0..n)
        .map(|k| {
            let (a, b) = (outline[k], outline[(k + 1) % n]);
            (a.min(b), a.max(b))
        })
        .collect();
    walls.sort_unstable();
    let is_wall = |a: u32, b: u32| walls.binary_search(&(a.min(b), a.max(b))).is_ok();

    // Flood the outside from the convex hull inwards, never crossing the outline.
    let mut outside = vec![false; cdt.num_all_faces()];
    let mut stack = Vec::new();
    for hull in cdt.convex_hull().filter(|_| n > 0) {
        for edge in [hull, hull.rev()] {
            let [a, b] = edge.vertices().map(|v| v.data().id);
            if let Some(f) = edge.face().as_inner() {
                if !is_wall(a, b) && !outside[f.index()] {
                    outside[f.index()] = true;
                    stack.push(f.fix());
                }
            }
        }
    }
    while let Some(f) = stack.pop() {
        for edge in cdt.face(f).adjacent_edges() {
            let [a, b] = edge.vertices().map(|v| v.data().id);
            if is_wall(a, b) {
                continue;
            }
            if let Some(g) = edge.rev().face().as_inner() {
                if !outside[g.index()] {
                    outside[g.index()] = true;
                    stack.push(g.fix());
                }
            }
        }
    }
    let triangles = cdt
        .inner_faces()
        .filter(|f| !outside[f.index()])
        .map(|f| f.vertices().map(|v| v.data().id))
        .collect();
    let constraint_edges = if constraints.is_empty() {
        Vec::new()
    } else {
        cdt.undirected_edges()
            .filter(|e| e.is_constraint_edge())
            .map(|e| e.vertices().map(|v| v.data().id))
            .filter(|[a, b]| !is_wall(*a, *b))
            .collect()
    };
    Ok(Cdt { triangles, constraint_edges })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::orient2d_approx;
    use crate::mesh::covering::Covering;
    use crate::mesh::procedural;

    fn area(p: &[DVec3], tris: &[[u32; 3]]) -> DVec3 {
        tris.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                0.5 * (b - a).cross(c - a)
            })
            .sum()
    }

    #[test]
    fn short_chords_tile_strictly_convex_faces_only() {
        // Corners on a circle in the plane z = 0.5 (fanned from the centre) or z = x / 2.
        let circle = |n: usize, tilt: f64| -> Vec<DVec3> {
            (0..n)
                .map(|i| {
                    let a = std::f64::consts::TAU * i as f64 / n as f64;
                    DVec3::new(a.cos(), a.sin(), if tilt == 0.0 { 0.5 } else { tilt * a.cos() })
                })
                .collect()
        };
        for (n, tilt) in [4, 5, 7, 16, 100, 1000].into_iter().flat_map(|n| [(n, 0.0), (n, 0.5)]) {
            let mut p = circle(n, tilt);
            let normal = newell_normal(p.iter().copied());
            let tris = match convex_tiling(&p) {
                Some(ConvexTiling::Centre(c)) if tilt == 0.0 => {
                    p.push(c);
                    (0..n as u32).map(|i| [n as u32, i, (i + 1) % n as u32]).collect()
                }
                Some(ConvexTiling::Corners(tris)) if tilt != 0.0 => {
                    assert_eq!(tris.len(), n - 2);
                    tris
                }
                other => panic!("{n}-gon, tilt {tilt}: {other:?}"),
            };
            // Every triangle turns like the face, exactly in its plane, and together they
            // cover its area once (up to rounding).
            assert!(tris.iter().all(|t| {
                let [a, b, c] = t.map(|i| p[i as usize]);
                (b - a).cross(c - a).dot(normal) > 0.0 && orient3d(p[0], p[1], p[2], c) == 0
            }));
            let whole = area(&p, &(1..n as u32 - 1).map(|i| [0, i, i + 1]).collect::<Vec<_>>());
            assert!((area(&p, &tris) - whole).length() <= 1e-12 * whole.length());
            // Each side of the outline in one triangle, each chord in two: a tiling.
            let side = |a: u32, b: u32| b < n as u32 && (b - a == 1 || b - a == n as u32 - 1);
            let mut edges = std::collections::HashMap::new();
            for t in &tris {
                for k in 0..3 {
                    let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                    *edges.entry((a, b)).or_insert(0) += 1;
                }
            }
            assert!(edges.iter().all(|(&(a, b), &c)| c == if side(a, b) { 1 } else { 2 }));
            // Short chords: far less in all than a corner fan's n − 3 chords of length up
            // to 2 (the centre's fan has long spokes, all at the centre).
            if tilt == 0.0 {
                continue;
            }
            let chords: f64 = edges
                .keys()
                .filter(|&&(a, b)| !side(a, b))
                .map(|&(a, b)| p[a as usize].distance(p[b as usize]))
                .sum();
            assert!(chords <= 4.0 * std::f64::consts::TAU * (n as f64).log2(), "{n}: {chords}");
        }
        // Not planar, a corner turning right, three corners on a line, a star (all left
        // turns, wound twice), reversed corners: none.
        let mut bent = circle(8, 0.0);
        bent[3].z = 1e-9;
        assert!(convex_tiling(&bent).is_none());
        let mut dented = circle(8, 0.0);
        dented[3] *= 0.5;
        assert!(convex_tiling(&dented).is_none());
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let mut straight = square.to_vec();
        straight.insert(1, (square[0] + square[1]) * 0.5);
        assert!(convex_tiling(&square).is_some());
        assert!(convex_tiling(&straight).is_none());
        let ring = circle(5, 0.0);
        let star: Vec<DVec3> = (0..5).map(|i| ring[i * 2 % 5]).collect();
        assert!(convex_tiling(&star).is_none());
        let reversed: Vec<DVec3> = ring.iter().rev().copied().collect();
        assert!(convex_tiling(&reversed).is_some());
        assert!(convex_tiling(&ring[..3]).is_none());
    }

    #[test]
    fn non_convex_l_is_tessellated_not_fanned() {
        let l: Vec<DVec3> = [(0.0, 0.0), (4.0, 0.0), (4.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 2.0))
            .collect();
        let tris = polygon(&l).unwrap();
        assert_eq!(tris.len(), 4);
        // Every triangle positive (counter-clockwise about +z): no overlap, area exactly 6.
        for t in &tris {
            let [a, b, c] = t.map(|i| l[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "{t:?}");
        }
        assert_eq!(area(&l, &tris), DVec3::new(0.0, 0.0, 6.0));
        // Reversed: clockwise about +z, i.e. counter-clockwise about −z.
        let rev: Vec<DVec3> = l.iter().rev().copied().collect();
        let tris = polygon(&rev).unwrap();
        assert_eq!(area(&rev, &tris), DVec3::new(0.0, 0.0, -6.0));
    }

    #[test]
    fn quads_pick_the_diagonal_inside() {
        // A dart: corner 2 is reflex, so only the 0–2 diagonal … no: only 1–3 … check area.
        let q: Vec<DVec3> = [(0.0, 0.0), (2.0, 1.0), (0.0, 2.0), (0.5, 1.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(y, 1.0, x))
            .collect();
        let tris = polygon(&q).unwrap();
        let n = newell_normal(q.iter().copied());
        assert!((area(&q, &tris) - 0.5 * n).length() < 1e-15);
        for t in &tris {
            let [a, b, c] = t.map(|i| q[i as usize]);
            assert!((b - a).cross(c - a).dot(n) > 0.0);
        }
    }

    #[test]
    fn collinear_corners_and_self_overlap() {
        // A square with an extra corner on its bottom side.
        let s: Vec<DVec3> = [(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        let tris = polygon(&s).unwrap();
        assert_eq!(tris.len(), 3);
        assert_eq!(area(&s, &tris), DVec3::new(0.0, 0.0, 4.0));
        // A bow-tie pentagon crosses itself.
        let bow: Vec<DVec3> = [(0.0, 0.0), (2.0, 2.0), (2.0, 0.0), (0.0, 2.0), (-1.0, 1.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        assert_eq!(polygon(&bow), Err(TriangulateError::Crossing));
        let flat = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::X * 3.0];
        assert_eq!(polygon(&flat), Err(TriangulateError::Degenerate));
    }

    #[test]
    fn constraints_become_edges() {
        // Unit square with a segment from the middle of the bottom to the middle of the top.
        let p = [
            DVec2::new(0.0, 0.0),
            DVec2::new(0.5, 0.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.5, 1.0),
            DVec2::new(0.0, 1.0),
            DVec2::new(0.5, 0.5),
        ];
        let out = cdt(&p, &[0, 1, 2, 3, 4, 5], &[[1, 6], [6, 4]]).unwrap();
        let mut inner: Vec<[u32; 2]> =
            out.constraint_edges.iter().map(|&[a, b]| [a.min(b), a.max(b)]).collect();
        inner.sort_unstable();
        assert_eq!(inner, vec![[1, 6], [4, 6]]);
        let tris = out.triangles;
        let has_edge = |a: u32, b: u32| tris.iter().any(|t| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b));
        assert!(has_edge(1, 6) || has_edge(6, 1));
        assert!(has_edge(6, 4) || has_edge(4, 6));
        let total: f64 =
            tris.iter().map(|t| orient2d_approx(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize])).sum();
        assert_eq!(total, 2.0);
        // Crossing diagonals conflict; through a vertex exactly on both, they are split there.
        assert_eq!(cdt(&p[..6], &[0, 1, 2, 3, 4, 5], &[[0, 3], [2, 5]]), Err(TriangulateError::Crossing));
        assert!(cdt(&p, &[0, 1, 2, 3, 4, 5], &[[0, 3], [2, 5]]).is_ok());
    }

    /// Σ |area| of the triangles, and their signed volume.
    fn measures(mesh: &Mesh) -> (f64, f64) {
        let c = Covering::new(mesh);
        (c.area(), c.volume())
    }

    #[test]
    fn non_convex_faces_keep_area_and_volume() {
        for name in procedural::BUILTIN_NAMES {
            let m = procedural::by_name(name).unwrap();
            let t = triangulated(&m);
            assert!(t.is_triangle_mesh());
            let want = m
                .faces()
                .map(|f| if fan_centre(m.positions(), f).is_some() { f.len() } else { f.len() - 2 })
                .sum::<usize>();
            assert_eq!(t.num_faces(), want, "{name}");
            let ((a0, v0), (a1, v1)) = (measures(&m), measures(&t));
            assert!(
                (a0 - a1).abs() <= 1e-12 * a0 && (v0 - v1).abs() <= 1e-12 * v0.abs(),
                "{name}: {a0} {a1} {v0} {v1}"
            );
            assert!(t.report().is_closed(), "{name}");
        }
        // A comb: a fan from its first vertex folds over the teeth.
        let comb = [
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 2.0),
            (4.0, 2.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 2.0),
            (2.0, 2.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let m = procedural::prism(&comb, 1.0).unwrap();
        let ((a0, v0), (a1, v1)) = (measures(&m), measures(&triangulated(&m)));
        assert!((a0 - a1).abs() < 1e-12 * a0 && (v0 - v1).abs() < 1e-12 * v0, "{a0} {a1} {v0} {v1}");
    }
}
