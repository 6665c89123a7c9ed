//! Triangle classification (§6.5): every refined triangle of A is in, out or on B, and
//! vice versa.
//!
//! - **On** (§6.2.2): a piece of a triangle that has coplanar partners in the other mesh
//!   is on the other surface when its centroid lies inside one of them — an exact 2D
//!   test in the common plane. The partner's orientation makes it *same* or *opposite*.
//! - **Groups** (§6.5.1): triangles connected across edges that are not on the cut
//!   curve lie on the same side of the other solid, so each group is classified by one
//!   interior point: the centroid of its largest triangle. [`Grouping::Plain`] tests
//!   every triangle's centroid instead (the thesis' "Nuevo" columns of Table 6-1); a
//!   sliver whose centroid lies within the method's tolerance of the other surface then
//!   takes the class its group's other answers give.
//! - **Point tests** go to the inclusion module through the caller (any method, the GPU
//!   ones included). A point the method finds *on the boundary* — within its tolerance
//!   of the other surface, although the piece is not on it (a thin sliver) — is decided
//!   by an exact ray-parity test on the f64 point ([`exact_parity`]).

use glam::DVec3;
use rayon::prelude::*;

use super::refine::{Refined, Refinement, Side, edge_key};
use crate::exact::{orient2d, orient3d};
use crate::inclusion;
use crate::mesh::disjoint_sets::UnionFind;
use crate::mesh::intersect::{TriangleSoup, segment_meets_triangle, triangle_projection};

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
}

impl ClassifyStats {
    /// Share of point tests saved against one test per triangle off the other surface
    /// (the thesis' "reducción", §6.6).
    pub fn saved_share(&self) -> f64 {
        let plain = self.triangles - self.on;
        if plain == 0 { 0.0 } else { 1.0 - self.point_tests as f64 / plain as f64 }
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
    let mut b_coplanar: Vec<(u32, u32, bool)> = r.coplanar.iter().map(|&(t, u, s)| (u, t, s)).collect();
    b_coplanar.sort_unstable_by_key(|c| (c.0, c.1));
    let (mut on_a, mut on_b) = rayon::join(
        || on_status(&r.a, &r.points, a, b, &r.coplanar),
        || on_status(&r.b, &r.points, b, a, &b_coplanar),
    );
    if r.stats.merged_points > 0 {
        coincident(r, &mut on_a, &mut on_b);
    }
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
        // Grouped: one point per group. Plain: one per off-surface triangle.
        let tested: Vec<u32> = match grouping {
            Grouping::Grouped => representatives(refined, &r.points, group, count),
            Grouping::Plain => {
                (0..refined.triangles.len() as u32).filter(|&t| on[t as usize].is_none()).collect()
            }
        };
        let points: Vec<DVec3> = tested.iter().map(|&t| centroid(refined, &r.points, t)).collect();
        stats.point_tests += points.len();
        let other_side = if side == Side::A { Side::B } else { Side::A };
        let answers = test(other_side, &points)?;
        let decisive = |c: &inclusion::Class| match c {
            inclusion::Class::Inside => Some(Class::In),
            inclusion::Class::Outside => Some(Class::Out),
            inclusion::Class::OnBoundary => None,
        };
        // A group takes the class of its decisive answers (all equal: the group lies on
        // one side). Plain mode keeps each triangle's own answer where it is decisive.
        let mut group_class: Vec<Option<Class>> = vec![None; count];
        for (&t, c) in tested.iter().zip(&answers) {
            if let Some(c) = decisive(c) {
                group_class[group[t as usize] as usize].get_or_insert(c);
            }
        }
        let mut own: Vec<Option<Class>> = vec![None; refined.triangles.len()];
        if grouping == Grouping::Plain {
            for (&t, c) in tested.iter().zip(&answers) {
                own[t as usize] = decisive(c);
            }
        }
        // A point within the method's tolerance of the other surface (a thin piece):
        // groups with no decisive answer are decided exactly, trying other triangles.
        let pending: Vec<usize> = (0..count).filter(|&g| group_class[g].is_none()).collect();
        stats.exact_fallbacks += answers.iter().filter(|c| decisive(c).is_none()).count();
        if !pending.is_empty() {
            let decided = decide_exactly(refined, &r.points, group, &pending, other, side)?;
            for (g, c) in pending.into_iter().zip(decided) {
                group_class[g] = Some(c);
            }
        }
        let group_class: Vec<Class> = group_class.into_iter().map(|c| c.unwrap_or(Class::Out)).collect();
        let cls: Vec<Class> = (0..refined.triangles.len())
            .map(|t| on[t].or(own[t]).unwrap_or_else(|| group_class[group[t] as usize]))
            .collect();
        classes.push(cls);
    }
    let b_classes = classes.pop().unwrap_or_default();
    let a_classes = classes.pop().unwrap_or_default();
    Ok(Classification { a: a_classes, b: b_classes, stats })
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
/// its centroid lies strictly inside a coplanar triangle of the other mesh.
fn on_status(
    refined: &Refined,
    points: &[DVec3],
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
            let partners = coplanar[lo..].iter().take_while(|c| c.0 == parent);
            let [p0, p1, p2] = own.triangle(parent as usize);
            let proj = triangle_projection(p0, p1, p2)?;
            let x = proj.apply(centroid(refined, points, t));
            for &(_, u, same) in partners {
                let tri = other.triangle(u as usize).map(|p| proj.apply(p));
                let s = orient2d(tri[0], tri[1], tri[2]);
                if (0..3).all(|k| s * orient2d(tri[k], tri[(k + 1) % 3], x) > 0) {
                    return Some(if same { Class::OnSame } else { Class::OnOpposite });
                }
            }
            None
        })
        .collect()
}

/// Pieces of A and B over the same three points are on each other's surface. Without
/// merged points (`super::snap`) that happens only to coplanar pairs, which
/// [`on_status`] decides; a merge can collapse a sliver of space between two cut
/// triangles that are not coplanar, leaving one triangle in both meshes.
fn coincident(r: &Refinement, on_a: &mut [Option<Class>], on_b: &mut [Option<Class>]) {
    // (sorted corners, piece, corners rotated to start at the smallest).
    let pieces = |refined: &Refined| -> Vec<([u32; 3], u32, [u32; 3])> {
        let mut v: Vec<([u32; 3], u32, [u32; 3])> = (0..refined.triangles.len() as u32)
            .filter(|&t| refined.cut[refined.parent[t as usize] as usize])
            .map(|t| {
                let c = refined.triangles[t as usize];
                let k = (0..3).min_by_key(|&k| c[k]).unwrap_or(0);
                let mut sorted = c;
                sorted.sort_unstable();
                (sorted, t, [c[k], c[(k + 1) % 3], c[(k + 2) % 3]])
            })
            .collect();
        v.sort_unstable();
        v
    };
    let (pa, pb) = (pieces(&r.a), pieces(&r.b));
    let (mut i, mut j) = (0, 0);
    while i < pa.len() && j < pb.len() {
        match pa[i].0.cmp(&pb[j].0) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                let class = if pa[i].2 == pb[j].2 { Class::OnSame } else { Class::OnOpposite };
                on_a[pa[i].1 as usize].get_or_insert(class);
                on_b[pb[j].1 as usize].get_or_insert(class);
                i += 1;
                j += 1;
            }
        }
    }
}

/// Group id of every refined triangle (on-triangles get their own groups, which are
/// never tested) and the number of groups of off-surface triangles, which come first.
fn groups(refined: &Refined, on: &[Option<Class>], r: &Refinement) -> (Vec<u32>, usize) {
    let n = refined.triangles.len();
    let mut sets = UnionFind::new(n);
    {
        // Edges of every triangle, sorted so that the triangles around an edge are adjacent.
        let mut edges: Vec<(u64, u32)> = (0..n as u32)
            .into_par_iter()
            .with_min_len(4096)
            .flat_map_iter(|t| {
                let [p, q, s] = refined.triangles[t as usize];
                [(edge_key(p, q), t), (edge_key(q, s), t), (edge_key(s, p), t)]
            })
            .collect();
        edges.par_sort_unstable();
        let mut i = 0;
        while i < edges.len() {
            let mut j = i + 1;
            while j < edges.len() && edges[j].0 == edges[i].0 {
                j += 1;
            }
            if j - i > 1 && r.cut_edges.binary_search(&edges[i].0).is_err() {
                for k in i + 1..j {
                    let (s, t) = (edges[i].1, edges[k].1);
                    if on[s as usize] == on[t as usize] {
                        sets.union(s, t);
                    }
                }
            }
            i = j;
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

/// One triangle per off-surface group: its largest.
fn representatives(refined: &Refined, points: &[DVec3], group: &[u32], count: usize) -> Vec<u32> {
    let mut best = vec![(f64::NEG_INFINITY, 0u32); count];
    for (t, &g) in group.iter().enumerate() {
        if (g as usize) < count {
            let a = double_area(refined, points, t as u32);
            if a > best[g as usize].0 {
                best[g as usize] = (a, t as u32);
            }
        }
    }
    best.into_iter().map(|b| b.1).collect()
}

/// Decides the groups `pending` by exact ray parity against `other`, trying the
/// group's triangles from the largest down until one centroid is off the surface.
fn decide_exactly(
    refined: &Refined,
    points: &[DVec3],
    group: &[u32],
    pending: &[usize],
    other: &TriangleSoup,
    side: Side,
) -> Result<Vec<Class>, ClassifyError> {
    pending
        .par_iter()
        .map(|&g| {
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
}
