//! Merging intersection points that rounding cannot tell apart (§6.4, robustness).
//!
//! Keys name intersection points exactly, but their coordinates are rounded f64. Where
//! the two surfaces are nearly degenerate to each other — a vertex of one a hair off the
//! other surface, two edges that almost cross — several exactly distinct points fall
//! within a few ulps of each other (or of an input vertex), and after rounding their
//! order along an edge or the side of a segment they lie on may be wrong: the cut
//! triangles' outlines fold or their constraints cross, and no triangulation exists.
//!
//! Such a cluster is one point for every practical purpose, so it becomes one: every new
//! point closer than `tolerance` to another new point joins its cluster (union-find over
//! a hash grid of cell `tolerance`), and a cluster within `tolerance` of an input vertex
//! named by the keys of its members (a corner of a simplex holding one of them) becomes
//! that vertex. The merge is global — one id per cluster for both meshes and every
//! triangle around it — so the cut curve stays shared and crack-free; input vertices are
//! never merged with each other, so no input edge collapses.

use std::collections::HashMap;

use glam::DVec3;

use crate::mesh::disjoint_sets::UnionFind;

/// Tolerance of the merge for points with coordinates up to `max_abs` and operands of
/// bounding-box diagonal `diagonal`: far below any feature of a real model, far above the
/// few ulps by which an intersection point's coordinates are off.
pub fn tolerance(max_abs: f64, diagonal: f64) -> f64 {
    (1e-12 * diagonal).max(64.0 * f64::EPSILON * max_abs)
}

/// The merged id of each new point: `new[k]` has id `first + k`; `anchors(k)` lists the
/// input vertices (by id, below `first`) it may snap to. Returns, per new point, the id
/// it becomes (its own when it stays).
pub fn merge(
    points: &[DVec3],
    first: u32,
    tolerance: f64,
    anchors: impl Fn(usize, &mut Vec<u32>),
) -> Vec<u32> {
    let new = &points[first as usize..];
    let n = new.len();
    let cell = |p: DVec3| (p / tolerance).floor().as_i64vec3().to_array();
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::with_capacity(n);
    for (k, &p) in new.iter().enumerate() {
        grid.entry(cell(p)).or_default().push(k as u32);
    }
    let mut sets = UnionFind::new(n);
    let mut near = false;
    for (k, &p) in new.iter().enumerate() {
        let c = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else { continue };
                    for &j in list {
                        if (j as usize) < k && new[j as usize].distance(p) <= tolerance {
                            sets.union(j, k as u32);
                            near = true;
                        }
                    }
                }
            }
        }
    }
    // Per cluster root: the closest anchor (distance, id).
    let mut best: Vec<(f64, u32)> = vec![(f64::INFINITY, u32::MAX); n];
    let mut candidates = Vec::new();
    for (k, &p) in new.iter().enumerate() {
        candidates.clear();
        anchors(k, &mut candidates);
        for &v in &candidates {
            let d = points[v as usize].distance(p);
            if d <= tolerance {
                let r = sets.find(k as u32) as usize;
                if (d, v) < best[r] {
                    best[r] = (d, v);
                }
                near = true;
            }
        }
    }
    if !near {
        return (first..first + n as u32).collect();
    }
    // A cluster that snaps to no anchor becomes its first point.
    let mut first_member = vec![u32::MAX; n];
    for k in 0..n as u32 {
        let r = sets.find(k) as usize;
        first_member[r] = first_member[r].min(k);
    }
    (0..n as u32)
        .map(|k| {
            let r = sets.find(k) as usize;
            match best[r] {
                (_, v) if v != u32::MAX => v,
                _ => first + first_member[r],
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clusters_merge_and_snap_to_the_closest_named_vertex() {
        let t = 1e-12;
        let points = [
            DVec3::ZERO,                   // 0: input vertex
            DVec3::X,                      // 1: input vertex
            DVec3::new(0.4e-12, 0.0, 0.0), // 2: new, near 0
            DVec3::new(1.2e-12, 0.0, 0.0), // 3: new, near 2 (not 0): joins its cluster
            DVec3::new(0.5, 0.0, 0.0),     // 4: new, alone
            DVec3::new(0.5, 0.5e-12, 0.0), // 5: new, near 4
            DVec3::new(1.0, 2e-12, 0.0),   // 6: new, too far from 1
        ];
        let map = merge(&points, 2, t, |_, out| out.extend([0, 1]));
        assert_eq!(map, vec![0, 0, 4, 4, 6]);
        // Without a named anchor the cluster keeps its smallest member.
        let map = merge(&points, 2, t, |_, _| {});
        assert_eq!(map, vec![2, 2, 4, 4, 6]);
        assert_eq!(merge(&points[..2], 2, t, |_, _| {}), Vec::<u32>::new());
    }
}
