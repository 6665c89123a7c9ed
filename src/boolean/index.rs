//! Candidate pairs (§6.4): the triangles of A and B whose boxes overlap, from one
//! spatial index over both meshes.
//!
//! The thesis builds one octree over both transformed meshes whose leaves concentrate
//! where the two meet. The same effect here: only triangles whose boxes reach into the
//! overlap of the two bounding boxes enter the index at all, the box hierarchy
//! ([`BoxTree`]) is built over those of B, and those of A query it in parallel.

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::intersect::BoxTree;

/// The closed-box overlap of two boxes, if any.
fn overlap(a: (DVec3, DVec3), b: (DVec3, DVec3)) -> Option<(DVec3, DVec3)> {
    let lo = a.0.max(b.0);
    let hi = a.1.min(b.1);
    lo.cmple(hi).all().then_some((lo, hi))
}

fn hull(boxes: &[(DVec3, DVec3)]) -> (DVec3, DVec3) {
    boxes.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), b| (lo.min(b.0), hi.max(b.1)))
}

/// Pairs (t, u), t a triangle of A and u of B, whose closed boxes overlap, sorted.
pub fn candidate_pairs(a_boxes: &[(DVec3, DVec3)], b_boxes: &[(DVec3, DVec3)]) -> Vec<(u32, u32)> {
    let Some(common) = overlap(hull(a_boxes), hull(b_boxes)) else { return Vec::new() };
    let reaching = |boxes: &[(DVec3, DVec3)]| -> Vec<u32> {
        (0..boxes.len() as u32)
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&t| overlap(boxes[t as usize], common).is_some())
            .collect()
    };
    let (a_ids, b_ids) = rayon::join(|| reaching(a_boxes), || reaching(b_boxes));
    let tree = BoxTree::over(b_boxes, b_ids);
    let mut pairs: Vec<(u32, u32)> = a_ids
        .par_iter()
        .with_min_len(256)
        .fold(Vec::new, |mut acc, &t| {
            let (lo, hi) = a_boxes[t as usize];
            tree.query(lo, hi, |u| acc.push((t, u)));
            acc
        })
        .reduce(Vec::new, |mut x, mut y| {
            if x.len() < y.len() {
                std::mem::swap(&mut x, &mut y);
            }
            x.extend(y);
            x
        });
    pairs.par_sort_unstable();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pairs_are_exactly_the_overlapping_boxes() {
        let a: Vec<(DVec3, DVec3)> =
            (0..50).map(|i| (DVec3::splat(i as f64), DVec3::splat(i as f64 + 1.5))).collect();
        let b: Vec<(DVec3, DVec3)> =
            (0..30).map(|i| (DVec3::splat(2.0 * i as f64), DVec3::splat(2.0 * i as f64 + 0.5))).collect();
        let brute: Vec<(u32, u32)> = (0..a.len() as u32)
            .flat_map(|t| (0..b.len() as u32).map(move |u| (t, u)))
            .filter(|&(t, u)| overlap(a[t as usize], b[u as usize]).is_some())
            .collect();
        assert_eq!(candidate_pairs(&a, &b), brute);
        assert!(!brute.is_empty());
    }
}
