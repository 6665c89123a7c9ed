//! Jordan ray crossings accelerated by an octree of the covering triangles (§4.2.2, the
//! thesis' "Jordan (Octree-6)"): only triangles in leaves the ray passes are tested.
//!
//! A triangle sits in every leaf its box (grown by ε) meets, so a ray can meet it in
//! several leaves; a crossing is counted only in the leaf that owns its hit point, the
//! leaves being half-open boxes [lo, hi) that tile the root exactly (children split at the
//! same midpoints their parent stores). The hit point is computed the same way in every
//! leaf, so exactly one leaf counts it.

use std::time::Instant;

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier, vec_bytes};
use super::error::{InclusionError, Result};
use super::jordan::{Hit, cast, ray_hit, segment_meets_box};
use super::surface::Surface;
use crate::mesh::Mesh;

/// Triangles a leaf may hold before it is split (when the depth allows).
const LEAF: usize = 16;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Index of the first of 8 children (0 for a leaf: the root is nobody's child).
    children: u32,
    /// Leaf triangles: `items[start..start + count]`.
    start: u32,
    count: u32,
}

impl Node {
    #[inline]
    fn owns(&self, x: DVec3) -> bool {
        x.x >= self.lo.x
            && x.y >= self.lo.y
            && x.z >= self.lo.z
            && x.x < self.hi.x
            && x.y < self.hi.y
            && x.z < self.hi.z
    }
}

/// Jordan crossings over an octree of covering triangles.
#[derive(Clone, Debug)]
pub struct JordanOctree {
    surface: Surface,
    nodes: Vec<Node>,
    items: Vec<u32>,
    depth: u32,
    /// How far triangle and node boxes are grown: ε, plus the rounding of hit points far
    /// from the origin (a crossing belongs to the leaf that owns its computed point, which
    /// must list the triangle).
    slack: f64,
    stats: BuildStats,
}

impl JordanOctree {
    /// Builds an octree of at most `depth` levels below the root (1..=10).
    pub fn new(mesh: &Mesh, depth: u32) -> Result<JordanOctree> {
        JordanOctree::with_policy(mesh, depth, false)
    }

    /// `allow_open` accepts open surfaces (see [`Surface::with_policy`]).
    pub fn with_policy(mesh: &Mesh, depth: u32, allow_open: bool) -> Result<JordanOctree> {
        if !(1..=10).contains(&depth) {
            return Err(InclusionError::OctreeDepth(depth));
        }
        let start = Instant::now();
        let surface = Surface::with_policy(mesh, allow_open)?;
        let eps = surface.eps();
        let covering = surface.covering();
        let (lo, hi) = surface.bounds();
        let slack = eps + 16.0 * f64::EPSILON * lo.abs().max(hi.abs()).max_element();
        let boxes: Vec<(DVec3, DVec3)> = (0..covering.triangles.len())
            .map(|t| {
                let [a, b, c] = covering.triangle(t);
                (a.min(b).min(c) - slack, a.max(b).max(c) + slack)
            })
            .collect();
        // The root strictly contains the bounding box grown by the slack, so every point that
        // can be on the boundary, and every hit point, is owned by some leaf.
        let (root_lo, root_hi) =
            (lo - 2.0 * slack - DVec3::splat(f64::MIN_POSITIVE), hi + 2.0 * slack + (hi - lo) * 1e-9);
        let mut nodes = vec![Node { lo: root_lo, hi: root_hi, children: 0, start: 0, count: 0 }];
        let mut items = Vec::new();
        let mut stack = vec![(0usize, 0u32, (0..boxes.len() as u32).collect::<Vec<u32>>())];
        while let Some((n, level, tris)) = stack.pop() {
            if level >= depth || tris.len() <= LEAF {
                nodes[n].start = items.len() as u32;
                nodes[n].count = tris.len() as u32;
                items.extend_from_slice(&tris);
                continue;
            }
            let (nlo, nhi) = (nodes[n].lo, nodes[n].hi);
            let mid = (nlo + nhi) * 0.5;
            let first = nodes.len();
            nodes[n].children = first as u32;
            for k in 0..8 {
                let pick = |axis: usize, lo: f64, mid: f64, hi: f64| {
                    if k >> axis & 1 == 1 { (mid, hi) } else { (lo, mid) }
                };
                let (x0, x1) = pick(0, nlo.x, mid.x, nhi.x);
                let (y0, y1) = pick(1, nlo.y, mid.y, nhi.y);
                let (z0, z1) = pick(2, nlo.z, mid.z, nhi.z);
                nodes.push(Node {
                    lo: DVec3::new(x0, y0, z0),
                    hi: DVec3::new(x1, y1, z1),
                    children: 0,
                    start: 0,
                    count: 0,
                });
            }
            for k in 0..8 {
                let (clo, chi) = (nodes[first + k].lo, nodes[first + k].hi);
                let inside: Vec<u32> = tris
                    .iter()
                    .copied()
                    .filter(|&t| {
                        let (tlo, thi) = boxes[t as usize];
                        tlo.cmple(chi).all() && thi.cmpge(clo).all()
                    })
                    .collect();
                stack.push((first + k, level + 1, inside));
            }
        }
        let bytes = surface.bytes() + vec_bytes(&nodes) + vec_bytes(&items);
        Ok(JordanOctree {
            surface,
            nodes,
            items,
            depth,
            slack,
            stats: BuildStats { build_time: start.elapsed(), bytes },
        })
    }

    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// The octree alone (nodes and triangle lists), without the shared surface data.
    pub fn index_stats(&self) -> BuildStats {
        BuildStats {
            build_time: self.stats.build_time,
            bytes: vec_bytes(&self.nodes) + vec_bytes(&self.items),
        }
    }

    fn leaf_items(&self, node: &Node) -> &[u32] {
        &self.items[node.start as usize..(node.start + node.count) as usize]
    }

    /// The leaf owning `p`, if `p` is in the root.
    fn leaf_of(&self, p: DVec3) -> Option<&Node> {
        let mut node = &self.nodes[0];
        if !node.owns(p) {
            return None;
        }
        while node.children != 0 {
            let mid = (node.lo + node.hi) * 0.5;
            let k = (p.x >= mid.x) as usize | ((p.y >= mid.y) as usize) << 1 | ((p.z >= mid.z) as usize) << 2;
            node = &self.nodes[node.children as usize + k];
        }
        Some(node)
    }

    /// Signed crossings along `d`, or `None` when the ray must be cast again.
    fn crossings(&self, p: DVec3, d: DVec3, reach: f64) -> Option<i32> {
        let covering = self.surface.covering();
        let slack = self.slack;
        let mut w = 0;
        let mut stack = [0u32; 96];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !segment_meets_box(p, d, reach, node.lo - slack, node.hi + slack) {
                continue;
            }
            if node.children != 0 {
                for k in 0..8 {
                    stack[top] = node.children + k;
                    top += 1;
                }
                continue;
            }
            for &t in self.leaf_items(node) {
                let [a, b, c] = covering.triangle(t as usize);
                match ray_hit(p, d, a, b, c, reach) {
                    Hit::Miss => {}
                    Hit::Cross { sign, x } => {
                        if node.owns(x) {
                            w += sign;
                        }
                    }
                    Hit::Degenerate => return None,
                }
            }
        }
        Some(w)
    }
}

impl Classifier for JordanOctree {
    fn name(&self) -> &str {
        "jordan-octree"
    }

    fn classify(&self, p: DVec3) -> Class {
        let surface = &self.surface;
        if !surface.in_bounds(p) {
            return Class::Outside;
        }
        // Every triangle within ε of p has a grown box holding p, hence is in p's leaf.
        let p = match self.leaf_of(p) {
            Some(leaf) => match surface.off_boundary(p, self.leaf_items(leaf).iter().map(|&t| t as usize)) {
                Some(p) => p,
                None => return Class::OnBoundary,
            },
            None => p,
        };
        cast(surface, p, |p, d, reach| self.crossings(p, d, reach))
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}
