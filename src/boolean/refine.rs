//! Mesh refinement (§6.4): after it, every triangle of A lies wholly inside, outside or
//! on B, and vice versa.
//!
//! The operands are [`Solid`]s: a file's mesh (every vertex an f64 input point) or the
//! exact result of an earlier step ([`super::operand::ExactSolid`]: vertices that may be
//! implicit points, every triangle in the plane of an input triangle, its support). The
//! refinement of two file meshes decides with f64 predicates where it can, as before; with
//! an exact operand every decision is a predicate on implicit points, and a step's result
//! is again an exact operand ([`super::select::assemble_exact`]).
//!
//! 1. Candidate pairs from the shared index ([`super::index`], boxes that certainly hold
//!    the triangles); each pair decided exactly ([`super::intersect::meet`]).
//! 2. Every intersection point, named by its [`Key`], gets one id, shared by A and B,
//!    and is kept *implicit* ([`crate::exact::implicit`]): an edge crossing a triangle's
//!    support plane, or two coplanar edges crossing (input edges where their ends are
//!    input vertices, else segments between implicit points), never rounded while the
//!    refinement and the classification decide anything on it (its rounded position is
//!    for the output only). Ids: A's vertices first, then B's, then the new points; a
//!    vertex of B exactly at a vertex of A takes A's id (keys are exact, so that is where
//!    a key names both vertices).
//! 3. Each cut triangle — one that has points on its edges or inside, or intersection
//!    segments — is re-triangulated in its support plane ([`crate::mesh::constrained`]),
//!    every decision an exact orientation of implicit points in the plane's axis-aligned
//!    projection: its corners and the points on its edges (in their exact order along
//!    the edge, shared with the neighbour across it) form the outline, points inside are
//!    inserted, intersection segments are constraints, so the cut curve appears as edges
//!    of both meshes. Uncut triangles are kept as they are.
//! 4. The cut curve's edges are recorded ([`Refinement::cut_edges`]): the constraints
//!    the triangulations contain, and the pieces of input edges that lie on the other
//!    surface. Classification groups triangles across every other edge.

use std::borrow::Cow;

use glam::{DVec2, DVec3};
use rayon::prelude::*;

use super::index::candidate_pairs;
use super::intersect::{Key, Meeting, Operands, Simplex, meet, separating_axis};
use super::operand::Solid;
use crate::exact::implicit::{self, Point, compare_implicit, orient2d_implicit};
use crate::exact::orient2d;
use crate::mesh::constrained::{self, Constrained, ConstrainedError};

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

/// The refinement could not be completed: with exact predicates on implicit points
/// neither can happen on valid operands, so both are reported as internal errors.
#[derive(Clone, Debug, thiserror::Error)]
pub enum RefineError {
    #[error(
        "internal error: triangle {triangle} of {side} (face {face}) cannot be re-triangulated near ({x}, {y}, {z}): {reason}; please report it",
        x = near.x, y = near.y, z = near.z
    )]
    Triangulate { side: Side, triangle: u32, face: u32, near: DVec3, reason: ConstrainedError },
    #[error("internal error: the intersection point {key:?} cannot be constructed; please report it")]
    Point { key: Key },
}

/// One mesh after refinement.
#[derive(Clone, Debug, Default)]
pub struct Refined {
    /// Triangles over the refinement's point ids, oriented like their parents.
    pub triangles: Vec<[u32; 3]>,
    /// The operand's triangle each one comes from (its parent: a piece of it, in its
    /// support plane).
    pub parent: Vec<u32>,
    /// Per operand triangle: true when it was cut and re-triangulated.
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
    /// Signs of predicates on implicit points that the floating-point filter could not
    /// decide and exact arithmetic did (see [`implicit::exact_signs`]).
    pub exact_signs: usize,
    /// New points whose rounded position needed exact arithmetic past double-double
    /// (see [`implicit::exact_roundings`]).
    pub exact_roundings: usize,
    /// Input triangles re-triangulated in A and in B.
    pub cut_a: usize,
    pub cut_b: usize,
}

/// Both meshes refined against each other.
#[derive(Clone, Debug, Default)]
pub struct Refinement {
    /// All points: A's positions, then B's, then the new intersection points rounded to
    /// f64 (an operand's implicit vertices rounded too: for the output and shapes,
    /// decisions use [`Refinement::point`]).
    pub points: Vec<DVec3>,
    /// A's and B's vertices exactly, for an operand that is not explicit ([`Solid`]);
    /// empty for a file operand (its vertices are its positions in `points`).
    pub vertices: [Vec<Point>; 2],
    /// The new intersection points, exactly: point id `first_new + k` is `implicit[k]`,
    /// named by `new_keys[k]`.
    pub implicit: Vec<Point>,
    pub new_keys: Vec<Key>,
    /// Id of the first new point (A's and B's vertex counts).
    pub first_new: u32,
    /// Input vertices on the other surface: (point id, its key), sorted by id.
    pub vertex_keys: Vec<(u32, Key)>,
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

    /// Point `id` exactly: an operand's vertex or an implicit intersection point.
    pub fn point(&self, id: u32) -> Cow<'_, Point> {
        let vertices = [&self.vertices[0][..], &self.vertices[1][..]];
        point_of(&self.points, (self.b_offset, self.first_new), vertices, &self.implicit, id)
    }

    /// True when point `id` is given by f64 coordinates (an operand's vertex that is an
    /// explicit point), so that tests on its position are tests on the point: every
    /// operand vertex of file operands (ids below [`Refinement::first_new`]), the explicit
    /// ones of an exact operand; never an intersection point.
    pub fn is_explicit(&self, id: u32) -> bool {
        if id >= self.first_new {
            return false;
        }
        let (list, k) = if id < self.b_offset {
            (&self.vertices[0], id)
        } else {
            (&self.vertices[1], id - self.b_offset)
        };
        list.get(k as usize).is_none_or(|p| matches!(p.definition(), implicit::Definition::Explicit(_)))
    }

    /// The key of point `id` when it lies on both surfaces (a new point, or an input
    /// vertex on the other surface).
    pub fn key_of(&self, id: u32) -> Option<Key> {
        if id >= self.first_new {
            return self.new_keys.get((id - self.first_new) as usize).copied();
        }
        self.vertex_keys.binary_search_by_key(&id, |x| x.0).ok().map(|i| self.vertex_keys[i].1)
    }

    pub fn side(&self, side: Side) -> &Refined {
        match side {
            Side::A => &self.a,
            Side::B => &self.b,
        }
    }
}

/// Point `id` of `points` as an exact point: ids below `b_offset` are A's vertices, then
/// B's up to `first`, then the `implicit` ones; an operand's vertices are its `vertices`
/// where given (not explicit), else explicit at their positions.
fn point_of<'a>(
    points: &[DVec3],
    (b_offset, first): (u32, u32),
    vertices: [&'a [Point]; 2],
    implicit: &'a [Point],
    id: u32,
) -> Cow<'a, Point> {
    if id >= first {
        return Cow::Borrowed(&implicit[(id - first) as usize]);
    }
    let (list, k) = if id < b_offset { (vertices[0], id) } else { (vertices[1], id - b_offset) };
    match list.get(k as usize) {
        Some(p) => Cow::Borrowed(p),
        None => Cow::Owned(Point::explicit(points[id as usize])),
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

    /// From (edge, point id) entries: the points of each edge in their exact order from
    /// its lower vertex id to the higher (`mesh`: the operand, whose vertices end the
    /// edges; `point`: a point id's exact point).
    fn build<'p, S: Solid>(
        mut entries: Vec<((u32, u32), u32)>,
        mesh: &'p S,
        point: &(dyn Fn(u32) -> Cow<'p, Point> + Sync),
    ) -> EdgePoints {
        let positions = mesh.rounded();
        entries.par_sort_unstable();
        let mut e =
            EdgePoints { edges: Vec::new(), starts: Vec::new(), ids: Vec::with_capacity(entries.len()) };
        for (edge, id) in entries {
            if e.edges.last() != Some(&edge) {
                e.edges.push(edge);
                e.starts.push(e.ids.len() as u32);
            }
            e.ids.push(id);
        }
        e.starts.push(e.ids.len() as u32);
        // Every point lies exactly on its edge's line: their order along the edge is their
        // order along an axis where its ends differ (the longest, unless implicit ends
        // round to one position: see `separating_axis`).
        let mut runs: Vec<&mut [u32]> = Vec::with_capacity(e.edges.len());
        let mut rest: &mut [u32] = &mut e.ids;
        for w in e.starts.windows(2) {
            let (run, tail) = rest.split_at_mut((w[1] - w[0]) as usize);
            runs.push(run);
            rest = tail;
        }
        runs.into_par_iter().zip(&e.edges).with_min_len(256).for_each(|(run, &(p, q))| {
            if run.len() < 2 {
                return;
            }
            let d = positions[q as usize] - positions[p as usize];
            let Some((axis, forward)) = separating_axis(d, || (mesh.point(p), mesh.point(q))) else {
                unreachable!("an edge's ends are distinct points")
            };
            let exact: Vec<(u32, Cow<'p, Point>)> = run.iter().map(|&id| (id, point(id))).collect();
            let mut order: Vec<usize> = (0..run.len()).collect();
            order.sort_by(|&i, &j| {
                let o = compare_implicit(axis, &exact[i].1, &exact[j].1);
                if forward { o } else { o.reverse() }
            });
            for (slot, i) in run.iter_mut().zip(order) {
                *slot = exact[i].0;
            }
        });
        e
    }
}

/// Refines the triangles of A and B against each other (§6.4): the pairs that meet
/// (step 1), one id per intersection key (step 2) and its exact point, the points on
/// each mesh's edges and inside its triangles, the segments per triangle and the cut
/// curve, then each side re-triangulated.
pub fn refine<A: Solid, B: Solid>(a: &A, b: &B) -> Result<Refinement, RefineError> {
    let exact_before = implicit::exact_signs();
    let ops = Operands::new(a, b);
    let (meetings, mut stats) = meetings(&ops);
    let keys = meeting_keys(&meetings);
    let (na, nb) = (a.rounded().len() as u32, b.rounded().len() as u32);
    let KeyIds { ids, new_keys, vertex_keys, b_alias } = KeyIds::assign(&keys, na, nb);
    // B's welded ids → point ids (aliased onto A's coincident vertices).
    let b_id = |v: u32| b_alias[v as usize];
    let first = na + nb;
    let implicit = implicit_points(&ops, &new_keys)?;
    stats.new_points = implicit.len();
    let mut points = Vec::with_capacity(first as usize + implicit.len());
    points.extend_from_slice(a.rounded());
    points.extend_from_slice(b.rounded());
    let roundings_before = implicit::exact_roundings();
    points.par_extend(implicit.par_iter().with_min_len(256).map(Point::position));
    stats.exact_roundings = implicit::exact_roundings() - roundings_before;
    let vertices = [exact_vertices(a), exact_vertices(b)];
    let vertex_lists = [&vertices[0][..], &vertices[1][..]];
    let point = |id: u32| point_of(&points, (na, first), vertex_lists, &implicit, id);

    // Points on edges and inside triangles, per mesh: exactly where their keys say.
    let (a_edge_entries, a_inside) = on_simplices(&keys, &ids, |k| k.a);
    let (b_edge_entries, b_inside) = on_simplices(&keys, &ids, |k| k.b);
    let (a_edges, b_edges) = rayon::join(
        || EdgePoints::build(a_edge_entries, a, &point),
        || EdgePoints::build(b_edge_entries, b, &point),
    );
    let id_of =
        |k: &Key| ids[keys.binary_search(k).unwrap_or_else(|_| unreachable!("every key was collected"))];
    let (a_segments, b_segments, coplanar) = segments(meetings);
    let curve = cut_curve(&a_segments, &b_segments, &id_of);

    let a_input = SideInput { side: Side::A, mesh: a, vertex_id: &|v| v, edges: &a_edges, inside: &a_inside };
    let b_input = SideInput { side: Side::B, mesh: b, vertex_id: &b_id, edges: &b_edges, inside: &b_inside };
    let ((ra, cut_a), (rb, cut_b)) = rayon::join(
        || refine_side(&a_input, a_segments, &points, &point, &id_of),
        || refine_side(&b_input, b_segments, &points, &point, &id_of),
    );
    let (ra, mut cut_edges) = (ra?, cut_a);
    let (rb, cut_b) = (rb?, cut_b);
    cut_edges.extend(cut_b);
    cut_edges.par_sort_unstable();
    cut_edges.dedup();
    stats.cut_a = ra.cut.iter().filter(|&&c| c).count();
    stats.cut_b = rb.cut.iter().filter(|&&c| c).count();
    stats.exact_signs = implicit::exact_signs() - exact_before;
    Ok(Refinement {
        points,
        vertices,
        implicit,
        new_keys,
        first_new: first,
        vertex_keys,
        b_offset: na,
        a: ra,
        b: rb,
        cut_edges,
        curve,
        coplanar,
        stats,
    })
}

/// An operand's vertices as exact points when it is not explicit (none for a file
/// operand: its positions are its points).
fn exact_vertices<S: Solid>(mesh: &S) -> Vec<Point> {
    if S::EXPLICIT {
        return Vec::new();
    }
    (0..mesh.rounded().len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|v| mesh.point(v).into_owned())
        .collect()
}

/// Step 1: the candidate pairs of A's and B's triangles (boxes that meet) and how each
/// pair that does meet meets; the statistics counted so far.
fn meetings<A: Solid, B: Solid>(ops: &Operands<A, B>) -> (Vec<(u32, u32, Meeting)>, RefineStats) {
    let (a_boxes, b_boxes) = rayon::join(|| ops.a.boxes(), || ops.b.boxes());
    let pairs = candidate_pairs(&a_boxes, &b_boxes);
    let meetings: Vec<(u32, u32, Meeting)> = pairs
        .par_iter()
        .with_min_len(512)
        .filter_map(|&(t, u)| match meet(ops, t, u) {
            Meeting::Apart => None,
            m => Some((t, u, m)),
        })
        .collect();
    let stats = RefineStats {
        candidate_pairs: pairs.len(),
        meeting_pairs: meetings.len(),
        coplanar_pairs: meetings.iter().filter(|m| matches!(m.2, Meeting::Coplanar { .. })).count(),
        ..RefineStats::default()
    };
    (meetings, stats)
}

/// Every key the meetings name, sorted, once.
fn meeting_keys(meetings: &[(u32, u32, Meeting)]) -> Vec<Key> {
    let mut keys: Vec<Key> = Vec::with_capacity(2 * meetings.len());
    for (_, _, m) in meetings {
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
    keys
}

/// Step 2: one point id per key.
struct KeyIds {
    /// The id of each key, in the keys' order.
    ids: Vec<u32>,
    /// The keys of new points (neither operand's vertex), id `na + nb + k` for the k-th.
    new_keys: Vec<Key>,
    /// Input vertices on the other surface: (point id, its key), sorted by id, once.
    vertex_keys: Vec<(u32, Key)>,
    /// B's vertex ids → point ids: `na + v`, or A's vertex at the same place.
    b_alias: Vec<u32>,
}

impl KeyIds {
    /// Keys naming a vertex of A come first (`Simplex` orders vertices first), so a vertex
    /// of B exactly at a vertex of A is aliased before any other key names it.
    fn assign(keys: &[Key], na: u32, nb: u32) -> KeyIds {
        let mut b_alias: Vec<u32> = (0..nb).map(|v| na + v).collect();
        let mut ids = Vec::with_capacity(keys.len());
        let mut new_keys = Vec::new();
        let mut vertex_keys = Vec::new();
        for k in keys {
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
            if id < na + nb {
                vertex_keys.push((id, *k));
            }
            ids.push(id);
        }
        vertex_keys.sort_unstable_by_key(|x| x.0);
        vertex_keys.dedup_by_key(|x| x.0);
        KeyIds { ids, new_keys, vertex_keys, b_alias }
    }
}

/// The exact point of every new key.
fn implicit_points<A: Solid, B: Solid>(
    ops: &Operands<A, B>,
    new_keys: &[Key],
) -> Result<Vec<Point>, RefineError> {
    let implicit: Vec<Option<Point>> = new_keys.par_iter().with_min_len(256).map(|k| k.point(ops)).collect();
    if let Some(k) = implicit.iter().position(Option::is_none) {
        return Err(RefineError::Point { key: new_keys[k] });
    }
    Ok(implicit.into_iter().flatten().collect())
}

/// (edge, point id) of the points inside a mesh's edges.
type EdgeEntries = Vec<((u32, u32), u32)>;

/// Where the points lie on one mesh (`simplex`: the key's simplex of that mesh): the
/// (edge, id) of points inside its edges, and the (triangle, id) of points inside its
/// triangles, sorted.
fn on_simplices(
    keys: &[Key],
    ids: &[u32],
    simplex: impl Fn(&Key) -> Simplex,
) -> (EdgeEntries, Vec<(u32, u32)>) {
    let mut edge_entries = Vec::new();
    let mut inside: Vec<(u32, u32)> = Vec::new();
    for (k, &id) in keys.iter().zip(ids) {
        match simplex(k) {
            Simplex::Edge(p, q) => edge_entries.push(((p, q), id)),
            Simplex::Face(t) => inside.push((t, id)),
            Simplex::Vertex(_) => {}
        }
    }
    inside.par_sort_unstable();
    (edge_entries, inside)
}

/// The segments of A's triangles and of B's where they meet, and the coplanar pairs
/// (A's triangle, B's, same orientation) sorted.
#[allow(clippy::type_complexity)]
fn segments(
    meetings: Vec<(u32, u32, Meeting)>,
) -> (Vec<TriangleSegment>, Vec<TriangleSegment>, Vec<(u32, u32, bool)>) {
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
    (a_segments, b_segments, coplanar)
}

/// The cut curve: every segment as a sorted pair of distinct point ids, once.
fn cut_curve(a: &[TriangleSegment], b: &[TriangleSegment], id_of: &dyn Fn(&Key) -> u32) -> Vec<[u32; 2]> {
    let mut curve: Vec<[u32; 2]> = a
        .iter()
        .chain(b)
        .map(|s| {
            let (x, y) = (id_of(&s.ends[0]), id_of(&s.ends[1]));
            [x.min(y), x.max(y)]
        })
        .filter(|[x, y]| x != y)
        .collect();
    curve.par_sort_unstable();
    curve.dedup();
    curve
}

/// An input edge's chain of point ids: its lower vertex, the points inside it in order,
/// its higher vertex.
struct Chain<'a> {
    first: u32,
    inner: &'a [u32],
    last: u32,
}

impl Chain<'_> {
    fn at(&self, k: usize) -> u32 {
        match k {
            0 => self.first,
            k if k <= self.inner.len() => self.inner[k - 1],
            _ => self.last,
        }
    }

    /// The first place of `id` in the chain.
    fn position(&self, id: u32) -> Option<usize> {
        (0..self.inner.len() + 2).find(|&k| self.at(k) == id)
    }
}

/// What refining one side needs to know about it.
struct SideInput<'a, S: Solid> {
    side: Side,
    mesh: &'a S,
    /// Welded vertex id → point id.
    vertex_id: &'a (dyn Fn(u32) -> u32 + Sync),
    edges: &'a EdgePoints,
    /// (triangle, point id) of points strictly inside triangles, sorted.
    inside: &'a [(u32, u32)],
}

/// Re-triangulates the cut triangles of one side. Returns the refined mesh and the cut
/// edges found on this side.
fn refine_side<'p, S: Solid>(
    input: &SideInput<S>,
    segments: Vec<TriangleSegment>,
    points: &[DVec3],
    point: &(dyn Fn(u32) -> Cow<'p, Point> + Sync),
    id_of: &(dyn Fn(&Key) -> u32 + Sync),
) -> (Result<Refined, RefineError>, Vec<u64>) {
    let (constraints, mut cut_edges) = constraints_and_edge_pieces(input, segments, id_of);
    let cut = cut_triangles(input, &constraints);
    let cut_ids: Vec<u32> = (0..cut.len() as u32).filter(|&t| cut[t as usize]).collect();
    let pieces: Vec<Result<(u32, Constrained), RefineError>> = cut_ids
        .par_iter()
        .with_min_len(16)
        .map(|&t| {
            let mesh = input.mesh;
            let tri = mesh.triangles()[t as usize];
            let corners = tri.map(|v| (input.vertex_id)(v));
            let chains = [0, 1, 2].map(|e| {
                let (p, q) = (tri[e], tri[(e + 1) % 3]);
                (input.edges.get(p, q), p > q)
            });
            let inside: Vec<u32> = input.inside[run_of(input.inside, t)].iter().map(|x| x.1).collect();
            let mut cons: Vec<[u32; 2]> = constraints[run_of(&constraints, t)]
                .iter()
                .map(|x| [x.1[0].min(x.1[1]), x.1[0].max(x.1[1])])
                .collect();
            cons.sort_unstable();
            cons.dedup();
            let shape = Shape { support: mesh.support(t), rounded: tri.map(|v| mesh.rounded()[v as usize]) };
            retriangulate(shape, corners, chains, &inside, &cons, points, point)
                .map(|pieces| (t, pieces))
                .map_err(|(reason, near)| RefineError::Triangulate {
                    side: input.side,
                    triangle: t,
                    face: mesh.face(t),
                    near,
                    reason,
                })
        })
        .collect();
    match assemble_side(input, cut, pieces, &mut cut_edges) {
        Ok(refined) => (Ok(refined), cut_edges),
        Err(e) => (Err(e), cut_edges),
    }
}

/// The entries of `list` (sorted by triangle) that belong to triangle `t`.
fn run_of<T>(list: &[(u32, T)], t: u32) -> std::ops::Range<usize> {
    list.partition_point(|x| x.0 < t)..list.partition_point(|x| x.0 <= t)
}

/// The segments of one side as constraints (point id pairs) per triangle, sorted by
/// triangle, and the pieces of the triangles' edges that segments run along (as edge keys).
fn constraints_and_edge_pieces<S: Solid>(
    input: &SideInput<S>,
    mut segments: Vec<TriangleSegment>,
    id_of: &(dyn Fn(&Key) -> u32 + Sync),
) -> (Vec<(u32, [u32; 2])>, Vec<u64>) {
    let triangles = input.mesh.triangles();
    segments.par_sort_unstable_by_key(|s| s.triangle);
    let mut constraints: Vec<(u32, [u32; 2])> = Vec::with_capacity(segments.len());
    let mut cut_edges: Vec<u64> = Vec::new();
    for s in &segments {
        let tri = triangles[s.triangle as usize];
        let (i0, i1) = (id_of(&s.ends[0]), id_of(&s.ends[1]));
        if i0 == i1 {
            continue;
        }
        // A segment with both ends on one edge's chain (its ends, the points on it, and
        // nothing else) runs along that edge.
        let along = (0..3).find_map(|e| {
            let (p, q) = (tri[e], tri[(e + 1) % 3]);
            let (lo, hi) = (p.min(q), p.max(q));
            let chain = Chain {
                first: (input.vertex_id)(lo),
                inner: input.edges.get(lo, hi),
                last: (input.vertex_id)(hi),
            };
            let x = chain.position(i0)?;
            let y = chain.position(i1)?;
            Some((chain, x, y))
        });
        match along {
            None => constraints.push((s.triangle, [i0, i1])),
            Some((chain, x, y)) => {
                // Mark the pieces of the edge's chain between the two ends.
                for k in x.min(y)..x.max(y) {
                    let (u, v) = (chain.at(k), chain.at(k + 1));
                    if u != v {
                        cut_edges.push(edge_key(u, v));
                    }
                }
            }
        }
    }
    (constraints, cut_edges)
}

/// Which triangles are cut: points inside, constraints, or points on an edge. Only edges
/// between two vertices that end an edge with points are looked up.
fn cut_triangles<S: Solid>(input: &SideInput<S>, constraints: &[(u32, [u32; 2])]) -> Vec<bool> {
    let triangles = input.mesh.triangles();
    let mut ends = vec![false; input.mesh.rounded().len()];
    for &(p, q) in &input.edges.edges {
        ends[p as usize] = true;
        ends[q as usize] = true;
    }
    let mut cut = vec![false; triangles.len()];
    for t in input.inside.iter().map(|x| x.0).chain(constraints.iter().map(|x| x.0)) {
        cut[t as usize] = true;
    }
    cut.par_iter_mut().with_min_len(4096).enumerate().for_each(|(t, c)| {
        let tri = triangles[t];
        *c = *c
            || (0..3).any(|e| {
                let (p, q) = (tri[e], tri[(e + 1) % 3]);
                ends[p as usize] && ends[q as usize] && !input.edges.get(p, q).is_empty()
            });
    });
    cut
}

/// The side's triangles in order: each cut one replaced by its pieces (whose segment edges
/// join `cut_edges`), the others kept with their welded corners.
fn assemble_side<S: Solid>(
    input: &SideInput<S>,
    cut: Vec<bool>,
    pieces: Vec<Result<(u32, Constrained), RefineError>>,
    cut_edges: &mut Vec<u64>,
) -> Result<Refined, RefineError> {
    let triangles = input.mesh.triangles();
    let n = triangles.len();
    let extra = 4 * (pieces.len());
    let mut refined = Refined {
        triangles: Vec::with_capacity(n + extra),
        parent: Vec::with_capacity(n + extra),
        cut: Vec::new(),
    };
    let mut pieces = pieces.into_iter();
    for t in 0..n as u32 {
        if cut[t as usize] {
            let next = match pieces.next() {
                Some(x) => x?,
                None => unreachable!("one result per cut triangle"),
            };
            debug_assert_eq!(next.0, t);
            for piece in next.1.triangles {
                refined.triangles.push(piece);
                refined.parent.push(t);
            }
            cut_edges.extend(next.1.segment_edges.iter().map(|&[x, y]| edge_key(x, y)));
        } else {
            refined.triangles.push(triangles[t as usize].map(|v| (input.vertex_id)(v)));
            refined.parent.push(t);
        }
    }
    refined.cut = cut;
    Ok(refined)
}

/// The two coordinate axes of the projection that drops the largest component of the
/// triangle's normal, in the order that keeps it counter-clockwise (decided exactly; the
/// drop only matters for the pieces' shapes, any non-degenerate one is exact); `None`
/// for a triangle without area.
pub fn plane_axes(tri: [DVec3; 3]) -> Option<[usize; 2]> {
    let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).abs();
    let mut drops = [0, 1, 2];
    drops.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    drops.into_iter().find_map(|k| {
        let axes = [(k + 1) % 3, (k + 2) % 3];
        let q = |p: DVec3| DVec2::new(p[axes[0]], p[axes[1]]);
        match orient2d(q(tri[0]), q(tri[1]), q(tri[2])) {
            0 => None,
            s if s > 0 => Some(axes),
            _ => Some([axes[1], axes[0]]),
        }
    })
}

/// A cut triangle's plane and rounded corners.
struct Shape {
    /// The input triangle whose plane holds it, oriented like it (explicit).
    support: [DVec3; 3],
    /// Its corners rounded (for messages).
    rounded: [DVec3; 3],
}

/// Re-triangulates one cut triangle (`shape`, point ids `corners`): outline = corners
/// and the points on each edge (`chains[e]`: the points of edge e in increasing
/// vertex-id order, and whether that runs against the triangle's direction), plus
/// interior points and constraints. Every decision is an exact orientation of the exact
/// points (`point`) in the axis-aligned projection that keeps the support plane (and so
/// the triangle) counter-clockwise; the rounded `points` only shape the triangles.
/// Returns the pieces over point ids.
fn retriangulate<'p>(
    shape: Shape,
    corners: [u32; 3],
    chains: [(&[u32], bool); 3],
    inside: &[u32],
    constraints: &[[u32; 2]],
    points: &[DVec3],
    point: &(dyn Fn(u32) -> Cow<'p, Point> + Sync),
) -> Result<Constrained, (ConstrainedError, DVec3)> {
    let pos = shape.rounded;
    let near = (pos[0] + pos[1] + pos[2]) / 3.0;
    let mut ids: Vec<u32> = Vec::with_capacity(8 + inside.len());
    // Per point, the triangle's edges it lies on (bit e: edge e, from corner e to e + 1):
    // three points on one edge are collinear by construction, which no filter can decide.
    let mut exact: Vec<(u32, Cow<'p, Point>, u8)> = Vec::with_capacity(11 + inside.len());
    for (e, (chain, reversed)) in chains.into_iter().enumerate() {
        if reversed {
            ids.extend(chain.iter().rev());
        } else {
            ids.extend_from_slice(chain);
        }
        exact.push((corners[e], point(corners[e]), 1 << e | 1 << ((e + 2) % 3)));
        exact.extend(chain.iter().map(|&id| (id, point(id), 1 << e)));
    }
    ids.extend_from_slice(inside);
    exact.extend(inside.iter().map(|&id| (id, point(id), 0)));
    exact.sort_unstable_by_key(|x| x.0);
    let get = |id: u32| match exact.binary_search_by_key(&id, |x| x.0) {
        Ok(i) => (&*exact[i].1, exact[i].2),
        Err(_) => unreachable!("every point of the triangle is listed"),
    };
    let axes = plane_axes(shape.support).ok_or((ConstrainedError::Corners, near))?;
    let orient = |a: u32, b: u32, c: u32| {
        let ((pa, ma), (pb, mb), (pc, mc)) = (get(a), get(b), get(c));
        if ma & mb & mc != 0 { 0 } else { orient2d_implicit(axes, pa, pb, pc) }
    };
    let at = |id: u32| {
        let p = points[id as usize];
        DVec2::new(p[axes[0]], p[axes[1]])
    };
    constrained::triangulate(corners, &ids, constraints, orient, at).map_err(|e| (e, near))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boolean::operand::ExactSolid;
    use crate::boolean::{Names, Operation, Options, Transform, evaluate};
    use crate::exact::implicit::{Definition, orient3d_implicit};
    use crate::mesh::Mesh;
    use crate::mesh::intersect::TriangleSoup;
    use crate::mesh::procedural;

    fn moved(mesh: &Mesh, steps: &str) -> Mesh {
        Transform::parse(steps).unwrap().apply(mesh).unwrap()
    }

    /// Everything both refinements hold is the same: ids, triangles, rounded points, keys,
    /// the points' definitions.
    fn assert_same(x: &Refinement, y: &Refinement) {
        assert_eq!(x.points, y.points);
        assert_eq!(x.new_keys, y.new_keys);
        assert_eq!(
            x.implicit.iter().map(Point::definition).collect::<Vec<_>>(),
            y.implicit.iter().map(Point::definition).collect::<Vec<_>>()
        );
        assert_eq!((x.first_new, x.b_offset), (y.first_new, y.b_offset));
        assert_eq!(x.vertex_keys, y.vertex_keys);
        for (p, q) in [(&x.a, &y.a), (&x.b, &y.b)] {
            assert_eq!((&p.triangles, &p.parent, &p.cut), (&q.triangles, &q.parent, &q.cut));
        }
        assert_eq!((&x.cut_edges, &x.curve, &x.coplanar), (&y.cut_edges, &y.curve, &y.coplanar));
    }

    /// An exact operand whose points are all input vertices refines as the file operand
    /// does, on either side: a cube against its exact 90° copy (coplanar faces) and against
    /// a generic turn.
    #[test]
    fn exact_operands_of_input_points_refine_as_file_operands() {
        let cube = procedural::cube();
        let a = TriangleSoup::new(&cube);
        for steps in ["matrix 0 -1 0 0 1 0 0 0 0 0 1 0", "rotate 1 2 3 10; translate 0.1 0.2 0.3"] {
            let b = TriangleSoup::new(&moved(&cube, steps));
            let (ea, eb) = (ExactSolid::from_soup(&a), ExactSolid::from_soup(&b));
            let plain = refine(&a, &b).unwrap();
            assert!(plain.stats.new_points > 0, "{steps}");
            if steps.starts_with("matrix") {
                assert!(plain.stats.coplanar_pairs > 0);
            }
            assert_same(&refine(&ea, &b).unwrap(), &plain);
            assert_same(&refine(&a, &eb).unwrap(), &plain);
            let both = refine(&ea, &eb).unwrap();
            assert_same(&both, &plain);
            assert_eq!(both.vertices.each_ref().map(Vec::len), [a.positions.len(), b.positions.len()]);
            assert!(plain.vertices.iter().all(Vec::is_empty));
        }
    }

    /// R = cube − (cube turned 1e-3° and shifted by a non-dyadic amount), kept exact, then
    /// refined against a third cube that cuts R's cut curve: the new points include
    /// segments between implicit points crossing a plane, and all are exact.
    #[test]
    fn an_exact_result_refines_exactly_against_a_third_solid() {
        let cube = procedural::cube();
        let b = moved(&cube, "rotate 1 2 3 0.001; translate 0.9 0.8 0.7");
        let ev = evaluate(&cube, &b, Names::default(), &Options::default(), None).unwrap();
        let r = ev.exact_result(Operation::Difference, true).unwrap();
        assert!(r.points.iter().any(|p| !matches!(p.definition(), Definition::Explicit(_))));
        // Centred on the cut edge where B's face x ≈ −0.1 meets A's top, turned.
        let c = moved(&cube, "scale 0.15; rotate 1 2 -1 17; translate -0.1 0.3 1");
        let c = TriangleSoup::new(&ev.frame.mesh_in_ref(&c));
        let x = refine(&r, &c).unwrap();
        assert!(x.implicit.iter().any(|p| matches!(p.definition(), Definition::SegmentPlane(_))));
        assert!(x.stats.cut_a > 0 && x.stats.cut_b > 0);

        // Every piece's corners lie on its support plane; every new point is a corner of
        // pieces of both sides.
        let mut seen = vec![[false; 2]; x.implicit.len()];
        for (k, refined) in [&x.a, &x.b].into_iter().enumerate() {
            for (piece, &parent) in refined.triangles.iter().zip(&refined.parent) {
                let support = if k == 0 { Solid::support(&r, parent) } else { Solid::support(&c, parent) };
                let [p, q, s] = support.map(Point::explicit);
                for &id in piece {
                    assert_eq!(orient3d_implicit(&p, &q, &s, &x.point(id)), 0);
                    if id >= x.first_new {
                        seen[(id - x.first_new) as usize][k] = true;
                    }
                }
            }
        }
        assert!(seen.iter().all(|s| s[0] && s[1]));

        // The pieces of each of R's triangles cover its area.
        let area = |t: [DVec3; 3]| (t[1] - t[0]).cross(t[2] - t[0]).length();
        let mut sums = vec![0.0; r.triangles.len()];
        for (piece, &parent) in x.a.triangles.iter().zip(&x.a.parent) {
            sums[parent as usize] += area(piece.map(|i| x.points[i as usize]));
        }
        for (t, sum) in sums.iter().enumerate() {
            let whole = area(r.triangles[t].map(|i| r.rounded[i as usize]));
            assert!((sum - whole).abs() <= 1e-12 * whole, "triangle {t}: {sum} vs {whole}");
        }

        // The cut curve is closed.
        assert!(!x.curve.is_empty());
        let mut ends = vec![0u32; x.points.len()];
        for s in &x.curve {
            s.iter().for_each(|&i| ends[i as usize] += 1);
        }
        assert!(ends.iter().all(|n| n % 2 == 0));
    }
}
