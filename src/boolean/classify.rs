//! Triangle classification (§6.5): every refined triangle of A is in, out or on B, and
//! vice versa.
//!
//! - **On** (§6.2.2): a piece of a triangle that has coplanar partners in the other mesh
//!   is on the other surface when its three corners lie in one of them (the partner's
//!   edges are constraints, so a piece is wholly in or out of it) — exact 2D
//!   orientations of the implicit corners in the common plane, no tolerance. The
//!   partner's orientation makes it *same* or *opposite*.
//! - **Groups** (§6.5.1): triangles connected across edges that are not on the cut
//!   curve lie on the same side of the other solid, so each group is classified once,
//!   from a probe that needs no rounded intersection point: an input vertex of the
//!   group off the other surface (an f64 point, tested with the inclusion method), else
//!   a corner of one of its triangles inside a face of the other mesh, whose side of
//!   that face's plane — the exact sign of an implicit point — is the group's side
//!   there. Only a group with neither (none in the tests) falls back to the centroid
//!   of its largest triangle, counted in [`ClassifyStats::rounded_probes`].
//!   [`Grouping::Plain`] probes every triangle instead (the thesis' "Nuevo" columns of
//!   Table 6-1).
//! - **Point tests** go to the inclusion module through the caller (any method, the GPU
//!   ones included). A point the method finds *on the boundary* — within its tolerance
//!   of the other surface, although the piece is not on it (a thin sliver) — is decided
//!   by an exact ray-parity test on the f64 point ([`exact_parity`]).
//!
//! ## Operands with implicit points
//!
//! Either operand may be a file's mesh (every point explicit) or an exact intermediate
//! result ([`super::operand::ExactSolid`]: implicit vertices, every triangle in the plane
//! of an input triangle, its *support*). Every function here is generic over
//! [`Solid`]; on an explicit operand ([`Solid::EXPLICIT`], a constant) it runs the f64
//! code it always ran. Against an implicit one:
//!
//! - the side of a point against a triangle's plane is `orient3d` on its support (three
//!   explicit points: exact in f64), every test on its edges an exact predicate on its
//!   corner points ([`orient3d_implicit`], [`orient2d_implicit`]), and boxes are the
//!   certain boxes of [`Solid::boxes`] ([`ray_crossings`], [`exact_parity`]);
//! - the on-test and the exact side of a probe use the other's corner points and support
//!   planes, the own triangle's projection its parent's support;
//! - an input vertex is a probe only when it is explicit ([`Refinement::is_explicit`]): an
//!   implicit vertex of an operand off the other surface is never tested by its rounded
//!   position, but by the exact parity of the point itself ([`exact_parity_point`]), after
//!   the group's exact sides and before a rounded centroid;
//! - an inclusion method is built on the rounded mesh of the implicit operand, and only its
//!   Inside and Outside answers count (its OnBoundary ones go to [`exact_parity`], as
//!   always). That is sound because every method's Inside or Outside means "more than ε
//!   from the rounded surface, with this winding number of it" (ε = 10⁻⁹ of its diagonal,
//!   [`crate::inclusion`]; the GPU methods send every point within their wider f32 band
//!   to the exact CPU test, which has the same ε band), while rounding moves each vertex
//!   by at most half an ulp per coordinate, δ: the exact surface is the rounded one
//!   moved vertex by vertex along straight lines, every point of the moving triangles
//!   staying within δ of the rounded surface, so when δ < ε it never sweeps over the
//!   point and its winding number around the point is the rounded one's. The caller checks
//!   δ against ε with room to spare ([`super::rounded_method_is_exact`]) and gives an
//!   operand that fails it (a tiny one far from the frame's origin) to [`ray_crossings`].

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;

use super::intersect::Simplex;
use super::operand::Solid;
use super::refine::{Refined, Refinement, Side, edge_key, plane_axes};
use crate::exact::implicit::{self, Point, orient2d_implicit, orient3d_implicit};
use crate::exact::orient3d;
use crate::inclusion;
use crate::mesh::disjoint_sets::UnionFind;
use crate::mesh::intersect::segment_meets_triangle;
use crate::mesh::validate::{HalfEdges, corner};

/// Where a refined triangle lies relative to the other solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Class {
    In,
    Out,
    /// On the other surface, facing the same way.
    OnSame,
    /// On the other surface, facing the other way.
    OnOpposite,
}

/// How many point tests classification makes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Grouping {
    /// One point per group of connected triangles (§6.5.1).
    #[default]
    Grouped,
    /// One point per triangle.
    Plain,
}

/// Counts of one classification.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClassifyStats {
    /// Refined triangles of A and B.
    pub triangles: usize,
    /// Of those, on the other surface (decided exactly, no point test).
    pub on: usize,
    /// Groups of triangles (off the other surface) in A and B.
    pub groups: usize,
    /// Point-in-solid tests made.
    pub point_tests: usize,
    /// Points the inclusion method put on the boundary, decided by exact ray parity.
    pub exact_fallbacks: usize,
    /// Of the point tests, those answered by exact ray crossings over the other operand's
    /// triangles without building the inclusion method ([`FEW_POINTS`] or fewer against
    /// it, with the default method; set by the caller of [`classify`]).
    pub ray_tests: usize,
    /// Groups (or, plain, triangles) decided by the exact side of an implicit corner,
    /// without a point test.
    pub local_sides: usize,
    /// Of the point tests, those at an implicit vertex of an operand with implicit
    /// points, by the exact parity of the point itself ([`exact_parity_point`]).
    pub implicit_probes: usize,
    /// Groups (or triangles) with no exact probe, tested at a rounded centroid.
    pub rounded_probes: usize,
    /// Signs on implicit points the filter left to exact arithmetic.
    pub exact_signs: usize,
}

impl ClassifyStats {
    /// Share of probes (point tests and exact local sides) saved against one per
    /// triangle off the other surface (the thesis' "reducción", §6.6).
    pub fn saved_share(&self) -> f64 {
        let plain = self.triangles - self.on;
        let probes = self.point_tests + self.local_sides;
        if plain == 0 { 0.0 } else { 1.0 - probes as f64 / plain as f64 }
    }
}

/// The classes of both refined meshes.
#[derive(Clone, Debug, Default)]
pub struct Classification {
    pub a: Vec<Class>,
    pub b: Vec<Class>,
    pub stats: ClassifyStats,
}

/// A classification could not be completed.
#[derive(Debug, thiserror::Error)]
pub enum ClassifyError {
    #[error(transparent)]
    Inclusion(#[from] inclusion::InclusionError),
    /// No point of a group could be decided (every candidate lies exactly on the other
    /// surface or every ray grazes it).
    #[error(
        "a group of {count} triangle(s) of {side} near ({x}, {y}, {z}) could not be classified exactly",
        x = near.x, y = near.y, z = near.z
    )]
    Undecided { side: Side, count: usize, near: DVec3 },
}

/// Classifies points against the input solid A or B with an inclusion method.
pub type PointTest<'a> = dyn FnMut(Side, &[DVec3]) -> inclusion::Result<Vec<inclusion::Class>> + 'a;

/// Classifies both refined meshes. `test(solid, points)` classifies points against the
/// operand `solid` (A or B) with an inclusion method.
pub fn classify<A: Solid, B: Solid>(
    r: &Refinement,
    a: &A,
    b: &B,
    grouping: Grouping,
    test: &mut PointTest,
) -> Result<Classification, ClassifyError> {
    let exact_before = implicit::exact_signs();
    let mut b_coplanar: Vec<(u32, u32, bool)> = r.coplanar.iter().map(|&(t, u, s)| (u, t, s)).collect();
    b_coplanar.sort_unstable_by_key(|c| (c.0, c.1));
    let (on_a, on_b) =
        rayon::join(|| on_status(r, &r.a, a, b, &r.coplanar), || on_status(r, &r.b, b, a, &b_coplanar));
    let ((groups_a, count_a), (groups_b, count_b)) =
        rayon::join(|| groups(&r.a, &on_a, r), || groups(&r.b, &on_b, r));

    let mut stats = ClassifyStats {
        triangles: r.a.triangles.len() + r.b.triangles.len(),
        on: on_a.iter().chain(&on_b).filter(|o| o.is_some()).count(),
        groups: count_a + count_b,
        ..ClassifyStats::default()
    };
    let view =
        SideView { side: Side::A, refined: &r.a, on: &on_a, group: &groups_a, count: count_a, other: b };
    let a_classes = classify_side(r, &view, grouping, test, &mut stats)?;
    let view =
        SideView { side: Side::B, refined: &r.b, on: &on_b, group: &groups_b, count: count_b, other: a };
    let b_classes = classify_side(r, &view, grouping, test, &mut stats)?;
    stats.exact_signs = implicit::exact_signs() - exact_before;
    Ok(Classification { a: a_classes, b: b_classes, stats })
}

/// One refined mesh with what [`classify`] knows of it: its triangles on the other
/// surface (`on`), its groups (`group` per triangle, `count` of them), and the other
/// operand.
struct SideView<'a, S> {
    side: Side,
    refined: &'a Refined,
    on: &'a [Option<Class>],
    group: &'a [u32],
    count: usize,
    other: &'a S,
}

/// The class of every triangle of one side: the probes (one per group, or one per
/// off-surface triangle), their point tests against the other solid, and exact ray
/// parity for the probes the test leaves on the boundary.
fn classify_side<S: Solid>(
    r: &Refinement,
    v: &SideView<S>,
    grouping: Grouping,
    test: &mut PointTest,
    stats: &mut ClassifyStats,
) -> Result<Vec<Class>, ClassifyError> {
    let (side, refined, on, group, count, other) = (v.side, v.refined, v.on, v.group, v.count, v.other);
    let probes = probes(r, v, grouping);
    let mut tested: Vec<u32> = Vec::new();
    let mut points: Vec<DVec3> = Vec::new();
    let mut known: Vec<(u32, Class)> = Vec::new();
    let mut at_implicit: Vec<(u32, u32)> = Vec::new();
    for &(t, p) in &probes {
        match p {
            Probe::Implicit(v) => at_implicit.push((t, v)),
            Probe::Vertex(v) => {
                tested.push(t);
                points.push(r.points[v as usize]);
            }
            Probe::Centroid(c) => {
                stats.rounded_probes += 1;
                tested.push(t);
                points.push(centroid(refined, &r.points, c));
            }
            Probe::Known(class) => known.push((t, class)),
        }
    }
    stats.local_sides += known.len();
    // Implicit vertices: the exact parity of the point itself (None: on the other surface
    // after all, or every ray grazed; the group then tries its centroids below).
    let implicit_answers: Vec<Option<bool>> =
        at_implicit.par_iter().map(|&(_, v)| exact_parity_point(&r.point(v), other)).collect();
    stats.implicit_probes += at_implicit.len();
    stats.point_tests += points.len() + at_implicit.len();
    let other_side = if side == Side::A { Side::B } else { Side::A };
    let answers = if points.is_empty() { Vec::new() } else { test(other_side, &points)? };
    let decisive = |c: &inclusion::Class| match c {
        inclusion::Class::Inside => Some(Class::In),
        inclusion::Class::Outside => Some(Class::Out),
        inclusion::Class::OnBoundary => None,
    };
    // A group takes the class of its probe (all its triangles lie on one side). Plain
    // mode keeps each triangle's own answer.
    let mut group_class: Vec<Option<Class>> = vec![None; count];
    let mut own: Vec<Option<Class>> = vec![None; refined.triangles.len()];
    let mut pending_points: Vec<(usize, Option<DVec3>)> = Vec::new();
    for ((&t, c), &p) in tested.iter().zip(&answers).zip(&points) {
        let g = group[t as usize] as usize;
        match decisive(c) {
            Some(c) => {
                group_class[g].get_or_insert(c);
                own[t as usize] = Some(c);
            }
            None => pending_points.push((g, Some(p))),
        }
    }
    for (&(t, _), inside) in at_implicit.iter().zip(&implicit_answers) {
        let g = group[t as usize] as usize;
        match inside {
            Some(inside) => {
                let c = if *inside { Class::In } else { Class::Out };
                group_class[g].get_or_insert(c);
                own[t as usize] = Some(c);
            }
            None => pending_points.push((g, None)),
        }
    }
    for &(t, c) in &known {
        group_class[group[t as usize] as usize].get_or_insert(c);
        own[t as usize] = Some(c);
    }
    if grouping == Grouping::Grouped {
        own.iter_mut().for_each(|o| *o = None);
    }
    // A probe within the method's tolerance of the other surface: decided by exact ray
    // parity, trying the group's other triangles after it.
    stats.exact_fallbacks += pending_points.len();
    let mut pending: Vec<(usize, Option<DVec3>)> =
        pending_points.into_iter().filter(|&(g, _)| group_class[g].is_none()).collect();
    pending.sort_by_key(|x| x.0);
    pending.dedup_by_key(|x| x.0);
    if !pending.is_empty() {
        let decided = decide_exactly(refined, &r.points, group, &pending, other, side)?;
        for ((g, _), c) in pending.into_iter().zip(decided) {
            group_class[g] = Some(c);
        }
    }
    let group_class: Vec<Class> = group_class.into_iter().map(|c| c.unwrap_or(Class::Out)).collect();
    Ok((0..refined.triangles.len())
        .map(|t| on[t].or(own[t]).unwrap_or_else(|| group_class[group[t] as usize]))
        .collect())
}

/// Grouped: one probe per group. Plain: one per off-surface triangle.
fn probes<S: Solid>(r: &Refinement, v: &SideView<S>, grouping: Grouping) -> Vec<(u32, Probe)> {
    let (side, refined, other) = (v.side, v.refined, v.other);
    // The other mesh's triangles by their sorted vertex ids, built when first asked.
    let by_vertices: OnceLock<Vec<([u32; 3], u32)>> = OnceLock::new();
    let faces = |s: [u32; 3]| -> Option<u32> {
        let list = by_vertices.get_or_init(|| {
            let triangles = other.triangles();
            let mut v: Vec<([u32; 3], u32)> = (0..triangles.len() as u32)
                .map(|u| {
                    let mut k = triangles[u as usize];
                    k.sort_unstable();
                    (k, u)
                })
                .collect();
            v.par_sort_unstable();
            v
        });
        let i = list.partition_point(|x| x.0 < s);
        // One triangle over these vertices (two would be coincident faces).
        match list.get(i..i + 2) {
            Some([x, y]) if x.0 == s && y.0 == s => None,
            _ => list.get(i).filter(|x| x.0 == s).map(|x| x.1),
        }
    };
    match grouping {
        Grouping::Grouped => group_probes(r, refined, v.group, v.count, other, side, &faces),
        Grouping::Plain => (0..refined.triangles.len() as u32)
            .into_par_iter()
            .with_min_len(1024)
            .filter(|&t| v.on[t as usize].is_none())
            .map(|t| {
                let p = probe(r, refined, t, other, side, &faces).or_else(|| implicit_probe(r, refined, t));
                (t, p.unwrap_or(Probe::Centroid(t)))
            })
            .collect(),
    }
}

/// How a group (or a triangle) is classified.
#[derive(Clone, Copy, Debug)]
enum Probe {
    /// By a point test at this explicit input vertex (point id), which lies off the other
    /// surface.
    Vertex(u32),
    /// By the exact parity of this implicit vertex of the operand (point id), which lies
    /// off the other surface ([`exact_parity_point`]).
    Implicit(u32),
    /// Already decided, by the exact side of an implicit corner.
    Known(Class),
    /// By a point test at this triangle's rounded centroid (no exact probe found).
    Centroid(u32),
}

/// An exact probe of refined triangle `t` of `side` against the other solid `other`: a
/// corner that is an input vertex off the other surface, or else the triangle's side of
/// a face u of the other mesh that it touches inside u — at a corner in u's interior, or
/// along an edge whose ends lie on two different edges of u (or a corner of u and its
/// opposite edge). Near such a place the other surface is u's plane alone and the
/// triangle cannot cross it (that crossing would be a cut edge), so the exact side of
/// its corners off u's plane is its side: behind u (u faces outward) is in.
/// `faces(s)` finds the other mesh's triangle over the sorted vertex ids `s`. u's plane is
/// its support (explicit), so each side is one exact sign of an implicit corner.
fn probe<S: Solid>(
    r: &Refinement,
    refined: &Refined,
    t: u32,
    other: &S,
    side: Side,
    faces: &dyn Fn([u32; 3]) -> Option<u32>,
) -> Option<Probe> {
    let tri = refined.triangles[t as usize];
    if let Some(&v) = tri.iter().find(|&&v| r.is_explicit(v) && r.key_of(v).is_none()) {
        return Some(Probe::Vertex(v));
    }
    let simplex = |id: u32| r.key_of(id).map(|key| if side == Side::A { key.b } else { key.a });
    let sx = tri.map(simplex);
    let side_of = |u: u32, corners: &[usize]| -> Option<Probe> {
        let [p, q, s] = other.support(u).map(Point::explicit);
        corners.iter().find_map(|&j| match orient3d_implicit(&p, &q, &s, &r.point(tri[j])) {
            0 => None,
            x if x < 0 => Some(Probe::Known(Class::In)),
            _ => Some(Probe::Known(Class::Out)),
        })
    };
    for (k, s) in sx.iter().enumerate() {
        if let Some(Simplex::Face(u)) = *s {
            if let Some(p) = side_of(u, &[(k + 1) % 3, (k + 2) % 3]) {
                return Some(p);
            }
        }
    }
    let vertices = |s: Simplex| -> Vec<u32> {
        match s {
            Simplex::Vertex(v) => vec![v],
            Simplex::Edge(p, q) => vec![p, q],
            Simplex::Face(_) => Vec::new(),
        }
    };
    for k in 0..3 {
        let (Some(x), Some(y)) = (sx[k], sx[(k + 1) % 3]) else { continue };
        // Two different edges, or a vertex and an edge not through it, span one triangle.
        let (vx, vy) = (vertices(x), vertices(y));
        if vx.is_empty() || vy.is_empty() || vx.len() + vy.len() < 3 {
            continue;
        }
        let mut all: Vec<u32> = vx.iter().chain(&vy).copied().collect();
        all.sort_unstable();
        all.dedup();
        let Ok(span) = <[u32; 3]>::try_from(all.as_slice()) else { continue };
        if vx.iter().all(|v| vy.contains(v)) || vy.iter().all(|v| vx.contains(v)) {
            continue;
        }
        if let Some(p) = faces(span).and_then(|u| side_of(u, &[(k + 2) % 3])) {
            return Some(p);
        }
    }
    None
}

/// A corner of refined triangle `t` that is an implicit vertex of its operand (not an
/// intersection point: off the other surface), for [`Probe::Implicit`].
fn implicit_probe(r: &Refinement, refined: &Refined, t: u32) -> Option<Probe> {
    let tri = refined.triangles[t as usize];
    tri.into_iter()
        .find(|&v| v < r.first_new && !r.is_explicit(v) && r.key_of(v).is_none())
        .map(Probe::Implicit)
}

/// One probe per off-surface group (the triangle it comes from, and the probe): the
/// first exact one among its triangles, else an implicit vertex of its operand among
/// them, else its largest triangle's centroid.
fn group_probes<S: Solid>(
    r: &Refinement,
    refined: &Refined,
    group: &[u32],
    count: usize,
    other: &S,
    side: Side,
    faces: &(dyn Fn([u32; 3]) -> Option<u32> + Sync),
) -> Vec<(u32, Probe)> {
    // Triangles by group (counting sort).
    let mut starts = vec![0u32; count + 1];
    for &g in group {
        if (g as usize) < count {
            starts[g as usize + 1] += 1;
        }
    }
    for g in 0..count {
        starts[g + 1] += starts[g];
    }
    let mut fill = starts.clone();
    let mut members = vec![0u32; starts[count] as usize];
    for (t, &g) in group.iter().enumerate() {
        if (g as usize) < count {
            members[fill[g as usize] as usize] = t as u32;
            fill[g as usize] += 1;
        }
    }
    (0..count)
        .into_par_iter()
        .map(|g| {
            let list = &members[starts[g] as usize..starts[g + 1] as usize];
            list.iter()
                .find_map(|&t| probe(r, refined, t, other, side, faces).map(|p| (t, p)))
                .or_else(|| list.iter().find_map(|&t| implicit_probe(r, refined, t).map(|p| (t, p))))
                .unwrap_or_else(|| {
                    let largest = list
                        .iter()
                        .copied()
                        .max_by(|&s, &t| {
                            double_area(refined, &r.points, s).total_cmp(&double_area(refined, &r.points, t))
                        })
                        .unwrap_or(0);
                    (largest, Probe::Centroid(largest))
                })
        })
        .collect()
}

fn centroid(refined: &Refined, points: &[DVec3], t: u32) -> DVec3 {
    let [p, q, s] = refined.triangles[t as usize].map(|i| points[i as usize]);
    (p + q + s) / 3.0
}

fn double_area(refined: &Refined, points: &[DVec3], t: u32) -> f64 {
    let [p, q, s] = refined.triangles[t as usize].map(|i| points[i as usize]);
    (q - p).cross(s - p).length()
}

/// On-status of every refined triangle of one side: `Some(OnSame | OnOpposite)` when
/// its three corners lie in a coplanar triangle of the other mesh (exact orientations of
/// the implicit corners, and of the other triangle's corner points, in the axis-aligned
/// projection of the parent's support plane).
fn on_status<O: Solid, S: Solid>(
    r: &Refinement,
    refined: &Refined,
    own: &O,
    other: &S,
    coplanar: &[(u32, u32, bool)],
) -> Vec<Option<Class>> {
    if coplanar.is_empty() {
        return vec![None; refined.triangles.len()];
    }
    (0..refined.triangles.len() as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|t| {
            let parent = refined.parent[t as usize];
            let lo = coplanar.partition_point(|c| c.0 < parent);
            let mut partners = coplanar[lo..].iter().take_while(|c| c.0 == parent).peekable();
            partners.peek()?;
            let axes = plane_axes(own.support(parent))?;
            let corners = refined.triangles[t as usize].map(|id| r.point(id));
            for &(_, u, same) in partners {
                let tri = other.triangles()[u as usize].map(|v| other.point(v));
                let s = orient2d_implicit(axes, &tri[0], &tri[1], &tri[2]);
                let within = (0..3).all(|k| {
                    corners.iter().all(|x| s * orient2d_implicit(axes, &tri[k], &tri[(k + 1) % 3], x) >= 0)
                });
                if s != 0 && within {
                    return Some(if same { Class::OnSame } else { Class::OnOpposite });
                }
            }
            None
        })
        .collect()
}

/// Group id of every refined triangle (on-triangles get their own groups, which are
/// never tested) and the number of groups of off-surface triangles, which come first.
fn groups(refined: &Refined, on: &[Option<Class>], r: &Refinement) -> (Vec<u32>, usize) {
    let n = refined.triangles.len();
    let mut sets = UnionFind::new(n);
    {
        // The sides of every triangle bucketed by their lower point, each bucket ordered by
        // (higher point, corner): the triangles around an edge are adjacent, in increasing
        // order.
        let half_edges = HalfEdges::of_triangles(&refined.triangles, r.points.len());
        // The points on the cut curve: only an edge between two of them is looked up.
        let mut on_curve = vec![false; r.points.len()];
        for &e in &r.cut_edges {
            on_curve[(e >> 32) as usize] = true;
            on_curve[(e & 0xffff_ffff) as usize] = true;
        }
        let is_cut_edge = |lo: usize, hi: u32| {
            on_curve[lo]
                && on_curve[hi as usize]
                && r.cut_edges.binary_search(&edge_key(lo as u32, hi)).is_ok()
        };
        for (lo, hi, run) in half_edges.edges() {
            if run.len() > 1 && !is_cut_edge(lo, hi) {
                let triangle = |item: u64| corner(item) as u32 / 3;
                let s = triangle(run[0]);
                for &item in &run[1..] {
                    let t = triangle(item);
                    if on[s as usize] == on[t as usize] {
                        sets.union(s, t);
                    }
                }
            }
        }
    }
    // Number the off-surface groups 0..count, then the rest.
    let mut id = vec![u32::MAX; n];
    let mut group = vec![0u32; n];
    let mut count = 0u32;
    for t in 0..n {
        if on[t].is_some() {
            continue;
        }
        let root = sets.find(t as u32) as usize;
        if id[root] == u32::MAX {
            id[root] = count;
            count += 1;
        }
        group[t] = id[root];
    }
    let mut extra = count;
    for t in 0..n {
        if on[t].is_some() {
            group[t] = extra;
            extra += 1;
        }
    }
    (group, count as usize)
}

/// Decides the groups `pending` (with the point their probe tested) by exact ray parity
/// against `other`: that point first, then the group's triangles' centroids from the
/// largest down until one is off the surface.
fn decide_exactly<S: Solid>(
    refined: &Refined,
    points: &[DVec3],
    group: &[u32],
    pending: &[(usize, Option<DVec3>)],
    other: &S,
    side: Side,
) -> Result<Vec<Class>, ClassifyError> {
    pending
        .par_iter()
        .map(|&(g, first)| {
            if let Some(inside) = first.and_then(|p| exact_parity(p, other)) {
                return Ok(if inside { Class::In } else { Class::Out });
            }
            let mut members: Vec<u32> =
                (0..group.len() as u32).filter(|&t| group[t as usize] as usize == g).collect();
            members.sort_by(|&s, &t| {
                double_area(refined, points, t).total_cmp(&double_area(refined, points, s))
            });
            for &t in members.iter().take(8) {
                if let Some(inside) = exact_parity(centroid(refined, points, t), other) {
                    return Ok(if inside { Class::In } else { Class::Out });
                }
            }
            let near = members.first().map_or(DVec3::ZERO, |&t| centroid(refined, points, t));
            Err(ClassifyError::Undecided { side, count: members.len(), near })
        })
        .collect()
}

/// At most this many points against one operand are answered by [`ray_crossings`], with no
/// structure built; more go to the inclusion method as asked. Counted on a 52 000-triangle
/// operand: building the default method's octants costs about 1 200 instructions per
/// triangle and each of its point tests about 10 per triangle, while the rays cost about
/// 50 per triangle for the whole batch plus about 10 for each point in a triangle's
/// y-range (a few for points spread over the model, all of them only when the points share
/// one y), so for this many points the rays cost less whatever their places.
pub const FEW_POINTS: usize = 1024;

/// Exact inside tests of a few f64 points against the closed surface `other`, with no
/// structure: the winding number of the surface around each point, counted along the ray
/// from it towards +x (each crossing adds the sign of the crossed triangle's normal along
/// x), every crossing decided by exact orientations. A triangle is looked at only for the
/// points in its y-range (points sorted by y), in its z-range and not beyond its x-range.
/// `Inside` for a non-zero winding number, as the inclusion methods decide; `OnBoundary`
/// for a point on the surface, or whose ray meets an edge or a vertex, or runs in a
/// triangle's plane (the caller decides those by [`exact_parity`]'s rays, as it does the
/// points an inclusion method finds on the boundary).
///
/// On an operand with implicit points the same tests are exact predicates: the edges'
/// in the yz projection on the corner points, the side of the point and the normal's sign
/// along x on the triangle's support (explicit), the ranges from certain boxes.
pub fn ray_crossings<S: Solid>(points: &[DVec3], other: &S) -> Vec<inclusion::Class> {
    use crate::exact::orient2d;
    let yz = |v: DVec3| glam::DVec2::new(v.y, v.z);
    let triangles = other.triangles();
    let sorted = sorted_by_y(points);
    if S::EXPLICIT {
        let positions = other.rounded();
        return windings(&sorted, triangles.len(), 4096, |t| {
            let [a, b, c] = triangles[t].map(|i| positions[i as usize]);
            let (pa, pb, pc) = (yz(a), yz(b), yz(c));
            // The triangle's normal along x (the orientation of its projection), taken
            // once, for the first point in its projection.
            let mut normal_x = None;
            let crossing = move |_: usize, p: DVec3| {
                let pp = yz(p);
                let e = [orient2d(pa, pb, pp), orient2d(pb, pc, pp), orient2d(pc, pa, pp)];
                if e.contains(&1) && e.contains(&-1) {
                    return Crossing::Apart;
                }
                let s = *normal_x.get_or_insert_with(|| orient2d(pa, pb, pc));
                if s == 0 || e.contains(&0) {
                    return Crossing::Grazing;
                }
                side_crossing(s, orient3d(a, b, c, p))
            };
            ((a.min(b).min(c), a.max(b).max(c)), crossing)
        });
    }
    // Implicit corners: the edge tests on them, the plane tests on the support (explicit,
    // in the triangle's plane and oriented like it: the same sign along x), the ranges
    // from certain boxes.
    const YZ: [usize; 2] = [1, 2];
    let exact: Vec<Point> = sorted.1.iter().map(|&p| Point::explicit(p)).collect();
    let boxes = other.boxes();
    windings(&sorted, triangles.len(), 1024, |t| {
        let mut corners = None;
        let mut normal_x = None;
        let exact = &exact;
        let crossing = move |k: usize, p: DVec3| {
            let [a, b, c] = corners.get_or_insert_with(|| triangles[t].map(|v| other.point(v)));
            let pp = &exact[k];
            let e = [
                orient2d_implicit(YZ, a, b, pp),
                orient2d_implicit(YZ, b, c, pp),
                orient2d_implicit(YZ, c, a, pp),
            ];
            if e.contains(&1) && e.contains(&-1) {
                return Crossing::Apart;
            }
            let [sa, sb, sc] = other.support(t as u32);
            let s = *normal_x.get_or_insert_with(|| orient2d(yz(sa), yz(sb), yz(sc)));
            if s == 0 || e.contains(&0) {
                return Crossing::Grazing;
            }
            side_crossing(s, orient3d(sa, sb, sc, p))
        };
        (boxes[t], crossing)
    })
}

/// What the ray from a point towards +x does at one triangle.
enum Crossing {
    /// Misses it.
    Apart,
    /// Meets an edge, a vertex or its plane (or starts on it): not decided by rays.
    Grazing,
    /// Crosses its interior, adding this to the winding number.
    Through(i32),
}

/// The crossing of a ray towards +x with a triangle whose projection holds its start
/// strictly inside: `normal_x` is the sign of the triangle's normal along x, `side` the
/// start's side of its plane; the ray meets the plane at t > 0 exactly when the start
/// lies on the side the normal turns away from +x.
fn side_crossing(normal_x: crate::exact::Sign, side: crate::exact::Sign) -> Crossing {
    match side {
        0 => Crossing::Grazing,
        o if o == -normal_x => Crossing::Through(i32::from(normal_x)),
        _ => Crossing::Apart,
    }
}

/// The classes of [`ray_crossings`] for the points as [`sorted_by_y`] gives them (their
/// order, and the points in it): `triangle(t)` gives triangle t's box (certain to hold it)
/// and its crossing test, called with (index among the sorted points, point) for the
/// points in its y-range, in its z-range and not beyond its x-range, whose rays have not
/// grazed yet.
fn windings<T, C>(
    (order, sorted): &(Vec<u32>, Vec<DVec3>),
    count: usize,
    min_len: usize,
    triangle: T,
) -> Vec<inclusion::Class>
where
    T: Fn(usize) -> ((DVec3, DVec3), C) + Sync,
    C: FnMut(usize, DVec3) -> Crossing,
{
    // Per sorted point: the winding number so far and whether the ray was degenerate.
    let state = (0..count)
        .into_par_iter()
        .with_min_len(min_len)
        .fold(
            || vec![(0i32, false); sorted.len()],
            |mut acc, t| {
                let ((lo, hi), mut crossing) = triangle(t);
                let first = sorted.partition_point(|p| p.y < lo.y);
                for (k, p) in sorted.iter().enumerate().skip(first) {
                    if p.y > hi.y {
                        break;
                    }
                    if p.z < lo.z || p.z > hi.z || p.x > hi.x || acc[k].1 {
                        continue;
                    }
                    match crossing(k, *p) {
                        Crossing::Apart => {}
                        Crossing::Grazing => acc[k].1 = true,
                        Crossing::Through(w) => acc[k].0 += w,
                    }
                }
                acc
            },
        )
        .reduce(|| vec![(0i32, false); sorted.len()], merge_windings);
    classes_of(order, &state)
}

/// The points' order by y, and the points in it.
fn sorted_by_y(points: &[DVec3]) -> (Vec<u32>, Vec<DVec3>) {
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by(|&i, &j| points[i as usize].y.total_cmp(&points[j as usize].y));
    let sorted = order.iter().map(|&i| points[i as usize]).collect();
    (order, sorted)
}

/// Two partial counts of [`ray_crossings`] (winding number, degenerate ray) added.
fn merge_windings(mut x: Vec<(i32, bool)>, y: Vec<(i32, bool)>) -> Vec<(i32, bool)> {
    for (u, v) in x.iter_mut().zip(y) {
        u.0 += v.0;
        u.1 |= v.1;
    }
    x
}

/// The classes of [`ray_crossings`] in the points' order, from the counts in y order.
fn classes_of(order: &[u32], state: &[(i32, bool)]) -> Vec<inclusion::Class> {
    let mut classes = vec![inclusion::Class::Outside; order.len()];
    for (&i, &(winding, degenerate)) in order.iter().zip(state) {
        classes[i as usize] = match (degenerate, winding) {
            (true, _) => inclusion::Class::OnBoundary,
            (false, 0) => inclusion::Class::Outside,
            (false, _) => inclusion::Class::Inside,
        };
    }
    classes
}

/// Directions of [`exact_parity`]'s segments, tried in turn.
const DIRECTIONS: [DVec3; 8] = [
    DVec3::new(0.577_215_664_9, 0.271_828_182_8, 0.314_159_265_3),
    DVec3::new(-0.414_213_562_3, 0.732_050_807_5, 0.236_067_977_4),
    DVec3::new(0.161_803_398_8, -0.683_147_180_5, 0.577_215_664_9),
    DVec3::new(-0.311_029_995_6, -0.477_121_254_7, -0.698_970_004_3),
    DVec3::new(0.845_098_040_0, 0.041_392_685_1, -0.903_089_987_0),
    DVec3::new(0.113_943_352_3, 0.954_242_509_4, -0.079_181_246_0),
    DVec3::new(-0.929_418_925_7, 0.146_128_035_7, 0.602_059_991_3),
    DVec3::new(0.778_151_250_4, -0.176_091_259_1, -0.361_727_836_0),
];

/// Exact inside test of the f64 point p against the closed surface `other`: parity of
/// the crossings of a segment from p to far outside, every crossing decided by exact
/// orientations; a segment that touches an edge, a vertex or a plane is cast again in
/// another direction. `None` when p lies on the surface or every direction grazes. On an
/// operand with implicit points: [`exact_parity_point`].
pub fn exact_parity<S: Solid>(p: DVec3, other: &S) -> Option<bool> {
    if !S::EXPLICIT {
        return exact_parity_point(&Point::explicit(p), other);
    }
    let (triangles, positions) = (other.triangles(), other.rounded());
    let (lo, hi) =
        positions.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    if p.cmplt(lo).any() || p.cmpgt(hi).any() {
        return Some(false);
    }
    let reach = 2.0 * ((hi - lo).length() + 1.0);
    'direction: for d in DIRECTIONS {
        let q = p + d.normalize() * reach;
        let mut crossings = 0u32;
        for tri in triangles {
            let [a, b, c] = tri.map(|i| positions[i as usize]);
            let sp = orient3d(a, b, c, p);
            let sq = orient3d(a, b, c, q);
            if sp * sq > 0 {
                continue;
            }
            if sp == 0 && sq == 0 {
                // The whole segment lies in the triangle's plane.
                if segment_meets_triangle(p, p, [a, b, c]) {
                    return None;
                }
                if segment_meets_triangle(p, q, [a, b, c]) {
                    continue 'direction;
                }
                continue;
            }
            let e = [orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a)];
            let mixed = e.contains(&1) && e.contains(&-1);
            if mixed {
                continue;
            }
            if sp == 0 {
                // p itself lies on the closed triangle.
                return None;
            }
            if sq == 0 || e.contains(&0) {
                // Through an edge or a vertex: cast again.
                continue 'direction;
            }
            crossings += 1;
        }
        return Some(crossings % 2 == 1);
    }
    None
}

/// [`exact_parity`] of a point of any kind (an implicit vertex of an operand, or an f64
/// point) against an operand of any kind: the segment from p towards an explicit far
/// point q, the sides of p and q against each triangle's support plane, the tests on its
/// edges exact orientations of p, q and its corner points. A segment that runs in a
/// triangle's plane is cast again unless p lies in the triangle (then `None`).
pub fn exact_parity_point<S: Solid>(p: &Point, other: &S) -> Option<bool> {
    let (triangles, rounded) = (other.triangles(), other.rounded());
    // Rounded positions are within half an ulp (≤ 2⁻⁵³·|x|) of the exact points: a box
    // wider by 2⁻⁵¹·|x| (and the smallest normal) holds them all, its own rounding included.
    let (lo, hi) =
        rounded.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    let widen = |x: DVec3| x.abs() * (2.0 * f64::EPSILON) + f64::MIN_POSITIVE;
    let (lo, hi) = (lo - widen(lo), hi + widen(hi));
    let (p_lo, p_hi) = p.bounds();
    if p_hi.cmplt(lo).any() || p_lo.cmpgt(hi).any() {
        return Some(false);
    }
    let at = p.position();
    let explicit = matches!(p.definition(), implicit::Definition::Explicit(_));
    let reach = 2.0 * ((hi - lo).length() + 1.0);
    'direction: for d in DIRECTIONS {
        let q = at + d.normalize() * reach;
        let eq = Point::explicit(q);
        let mut crossings = 0u32;
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = other.support(t as u32);
            let sq = orient3d(a, b, c, q);
            let sp = if explicit {
                orient3d(a, b, c, at)
            } else {
                let [ea, eb, ec] = [a, b, c].map(Point::explicit);
                orient3d_implicit(&ea, &eb, &ec, p)
            };
            if sp * sq > 0 {
                continue;
            }
            let corners = tri.map(|v| other.point(v));
            let [ca, cb, cc] = [&*corners[0], &*corners[1], &*corners[2]];
            if sp == 0 && sq == 0 {
                // The whole segment lies in the triangle's plane: p on the triangle, else
                // another direction (it may touch the triangle).
                let axes = plane_axes([a, b, c])?;
                let s = orient2d_implicit(axes, ca, cb, cc);
                let within = [(ca, cb), (cb, cc), (cc, ca)]
                    .iter()
                    .all(|(x, y)| s * orient2d_implicit(axes, x, y, p) >= 0);
                if s != 0 && within {
                    return None;
                }
                continue 'direction;
            }
            let e = [
                orient3d_implicit(p, &eq, ca, cb),
                orient3d_implicit(p, &eq, cb, cc),
                orient3d_implicit(p, &eq, cc, ca),
            ];
            if e.contains(&1) && e.contains(&-1) {
                continue;
            }
            if sp == 0 {
                return None;
            }
            if sq == 0 || e.contains(&0) {
                continue 'direction;
            }
            crossings += 1;
        }
        return Some(crossings % 2 == 1);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boolean::operand::ExactSolid;
    use crate::boolean::{TestCounts, point_test, refine, rounded_mesh, rounded_method_is_exact};
    use crate::inclusion::{Method, Solver};
    use crate::mesh::intersect::TriangleSoup;
    use crate::mesh::procedural;

    #[test]
    fn exact_parity_of_a_cube() {
        let soup = TriangleSoup::new(&procedural::cube());
        assert_eq!(exact_parity(DVec3::new(0.1, 0.2, 0.3), &soup), Some(true));
        assert_eq!(exact_parity(DVec3::new(1.5, 0.2, 0.3), &soup), Some(false));
        // Exactly on a face, and on an edge.
        assert_eq!(exact_parity(DVec3::new(1.0, 0.2, 0.3), &soup), None);
        assert_eq!(exact_parity(DVec3::new(1.0, 1.0, 0.3), &soup), None);
        // A hair inside, below any tolerance.
        assert_eq!(exact_parity(DVec3::new(1.0 - 1e-15, 0.0, 0.0), &soup), Some(true));
        // The centre: rays through nothing special.
        assert_eq!(exact_parity(DVec3::ZERO, &soup), Some(true));
    }

    #[test]
    fn ray_crossings_agree_with_exact_parity() {
        // Grid points, some of whose rays run through the diagonals of the cubes' faces; a
        // torus, whose rays cross the surface up to four times; a cube with a cavity.
        for mesh in [procedural::cube(), procedural::torus(1.0, 0.4, 24, 12), procedural::cube_with_cavity()]
        {
            let soup = TriangleSoup::new(&mesh);
            let points: Vec<DVec3> = (0..9 * 9 * 9)
                .map(|k| DVec3::new((k % 9) as f64, (k / 9 % 9) as f64, (k / 81) as f64) * 0.375 - 1.5)
                .collect();
            let classes = ray_crossings(&points, &soup);
            let mut decided = 0;
            for (p, c) in points.iter().zip(&classes) {
                let parity = exact_parity(*p, &soup);
                match c {
                    inclusion::Class::Inside => assert_eq!(parity, Some(true), "{p}"),
                    inclusion::Class::Outside => assert_eq!(parity, Some(false), "{p}"),
                    inclusion::Class::OnBoundary => continue,
                }
                decided += 1;
            }
            assert!(decided > points.len() / 2, "{decided}");
            // Points on the surface are never decided.
            for &p in mesh.positions() {
                assert_eq!(ray_crossings(&[p], &soup), vec![inclusion::Class::OnBoundary]);
            }
        }
        assert_eq!(
            ray_crossings(&[DVec3::new(1.0, 0.2, 0.3)], &TriangleSoup::new(&procedural::cube())),
            vec![inclusion::Class::OnBoundary]
        );
        assert!(ray_crossings(&[], &TriangleSoup::new(&procedural::cube())).is_empty());
    }

    /// 9³ grid points over [-1.5, 1.5]³.
    fn grid() -> Vec<DVec3> {
        (0..9 * 9 * 9)
            .map(|k| DVec3::new((k % 9) as f64, (k / 9 % 9) as f64, (k / 81) as f64) * 0.375 - 1.5)
            .collect()
    }

    #[test]
    fn an_exact_solid_of_a_file_operand_gets_the_same_answers() {
        for mesh in [procedural::cube(), procedural::torus(1.0, 0.4, 24, 12), procedural::cube_with_cavity()]
        {
            let soup = TriangleSoup::new(&mesh);
            let exact = ExactSolid::from_soup(&soup);
            let points = grid();
            assert_eq!(ray_crossings(&points, &exact), ray_crossings(&points, &soup));
            for &p in points.iter().chain(mesh.positions()) {
                let want = exact_parity(p, &soup);
                assert_eq!(exact_parity(p, &exact), want, "{p}");
                assert_eq!(exact_parity_point(&Point::explicit(p), &soup), want, "{p}");
            }
        }
    }

    /// Cube A against a turned copy and against a box sharing four of its face planes
    /// (coplanar pieces, on-tests), classified over the file operands and over their
    /// exact solids.
    #[test]
    fn classify_gives_the_same_classes_on_exact_solids_of_file_operands() {
        let turned = procedural::cube()
            .map_positions(|p| {
                glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.3) * p + 0.1
            })
            .unwrap();
        let shifted = procedural::box_between(DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0));
        let sa = TriangleSoup::new(&procedural::cube());
        for (mesh, coplanar) in [(turned, false), (shifted, true)] {
            let sb = TriangleSoup::new(&mesh);
            let r = refine::refine(&sa, &sb).unwrap();
            assert_eq!(!r.coplanar.is_empty(), coplanar);
            let (ea, eb) = (ExactSolid::from_soup(&sa), ExactSolid::from_soup(&sb));
            let mut rays = |side: Side, p: &[DVec3]| -> inclusion::Result<Vec<inclusion::Class>> {
                Ok(if side == Side::A { ray_crossings(p, &sa) } else { ray_crossings(p, &sb) })
            };
            let want = classify(&r, &sa, &sb, Grouping::Grouped, &mut rays).unwrap();
            let mut exact_rays = |side: Side, p: &[DVec3]| -> inclusion::Result<Vec<inclusion::Class>> {
                Ok(if side == Side::A { ray_crossings(p, &ea) } else { ray_crossings(p, &eb) })
            };
            for grouping in [Grouping::Grouped, Grouping::Plain] {
                let got = classify(&r, &ea, &eb, grouping, &mut exact_rays).unwrap();
                assert_eq!((&got.a, &got.b), (&want.a, &want.b), "{grouping:?}");
            }
            assert!(want.a.iter().chain(&want.b).any(|&c| c == Class::In));
        }
    }

    /// The hexahedron x ≥ 0, y ≥ 0, z ≥ 0, 3x + z ≤ 1, x + 3y ≤ 1, y + 3z ≤ 1 as an operand
    /// with implicit points: each corner (1/3, 2/9: not representable) where a segment
    /// between explicit points of two of its planes crosses the third, each face's two
    /// triangles supported by three explicit points of its plane. Also its six planes
    /// oriented outward: inside iff strictly behind all six (convex), the oracle.
    fn hexahedron() -> (ExactSolid, [[DVec3; 3]; 6]) {
        let v = DVec3::new;
        // Per (axis, high) = 2·axis + high: three explicit points and the outward normal.
        let mut planes = [
            [v(0.0, 0.0, 0.0), v(0.0, 1.0, 0.0), v(0.0, 0.0, 1.0)],
            [v(0.0, 0.0, 1.0), v(0.0, 1.0, 1.0), v(0.5, 0.0, -0.5)],
            [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 0.0, 1.0)],
            [v(1.0, 0.0, 0.0), v(1.0, 0.0, 1.0), v(-0.5, 0.5, 0.0)],
            [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)],
            [v(0.0, 1.0, 0.0), v(1.0, 1.0, 0.0), v(0.0, -0.5, 0.5)],
        ];
        let outward = [
            v(-1.0, 0.0, 0.0),
            v(3.0, 0.0, 1.0),
            v(0.0, -1.0, 0.0),
            v(1.0, 3.0, 0.0),
            v(0.0, 0.0, -1.0),
            v(0.0, 1.0, 3.0),
        ];
        for (plane, n) in planes.iter_mut().zip(outward) {
            let [a, b, c] = *plane;
            if (b - a).cross(c - a).dot(n) < 0.0 {
                *plane = [a, c, b];
            }
        }
        // Corner bits: x high, y high, z high.
        let corner = |p: DVec3, q: DVec3, plane: usize| Point::edge_plane(p, q, planes[plane]).unwrap();
        let points = vec![
            Point::explicit(DVec3::ZERO),
            corner(v(-1.0, 0.0, 0.0), v(1.0, 0.0, 0.0), 1),
            corner(v(0.0, -1.0, 0.0), v(0.0, 2.0, 0.0), 3),
            corner(v(1.0, 0.0, 0.0), v(-2.0, 1.0, 0.0), 1),
            corner(v(0.0, 0.0, -1.0), v(0.0, 0.0, 2.0), 5),
            corner(v(0.0, 0.0, 1.0), v(1.0, 0.0, -2.0), 5),
            corner(v(0.0, 1.0, 0.0), v(0.0, -2.0, 1.0), 3),
            corner(v(1.0, 0.0, -2.0), v(-2.0, 1.0, 7.0), 5),
        ];
        let rounded: Vec<DVec3> = points.iter().map(Point::position).collect();
        assert_eq!(rounded[3], v(1.0 / 3.0, 2.0 / 9.0, 0.0));
        assert_eq!(rounded[7], DVec3::splat(0.25));
        let (mut triangles, mut support) = (Vec::new(), Vec::new());
        for face in 0..6 {
            let (axis, high) = (face / 2, face % 2);
            let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
            let c =
                [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(bu, bw)| (high << axis | bu << u | bw << w) as u32);
            for mut t in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
                let [a, b, d] = t.map(|i| rounded[i as usize]);
                if (b - a).cross(d - a).dot(outward[face]) < 0.0 {
                    t.swap(1, 2);
                }
                triangles.push(t);
                support.push(planes[face]);
            }
        }
        (ExactSolid { points, rounded, triangles, support }, planes)
    }

    /// Inside iff strictly behind every plane; `None` on the boundary.
    fn behind_all(planes: &[[DVec3; 3]; 6], p: DVec3) -> Option<bool> {
        let sides = planes.map(|[a, b, c]| orient3d(a, b, c, p));
        match sides.iter().max() {
            Some(&s) if s > 0 => Some(false),
            Some(&s) if s < 0 => Some(true),
            _ => None,
        }
    }

    /// Probes within 3 ulps of the hexahedron's three slanted faces (along y = z = s and
    /// its turns), and within 2 ulps of each rounded corner.
    fn near_probes(solid: &ExactSolid) -> Vec<DVec3> {
        let up = |x: f64| match x {
            0.0 => f64::from_bits(1),
            x if x > 0.0 => f64::from_bits(x.to_bits() + 1),
            x => f64::from_bits(x.to_bits() - 1),
        };
        let step = |x: f64, k: i64| {
            let mut x = x;
            for _ in 0..k.abs() {
                x = if k > 0 { up(x) } else { -up(-x) };
            }
            x
        };
        let mut probes = Vec::new();
        for k in 1..=64 {
            let s = k as f64 / 4096.0;
            let f = (1.0 - s) / 3.0;
            for d in -3..=3 {
                let x = step(f, d);
                probes.extend([DVec3::new(x, s, s), DVec3::new(s, x, s), DVec3::new(s, s, x)]);
            }
        }
        for &r in &solid.rounded {
            for k in 0..27 {
                let d = [k % 3, k / 3 % 3, k / 9].map(|x| 2 * (x as i64 - 1));
                probes.push(DVec3::new(step(r.x, d[0]), step(r.y, d[1]), step(r.z, d[2])));
            }
        }
        probes
    }

    #[test]
    fn an_implicit_operand_classifies_points_ulps_from_it_exactly() {
        let (solid, planes) = hexahedron();
        let probes = near_probes(&solid);
        let rounded = TriangleSoup::new(&rounded_mesh(&solid).unwrap());
        let rays = ray_crossings(&probes, &solid);
        let (mut wrong, mut decided) = (0, 0);
        for (&p, ray) in probes.iter().zip(&rays) {
            let want = behind_all(&planes, p);
            assert_eq!(exact_parity(p, &solid), want, "{p}");
            assert_eq!(exact_parity_point(&Point::explicit(p), &solid), want, "{p}");
            match ray {
                inclusion::Class::Inside => assert_eq!(want, Some(true), "{p}"),
                inclusion::Class::Outside => assert_eq!(want, Some(false), "{p}"),
                inclusion::Class::OnBoundary => continue,
            }
            decided += 1;
            // The rounded mesh's own exact answer differs here and there.
            if want.is_some() && exact_parity(p, &rounded) != want {
                wrong += 1;
            }
        }
        assert!(wrong > 0 && decided > probes.len() / 2, "{wrong} {decided}");
        // A corner point tested as itself: inside or on, never by its rounded position.
        for p in &solid.points {
            assert_eq!(exact_parity_point(p, &solid), None);
        }
        assert_eq!(exact_parity_point(&Point::explicit(DVec3::splat(3.0)), &solid), Some(false));
    }

    /// The default method built on the rounded mesh: its Inside and Outside answers are the
    /// exact ones on a grid, and probes ulps from the faces come back OnBoundary, for the
    /// exact parity.
    #[test]
    fn a_method_on_the_rounded_mesh_answers_only_off_its_band() {
        let (solid, planes) = hexahedron();
        assert!(rounded_method_is_exact(&solid));
        let mesh = rounded_mesh(&solid).unwrap();
        let options = inclusion::Options { known_closed: true, ..inclusion::Options::default() };
        let mut solver = Some(Solver::new(Method::Octants, &mesh, &options, None, None).unwrap());
        let mut counts = TestCounts::default();
        let grid: Vec<DVec3> = (0..12 * 12 * 12)
            .map(|k| DVec3::new((k % 12) as f64, (k / 12 % 12) as f64, (k / 144) as f64) * 0.0375 - 0.03)
            .collect();
        let near = near_probes(&solid);
        let points: Vec<DVec3> = grid.iter().chain(&near).copied().collect();
        let unused = || -> inclusion::Result<Solver> { unreachable!("built") };
        let answers = point_test(&solid, &points, &mut solver, unused, &mut counts).unwrap();
        assert_eq!(counts.ray_tests, 0);
        let mut inside = 0;
        for (k, (&p, answer)) in points.iter().zip(&answers).enumerate() {
            let want = behind_all(&planes, p);
            let got = match answer {
                inclusion::Class::Inside => Some(true),
                inclusion::Class::Outside => Some(false),
                inclusion::Class::OnBoundary => {
                    // Decided as the classification decides it.
                    exact_parity(p, &solid)
                }
            };
            assert_eq!(got, want, "{p}");
            inside += (want == Some(true)) as usize;
            if k >= grid.len() && (k - grid.len()) < 64 * 21 {
                assert_eq!(*answer, inclusion::Class::OnBoundary, "{p}");
            }
        }
        assert!(inside > 100, "{inside}");
    }

    /// An operand whose rounding may move it by more than the methods' band (a tiny one
    /// far from the origin) is answered by exact rays, the method left unused.
    #[test]
    fn a_tiny_operand_far_from_the_origin_gets_exact_rays() {
        let size = 1e-9;
        let tiny = procedural::box_between(DVec3::ONE, DVec3::ONE + size);
        let solid = ExactSolid::from_soup(&TriangleSoup::new(&tiny));
        assert!(!rounded_method_is_exact(&solid));
        let options = inclusion::Options { known_closed: true, ..inclusion::Options::default() };
        let mut solver = Some(Solver::new(Method::Octants, &tiny, &options, None, None).unwrap());
        let mut counts = TestCounts::default();
        // Inside (off the faces' diagonals, which a ray along x through y = z would meet),
        // outside, at a corner.
        let points = [DVec3::ONE + DVec3::new(0.5, 0.3, 0.6) * size, DVec3::ONE + 2.0 * size, DVec3::ONE];
        let unused = || -> inclusion::Result<Solver> { unreachable!("built") };
        let answers = point_test(&solid, &points, &mut solver, unused, &mut counts).unwrap();
        assert_eq!(counts.ray_tests, 3);
        assert_eq!(
            answers,
            vec![inclusion::Class::Inside, inclusion::Class::Outside, inclusion::Class::OnBoundary]
        );
    }
}
