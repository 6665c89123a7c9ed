//! Constrained triangulation of one triangle decided by orientation signs alone, so that
//! it works on points that have no exact coordinates (the Booleans' implicit
//! intersection points, [`crate::exact::implicit`]): the caller gives an exact
//! `orient(a, b, c)` over its point ids, and a triangle whose corners, points on its
//! edges and points inside it, plus segments between them, are to become edges.
//!
//! The algorithm is the classic one, with every decision an orientation sign:
//!
//! 1. points are inserted one by one: located by a walk from the last triangle made,
//!    a point inside a triangle splits it in three, one on an edge splits the two
//!    triangles sharing it (or the one, on the outline);
//! 2. each segment is inserted by flipping away the edges it crosses (Sloan's
//!    algorithm: a crossing edge of a strictly convex quadrilateral is flipped, one of a
//!    non-convex one waits); a segment through a point is split there;
//! 3. the other edges are then flipped towards Delaunay with an *approximate* in-circle
//!    test on rounded positions, each flip only where the quadrilateral is strictly
//!    convex by the exact signs: the shape of the triangles comes from f64, their
//!    validity never does.
//!
//! The result covers the triangle exactly, every triangle counter-clockwise by the exact
//! orientation, every segment (split at the points it passes through) an edge.

use std::collections::VecDeque;

use super::hash::{HashMap, HashMapExt, HashSet, HashSetExt};

use glam::DVec2;

use crate::exact::Sign;

/// Why a triangulation could not be made: each means the input was not a planar
/// straight-line graph in the triangle.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ConstrainedError {
    #[error("the corners do not make a counter-clockwise triangle")]
    Corners,
    #[error("point {0} lies outside the triangle")]
    Outside(u32),
    #[error("points {0} and {1} coincide")]
    Duplicate(u32, u32),
    #[error("segment {0}–{1} crosses segment {2}–{3}")]
    Crossing(u32, u32, u32, u32),
    #[error("segment {0}–{1} joins a point that is not in the triangulation")]
    Unknown(u32, u32),
}

/// The triangles and the segments' edges, both over the caller's ids.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Constrained {
    /// Counter-clockwise triangles covering the triangle.
    pub triangles: Vec<[u32; 3]>,
    /// The segments as edges, split where points lie on them; those along the outline
    /// excluded.
    pub segment_edges: Vec<[u32; 2]>,
}

const NONE: u32 = u32::MAX;

/// Triangles with neighbours: `adj[t][i]` is across the edge (v[i], v[i + 1]).
struct Mesh2<'a, O: Fn(u32, u32, u32) -> Sign> {
    ids: &'a [u32],
    orient: O,
    tris: Vec<[u32; 3]>,
    adj: Vec<[u32; 3]>,
    /// One triangle per vertex (local index).
    around: Vec<u32>,
    fixed: HashSet<(u32, u32)>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

impl<O: Fn(u32, u32, u32) -> Sign> Mesh2<'_, O> {
    fn o(&self, a: u32, b: u32, c: u32) -> Sign {
        (self.orient)(self.ids[a as usize], self.ids[b as usize], self.ids[c as usize])
    }

    fn set(&mut self, t: u32, v: [u32; 3], adj: [u32; 3]) {
        let t = t as usize;
        if t == self.tris.len() {
            self.tris.push(v);
            self.adj.push(adj);
        } else {
            self.tris[t] = v;
            self.adj[t] = adj;
        }
        for x in v {
            self.around[x as usize] = t as u32;
        }
    }

    /// Points the neighbour `n` (if any) that pointed at `old` to `new`.
    fn relink(&mut self, n: u32, old: u32, new: u32) {
        if n != NONE {
            if let Some(i) = self.adj[n as usize].iter().position(|&x| x == old) {
                self.adj[n as usize][i] = new;
            }
        }
    }

    /// The triangle holding point p and how: (t, None) inside, (t, Some(i)) on edge i.
    /// Each triangle's three signs are taken once: the walk's tests are the ones that
    /// place the point.
    fn locate(&self, p: u32, start: u32) -> Result<(u32, Option<usize>), ConstrainedError> {
        let mut t = start;
        let limit = 3 * self.tris.len() + 8;
        for step in 0..limit {
            let v = self.tris[t as usize];
            let mut signs = [0; 3];
            let mut moved = false;
            // Start the test at a rotating edge so that a walk cannot circle.
            for k in 0..3 {
                let i = (k + step) % 3;
                signs[i] = self.o(v[i], v[(i + 1) % 3], p);
                if signs[i] < 0 {
                    let n = self.adj[t as usize][i];
                    if n == NONE {
                        return Err(ConstrainedError::Outside(self.ids[p as usize]));
                    }
                    t = n;
                    moved = true;
                    break;
                }
            }
            if !moved {
                return self.classify_in(t, p, signs);
            }
        }
        // A walk that did not arrive: look at every triangle.
        for t in 0..self.tris.len() as u32 {
            let v = self.tris[t as usize];
            let mut signs = [0; 3];
            if (0..3).all(|i| {
                signs[i] = self.o(v[i], v[(i + 1) % 3], p);
                signs[i] >= 0
            }) {
                return self.classify_in(t, p, signs);
            }
        }
        Err(ConstrainedError::Outside(self.ids[p as usize]))
    }

    /// Where p lies in triangle t, from the signs of p against its three edges (none
    /// negative): inside, on one edge, or at a corner (an error).
    fn classify_in(
        &self,
        t: u32,
        p: u32,
        signs: [Sign; 3],
    ) -> Result<(u32, Option<usize>), ConstrainedError> {
        let v = self.tris[t as usize];
        let mut zeros = (0..3).filter(|&i| signs[i] == 0);
        match (zeros.next(), zeros.next(), zeros.next()) {
            (None, _, _) => Ok((t, None)),
            (Some(i), None, _) => Ok((t, Some(i))),
            // On two edges: at their common corner.
            (Some(i), Some(j), None) => {
                let corner = if (i + 1) % 3 == j { v[j] } else { v[i] };
                Err(ConstrainedError::Duplicate(self.ids[corner as usize], self.ids[p as usize]))
            }
            _ => Err(ConstrainedError::Corners),
        }
    }

    fn insert(&mut self, p: u32, start: u32) -> Result<u32, ConstrainedError> {
        let (t, on) = self.locate(p, start)?;
        let v = self.tris[t as usize];
        let n = self.adj[t as usize];
        match on {
            None => {
                let [a, b, c] = v;
                let (t1, t2) = (self.tris.len() as u32, self.tris.len() as u32 + 1);
                self.set(t, [a, b, p], [n[0], t1, t2]);
                self.set(t1, [b, c, p], [n[1], t2, t]);
                self.set(t2, [c, a, p], [n[2], t, t1]);
                self.relink(n[1], t, t1);
                self.relink(n[2], t, t2);
            }
            Some(i) => {
                let (a, b, c) = (v[i], v[(i + 1) % 3], v[(i + 2) % 3]);
                let (n_bc, n_ca) = (n[(i + 1) % 3], n[(i + 2) % 3]);
                let u = n[i];
                let t1 = self.tris.len() as u32;
                if u == NONE {
                    self.set(t, [a, p, c], [NONE, t1, n_ca]);
                    self.set(t1, [p, b, c], [NONE, n_bc, t]);
                    self.relink(n_bc, t, t1);
                } else {
                    let uv = self.tris[u as usize];
                    let un = self.adj[u as usize];
                    let j = (0..3)
                        .find(|&j| uv[j] == b && uv[(j + 1) % 3] == a)
                        .ok_or(ConstrainedError::Corners)?;
                    let d = uv[(j + 2) % 3];
                    let (n_ad, n_db) = (un[(j + 1) % 3], un[(j + 2) % 3]);
                    let u1 = t1 + 1;
                    // t: a p c, t1: p b c; u: b p d, u1: p a d.
                    self.set(t, [a, p, c], [u1, t1, n_ca]);
                    self.set(t1, [p, b, c], [u, n_bc, t]);
                    self.set(u, [b, p, d], [t1, u1, n_db]);
                    self.set(u1, [p, a, d], [t, n_ad, u]);
                    self.relink(n_bc, t, t1);
                    self.relink(n_ad, u, u1);
                }
                if self.fixed.remove(&key(a, b)) {
                    self.fixed.insert(key(a, p));
                    self.fixed.insert(key(p, b));
                }
            }
        }
        Ok(t)
    }

    /// The triangles around vertex a, by rotation from its recorded triangle both ways.
    fn star(&self, a: u32) -> Vec<u32> {
        let start = self.around[a as usize];
        let mut out = Vec::with_capacity(16);
        out.push(start);
        for dir in 0..2 {
            let mut t = start;
            for _ in 0..self.tris.len() {
                let v = self.tris[t as usize];
                let Some(i) = v.iter().position(|&x| x == a) else { break };
                // Across (v[i+2], a) one way, across (a, v[i+1]) the other.
                let n = if dir == 0 { self.adj[t as usize][(i + 2) % 3] } else { self.adj[t as usize][i] };
                if n == NONE || n == start {
                    break;
                }
                out.push(n);
                t = n;
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The triangle and index i with edge (v[i], v[i + 1]) = (a, b), if that edge exists.
    fn find_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        self.star(a).into_iter().find_map(|t| {
            let v = self.tris[t as usize];
            let i = v.iter().position(|&x| x == a)?;
            (v[(i + 1) % 3] == b).then_some((t, i))
        })
    }

    fn has_edge(&self, a: u32, b: u32) -> bool {
        self.find_edge(a, b).is_some() || self.find_edge(b, a).is_some()
    }

    /// Flips the edge shared by t (at index i) and its neighbour.
    fn flip(&mut self, t: u32, i: usize) {
        let v = self.tris[t as usize];
        let n = self.adj[t as usize];
        let u = n[i];
        let (a, b, c) = (v[i], v[(i + 1) % 3], v[(i + 2) % 3]);
        let uv = self.tris[u as usize];
        let un = self.adj[u as usize];
        let j = (0..3).position(|j| uv[j] == b).unwrap_or(0);
        let d = uv[(j + 2) % 3];
        let (n_bc, n_ca) = (n[(i + 1) % 3], n[(i + 2) % 3]);
        let (n_ad, n_db) = (un[(j + 1) % 3], un[(j + 2) % 3]);
        // t: a b c + u: b a d  →  t: c a d, u: d b c.
        self.set(t, [c, a, d], [n_ca, n_ad, u]);
        self.set(u, [d, b, c], [n_db, n_bc, t]);
        self.relink(n_ad, u, t);
        self.relink(n_bc, t, u);
    }

    /// The edge (v[i], v[i+1]) of t and its neighbour's far corner: (a, b, c, d) with
    /// t = a b c and the neighbour b a d, when the neighbour exists.
    fn quad(&self, t: u32, i: usize) -> Option<[u32; 4]> {
        let v = self.tris[t as usize];
        let u = self.adj[t as usize][i];
        if u == NONE {
            return None;
        }
        let uv = self.tris[u as usize];
        let j = (0..3).position(|j| uv[j] == v[(i + 1) % 3])?;
        Some([v[i], v[(i + 1) % 3], v[(i + 2) % 3], uv[(j + 2) % 3]])
    }

    /// True when the quadrilateral a d b c (diagonal ab) is strictly convex: the other
    /// diagonal cd crosses ab properly.
    fn flippable(&self, [a, b, c, d]: [u32; 4]) -> bool {
        self.o(c, d, a) * self.o(c, d, b) < 0
    }

    /// Makes the segment (a, b) an edge.
    fn constrain(&mut self, a: u32, b: u32) -> Result<(), ConstrainedError> {
        let err_ids = |s: &Self, x: u32, y: u32, p: u32, q: u32| {
            ConstrainedError::Crossing(
                s.ids[x as usize],
                s.ids[y as usize],
                s.ids[p as usize],
                s.ids[q as usize],
            )
        };
        let (mut a, b) = (a, b);
        while a != b {
            if self.has_edge(a, b) {
                self.fixed.insert(key(a, b));
                return Ok(());
            }
            // The triangle at a whose wedge holds the direction to b: v1 right of a→b
            // (or on it), v2 strictly left.
            let (mut right, mut left, mut along) = (NONE, NONE, NONE);
            for s in self.star(a) {
                let v = self.tris[s as usize];
                let Some(i) = v.iter().position(|&x| x == a) else { continue };
                let (v1, v2) = (v[(i + 1) % 3], v[(i + 2) % 3]);
                let (o1, o2) = (self.o(a, v1, b), self.o(a, b, v2));
                if o1 >= 0 && o2 > 0 {
                    (right, left) = (v1, v2);
                    break;
                }
                if o1 > 0 && o2 == 0 {
                    // v2 lies on the segment (a is on the outline, the segment along it).
                    along = v2;
                }
            }
            if right == NONE {
                if along == NONE {
                    return Err(ConstrainedError::Outside(self.ids[b as usize]));
                }
                self.fixed.insert(key(a, along));
                a = along;
                continue;
            }
            if self.o(a, right, b) == 0 {
                // The segment runs through `right`: its first piece is that edge.
                self.fixed.insert(key(a, right));
                a = right;
                continue;
            }
            // Walk across the edges the segment crosses, up to b or a point on it.
            let mut crossing: VecDeque<(u32, u32)> = VecDeque::new();
            let mut end = b;
            loop {
                if self.fixed.contains(&key(right, left)) {
                    return Err(err_ids(self, a, b, right, left));
                }
                crossing.push_back((right, left));
                let (s, i) = self
                    .find_edge(left, right)
                    .ok_or_else(|| ConstrainedError::Outside(self.ids[b as usize]))?;
                let w = self.tris[s as usize][(i + 2) % 3];
                if w == b {
                    break;
                }
                match self.o(a, b, w) {
                    0 => {
                        end = w;
                        break;
                    }
                    x if x < 0 => right = w,
                    _ => left = w,
                }
            }
            // Flip the crossing edges away (Sloan).
            let mut waiting = 0;
            while let Some((p, q)) = crossing.pop_front() {
                let (s, i) = self.find_edge(p, q).ok_or(ConstrainedError::Corners)?;
                let Some(quad) = self.quad(s, i) else { return Err(ConstrainedError::Corners) };
                if !self.flippable(quad) {
                    crossing.push_back((p, q));
                    waiting += 1;
                    if waiting > 4 * (crossing.len() + 1) * (crossing.len() + 1) + 64 {
                        return Err(err_ids(self, a, end, p, q));
                    }
                    continue;
                }
                waiting = 0;
                self.flip(s, i);
                let [_, _, c, d] = quad;
                // The new edge c–d still crosses the segment when c and d are strictly on
                // opposite sides of it and neither is an end.
                if c != a && d != a && c != end && d != end && self.o(a, end, c) * self.o(a, end, d) < 0 {
                    crossing.push_back((c, d));
                }
            }
            self.fixed.insert(key(a, end));
            a = end;
        }
        Ok(())
    }

    /// Lawson flips towards Delaunay by an approximate in-circle test, each one only where
    /// the exact signs say the quadrilateral is strictly convex; bounded.
    fn improve(&mut self, at: &dyn Fn(u32) -> DVec2) {
        let budget = 16 * self.tris.len() + 16;
        let mut flips = 0;
        let mut changed = true;
        while changed && flips < budget {
            changed = false;
            for t in 0..self.tris.len() as u32 {
                for i in 0..3 {
                    let Some(quad) = self.quad(t, i) else { continue };
                    let [a, b, c, d] = quad;
                    if self.fixed.contains(&key(a, b)) || !in_circle(at(a), at(b), at(c), at(d)) {
                        continue;
                    }
                    if self.flippable(quad) {
                        self.flip(t, i);
                        flips += 1;
                        changed = true;
                        break;
                    }
                }
            }
        }
    }
}

/// True when d lies clearly inside the circle through a, b, c (counter-clockwise), by
/// f64 arithmetic: for the shape of the triangles only.
fn in_circle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let det = ad.length_squared() * bd.perp_dot(cd)
        + bd.length_squared() * cd.perp_dot(ad)
        + cd.length_squared() * ad.perp_dot(bd);
    let scale = ad.length_squared() * bd.length() * cd.length()
        + bd.length_squared() * cd.length() * ad.length()
        + cd.length_squared() * ad.length() * bd.length();
    det > 1e-10 * scale
}

/// Triangulates the triangle `corners` (counter-clockwise by `orient`) with the `points`
/// (on its edges or inside it) as vertices and the `segments` (between any of these) as
/// edges. `orient(a, b, c)` must be exact (positive when a, b, c turn counter-clockwise
/// in the triangle's plane); `at` gives rounded 2-D positions in the same frame, for the
/// shape of the triangles only.
pub fn triangulate(
    corners: [u32; 3],
    points: &[u32],
    segments: &[[u32; 2]],
    orient: impl Fn(u32, u32, u32) -> Sign,
    at: impl Fn(u32) -> DVec2,
) -> Result<Constrained, ConstrainedError> {
    if orient(corners[0], corners[1], corners[2]) <= 0 {
        return Err(ConstrainedError::Corners);
    }
    let mut ids: Vec<u32> = corners.to_vec();
    ids.extend_from_slice(points);
    let mut local: HashMap<u32, u32> = HashMap::with_capacity(ids.len());
    for (i, &id) in ids.iter().enumerate() {
        if let Some(&j) = local.get(&id) {
            return Err(ConstrainedError::Duplicate(ids[j as usize], id));
        }
        local.insert(id, i as u32);
    }
    let mut m = Mesh2 {
        ids: &ids,
        orient,
        tris: Vec::with_capacity(2 * ids.len()),
        adj: Vec::with_capacity(2 * ids.len()),
        around: vec![0; ids.len()],
        fixed: HashSet::new(),
    };
    m.set(0, [0, 1, 2], [NONE; 3]);
    let mut last = 0;
    for p in 3..ids.len() as u32 {
        last = m.insert(p, last)?;
    }
    for &[a, b] in segments {
        let (Some(&la), Some(&lb)) = (local.get(&a), local.get(&b)) else {
            return Err(ConstrainedError::Unknown(a, b));
        };
        m.constrain(la, lb)?;
    }
    let at_local = |i: u32| at(ids[i as usize]);
    m.improve(&at_local);
    let triangles = m.tris.iter().map(|t| t.map(|i| ids[i as usize])).collect();
    let mut segment_edges: Vec<[u32; 2]> = Vec::new();
    for t in 0..m.tris.len() {
        for i in 0..3 {
            let (a, b) = (m.tris[t][i], m.tris[t][(i + 1) % 3]);
            // Each inner edge once (from its lower-id side), outline edges never.
            if a < b && m.adj[t][i] != NONE && m.fixed.contains(&key(a, b)) {
                segment_edges.push([ids[a as usize], ids[b as usize]]);
            }
        }
    }
    Ok(Constrained { triangles, segment_edges })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::orient2d;
    use crate::random::Rng;

    fn run(p: &[DVec2], points: &[u32], segments: &[[u32; 2]]) -> Result<Constrained, ConstrainedError> {
        triangulate(
            [0, 1, 2],
            points,
            segments,
            |a, b, c| orient2d(p[a as usize], p[b as usize], p[c as usize]),
            |i| p[i as usize],
        )
    }

    /// Every triangle counter-clockwise, areas summing to the whole, every segment a
    /// chain of edges, every point used.
    fn check(p: &[DVec2], out: &Constrained, segments: &[[u32; 2]]) {
        let area = |t: &[u32; 3]| {
            (p[t[1] as usize] - p[t[0] as usize]).perp_dot(p[t[2] as usize] - p[t[0] as usize])
        };
        for t in &out.triangles {
            assert!(orient2d(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]) > 0, "{t:?}");
        }
        let total: f64 = out.triangles.iter().map(area).sum();
        let whole = area(&[0, 1, 2]);
        assert!((total - whole).abs() <= 1e-9 * whole, "{total} {whole}");
        let mut edges: HashSet<(u32, u32)> = HashSet::new();
        for t in &out.triangles {
            for i in 0..3 {
                edges.insert(key(t[i], t[(i + 1) % 3]));
            }
        }
        let used: HashSet<u32> = out.triangles.iter().flatten().copied().collect();
        assert_eq!(used.len(), p.len());
        for &[a, b] in segments {
            // The points on segment ab, in order, must be joined by edges.
            let (pa, pb) = (p[a as usize], p[b as usize]);
            let mut on: Vec<(f64, u32)> = (0..p.len() as u32)
                .filter(|&x| orient2d(pa, pb, p[x as usize]) == 0)
                .map(|x| ((p[x as usize] - pa).dot(pb - pa), x))
                .filter(|&(l, _)| l >= 0.0 && l <= (pb - pa).length_squared())
                .collect();
            on.sort_by(|x, y| x.0.total_cmp(&y.0));
            for w in on.windows(2) {
                assert!(edges.contains(&key(w[0].1, w[1].1)), "segment {a}-{b} misses {}-{}", w[0].1, w[1].1);
            }
        }
    }

    #[test]
    fn points_inside_and_on_edges() {
        let p = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 4.0),
            DVec2::new(1.0, 0.0),
            DVec2::new(2.0, 2.0),
            DVec2::new(0.0, 3.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(0.5, 2.0),
        ];
        let out = run(&p, &[3, 4, 5, 6, 7], &[]).unwrap();
        // 2 inside + 6 on the outline: 2·2 + 6 − 2 triangles.
        assert_eq!(out.triangles.len(), 2 * 2 + 6 - 2);
        check(&p, &out, &[]);
    }

    #[test]
    fn segments_become_edges_split_at_points_on_them() {
        // A segment from one edge to another passing through an inside point, and one
        // crossing many Delaunay edges.
        let mut p = vec![DVec2::new(0.0, 0.0), DVec2::new(8.0, 0.0), DVec2::new(0.0, 8.0)];
        p.push(DVec2::new(0.0, 1.0)); // 3, on the left edge
        p.push(DVec2::new(6.0, 2.0)); // 4, on the hypotenuse
        p.push(DVec2::new(3.0, 1.5)); // 5, exactly on 3–4
        for i in 0..6 {
            p.push(DVec2::new(0.5 + 0.9 * i as f64, 0.25 + (i % 2) as f64 * 2.5)); // zigzag around the segment
        }
        let points: Vec<u32> = (3..p.len() as u32).collect();
        let segs = [[3, 4]];
        let out = run(&p, &points, &segs).unwrap();
        check(&p, &out, &segs);
        let mut se = out.segment_edges.clone();
        se.iter_mut().for_each(|e| e.sort());
        se.sort();
        assert_eq!(se, vec![[3, 5], [4, 5]]);
    }

    #[test]
    fn crossing_segments_and_duplicates_are_errors() {
        let p = vec![
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(0.0, 4.0),
            DVec2::new(1.0, 1.0),
            DVec2::new(2.0, 1.0),
            DVec2::new(1.5, 0.5),
            DVec2::new(1.5, 1.5),
            DVec2::new(1.0, 1.0),
        ];
        assert!(matches!(run(&p, &[3, 4, 5, 6], &[[3, 4], [5, 6]]), Err(ConstrainedError::Crossing(..))));
        assert!(matches!(run(&p, &[3, 4, 5, 6, 7], &[]), Err(ConstrainedError::Duplicate(..))));
        let outside =
            vec![DVec2::new(0.0, 0.0), DVec2::new(4.0, 0.0), DVec2::new(0.0, 4.0), DVec2::new(3.0, 3.0)];
        assert_eq!(run(&outside, &[3], &[]), Err(ConstrainedError::Outside(3)));
    }

    /// Random points and a random set of non-crossing segments (a chain through sorted
    /// points, which cannot cross itself when sorted by angle around a corner).
    #[test]
    fn random_inputs_are_valid_triangulations() {
        let mut rng = Rng::new(5);
        for round in 0..60 {
            let mut p = vec![DVec2::new(0.0, 0.0), DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)];
            let n = 3 + round * 2;
            while p.len() < n + 3 {
                let (x, y) = (rng.next_f64(), rng.next_f64());
                // Snap some to a coarse lattice so that collinear and on-edge points occur.
                let (x, y) = if rng.below(2) == 0 {
                    ((x * 8.0).floor() / 8.0, (y * 8.0).floor() / 8.0)
                } else {
                    (x, y)
                };
                let q = DVec2::new(x, y);
                if x + y <= 1.0 && !p.contains(&q) {
                    p.push(q);
                }
            }
            // Segments: a star from the origin corner to every point, sorted by angle, is
            // crossing-free; keep every other ray and the chain between consecutive points.
            let mut by_angle: Vec<u32> = (3..p.len() as u32).collect();
            by_angle.sort_by(|&a, &b| {
                p[a as usize].y.atan2(p[a as usize].x).total_cmp(&p[b as usize].y.atan2(p[b as usize].x))
            });
            let rays: Vec<[u32; 2]> = by_angle.iter().step_by(3).map(|&x| [0, x]).collect();
            // The chain through the points by angle is star-shaped around the corner: it
            // does not cross itself (rays through collinear points overlap, which is fine).
            let chain: Vec<[u32; 2]> = by_angle.windows(2).map(|w| [w[0], w[1]]).collect();
            let points: Vec<u32> = (3..p.len() as u32).collect();
            for segs in [rays, chain] {
                match run(&p, &points, &segs) {
                    Ok(out) => check(&p, &out, &segs),
                    Err(e) => panic!("round {round}: {e}"),
                }
            }
        }
    }

    /// The orientation oracle is all the triangulation looks at: implicit points whose
    /// rounded positions are useless for decisions triangulate as exactly as explicit ones.
    #[test]
    fn works_on_implicit_points() {
        use crate::exact::implicit::{Point, orient2d_implicit};
        use glam::DVec3;
        // Triangle in the plane z = 0; points where segments (from z = −1 to z = 1) cross
        // it, some exactly on the line between two others.
        let corners = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let plane = corners;
        let mut pts: Vec<Point> = corners.iter().map(|&c| Point::explicit(c)).collect();
        let cross = |x: f64, y: f64, dx: f64, dy: f64| {
            Point::edge_plane(DVec3::new(x - dx, y - dy, -1.0), DVec3::new(x + dx, y + dy, 1.0), plane)
                .unwrap()
        };
        // Crossing points of segments whose ends are rounded: nowhere near f64 values.
        pts.push(cross(0.1, 0.3, 0.01 / 3.0, 0.03 / 3.0));
        pts.push(cross(0.2, 0.6, 0.07 / 3.0, 0.21 / 3.0));
        pts.push(cross(0.4, 0.2, 0.0, 0.0));
        pts.push(cross(0.1, 0.1, 1.0 / 3.0, -1.0 / 7.0));
        let orient = |a: u32, b: u32, c: u32| {
            orient2d_implicit([0, 1], &pts[a as usize], &pts[b as usize], &pts[c as usize])
        };
        let at = |i: u32| pts[i as usize].position().truncate();
        let out = triangulate([0, 1, 2], &[3, 4, 5, 6], &[[3, 5], [5, 4], [6, 3]], orient, at).unwrap();
        for t in &out.triangles {
            assert!(orient(t[0], t[1], t[2]) > 0);
        }
        let used: HashSet<u32> = out.triangles.iter().flatten().copied().collect();
        assert_eq!(used.len(), 7);
        assert_eq!(out.triangles.len(), 2 * 4 + 3 - 2);
        assert_eq!(out.segment_edges.len(), 3);
    }
}
