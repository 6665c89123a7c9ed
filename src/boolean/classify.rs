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

use std::sync::OnceLock;

use glam::DVec3;
use rayon::prelude::*;

use super::intersect::Simplex;
use super::refine::{Refined, Refinement, Side, edge_key, plane_axes};
use crate::exact::implicit::{self, Point, orient2d_implicit, orient3d_implicit};
use crate::exact::orient3d;
use crate::inclusion;
use crate::mesh::disjoint_sets::UnionFind;
use crate::mesh::intersect::{TriangleSoup, segment_meets_triangle};
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
/// input solid `solid` (A or B) with an inclusion method.
pub fn classify(
    r: &Refinement,
    a: &TriangleSoup,
    b: &TriangleSoup,
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
    let mut classes = Vec::new();
    for (side, refined, on, (group, count), other) in
        [(Side::A, &r.a, &on_a, (&groups_a, count_a), b), (Side::B, &r.b, &on_b, (&groups_b, count_b), a)]
    {
        let view = SideView { side, refined, on, group, count, other };
        classes.push(classify_side(r, &view, grouping, test, &mut stats)?);
    }
    stats.exact_signs = implicit::exact_signs() - exact_before;
    let b_classes = classes.pop().unwrap_or_default();
    let a_classes = classes.pop().unwrap_or_default();
    Ok(Classification { a: a_classes, b: b_classes, stats })
}

/// One refined mesh with what [`classify`] knows of it: its triangles on the other
/// surface (`on`), its groups (`group` per triangle, `count` of them), and the other
/// input mesh.
struct SideView<'a> {
    side: Side,
    refined: &'a Refined,
    on: &'a [Option<Class>],
    group: &'a [u32],
    count: usize,
    other: &'a TriangleSoup,
}

/// The class of every triangle of one side: the probes (one per group, or one per
/// off-surface triangle), their point tests against the other solid, and exact ray
/// parity for the probes the test leaves on the boundary.
fn classify_side(
    r: &Refinement,
    v: &SideView,
    grouping: Grouping,
    test: &mut PointTest,
    stats: &mut ClassifyStats,
) -> Result<Vec<Class>, ClassifyError> {
    let (side, refined, on, group, count, other) = (v.side, v.refined, v.on, v.group, v.count, v.other);
    let probes = probes(r, v, grouping);
    let mut tested: Vec<u32> = Vec::new();
    let mut points: Vec<DVec3> = Vec::new();
    let mut known: Vec<(u32, Class)> = Vec::new();
    for &(t, p) in &probes {
        match p {
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
    stats.point_tests += points.len();
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
fn probes(r: &Refinement, v: &SideView, grouping: Grouping) -> Vec<(u32, Probe)> {
    let (side, refined, other) = (v.side, v.refined, v.other);
    // The other mesh's triangles by their sorted vertex ids, built when first asked.
    let by_vertices: OnceLock<Vec<([u32; 3], u32)>> = OnceLock::new();
    let faces = |s: [u32; 3]| -> Option<u32> {
        let list = by_vertices.get_or_init(|| {
            let mut v: Vec<([u32; 3], u32)> = (0..other.triangles.len() as u32)
                .map(|u| {
                    let mut k = other.triangles[u as usize];
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
            .map(|t| (t, probe(r, refined, t, other, side, &faces).unwrap_or(Probe::Centroid(t))))
            .collect(),
    }
}

/// How a group (or a triangle) is classified.
#[derive(Clone, Copy, Debug)]
enum Probe {
    /// By a point test at this input vertex (point id), which lies off the other surface.
    Vertex(u32),
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
/// `faces(s)` finds the other mesh's triangle over the sorted vertex ids `s`.
fn probe(
    r: &Refinement,
    refined: &Refined,
    t: u32,
    other: &TriangleSoup,
    side: Side,
    faces: &dyn Fn([u32; 3]) -> Option<u32>,
) -> Option<Probe> {
    let tri = refined.triangles[t as usize];
    if let Some(&v) = tri.iter().find(|&&v| v < r.first_new && r.key_of(v).is_none()) {
        return Some(Probe::Vertex(v));
    }
    let simplex = |id: u32| r.key_of(id).map(|key| if side == Side::A { key.b } else { key.a });
    let sx = tri.map(simplex);
    let side_of = |u: u32, corners: &[usize]| -> Option<Probe> {
        let [p, q, s] = other.triangle(u as usize).map(Point::explicit);
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

/// One probe per off-surface group (the triangle it comes from, and the probe): the
/// first exact one among its triangles, else its largest triangle's centroid.
fn group_probes(
    r: &Refinement,
    refined: &Refined,
    group: &[u32],
    count: usize,
    other: &TriangleSoup,
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
/// the implicit corners in the plane's axis-aligned projection).
fn on_status(
    r: &Refinement,
    refined: &Refined,
    own: &TriangleSoup,
    other: &TriangleSoup,
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
            let axes = plane_axes(own.triangle(parent as usize))?;
            let corners = refined.triangles[t as usize].map(|id| r.point(id));
            for &(_, u, same) in partners {
                let tri = other.triangle(u as usize).map(Point::explicit);
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
fn decide_exactly(
    refined: &Refined,
    points: &[DVec3],
    group: &[u32],
    pending: &[(usize, Option<DVec3>)],
    other: &TriangleSoup,
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

/// Exact inside tests of a few f64 points against the closed surface `soup`, with no
/// structure: the winding number of the surface around each point, counted along the ray
/// from it towards +x (each crossing adds the sign of the crossed triangle's normal along
/// x), every crossing decided by exact orientations. A triangle is looked at only for the
/// points in its y-range (points sorted by y), in its z-range and not beyond its x-range.
/// `Inside` for a non-zero winding number, as the inclusion methods decide; `OnBoundary`
/// for a point on the surface, or whose ray meets an edge or a vertex, or runs in a
/// triangle's plane (the caller decides those by [`exact_parity`]'s rays, as it does the
/// points an inclusion method finds on the boundary).
pub fn ray_crossings(points: &[DVec3], soup: &TriangleSoup) -> Vec<inclusion::Class> {
    use crate::exact::orient2d;
    let mut order: Vec<u32> = (0..points.len() as u32).collect();
    order.sort_by(|&i, &j| points[i as usize].y.total_cmp(&points[j as usize].y));
    let sorted: Vec<DVec3> = order.iter().map(|&i| points[i as usize]).collect();
    // Per sorted point: the winding number so far and whether the ray was degenerate.
    let state = (0..soup.triangles.len())
        .into_par_iter()
        .with_min_len(4096)
        .fold(
            || vec![(0i32, false); sorted.len()],
            |mut acc, t| {
                let [a, b, c] = soup.triangle(t);
                let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
                let yz = |v: DVec3| glam::DVec2::new(v.y, v.z);
                let (pa, pb, pc) = (yz(a), yz(b), yz(c));
                // The triangle's normal along x (the orientation of its projection), taken
                // once, for the first point in its projection.
                let mut normal_x = None;
                let first = sorted.partition_point(|p| p.y < lo.y);
                for (k, p) in sorted.iter().enumerate().skip(first) {
                    if p.y > hi.y {
                        break;
                    }
                    if p.z < lo.z || p.z > hi.z || p.x > hi.x || acc[k].1 {
                        continue;
                    }
                    let pp = yz(*p);
                    let e = [orient2d(pa, pb, pp), orient2d(pb, pc, pp), orient2d(pc, pa, pp)];
                    if e.contains(&1) && e.contains(&-1) {
                        continue;
                    }
                    let s = *normal_x.get_or_insert_with(|| orient2d(pa, pb, pc));
                    if s == 0 || e.contains(&0) {
                        acc[k].1 = true;
                        continue;
                    }
                    // p strictly inside the projection: the ray meets the plane once, at
                    // t > 0 exactly when p lies on the side the normal turns away from +x.
                    match orient3d(a, b, c, *p) {
                        0 => acc[k].1 = true,
                        o if o == -s => acc[k].0 += i32::from(s),
                        _ => {}
                    }
                }
                acc
            },
        )
        .reduce(
            || vec![(0i32, false); sorted.len()],
            |mut x, y| {
                for (u, v) in x.iter_mut().zip(y) {
                    u.0 += v.0;
                    u.1 |= v.1;
                }
                x
            },
        );
    let mut classes = vec![inclusion::Class::Outside; points.len()];
    for (&i, &(winding, degenerate)) in order.iter().zip(&state) {
        classes[i as usize] = match (degenerate, winding) {
            (true, _) => inclusion::Class::OnBoundary,
            (false, 0) => inclusion::Class::Outside,
            (false, _) => inclusion::Class::Inside,
        };
    }
    classes
}

/// Exact inside test of the f64 point p against the closed surface `soup`: parity of
/// the crossings of a segment from p to far outside, every crossing decided by exact
/// orientations; a segment that touches an edge, a vertex or a plane is cast again in
/// another direction. `None` when p lies on the surface or every direction grazes.
pub fn exact_parity(p: DVec3, soup: &TriangleSoup) -> Option<bool> {
    let (lo, hi) = soup
        .positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &x| (lo.min(x), hi.max(x)));
    if p.cmplt(lo).any() || p.cmpgt(hi).any() {
        return Some(false);
    }
    let reach = 2.0 * ((hi - lo).length() + 1.0);
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
    'direction: for d in DIRECTIONS {
        let q = p + d.normalize() * reach;
        let mut crossings = 0u32;
        for t in 0..soup.triangles.len() {
            let [a, b, c] = soup.triangle(t);
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

#[cfg(test)]
mod tests {
    use super::*;
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
}
