//! Mesh refinement (§6.4): after it, every triangle of A lies wholly inside, outside or
//! on B, and vice versa.
//!
//! 1. Candidate pairs from the shared index ([`super::index`]); each pair decided
//!    exactly ([`super::intersect::meet`]).
//! 2. Every intersection point, named by its [`Key`], gets one id and one position,
//!    shared by A and B. Ids: A's vertices first, then B's, then the new points; a
//!    vertex of B at the position of a vertex of A takes A's id.
//! 3. Each cut triangle — one that has points on its edges or inside, or intersection
//!    segments — is re-triangulated in its own plane by constrained Delaunay
//!    ([`crate::mesh::triangulate::cdt`]): its corners and the points on its edges (in
//!    order, shared with the neighbour across each edge) form the outline, points
//!    inside are inserted, intersection segments are constraints, so the cut curve
//!    appears as edges of both meshes. Uncut triangles are kept as they are.
//! 4. The cut curve's edges are recorded ([`Refinement::cut_edges`]): the constraints
//!    the triangulations contain, and the pieces of input edges that lie on the other
//!    surface. Classification groups triangles across every other edge.

use glam::DVec3;
use rayon::prelude::*;

use super::index::candidate_pairs;
use super::intersect::{Key, Meeting, Operands, Simplex, meet};
use super::snap;
use crate::mesh::intersect::{TriangleSoup, triangle_projection};
use crate::mesh::triangulate::{self, TriangulateError};

/// Which operand.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    A,
    B,
}

impl std::fmt::Display for Side {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Side::A => "A",
            Side::B => "B",
        })
    }
}

/// A cut triangle could not be re-triangulated.
#[derive(Clone, Debug, thiserror::Error)]
#[error(
    "triangle {triangle} of {side} (face {face}) cannot be re-triangulated near ({x}, {y}, {z}): {reason}; \
     the intersection is numerically degenerate there (points closer than rounding)",
    x = near.x, y = near.y, z = near.z
)]
pub struct RefineError {
    pub side: Side,
    pub triangle: u32,
    pub face: u32,
    pub near: DVec3,
    pub reason: TriangulateError,
}

/// One mesh after refinement.
#[derive(Clone, Debug, Default)]
pub struct Refined {
    /// Triangles over the refinement's point ids, oriented like their parents.
    pub triangles: Vec<[u32; 3]>,
    /// The input triangle (of the operand's [`TriangleSoup`]) each one comes from.
    pub parent: Vec<u32>,
    /// Per input triangle: true when it was cut and re-triangulated.
    pub cut: Vec<bool>,
}

/// What the refinement found and did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RefineStats {
    /// Triangle pairs whose boxes overlap.
    pub candidate_pairs: usize,
    /// Pairs that meet (in a point, a segment or a coplanar polygon).
    pub meeting_pairs: usize,
    /// Of those, coplanar pairs.
    pub coplanar_pairs: usize,
    /// Intersection points that are not input vertices.
    pub new_points: usize,
    /// Points merged because rounding cannot tell them apart ([`super::snap`]): new
    /// points merged into a cluster or onto an input vertex, and vertices of B merged
    /// onto vertices of A.
    pub merged_points: usize,
    /// Input triangles re-triangulated in A and in B.
    pub cut_a: usize,
    pub cut_b: usize,
}

/// Both meshes refined against each other.
#[derive(Clone, Debug, Default)]
pub struct Refinement {
    /// All points: A's positions, then B's, then the new intersection points.
    pub points: Vec<DVec3>,
    /// Number of A's positions (B's vertex v has id `b_offset + v`, unless it sits on
    /// a vertex of A).
    pub b_offset: u32,
    pub a: Refined,
    pub b: Refined,
    /// Edges on the cut curve (`lo << 32 | hi` of their point ids), sorted.
    pub cut_edges: Vec<u64>,
    /// The segments where the surfaces meet (point id pairs): the cut curve, for
    /// pictures; coplanar overlaps contribute their outlines.
    pub curve: Vec<[u32; 2]>,
    /// Coplanar pairs (t of A, u of B, same orientation), sorted by t.
    pub coplanar: Vec<(u32, u32, bool)>,
    pub stats: RefineStats,
}

/// `lo << 32 | hi` of an edge.
#[inline]
pub fn edge_key(a: u32, b: u32) -> u64 {
    (a.min(b) as u64) << 32 | a.max(b) as u64
}

impl Refinement {
    /// True when the edge (a, b) lies on the cut curve.
    pub fn is_cut_edge(&self, a: u32, b: u32) -> bool {
        self.cut_edges.binary_search(&edge_key(a, b)).is_ok()
    }

    pub fn side(&self, side: Side) -> &Refined {
        match side {
            Side::A => &self.a,
            Side::B => &self.b,
        }
    }
}

/// Segments of one triangle: constraints, and pieces lying along one of its edges.
struct TriangleSegment {
    triangle: u32,
    ends: [Key; 2],
}

/// Per-edge point lists of one mesh: the points strictly inside each input edge, in
/// order from the lower vertex id to the higher.
struct EdgePoints {
    edges: Vec<(u32, u32)>,
    starts: Vec<u32>,
    ids: Vec<u32>,
}

impl EdgePoints {
    fn get(&self, a: u32, b: u32) -> &[u32] {
        match self.edges.binary_search(&(a.min(b), a.max(b))) {
            Ok(i) => &self.ids[self.starts[i] as usize..self.starts[i + 1] as usize],
            Err(_) => &[],
        }
    }

    /// From (edge, point id, parameter) entries.
    fn build(mut entries: Vec<((u32, u32), f64, u32)>) -> EdgePoints {
        entries.par_sort_unstable_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
        let mut e =
            EdgePoints { edges: Vec::new(), starts: Vec::new(), ids: Vec::with_capacity(entries.len()) };
        for (edge, _, id) in entries {
            if e.edges.last() != Some(&edge) {
                e.edges.push(edge);
                e.starts.push(e.ids.len() as u32);
            } else if e.ids[*e.starts.last().unwrap_or(&0) as usize..].contains(&id) {
                // A merged point named twice along the edge: its first place only, the
                // same for both triangles sharing the edge.
                continue;
            }
            e.ids.push(id);
        }
        e.starts.push(e.ids.len() as u32);
        e
    }
}

/// Refines the triangles of A and B against each other (§6.4).
pub fn refine(a: &TriangleSoup, b: &TriangleSoup) -> Result<Refinement, RefineError> {
    let ops = Operands {
        a_positions: &a.positions,
        a_triangles: &a.triangles,
        b_positions: &b.positions,
        b_triangles: &b.triangles,
    };
    let (a_boxes, b_boxes) = rayon::join(|| a.boxes(), || b.boxes());
    let pairs = candidate_pairs(&a_boxes, &b_boxes);
    let meetings: Vec<(u32, u32, Meeting)> = pairs
        .par_iter()
        .with_min_len(512)
        .filter_map(|&(t, u)| match meet(&ops, t, u) {
            Meeting::Apart => None,
            m => Some((t, u, m)),
        })
        .collect();
    let mut stats = RefineStats {
        candidate_pairs: pairs.len(),
        meeting_pairs: meetings.len(),
        coplanar_pairs: meetings.iter().filter(|m| matches!(m.2, Meeting::Coplanar { .. })).count(),
        ..RefineStats::default()
    };
    drop(pairs);

    // Step 2: one id per key.
    let mut keys: Vec<Key> = Vec::with_capacity(2 * meetings.len());
    for (_, _, m) in &meetings {
        match m {
            Meeting::Apart => {}
            Meeting::Point(k) => keys.push(*k),
            Meeting::Segment(s) => keys.extend_from_slice(s),
            Meeting::Coplanar { in_a, in_b, points, .. } => {
                keys.extend(in_a.iter().flatten());
                keys.extend(in_b.iter().flatten());
                keys.extend_from_slice(points);
            }
        }
    }
    keys.par_sort_unstable();
    keys.dedup();
    let na = a.positions.len() as u32;
    let nb = b.positions.len() as u32;
    let (lo, hi) = a
        .positions
        .iter()
        .chain(&b.positions)
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let tolerance = snap::tolerance(lo.abs().max(hi.abs()).max_element(), (hi - lo).length());
    let mut b_alias: Vec<u32> = (0..nb).map(|v| na + v).collect();
    // A vertex of B closer than rounding to a vertex of A (a copy turned by 90°, whose
    // cosines are not exactly 0) is that vertex, as if they coincided exactly: otherwise
    // both, and the points around them, would be distinct points a few ulps apart.
    {
        let mut taken = vec![false; na as usize];
        for (t, u, _) in &meetings {
            for va in a.triangles[*t as usize] {
                for vb in b.triangles[*u as usize] {
                    let (pa, pb) = (a.positions[va as usize], b.positions[vb as usize]);
                    if b_alias[vb as usize] == na + vb && !taken[va as usize] && pa.distance(pb) <= tolerance
                    {
                        b_alias[vb as usize] = va;
                        taken[va as usize] = true;
                        stats.merged_points += usize::from(pa != pb);
                    }
                }
            }
        }
    }
    let mut ids = Vec::with_capacity(keys.len());
    let mut new_keys = Vec::new();
    for k in &keys {
        let id = match (k.a, k.b) {
            (Simplex::Vertex(va), Simplex::Vertex(vb)) => {
                b_alias[vb as usize] = va;
                va
            }
            (Simplex::Vertex(va), _) => va,
            (_, Simplex::Vertex(vb)) => b_alias[vb as usize],
            _ => {
                new_keys.push(*k);
                na + nb + new_keys.len() as u32 - 1
            }
        };
        ids.push(id);
    }
    // B's welded ids → point ids (aliased onto A's coincident vertices).
    let b_id = |v: u32| b_alias[v as usize];
    let new_positions: Vec<DVec3> = new_keys.par_iter().map(|k| k.position(&ops)).collect();
    stats.new_points = new_positions.len();
    let mut points = Vec::with_capacity((na + nb) as usize + new_positions.len());
    points.extend_from_slice(&a.positions);
    points.extend_from_slice(&b.positions);
    points.extend(new_positions);
    // Points closer than rounding become one (see `snap`), onto an input vertex of a
    // simplex naming one of them when there is one.
    let first = na + nb;
    let corners = |s: Simplex, tris: &[[u32; 3]], id: &dyn Fn(u32) -> u32, out: &mut Vec<u32>| match s {
        Simplex::Vertex(v) => out.push(id(v)),
        Simplex::Edge(p, q) => out.extend([id(p), id(q)]),
        Simplex::Face(t) => out.extend(tris[t as usize].map(id)),
    };
    let merged = snap::merge(&points, first, tolerance, |k, out| {
        corners(new_keys[k].a, &a.triangles, &|v| v, out);
        corners(new_keys[k].b, &b.triangles, &b_id, out);
    });
    stats.merged_points += merged.iter().enumerate().filter(|&(k, &m)| m != first + k as u32).count();
    if stats.merged_points > 0 {
        for id in ids.iter_mut().filter(|id| **id >= first) {
            *id = merged[(*id - first) as usize];
        }
    }

    // Points on edges and inside triangles, per mesh.
    let param = |p: DVec3, q: DVec3, x: DVec3| (x - p).dot(q - p);
    // A new point inside a triangle but closer than rounding to one of its edges (an
    // edge of the other mesh running a hair off this one's) goes onto that edge, for
    // both triangles sharing it: rounded, it may even lie across the edge.
    let onto_edge = |tri: [u32; 3], pos: &[DVec3], id: u32| -> Option<((u32, u32), f64)> {
        if id < first {
            return None;
        }
        let x = points[id as usize];
        (0..3).find_map(|e| {
            let (p, q) = (tri[e].min(tri[(e + 1) % 3]), tri[e].max(tri[(e + 1) % 3]));
            let (pp, pq) = (pos[p as usize], pos[q as usize]);
            let l = param(pp, pq, x);
            let closest = pp + (pq - pp) * (l / (pq - pp).length_squared()).clamp(0.0, 1.0);
            (closest.distance(x) <= tolerance).then_some(((p, q), l))
        })
    };
    let mut rounds = 0;
    let (a_edges, b_edges, a_inside, b_inside) = loop {
        let mut snapped = 0;
        let mut a_edge_entries = Vec::new();
        let mut b_edge_entries = Vec::new();
        let mut a_inside: Vec<(u32, u32)> = Vec::new();
        let mut b_inside: Vec<(u32, u32)> = Vec::new();
        for (k, &id) in keys.iter().zip(&ids) {
            match k.a {
                Simplex::Edge(p, q) => {
                    let l = param(a.positions[p as usize], a.positions[q as usize], points[id as usize]);
                    a_edge_entries.push(((p, q), l, id));
                }
                Simplex::Face(t) => match onto_edge(a.triangles[t as usize], &a.positions, id) {
                    Some((edge, l)) => {
                        a_edge_entries.push((edge, l, id));
                        snapped += 1;
                    }
                    None => a_inside.push((t, id)),
                },
                Simplex::Vertex(_) => {}
            }
            match k.b {
                Simplex::Edge(p, q) => {
                    let l = param(b.positions[p as usize], b.positions[q as usize], points[id as usize]);
                    b_edge_entries.push(((p, q), l, id));
                }
                Simplex::Face(u) => match onto_edge(b.triangles[u as usize], &b.positions, id) {
                    Some((edge, l)) => {
                        b_edge_entries.push((edge, l, id));
                        snapped += 1;
                    }
                    None => b_inside.push((u, id)),
                },
                Simplex::Vertex(_) => {}
            }
        }
        a_inside.sort_unstable();
        b_inside.par_sort_unstable();
        let (a_edges, b_edges) =
            rayon::join(|| EdgePoints::build(a_edge_entries), || EdgePoints::build(b_edge_entries));
        // A merged point on two edges of one triangle is its corner there (it was a
        // cluster around that corner not quite within the tolerance of it): merge it onto
        // the corner everywhere, and sort the points again.
        rounds += 1;
        if rounds == 1 {
            stats.merged_points += snapped;
        }
        if stats.merged_points == 0 || rounds > 3 {
            break (a_edges, b_edges, a_inside, b_inside);
        }
        let mut onto: Vec<(u32, u32)> = Vec::new();
        for (soup, edges, id) in
            [(a, &a_edges, &(|v: u32| v) as &dyn Fn(u32) -> u32), (b, &b_edges, &b_id as &dyn Fn(u32) -> u32)]
        {
            for tri in &soup.triangles {
                let chains = [0, 1, 2].map(|e| edges.get(tri[e], tri[(e + 1) % 3]));
                if chains.iter().all(|c| c.is_empty()) {
                    continue;
                }
                for e in 0..3 {
                    for &x in chains[e] {
                        // Edges e and e + 1 share corner e + 1, edges e and e + 2 corner e.
                        if chains[(e + 1) % 3].contains(&x) {
                            onto.push((x, id(tri[(e + 1) % 3])));
                        } else if chains[(e + 2) % 3].contains(&x) {
                            onto.push((x, id(tri[e])));
                        } else if x == id(tri[(e + 2) % 3]) {
                            onto.push((x, x));
                        }
                    }
                }
            }
        }
        onto.retain(|&(x, v)| x != v && x >= first);
        if onto.is_empty() {
            break (a_edges, b_edges, a_inside, b_inside);
        }
        onto.sort_unstable();
        onto.dedup_by_key(|o| o.0);
        stats.merged_points += onto.len();
        for id in ids.iter_mut() {
            if let Ok(i) = onto.binary_search_by_key(id, |o| o.0) {
                *id = onto[i].1;
            }
        }
    };

    let id_of =
        |k: &Key| ids[keys.binary_search(k).unwrap_or_else(|_| unreachable!("every key was collected"))];

    // Segments per triangle, and the cut curve.
    let mut a_segments = Vec::new();
    let mut b_segments = Vec::new();
    let mut coplanar = Vec::new();
    for (t, u, m) in &meetings {
        match m {
            Meeting::Segment(s) => {
                a_segments.push(TriangleSegment { triangle: *t, ends: *s });
                b_segments.push(TriangleSegment { triangle: *u, ends: *s });
            }
            Meeting::Coplanar { in_a, in_b, same, .. } => {
                a_segments.extend(in_a.iter().map(|s| TriangleSegment { triangle: *t, ends: *s }));
                b_segments.extend(in_b.iter().map(|s| TriangleSegment { triangle: *u, ends: *s }));
                coplanar.push((*t, *u, *same));
            }
            _ => {}
        }
    }
    drop(meetings);
    coplanar.sort_unstable_by_key(|c| (c.0, c.1));
    let mut curve: Vec<[u32; 2]> = a_segments
        .iter()
        .chain(&b_segments)
        .map(|s| {
            let (x, y) = (id_of(&s.ends[0]), id_of(&s.ends[1]));
            [x.min(y), x.max(y)]
        })
        .filter(|[x, y]| x != y)
        .collect();
    curve.par_sort_unstable();
    curve.dedup();

    let a_input = SideInput { side: Side::A, soup: a, vertex_id: &|v| v, edges: &a_edges, inside: &a_inside };
    let b_input = SideInput { side: Side::B, soup: b, vertex_id: &b_id, edges: &b_edges, inside: &b_inside };
    let ((ra, cut_a), (rb, cut_b)) = rayon::join(
        || refine_side(&a_input, a_segments, &points, &id_of),
        || refine_side(&b_input, b_segments, &points, &id_of),
    );
    let (ra, mut cut_edges) = (ra?, cut_a);
    let (rb, cut_b) = (rb?, cut_b);
    cut_edges.extend(cut_b);
    cut_edges.par_sort_unstable();
    cut_edges.dedup();
    stats.cut_a = ra.cut.iter().filter(|&&c| c).count();
    stats.cut_b = rb.cut.iter().filter(|&&c| c).count();
    Ok(Refinement { points, b_offset: na, a: ra, b: rb, cut_edges, curve, coplanar, stats })
}

/// What refining one side needs to know about it.
struct SideInput<'a> {
    side: Side,
    soup: &'a TriangleSoup,
    /// Welded vertex id → point id.
    vertex_id: &'a (dyn Fn(u32) -> u32 + Sync),
    edges: &'a EdgePoints,
    /// (triangle, point id) of points strictly inside triangles, sorted.
    inside: &'a [(u32, u32)],
}

/// Re-triangulates the cut triangles of one side. Returns the refined mesh and the cut
/// edges found on this side.
fn refine_side(
    input: &SideInput,
    mut segments: Vec<TriangleSegment>,
    points: &[DVec3],
    id_of: &(dyn Fn(&Key) -> u32 + Sync),
) -> (Result<Refined, RefineError>, Vec<u64>) {
    let soup = input.soup;
    let n = soup.triangles.len();
    segments.par_sort_unstable_by_key(|s| s.triangle);
    // Constraints (point id pairs) per triangle, and the pieces along its edges.
    let mut constraints: Vec<(u32, [u32; 2])> = Vec::with_capacity(segments.len());
    let mut cut_edges: Vec<u64> = Vec::new();
    for s in &segments {
        let tri = soup.triangles[s.triangle as usize];
        let (i0, i1) = (id_of(&s.ends[0]), id_of(&s.ends[1]));
        if i0 == i1 {
            continue;
        }
        // A segment with both ends on one edge's chain (its ends, the points on it, and
        // those snapped onto it) runs along that edge.
        let along = (0..3).find_map(|e| {
            let (p, q) = (tri[e], tri[(e + 1) % 3]);
            let (lo, hi) = (p.min(q), p.max(q));
            let mut chain = vec![(input.vertex_id)(lo)];
            chain.extend_from_slice(input.edges.get(lo, hi));
            chain.push((input.vertex_id)(hi));
            let x = chain.iter().position(|&c| c == i0)?;
            let y = chain.iter().position(|&c| c == i1)?;
            Some((chain, x, y))
        });
        match along {
            None => constraints.push((s.triangle, [i0, i1])),
            Some((chain, x, y)) => {
                // Mark the pieces of the edge's chain between the two ends.
                for w in chain[x.min(y)..=x.max(y)].windows(2) {
                    if w[0] != w[1] {
                        cut_edges.push(edge_key(w[0], w[1]));
                    }
                }
            }
        }
    }
    drop(segments);
    let range_of = |list: &[(u32, u32)], t: u32| {
        let lo = list.partition_point(|x| x.0 < t);
        let hi = list.partition_point(|x| x.0 <= t);
        lo..hi
    };
    let constraint_range = |t: u32| {
        let lo = constraints.partition_point(|x| x.0 < t);
        let hi = constraints.partition_point(|x| x.0 <= t);
        lo..hi
    };
    let is_cut = |t: u32| {
        let tri = soup.triangles[t as usize];
        !range_of(input.inside, t).is_empty()
            || !constraint_range(t).is_empty()
            || (0..3).any(|e| !input.edges.get(tri[e], tri[(e + 1) % 3]).is_empty())
    };
    let cut: Vec<bool> = (0..n as u32).into_par_iter().with_min_len(4096).map(is_cut).collect();
    let cut_ids: Vec<u32> = (0..n as u32).filter(|&t| cut[t as usize]).collect();
    let pieces: Vec<Result<(u32, triangulate::Cdt), RefineError>> = cut_ids
        .par_iter()
        .with_min_len(16)
        .map(|&t| {
            let tri = soup.triangles[t as usize];
            let corners = tri.map(|v| (input.vertex_id)(v));
            let chains = [0, 1, 2].map(|e| {
                let (p, q) = (tri[e], tri[(e + 1) % 3]);
                (input.edges.get(p, q), p > q)
            });
            let inside: Vec<u32> = input.inside[range_of(input.inside, t)].iter().map(|x| x.1).collect();
            let mut cons: Vec<[u32; 2]> = constraints[constraint_range(t)]
                .iter()
                .map(|x| [x.1[0].min(x.1[1]), x.1[0].max(x.1[1])])
                .collect();
            cons.sort_unstable();
            cons.dedup();
            retriangulate(soup.triangle(t as usize), corners, chains, &inside, &cons, points)
                .map(|cdt| (t, cdt))
                .map_err(|(reason, near)| RefineError {
                    side: input.side,
                    triangle: t,
                    face: soup.face_of[t as usize],
                    near,
                    reason,
                })
        })
        .collect();
    let mut refined = Refined {
        triangles: Vec::with_capacity(n + 4 * cut_ids.len()),
        parent: Vec::with_capacity(n + 4 * cut_ids.len()),
        cut: Vec::new(),
    };
    let mut pieces = pieces.into_iter().peekable();
    for t in 0..n as u32 {
        if cut[t as usize] {
            let next = match pieces.next() {
                Some(Ok(x)) => x,
                Some(Err(e)) => return (Err(e), cut_edges),
                None => unreachable!("one result per cut triangle"),
            };
            debug_assert_eq!(next.0, t);
            for piece in next.1.triangles {
                refined.triangles.push(piece);
                refined.parent.push(t);
            }
            cut_edges.extend(next.1.constraint_edges.iter().map(|&[x, y]| edge_key(x, y)));
        } else {
            refined.triangles.push(soup.triangles[t as usize].map(|v| (input.vertex_id)(v)));
            refined.parent.push(t);
        }
    }
    refined.cut = cut;
    (Ok(refined), cut_edges)
}

/// Re-triangulates one cut triangle (corners `pos`, point ids `corners`): outline =
/// corners and the points on each edge (`chains[e]`: the points of edge e in increasing
/// vertex-id order, and whether that runs against the triangle's direction), plus
/// interior points and constraints. Returns the pieces over point ids.
fn retriangulate(
    pos: [DVec3; 3],
    corners: [u32; 3],
    chains: [(&[u32], bool); 3],
    inside: &[u32],
    constraints: &[[u32; 2]],
    points: &[DVec3],
) -> Result<triangulate::Cdt, (TriangulateError, DVec3)> {
    let near = (pos[0] + pos[1] + pos[2]) / 3.0;
    let proj = triangle_projection(pos[0], pos[1], pos[2]).ok_or((TriangulateError::Degenerate, near))?;
    let mut ids: Vec<u32> = Vec::with_capacity(8 + inside.len());
    for e in 0..3 {
        ids.push(corners[e]);
        let (chain, reversed) = chains[e];
        if reversed {
            ids.extend(chain.iter().rev());
        } else {
            ids.extend_from_slice(chain);
        }
    }
    // Merged points (`snap`) may repeat a neighbour or a corner: drop the repeats, the
    // same way on both sides of a shared edge.
    ids.dedup();
    while ids.len() > 1 && ids.first() == ids.last() {
        ids.pop();
    }
    let outline_len = ids.len();
    let mut outline_sorted = ids.clone();
    outline_sorted.sort_unstable();
    let mut interior: Vec<u32> =
        inside.iter().copied().filter(|g| outline_sorted.binary_search(g).is_err()).collect();
    interior.sort_unstable();
    interior.dedup();
    ids.extend(interior);
    // Local index of each point id.
    let mut lookup: Vec<(u32, u32)> = ids.iter().enumerate().map(|(i, &g)| (g, i as u32)).collect();
    lookup.sort_unstable();
    if lookup.windows(2).any(|w| w[0].0 == w[1].0) {
        return Err((TriangulateError::Duplicate, near));
    }
    let local = |g: u32| lookup.binary_search_by_key(&g, |x| x.0).ok().map(|i| lookup[i].1);
    let mut cons = Vec::with_capacity(constraints.len());
    for &[x, y] in constraints {
        let (Some(lx), Some(ly)) = (local(x), local(y)) else {
            return Err((TriangulateError::Crossing, points[x as usize]));
        };
        cons.push([lx, ly]);
    }
    let p2: Vec<glam::DVec2> = ids.iter().map(|&g| proj.apply(points[g as usize])).collect();
    let outline: Vec<u32> = (0..outline_len as u32).collect();
    let out = triangulate::cdt(&p2, &outline, &cons).map_err(|e| (e, near))?;
    Ok(triangulate::Cdt {
        triangles: out.triangles.into_iter().map(|t| t.map(|l| ids[l as usize])).collect(),
        constraint_edges: out.constraint_edges.into_iter().map(|e| e.map(|l| ids[l as usize])).collect(),
    })
}
