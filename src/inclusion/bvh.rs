//! Bounding-box hierarchy over the covering tetras (§4.3.2.2, Table 4-1 "jerarquía de
//! cajas"): a point is tested only against the tetras whose grown boxes hold it.
//!
//! The thesis notes the weakness: tetras joined to one apex are long and their boxes big,
//! so few are discarded near the apex. Boxes alone are kept as the thesis' comparison
//! point in its structure; each node also carries the box of its tetras' base triangles,
//! and a point is only sent into a node when the ray from it away from the apex meets
//! that box (grown by a proven margin): a point in a tetra sees the tetra's base along
//! that ray, so the test drops no tetra the verdict would count, and what is left is the
//! handful of tetras around one ray instead of every tetra whose box holds the point.
//!
//! The margin. The verdict counts q when its four plane values are ≥ −ε (in f64), so q
//! lies in the tetra T′ bounded by the planes moved out by ε′ (ε plus the f64 error of a
//! plane value). T′ has apex O + w and base vertices Qᵢ + δᵢ, shifts found by solving the
//! moved planes (|w|, |δᵢ| ≤ W: about ε times the tetra's conditioning). The ray from q
//! away from O + w meets T′'s base at y = q + s·(q − O − w), with s = |y − q| / |q − O − w|
//! ≤ (D + 2W)/(|q − O| − W) for a tetra box diagonal ≤ D; the ray away from O passes
//! within s·W of y, and y is within W of the base triangle's box. Hence the margin
//! W·(1 + (D + 2W)/(|q − O| − W)), plus the rounding of the ray-box test; points with
//! |q − O| ≤ W, and nodes holding a flat or degenerate tetra (W = ∞), skip the ray test.

use std::time::Instant;

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::cpu::FeitoTorres;
use super::tetra::{CompactPlanes, Kind, TetraPlanes};

/// Tetras per leaf.
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    /// Box of the tetras (grown by ε, as in the verdict), relative to the apex.
    lo: DVec3,
    hi: DVec3,
    /// Box of their base triangles, relative to the apex.
    base_lo: DVec3,
    base_hi: DVec3,
    /// Largest shift W of their moved planes' vertices (module docs); ∞ when one is not
    /// regular.
    shift: f64,
    /// Leaf: first index into `order`; inner node: index of the left child (right = +1).
    first: u32,
    /// Leaf: number of tetras; inner node: 0.
    count: u32,
}

const EMPTY: Node = Node {
    lo: DVec3::ZERO,
    hi: DVec3::ZERO,
    base_lo: DVec3::ZERO,
    base_hi: DVec3::ZERO,
    shift: 0.0,
    first: 0,
    count: 0,
};

impl Node {
    #[inline]
    fn holds(&self, q: DVec3) -> bool {
        q.cmpge(self.lo).all() && q.cmple(self.hi).all()
    }

    /// Whether the ray {λ·q : λ ≥ 1} (from q away from the apex) may meet a base of this
    /// node's tetras (module docs): `ray.norm` is |q|, `ray.diag` the bound D.
    #[inline]
    fn on_ray(&self, q: DVec3, ray: &Ray) -> bool {
        let w = self.shift;
        if ray.norm <= w || !w.is_finite() {
            return true;
        }
        // The rounding of the slab test below: a few ulps of coordinates within D.
        let m = w * (1.0 + (ray.diag + 2.0 * w) / (ray.norm - w)) + 1e-14 * ray.diag;
        let (lo, hi) = (self.base_lo - m, self.base_hi + m);
        let (mut a, mut b) = (1.0f64, f64::INFINITY);
        for axis in 0..3 {
            let (qa, l, h) = (q[axis], lo[axis], hi[axis]);
            if qa == 0.0 {
                if l > 0.0 || h < 0.0 {
                    return false;
                }
            } else {
                let (t0, t1) = if qa > 0.0 { (l / qa, h / qa) } else { (h / qa, l / qa) };
                a = a.max(t0);
                b = b.min(t1);
            }
        }
        a <= b
    }
}

/// What a query needs for [`Node::on_ray`].
#[derive(Clone, Copy, Debug)]
struct Ray {
    norm: f64,
    diag: f64,
}

/// The largest shift of a regular tetra's vertices when its four planes (unit normals)
/// move out by `eps`: each vertex is where three of the planes meet, and moves by
/// eps·|Σ of the pairwise cross products| / |det| (Cramer's rule); ∞ for flat and
/// degenerate tetras.
fn vertex_shift(t: &TetraPlanes, eps: f64) -> f64 {
    if t.kind != Kind::Regular {
        return f64::INFINITY;
    }
    let [n0, n1, n2] = t.side;
    let b = t.base;
    // Apex: sides 0, 1, 2; Q1: sides 0 and 2 and the base; Q2: 0, 1, base; Q3: 1, 2, base.
    let shift = |a: DVec3, b: DVec3, c: DVec3| {
        let det = a.dot(b.cross(c)).abs();
        let sum = (b.cross(c) + c.cross(a) + a.cross(b)).length();
        if det > 0.0 { eps * sum / det } else { f64::INFINITY }
    };
    let w = shift(n0, n1, n2).max(shift(n0, n2, b)).max(shift(n0, n1, b)).max(shift(n1, n2, b));
    // The f64 solve's own rounding is far below 1 %.
    if w.is_finite() { w * 1.01 } else { f64::INFINITY }
}

/// Feito-Torres over a BVH of tetra boxes.
#[derive(Clone, Debug)]
pub struct Bvh {
    ft: FeitoTorres,
    nodes: Vec<Node>,
    order: Vec<u32>,
    compact: Vec<CompactPlanes>,
    index_stats: BuildStats,
    /// Diagonal of the root box: bounds every tetra's size (D in the module docs).
    diag: f64,
}

impl Bvh {
    /// Builds the hierarchy over `ft`'s tetras (median split on the longest axis).
    pub fn new(ft: FeitoTorres) -> Bvh {
        let start = Instant::now();
        let tetras = ft.tetras();
        let o = ft.apex();
        let (slo, shi) = ft.surface().bounds();
        // ε′: ε plus the f64 error of a plane value (unit normals, |q|₁ and offsets within
        // a few box diagonals).
        let eps = ft.surface().eps() + 1e-14 * ((shi - o).abs() + (slo - o).abs()).element_sum();
        let bases: Vec<(DVec3, DVec3, f64)> = (0..tetras.len())
            .map(|t| {
                let [a, b, c] = ft.tetra_vertices(t).map(|v| v - o);
                (a.min(b).min(c), a.max(b).max(c), vertex_shift(&tetras[t], eps))
            })
            .collect();
        let mut order: Vec<u32> = (0..tetras.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * tetras.len() / LEAF + 1);
        // Split on the base triangles' centres: the ray test prunes by them.
        let centre = |t: u32| (bases[t as usize].0 + bases[t as usize].1) * 0.5;
        // Explicit stack of (node index, range in `order`).
        nodes.push(EMPTY);
        let mut stack = vec![(0usize, 0usize, order.len())];
        while let Some((n, a, b)) = stack.pop() {
            let mut node = order[a..b].iter().fold(
                Node {
                    lo: DVec3::INFINITY,
                    hi: DVec3::NEG_INFINITY,
                    base_lo: DVec3::INFINITY,
                    base_hi: DVec3::NEG_INFINITY,
                    ..EMPTY
                },
                |n, &t| {
                    let (tp, base) = (&tetras[t as usize], &bases[t as usize]);
                    Node {
                        lo: n.lo.min(tp.lo),
                        hi: n.hi.max(tp.hi),
                        base_lo: n.base_lo.min(base.0),
                        base_hi: n.base_hi.max(base.1),
                        shift: n.shift.max(base.2),
                        ..n
                    }
                },
            );
            if b - a <= LEAF {
                nodes[n] = Node { first: a as u32, count: (b - a) as u32, ..node };
                continue;
            }
            let (clo, chi) =
                order[a..b].iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &t| {
                    (lo.min(centre(t)), hi.max(centre(t)))
                });
            let ext = chi - clo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = (a + b) / 2;
            order[a..b].select_nth_unstable_by(mid - a, |&s, &t| centre(s)[axis].total_cmp(&centre(t)[axis]));
            let left = nodes.len();
            nodes.push(EMPTY);
            nodes.push(EMPTY);
            node.first = left as u32;
            nodes[n] = node;
            stack.push((left, a, mid));
            stack.push((left + 1, mid, b));
        }
        let compact = ft.compact_planes();
        let bytes = vec_bytes(&nodes) + vec_bytes(&order) + vec_bytes(&compact);
        let index_stats = BuildStats { build_time: start.elapsed(), bytes };
        let diag = nodes.first().map_or(0.0, |root| (root.hi - root.lo).length());
        Bvh { ft, nodes, order, compact, index_stats, diag }
    }

    pub fn base(&self) -> &FeitoTorres {
        &self.ft
    }

    /// Time and memory of the hierarchy alone.
    pub fn index_stats(&self) -> BuildStats {
        self.index_stats
    }

    /// The tetras whose grown boxes hold `p` and whose bases the ray from `p` away from
    /// the apex may meet, leaf by leaf.
    pub fn candidates(&self, p: DVec3) -> Candidates<'_> {
        let q = p - self.ft.apex();
        let ray = Ray { norm: q.length(), diag: self.diag };
        let mut stack = [0u32; 64];
        let mut depth = 0;
        if !self.order.is_empty() {
            stack[0] = 0;
            depth = 1;
        }
        Candidates { bvh: self, q, ray, stack, depth, leaf: 0..0 }
    }
}

/// Iterator over the tetras of the BVH leaves holding a point (no allocation).
pub struct Candidates<'a> {
    bvh: &'a Bvh,
    q: DVec3,
    ray: Ray,
    stack: [u32; 64],
    depth: usize,
    leaf: std::ops::Range<usize>,
}

impl Iterator for Candidates<'_> {
    type Item = u32;

    fn next(&mut self) -> Option<u32> {
        loop {
            if let Some(i) = self.leaf.next() {
                return Some(self.bvh.order[i]);
            }
            if self.depth == 0 {
                return None;
            }
            self.depth -= 1;
            let node = &self.bvh.nodes[self.stack[self.depth] as usize];
            if !node.holds(self.q) || !node.on_ray(self.q, &self.ray) {
                continue;
            }
            if node.count > 0 {
                self.leaf = node.first as usize..(node.first + node.count) as usize;
            } else if self.depth + 2 <= self.stack.len() {
                self.stack[self.depth] = node.first;
                self.stack[self.depth + 1] = node.first + 1;
                self.depth += 2;
            }
        }
    }
}

impl Classifier for Bvh {
    fn name(&self) -> &str {
        "bvh"
    }

    fn classify(&self, p: DVec3) -> Class {
        self.ft.classify_among_compact(p, self.candidates(p), &self.compact)
    }

    fn build_stats(&self) -> BuildStats {
        let base = self.ft.build_stats();
        BuildStats {
            build_time: base.build_time + self.index_stats.build_time,
            bytes: base.bytes + self.index_stats.bytes,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inclusion::cpu::APEX_BALL;
    use crate::inclusion::tetra::{Verdict, octant_bit};
    use crate::mesh::procedural;
    use crate::random::Rng;

    /// Every tetra whose verdict is not `Outside` is a candidate: points spread out, on and
    /// a few ε off the tetras' faces (through the apex and bases), near their vertices and
    /// just outside the apex ball.
    #[test]
    fn the_ray_test_keeps_every_tetra_the_verdict_counts() {
        let mut rng = Rng::new(11);
        for mesh in [procedural::torus_knot(), procedural::cube_with_cavity(), procedural::sphere(40, 60)] {
            let bvh = Bvh::new(FeitoTorres::new(&mesh).unwrap());
            let ft = bvh.base();
            let (o, eps) = (ft.apex(), ft.surface().eps());
            let (lo, hi) = ft.surface().bounds();
            let n = ft.tetras().len();
            let mut kept = 0usize;
            let mut counted = 0usize;
            for i in 0..4000 {
                let t = rng.below(n as u64) as usize;
                let [a, b, c] = ft.tetra_vertices(t);
                let (u, v) = (rng.next_f64(), rng.next_f64());
                let off = rng.range_f64(-3.0, 3.0) * eps;
                let p = match i % 6 {
                    0 => rng.point_in_box(lo - (hi - lo) * 0.1, hi + (hi - lo) * 0.1),
                    // A face through the apex.
                    1 => o + (a - o) * u + (b - o) * (1.0 - u) * v,
                    // The base.
                    2 => a + (b - a) * u + (c - a) * (1.0 - u) * v,
                    // Near a vertex.
                    3 => [a, b, c][rng.below(3) as usize] + DVec3::splat(off),
                    // Just outside the apex ball, towards the base.
                    4 => o + (a - o).normalize() * ft.surface().scale() * APEX_BALL * 1.5,
                    _ => o + ((a + b + c) / 3.0 - o) * rng.range_f64(0.0, 1.2),
                };
                let p = p + DVec3::new(off, -off, off * 0.5);
                let q = p - o;
                let octant = octant_bit(q);
                let candidates: std::collections::HashSet<u32> = bvh.candidates(p).collect();
                kept += candidates.len();
                for (t, tp) in ft.tetras().iter().enumerate() {
                    if !matches!(tp.verdict(q, octant, eps), Verdict::Outside) {
                        counted += 1;
                        assert!(candidates.contains(&(t as u32)), "tetra {t} dropped for point {p}");
                    }
                }
            }
            // The test is not vacuous, and the ray prunes.
            assert!(counted > 1000, "{counted}");
            assert!(n < 1000 || kept < 4000 * n / 20, "{kept} candidates for {n} tetras");
        }
    }
}
