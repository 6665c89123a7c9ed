//! Triangle–triangle intersection of one candidate pair (§6.4): which part of t ∈ A
//! meets u ∈ B, decided with exact predicates.
//!
//! The operands are [`Solid`]s: a file's mesh (every point an f64 input vertex: the
//! predicates are the f64 ones, [`crate::exact`], as fast as they are) or the exact result
//! of an earlier step ([`super::operand::ExactSolid`]), whose vertices may be implicit
//! points. Then every decision is a predicate on implicit points
//! ([`crate::exact::implicit`]): a triangle's plane is its *support* (the input triangle
//! it is a piece of: explicit), its corners are the operand's points, and points along a
//! segment are ordered by exact comparisons of one coordinate.
//!
//! A point where the two surfaces meet is named by the pair of smallest simplices that
//! hold it, one of A (vertex, edge or triangle) and one of B: a [`Key`]. Keys are exact
//! (every simplex is found by exact orientation signs) and canonical (the same point
//! gets the same key from every pair of triangles that finds it), so each intersection
//! point is created once and shared by both meshes and by every triangle around it:
//! the cut curve has no cracks. Coordinates are computed later, once per key, from the
//! key alone ([`Key::position`]).
//!
//! A pair that is not coplanar meets in a segment, a point or nothing: the part of t on
//! u's plane clipped by u, and vice versa; its ends are the ends of either part that lie
//! in the other triangle. A coplanar pair meets in a convex polygon; its boundary within
//! t is made of u's edges clipped to t (constraints for t) and within u of t's edges
//! clipped to u (constraints for u).

use std::borrow::Cow;
use std::cmp::Ordering;

use glam::{DVec2, DVec3};

use super::operand::Solid;
use super::refine::plane_axes;
use crate::exact::implicit::{Definition, Point, compare_implicit, orient2d_implicit, orient3d_implicit};
use crate::exact::{Sign, line_crossing, orient2d, orient3d};
use crate::mesh::intersect::triangle_projection;

/// The smallest simplex of one mesh that holds a point (vertex ids are position-welded
/// ids of that mesh; an edge's ends are in increasing order).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Simplex {
    Vertex(u32),
    Edge(u32, u32),
    Face(u32),
}

impl Simplex {
    fn edge(a: u32, b: u32) -> Simplex {
        Simplex::Edge(a.min(b), a.max(b))
    }

    /// True when this simplex is the edge (a, b) or one of its ends.
    pub fn within_edge(self, a: u32, b: u32) -> bool {
        match self {
            Simplex::Vertex(v) => v == a || v == b,
            Simplex::Edge(p, q) => (p, q) == (a.min(b), a.max(b)),
            Simplex::Face(_) => false,
        }
    }
}

/// An intersection point: the simplex of A and the simplex of B holding it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Key {
    pub a: Simplex,
    pub b: Simplex,
}

/// The two operands, triangles over welded vertex ids ([`Solid`]).
pub struct Operands<'a, A: Solid, B: Solid> {
    pub a: &'a A,
    pub b: &'a B,
    // Their triangles and positions (rounded where implicit), at hand for the f64 path.
    a_positions: &'a [DVec3],
    a_triangles: &'a [[u32; 3]],
    b_positions: &'a [DVec3],
    b_triangles: &'a [[u32; 3]],
}

impl<'a, A: Solid, B: Solid> Operands<'a, A, B> {
    /// Both operands explicit: every decision is an f64 predicate on the positions.
    const EXPLICIT: bool = A::EXPLICIT && B::EXPLICIT;

    pub fn new(a: &'a A, b: &'a B) -> Operands<'a, A, B> {
        Operands {
            a,
            b,
            a_positions: a.rounded(),
            a_triangles: a.triangles(),
            b_positions: b.rounded(),
            b_triangles: b.triangles(),
        }
    }

    fn a_tri(&self, t: u32) -> [DVec3; 3] {
        self.a_triangles[t as usize].map(|i| self.a_positions[i as usize])
    }

    fn b_tri(&self, u: u32) -> [DVec3; 3] {
        self.b_triangles[u as usize].map(|i| self.b_positions[i as usize])
    }
}

/// The input vertex a point is, if it is one.
fn explicit(p: &Point) -> Option<DVec3> {
    match *p.definition() {
        Definition::Explicit(x) => Some(x),
        _ => None,
    }
}

/// Where the edge (p, q) of `own` crosses the support plane of triangle u of `other`: an
/// input edge crossing an input plane when p and q are explicit, else the segment between
/// the two points crossing it.
fn edge_face<S: Solid, T: Solid>(own: &S, (p, q): (u32, u32), other: &T, u: u32) -> Option<Point> {
    let plane = other.support(u);
    if S::EXPLICIT {
        let pos = own.rounded();
        return Point::edge_plane(pos[p as usize], pos[q as usize], plane).ok();
    }
    let (p, q) = (own.point(p), own.point(q));
    match (explicit(&p), explicit(&q)) {
        (Some(x), Some(y)) => Point::edge_plane(x, y, plane).ok(),
        _ => {
            let [a, b, c] = plane.map(Point::explicit);
            Point::segment_plane(&p, &q, [&a, &b, &c]).ok()
        }
    }
}

/// Where the coplanar input edges pq and rs cross. Any point off the two edges' plane
/// names the crossing; one a unit step from p along an axis, the normal's largest
/// component first.
fn explicit_edge_edge(p: DVec3, q: DVec3, r: DVec3, s: DVec3) -> Option<Point> {
    let n = (q - p).cross(s - r).abs();
    let mut axes = [0, 1, 2];
    axes.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    axes.into_iter().find_map(|k| {
        let mut off = p;
        off[k] += if p[k] > 0.0 { -1.0 } else { 1.0 };
        Point::edge_edge(p, q, r, s, off).ok()
    })
}

/// Where the coplanar segments pq and rs (points of any kind; `near`: p rounded) cross:
/// pq against the plane through r, s and a point off their plane. Of `near` and its unit
/// steps along the three axes (four points not in one plane) one is off it.
fn segment_segment(p: &Point, q: &Point, r: &Point, s: &Point, near: DVec3) -> Option<Point> {
    let steps = [0, 1, 2].map(|k| {
        let mut off = near;
        off[k] += if near[k] > 0.0 { -1.0 } else { 1.0 };
        off
    });
    steps
        .into_iter()
        .chain([near])
        .find_map(|off| Point::segment_segment(p, q, r, s, &Point::explicit(off)).ok())
}

impl Key {
    /// The point itself, from the key alone, as an implicit point
    /// ([`crate::exact::implicit`]): an operand's vertex as it is, an edge crossing a
    /// triangle's support plane, or two coplanar edges crossing each other (input edges
    /// and planes where the edge's ends are input vertices, else segments between the
    /// operand's points). Every predicate on it is exact; `None` only for keys no pair
    /// produces (two faces), or inputs that are not what the exact tests said.
    pub fn point<A: Solid, B: Solid>(&self, ops: &Operands<A, B>) -> Option<Point> {
        match (self.a, self.b) {
            (Simplex::Vertex(v), _) => Some(ops.a.point(v).into_owned()),
            (_, Simplex::Vertex(v)) => Some(ops.b.point(v).into_owned()),
            (Simplex::Edge(p, q), Simplex::Face(u)) => edge_face(ops.a, (p, q), ops.b, u),
            (Simplex::Face(t), Simplex::Edge(p, q)) => edge_face(ops.b, (p, q), ops.a, t),
            (Simplex::Edge(p, q), Simplex::Edge(r, s)) => {
                if Operands::<A, B>::EXPLICIT {
                    let (pa, pb) = (ops.a_positions, ops.b_positions);
                    return explicit_edge_edge(
                        pa[p as usize],
                        pa[q as usize],
                        pb[r as usize],
                        pb[s as usize],
                    );
                }
                let near = ops.a.rounded()[p as usize];
                let (p, q, r, s) = (ops.a.point(p), ops.a.point(q), ops.b.point(r), ops.b.point(s));
                match [&p, &q, &r, &s].map(|x| explicit(x)) {
                    [Some(p), Some(q), Some(r), Some(s)] => explicit_edge_edge(p, q, r, s),
                    _ => segment_segment(&p, &q, &r, &s, near),
                }
            }
            // Two triangles' interiors never hold an end of their intersection.
            (Simplex::Face(_), Simplex::Face(_)) => None,
        }
    }

    /// The point's coordinates rounded to f64 ([`Point::position`]), for output and
    /// pictures only; a key no pair produces gives the first corner of A's simplex.
    pub fn position<A: Solid, B: Solid>(&self, ops: &Operands<A, B>) -> DVec3 {
        match self.point(ops) {
            Some(x) => x.position(),
            None => match self.a {
                Simplex::Vertex(v) | Simplex::Edge(v, _) => ops.a_positions[v as usize],
                Simplex::Face(t) => ops.a_tri(t)[0],
            },
        }
    }
}

/// How one candidate pair meets.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Meeting {
    #[default]
    Apart,
    /// A single point.
    Point(Key),
    /// A segment, a constraint in both triangles.
    Segment([Key; 2]),
    /// Coplanar triangles: segments to insert in t (u's edges clipped to t), in u (t's
    /// edges clipped to u), and whether u faces the same way as t.
    Coplanar { in_a: Vec<[Key; 2]>, in_b: Vec<[Key; 2]>, points: Vec<Key>, same: bool },
}

/// The minimal simplex of triangle `tri` (ids `ids`) holding the coplanar point x, in the
/// projection `proj` of that plane; `None` when x lies outside.
fn locate_2d(tri: [DVec2; 3], ids: [u32; 3], face: u32, x: DVec2) -> Option<Simplex> {
    let s = orient2d(tri[0], tri[1], tri[2]);
    let o = [0, 1, 2].map(|k| s * orient2d(tri[k], tri[(k + 1) % 3], x));
    if o.contains(&-1) {
        return None;
    }
    Some(simplex_of_signs(o, ids, face))
}

/// The simplex that the signs `o` of a point against a triangle's three edges name, the
/// point being on the triangle: its face (no zero), edge k (o[k] = 0) or, on two edges,
/// their common vertex (edges k and k+1 share vertex k+1).
fn simplex_of_signs(o: [i8; 3], ids: [u32; 3], face: u32) -> Simplex {
    match o.iter().filter(|&&v| v == 0).count() {
        0 => Simplex::Face(face),
        1 => {
            let k = o.iter().position(|&v| v == 0).unwrap_or(0);
            Simplex::edge(ids[k], ids[(k + 1) % 3])
        }
        _ => {
            let k = (0..3).find(|&k| o[k] == 0 && o[(k + 1) % 3] == 0).unwrap_or(0);
            Simplex::Vertex(ids[(k + 1) % 3])
        }
    }
}

/// The minimal simplex of triangle `tri` (ids `ids`) where the segment pq, which
/// reaches its plane at one point, crosses it; `None` when it passes outside.
fn locate_crossing(p: DVec3, q: DVec3, tri: [DVec3; 3], ids: [u32; 3], face: u32) -> Option<Simplex> {
    let o = [0, 1, 2].map(|k| orient3d(p, q, tri[k], tri[(k + 1) % 3]));
    if o.contains(&1) && o.contains(&-1) {
        return None;
    }
    Some(simplex_of_signs(o, ids, face))
}

/// Up to two distinct keys (more would mean the inputs are not what the exact tests
/// said, which cannot happen; extra ones are ignored).
#[derive(Default)]
struct Ends {
    keys: [Option<Key>; 3],
}

impl Ends {
    fn push(&mut self, k: Key) {
        for slot in &mut self.keys {
            match slot {
                Some(x) if *x == k => return,
                None => {
                    *slot = Some(k);
                    return;
                }
                _ => {}
            }
        }
    }

    /// The ends of triangle `p`'s meeting with the plane of triangle `q` that lie in `q`:
    /// its vertices on that plane (`signs[i] == 0`) and its edges crossing it. One function
    /// for both operands: `p_is_a` says whether `p` is A's triangle, so that every key
    /// names A's simplex first.
    fn of_crossing(
        &mut self,
        (p, p_ids, signs): ([DVec3; 3], [u32; 3], [Sign; 3]),
        (q, q_ids, q_face): ([DVec3; 3], [u32; 3], u32),
        p_is_a: bool,
    ) {
        let key = |mine: Simplex, other: Simplex| {
            if p_is_a { Key { a: mine, b: other } } else { Key { a: other, b: mine } }
        };
        let proj = triangle_projection(q[0], q[1], q[2]);
        for i in 0..3 {
            let j = (i + 1) % 3;
            if signs[i] == 0 {
                if let Some(proj) = proj {
                    let tri = q.map(|x| proj.apply(x));
                    if let Some(s) = locate_2d(tri, q_ids, q_face, proj.apply(p[i])) {
                        self.push(key(Simplex::Vertex(p_ids[i]), s));
                    }
                }
            } else if signs[i] * signs[j] < 0 {
                if let Some(s) = locate_crossing(p[i], p[j], q, q_ids, q_face) {
                    self.push(key(Simplex::edge(p_ids[i], p_ids[j]), s));
                }
            }
        }
    }

    fn meeting(&self) -> Meeting {
        match self.keys {
            [None, ..] => Meeting::Apart,
            [Some(k), None, _] => Meeting::Point(k),
            [Some(a), Some(b), _] => Meeting::Segment([a, b]),
        }
    }
}

/// Decides how triangle t of A and triangle u of B meet (both non-degenerate): with f64
/// predicates when both operands are explicit, else with predicates on their points.
pub fn meet<A: Solid, B: Solid>(ops: &Operands<A, B>, t: u32, u: u32) -> Meeting {
    if Operands::<A, B>::EXPLICIT { meet_explicit(ops, t, u) } else { meet_exact(ops, t, u) }
}

/// [`meet`] of explicit operands.
fn meet_explicit<A: Solid, B: Solid>(ops: &Operands<A, B>, t: u32, u: u32) -> Meeting {
    let (ta, tb) = (ops.a_tri(t), ops.b_tri(u));
    let (ia, ib) = (ops.a_triangles[t as usize], ops.b_triangles[u as usize]);
    let sa = ta.map(|p| orient3d(tb[0], tb[1], tb[2], p));
    if sa == [1, 1, 1] || sa == [-1, -1, -1] {
        return Meeting::Apart;
    }
    let sb = tb.map(|p| orient3d(ta[0], ta[1], ta[2], p));
    if sb == [1, 1, 1] || sb == [-1, -1, -1] {
        return Meeting::Apart;
    }
    if sa == [0, 0, 0] {
        return coplanar(ops, t, u);
    }
    let mut ends = Ends::default();
    // Ends of t ∩ plane(u) that lie in u, then of u ∩ plane(t) that lie in t.
    ends.of_crossing((ta, ia, sa), (tb, ib, u), true);
    ends.of_crossing((tb, ib, sb), (ta, ia, t), false);
    ends.meeting()
}

/// The coplanar case: each triangle's edges clipped to the other, in t's projection
/// (exact: all six points lie in one plane).
fn coplanar<A: Solid, B: Solid>(ops: &Operands<A, B>, t: u32, u: u32) -> Meeting {
    let (ta, tb) = (ops.a_tri(t), ops.b_tri(u));
    let (ia, ib) = (ops.a_triangles[t as usize], ops.b_triangles[u as usize]);
    let Some(proj) = triangle_projection(ta[0], ta[1], ta[2]) else { return Meeting::Apart };
    let a2 = ta.map(|p| proj.apply(p));
    let b2 = tb.map(|p| proj.apply(p));
    let same = orient2d(a2[0], a2[1], a2[2]) == orient2d(b2[0], b2[1], b2[2]);
    let mut in_a = Vec::new();
    let mut in_b = Vec::new();
    let mut points = Vec::new();
    // u's edges clipped to t.
    for k in 0..3 {
        let (j, l) = (k, (k + 1) % 3);
        let pts = clip((b2[j], b2[l]), (ib[j], ib[l]), (a2, ia, t), |own, other| Key { a: other, b: own });
        emit(&pts, |x| x.1, &mut in_a, &mut points);
    }
    // t's edges clipped to u.
    for k in 0..3 {
        let (j, l) = (k, (k + 1) % 3);
        let pts = clip((a2[j], a2[l]), (ia[j], ia[l]), (b2, ib, u), |own, other| Key { a: own, b: other });
        emit(&pts, |x| x.1, &mut in_b, &mut points);
    }
    if in_a.is_empty() && in_b.is_empty() && points.is_empty() {
        return Meeting::Apart;
    }
    Meeting::Coplanar { in_a, in_b, points, same }
}

/// Consecutive keys along a clipped edge (`key` of each entry) become segments; a lone
/// key is a point.
fn emit<T>(pts: &[T], key: impl Fn(&T) -> Key, segments: &mut Vec<[Key; 2]>, points: &mut Vec<Key>) {
    match pts.len() {
        0 => {}
        1 => points.push(key(&pts[0])),
        _ => segments.extend(pts.windows(2).map(|w| [key(&w[0]), key(&w[1])])),
    }
}

/// The keys of the points of segment pr (ids ip, ir, one mesh) that lie in the
/// coplanar triangle `tri` (ids `tid`, face `face`, the other mesh), sorted along pr.
/// The order is exact: more than two points occur only where pr runs along an edge of
/// `tri`, and then all are input vertices on one line, ordered by their coordinate along
/// pr's larger component (an edge crossing, inexact, is then never among them).
/// `key(own, other)` builds a key from the segment's simplex and the triangle's.
fn clip(
    (p, r): (DVec2, DVec2),
    (ip, ir): (u32, u32),
    (tri, tid, face): ([DVec2; 3], [u32; 3], u32),
    key: impl Fn(Simplex, Simplex) -> Key,
) -> Vec<(f64, Key)> {
    let mut pts: Vec<(f64, Key)> = Vec::with_capacity(3);
    let mut push = |l: f64, k: Key| {
        if !pts.iter().any(|(_, x)| *x == k) {
            pts.push((l, k));
        }
    };
    let d = r - p;
    let axis = if d.x.abs() >= d.y.abs() { 0 } else { 1 };
    let along = |x: DVec2| if d[axis] > 0.0 { x[axis] } else { -x[axis] };
    if let Some(s) = locate_2d(tri, tid, face, p) {
        push(along(p), key(Simplex::Vertex(ip), s));
    }
    if let Some(s) = locate_2d(tri, tid, face, r) {
        push(along(r), key(Simplex::Vertex(ir), s));
    }
    let own_edge = Simplex::edge(ip, ir);
    for k in 0..3 {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        let oa = orient2d(p, r, a);
        let ob = orient2d(p, r, b);
        let op = orient2d(a, b, p);
        let or = orient2d(a, b, r);
        if oa * ob < 0 && op * or < 0 {
            // Proper crossing of the two edges' interiors.
            let l = line_crossing(a, b, p, r);
            push(along(p) + l * d[axis].abs(), key(own_edge, Simplex::edge(tid[k], tid[(k + 1) % 3])));
        }
        // A corner of the triangle on the segment's interior.
        for (o, v, id) in [(oa, a, tid[k]), (ob, b, tid[(k + 1) % 3])] {
            if o == 0 {
                // On pr's line: strictly between p and r by the coordinate, exactly.
                if along(p) < along(v) && along(v) < along(r) {
                    push(along(v), key(own_edge, Simplex::Vertex(id)));
                }
            }
        }
    }
    pts.sort_by(|x, y| x.0.total_cmp(&y.0));
    pts
}

/// An axis along which point b differs from point a, and whether b is the greater there,
/// decided exactly. `d`: b's rounded position minus a's ([`Point::position`], correctly
/// rounded, or the input positions themselves). Rounding is monotone, so where the rounded
/// coordinates differ the exact ones differ the same way: the largest difference serves;
/// only ends that round to one position are compared exactly (`exact()` gives them).
pub(super) fn separating_axis<'p>(
    d: DVec3,
    exact: impl FnOnce() -> (Cow<'p, Point>, Cow<'p, Point>),
) -> Option<(usize, bool)> {
    let axis = d.abs().max_position();
    if d[axis] != 0.0 {
        return Some((axis, d[axis] > 0.0));
    }
    let (a, b) = exact();
    (0..3).find_map(|axis| match compare_implicit(axis, &a, &b) {
        Ordering::Equal => None,
        o => Some((axis, o == Ordering::Less)),
    })
}

/// A triangle of an operand with implicit points: its corners, ids, index and support
/// plane (explicit).
struct ExactTriangle<'p> {
    corners: [Cow<'p, Point>; 3],
    /// The corners' rounded positions (for shapes and for choosing axes).
    rounded: [DVec3; 3],
    ids: [u32; 3],
    face: u32,
    support: [DVec3; 3],
    plane: [Point; 3],
}

impl<'p> ExactTriangle<'p> {
    fn of<S: Solid>(solid: &'p S, t: u32) -> ExactTriangle<'p> {
        let ids = solid.triangles()[t as usize];
        let support = solid.support(t);
        ExactTriangle {
            corners: ids.map(|i| solid.point(i)),
            rounded: ids.map(|i| solid.rounded()[i as usize]),
            ids,
            face: t,
            support,
            plane: support.map(Point::explicit),
        }
    }

    fn corner(&self, k: usize) -> &Point {
        &self.corners[k]
    }

    fn corners(&self) -> [&Point; 3] {
        [self.corner(0), self.corner(1), self.corner(2)]
    }

    /// The side of the support plane `x` lies on.
    fn side(&self, x: &Point) -> Sign {
        let [a, b, c] = &self.plane;
        orient3d_implicit(a, b, c, x)
    }
}

/// [`meet`] with predicates on the operands' points (one of them is not explicit).
fn meet_exact<A: Solid, B: Solid>(ops: &Operands<A, B>, t: u32, u: u32) -> Meeting {
    let (ta, tb) = (ExactTriangle::of(ops.a, t), ExactTriangle::of(ops.b, u));
    let sa = [0, 1, 2].map(|k| tb.side(ta.corner(k)));
    if sa == [1, 1, 1] || sa == [-1, -1, -1] {
        return Meeting::Apart;
    }
    let sb = [0, 1, 2].map(|k| ta.side(tb.corner(k)));
    if sb == [1, 1, 1] || sb == [-1, -1, -1] {
        return Meeting::Apart;
    }
    if sa == [0, 0, 0] {
        return coplanar_exact(&ta, &tb);
    }
    let mut ends = Ends::default();
    ends.of_crossing_exact((&ta, sa), &tb, true);
    ends.of_crossing_exact((&tb, sb), &ta, false);
    ends.meeting()
}

/// [`locate_2d`] of implicit points, in the projection on `axes`.
fn locate_2d_exact(
    axes: [usize; 2],
    tri: [&Point; 3],
    ids: [u32; 3],
    face: u32,
    x: &Point,
) -> Option<Simplex> {
    let s = orient2d_implicit(axes, tri[0], tri[1], tri[2]);
    let o = [0, 1, 2].map(|k| s * orient2d_implicit(axes, tri[k], tri[(k + 1) % 3], x));
    if o.contains(&-1) {
        return None;
    }
    Some(simplex_of_signs(o, ids, face))
}

/// [`locate_crossing`] of implicit points.
fn locate_crossing_exact(p: &Point, q: &Point, tri: &ExactTriangle) -> Option<Simplex> {
    let o = [0, 1, 2].map(|k| orient3d_implicit(p, q, tri.corner(k), tri.corner((k + 1) % 3)));
    if o.contains(&1) && o.contains(&-1) {
        return None;
    }
    Some(simplex_of_signs(o, tri.ids, tri.face))
}

impl Ends {
    /// [`Ends::of_crossing`] with predicates on implicit points: the corners of `p` on the
    /// support plane of `q` located in `q` (in the projection of that plane), `p`'s edges
    /// crossing it located against `q`'s corners.
    fn of_crossing_exact(
        &mut self,
        (p, signs): (&ExactTriangle, [Sign; 3]),
        q: &ExactTriangle,
        p_is_a: bool,
    ) {
        let key = |mine: Simplex, other: Simplex| {
            if p_is_a { Key { a: mine, b: other } } else { Key { a: other, b: mine } }
        };
        for i in 0..3 {
            let j = (i + 1) % 3;
            if signs[i] == 0 {
                if let Some(axes) = plane_axes(q.support) {
                    if let Some(s) = locate_2d_exact(axes, q.corners(), q.ids, q.face, p.corner(i)) {
                        self.push(key(Simplex::Vertex(p.ids[i]), s));
                    }
                }
            } else if signs[i] * signs[j] < 0 {
                if let Some(s) = locate_crossing_exact(p.corner(i), p.corner(j), q) {
                    self.push(key(Simplex::edge(p.ids[i], p.ids[j]), s));
                }
            }
        }
    }
}

/// A point off the plane through `plane` (explicit, not on one line): a unit step from
/// its first point along an axis (one of three steps leaves the plane).
fn off_plane(plane: [DVec3; 3]) -> Option<Point> {
    let [a, b, c] = plane;
    (0..3).find_map(|k| {
        let mut off = a;
        off[k] += if a[k] > 0.0 { -1.0 } else { 1.0 };
        (orient3d(a, b, c, off) != 0).then(|| Point::explicit(off))
    })
}

/// [`coplanar`] with predicates on implicit points, in the projection of t's support
/// plane (u's is the same plane: t's corners lie on it).
fn coplanar_exact(ta: &ExactTriangle, tb: &ExactTriangle) -> Meeting {
    let (Some(axes), Some(off)) = (plane_axes(ta.support), off_plane(ta.support)) else {
        return Meeting::Apart;
    };
    let (a, b) = (ta.corners(), tb.corners());
    let same = orient2d_implicit(axes, a[0], a[1], a[2]) == orient2d_implicit(axes, b[0], b[1], b[2]);
    let mut in_a = Vec::new();
    let mut in_b = Vec::new();
    let mut points = Vec::new();
    // u's edges clipped to t.
    for k in 0..3 {
        let (j, l) = (k, (k + 1) % 3);
        let pts = clip_exact(
            ([b[j], b[l]], [tb.ids[j], tb.ids[l]], tb.rounded[l] - tb.rounded[j]),
            (a, ta.ids, ta.face),
            (axes, &off),
            |own, other| Key { a: other, b: own },
        );
        emit(&pts, |x| x.1, &mut in_a, &mut points);
    }
    // t's edges clipped to u.
    for k in 0..3 {
        let (j, l) = (k, (k + 1) % 3);
        let pts = clip_exact(
            ([a[j], a[l]], [ta.ids[j], ta.ids[l]], ta.rounded[l] - ta.rounded[j]),
            (b, tb.ids, tb.face),
            (axes, &off),
            |own, other| Key { a: own, b: other },
        );
        emit(&pts, |x| x.1, &mut in_b, &mut points);
    }
    if in_a.is_empty() && in_b.is_empty() && points.is_empty() {
        return Meeting::Apart;
    }
    Meeting::Coplanar { in_a, in_b, points, same }
}

/// [`clip`] of implicit points: the keys of the points of segment pr (ids, and `d` = r − p
/// rounded) that lie in the coplanar triangle `tri`, sorted along pr, in the projection on
/// `axes`. They are ordered by exact comparisons of their coordinate along an axis where
/// p and r differ (all lie on pr); a crossing of pr with an edge of `tri` is made for
/// that as the segments' crossing (`off`: a point off their plane).
#[allow(clippy::type_complexity)]
fn clip_exact<'p>(
    ([p, r], [ip, ir], d): ([&'p Point; 2], [u32; 2], DVec3),
    (tri, tid, face): ([&'p Point; 3], [u32; 3], u32),
    (axes, off): ([usize; 2], &Point),
    key: impl Fn(Simplex, Simplex) -> Key,
) -> Vec<(Cow<'p, Point>, Key)> {
    let mut pts: Vec<(Cow<'p, Point>, Key)> = Vec::with_capacity(3);
    let Some((axis, forward)) = separating_axis(d, || (Cow::Borrowed(p), Cow::Borrowed(r))) else {
        return pts;
    };
    let order = |x: &Point, y: &Point| {
        let o = compare_implicit(axis, x, y);
        if forward { o } else { o.reverse() }
    };
    let mut push = |x: Cow<'p, Point>, k: Key| {
        if !pts.iter().any(|(_, y)| *y == k) {
            pts.push((x, k));
        }
    };
    if let Some(s) = locate_2d_exact(axes, tri, tid, face, p) {
        push(Cow::Borrowed(p), key(Simplex::Vertex(ip), s));
    }
    if let Some(s) = locate_2d_exact(axes, tri, tid, face, r) {
        push(Cow::Borrowed(r), key(Simplex::Vertex(ir), s));
    }
    let own_edge = Simplex::edge(ip, ir);
    for k in 0..3 {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        let oa = orient2d_implicit(axes, p, r, a);
        let ob = orient2d_implicit(axes, p, r, b);
        let op = orient2d_implicit(axes, a, b, p);
        let or = orient2d_implicit(axes, a, b, r);
        if oa * ob < 0 && op * or < 0 {
            // Proper crossing of the two edges' interiors: coplanar, strictly crossing, and
            // `off` is off their plane, so the crossing exists.
            let x = Point::segment_segment(p, r, a, b, off)
                .unwrap_or_else(|e| unreachable!("properly crossing coplanar segments: {e}"));
            push(Cow::Owned(x), key(own_edge, Simplex::edge(tid[k], tid[(k + 1) % 3])));
        }
        // A corner of the triangle on the segment's interior.
        for (o, v, id) in [(oa, a, tid[k]), (ob, b, tid[(k + 1) % 3])] {
            if o == 0 && order(p, v) == Ordering::Less && order(v, r) == Ordering::Less {
                push(Cow::Borrowed(v), key(own_edge, Simplex::Vertex(id)));
            }
        }
    }
    pts.sort_by(|x, y| order(&x.0, &y.0));
    pts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boolean::operand::ExactSolid;
    use crate::mesh::intersect::TriangleSoup;

    fn soup(positions: &[DVec3], triangles: &[[u32; 3]]) -> TriangleSoup {
        let face_of = (0..triangles.len() as u32).collect();
        TriangleSoup {
            positions: positions.to_vec(),
            triangles: triangles.to_vec(),
            face_of,
            failed: Vec::new(),
        }
    }

    /// The pair's meeting is the same when the operands are taken as exact ones (all
    /// their points explicit), mixed or both; so are its points.
    fn same_with_exact_points(sa: &TriangleSoup, sb: &TriangleSoup) {
        let (ea, eb) = (ExactSolid::from_soup(sa), ExactSolid::from_soup(sb));
        let m = meet(&Operands::new(sa, sb), 0, 0);
        assert_eq!(meet(&Operands::new(&ea, sb), 0, 0), m);
        assert_eq!(meet(&Operands::new(sa, &eb), 0, 0), m);
        assert_eq!(meet(&Operands::new(&ea, &eb), 0, 0), m);
        let keys: Vec<Key> = match m {
            Meeting::Apart => Vec::new(),
            Meeting::Point(k) => vec![k],
            Meeting::Segment(s) => s.to_vec(),
            Meeting::Coplanar { in_a, in_b, points, .. } => {
                in_a.iter().chain(&in_b).flatten().chain(&points).copied().collect()
            }
        };
        for k in keys {
            let x = k.point(&Operands::new(sa, sb)).unwrap();
            assert_eq!(k.point(&Operands::new(&ea, &eb)).unwrap().definition(), x.definition());
        }
    }

    #[test]
    fn piercing_pair_gives_one_segment_with_edge_face_keys() {
        let pa = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(4.0, 0.0, 0.0), DVec3::new(0.0, 4.0, 0.0)];
        let pb = [DVec3::new(1.0, 1.0, -1.0), DVec3::new(1.0, 1.0, 1.0), DVec3::new(1.0, 9.0, 0.0)];
        let (ta, tb) = ([[0, 1, 2]], [[0, 1, 2]]);
        let (sa, sb) = (soup(&pa, &ta), soup(&pb, &tb));
        let o = Operands::new(&sa, &sb);
        same_with_exact_points(&sa, &sb);
        let m = meet(&o, 0, 0);
        let Meeting::Segment(keys) = m else { panic!("{m:?}") };
        // One end: B's edge 0–1 pierces t's interior; the other: t's edge 2–0 (x = 0)? No:
        // u lies in the plane x = 1, so it meets t's edge 1–2 (x + y = 4) at (1, 3, 0).
        assert!(keys.contains(&Key { a: Simplex::Face(0), b: Simplex::Edge(0, 1) }), "{keys:?}");
        let other = keys.iter().find(|k| k.a != Simplex::Face(0)).unwrap();
        assert_eq!(other.a, Simplex::Edge(1, 2));
        assert_eq!(other.b, Simplex::Face(0));
        assert_eq!(other.position(&o), DVec3::new(1.0, 3.0, 0.0));
        assert_eq!(
            keys.iter().find(|k| k.a == Simplex::Face(0)).unwrap().position(&o),
            DVec3::new(1.0, 1.0, 0.0)
        );
    }

    #[test]
    fn coplanar_overlap_clips_both_ways() {
        let pa = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
        let pb = [DVec3::new(1.0, -1.0, 0.0), DVec3::new(1.0, 3.0, 0.0), DVec3::new(-1.0, 1.0, 0.0)];
        let (ta, tb) = ([[0, 1, 2]], [[0, 1, 2]]);
        let (sa, sb) = (soup(&pa, &ta), soup(&pb, &tb));
        let o = Operands::new(&sa, &sb);
        same_with_exact_points(&sa, &sb);
        let Meeting::Coplanar { in_a, in_b, same, .. } = meet(&o, 0, 0) else { panic!() };
        assert!(same);
        // B's edge 0–1 (x = 1) crosses t from (1, 0) to (1, 1).
        let seg =
            in_a.iter().find(|s| s.iter().all(|k| k.b == Simplex::Edge(0, 1) || k.b == Simplex::Vertex(0)));
        let seg = seg.unwrap_or_else(|| panic!("{in_a:?}"));
        let mut ends: Vec<DVec3> = seg.iter().map(|k| k.position(&o)).collect();
        ends.sort_by(|a, b| a.y.total_cmp(&b.y));
        assert_eq!(ends, vec![DVec3::new(1.0, 0.0, 0.0), DVec3::new(1.0, 1.0, 0.0)]);
        assert!(!in_b.is_empty());
    }

    #[test]
    fn touching_at_a_vertex_is_a_point() {
        let pa = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0)];
        let pb = [DVec3::new(0.5, 0.5, 0.0), DVec3::new(1.0, 1.0, 1.0), DVec3::new(0.0, 1.0, 1.0)];
        let (ta, tb) = ([[0, 1, 2]], [[0, 1, 2]]);
        let (sa, sb) = (soup(&pa, &ta), soup(&pb, &tb));
        let o = Operands::new(&sa, &sb);
        same_with_exact_points(&sa, &sb);
        assert_eq!(meet(&o, 0, 0), Meeting::Point(Key { a: Simplex::Face(0), b: Simplex::Vertex(0) }));
    }
}
