//! Bounding-box hierarchy over the covering tetras (§4.3.2.2, Table 4-1 "jerarquía de
//! cajas"): a point is tested only against the tetras whose grown boxes hold it.
//!
//! The thesis notes the weakness: tetras joined to one apex are long and their boxes big,
//! so few are discarded near the apex. Kept as the thesis' comparison point.

use std::time::Instant;

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::cpu::FeitoTorres;
use super::tetra::CompactPlanes;

/// Tetras per leaf.
const LEAF: usize = 4;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first index into `order`; inner node: index of the left child (right = +1).
    first: u32,
    /// Leaf: number of tetras; inner node: 0.
    count: u32,
}

impl Node {
    #[inline]
    fn holds(&self, q: DVec3) -> bool {
        q.cmpge(self.lo).all() && q.cmple(self.hi).all()
    }
}

/// Feito-Torres over a BVH of tetra boxes.
#[derive(Clone, Debug)]
pub struct Bvh {
    ft: FeitoTorres,
    nodes: Vec<Node>,
    order: Vec<u32>,
    compact: Vec<CompactPlanes>,
    index_stats: BuildStats,
}

impl Bvh {
    /// Builds the hierarchy over `ft`'s tetras (median split on the longest axis).
    pub fn new(ft: FeitoTorres) -> Bvh {
        let start = Instant::now();
        let tetras = ft.tetras();
        let mut order: Vec<u32> = (0..tetras.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * tetras.len() / LEAF + 1);
        let centre = |t: u32| (tetras[t as usize].lo + tetras[t as usize].hi) * 0.5;
        // Explicit stack of (node index, range in `order`).
        nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 });
        let mut stack = vec![(0usize, 0usize, order.len())];
        while let Some((n, a, b)) = stack.pop() {
            let (lo, hi) = order[a..b].iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &t| {
                (lo.min(tetras[t as usize].lo), hi.max(tetras[t as usize].hi))
            });
            if b - a <= LEAF {
                nodes[n] = Node { lo, hi, first: a as u32, count: (b - a) as u32 };
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
            nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 });
            nodes.push(Node { lo: DVec3::ZERO, hi: DVec3::ZERO, first: 0, count: 0 });
            nodes[n] = Node { lo, hi, first: left as u32, count: 0 };
            stack.push((left, a, mid));
            stack.push((left + 1, mid, b));
        }
        let compact = ft.compact_planes();
        let bytes = vec_bytes(&nodes) + vec_bytes(&order) + vec_bytes(&compact);
        let index_stats = BuildStats { build_time: start.elapsed(), bytes };
        Bvh { ft, nodes, order, compact, index_stats }
    }

    pub fn base(&self) -> &FeitoTorres {
        &self.ft
    }

    /// Time and memory of the hierarchy alone.
    pub fn index_stats(&self) -> BuildStats {
        self.index_stats
    }

    /// The tetras whose grown boxes hold `p`, leaf by leaf.
    pub fn candidates(&self, p: DVec3) -> Candidates<'_> {
        let q = p - self.ft.apex();
        let mut stack = [0u32; 64];
        let mut depth = 0;
        if !self.order.is_empty() {
            stack[0] = 0;
            depth = 1;
        }
        Candidates { bvh: self, q, stack, depth, leaf: 0..0 }
    }
}

/// Iterator over the tetras of the BVH leaves holding a point (no allocation).
pub struct Candidates<'a> {
    bvh: &'a Bvh,
    q: DVec3,
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
            if !node.holds(self.q) {
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
