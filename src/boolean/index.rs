//! Candidate pairs (§6.4): the triangles of A and B whose boxes overlap, from one
//! spatial index over both meshes.
//!
//! The thesis builds one octree over both transformed meshes whose leaves concentrate
//! where the two meet. Here a uniform grid over the region where the two bounding
//! boxes overlap ([`crate::mesh::boxgrid`]) holds the triangles of both meshes that
//! reach into it; only cells holding triangles of both give pairs.

use crate::mesh::boxgrid::{Box3, box_pairs};

/// Pairs (t, u), t a triangle of A and u of B, whose closed boxes overlap, sorted.
pub fn candidate_pairs(a_boxes: &[Box3], b_boxes: &[Box3]) -> Vec<(u32, u32)> {
    box_pairs(a_boxes, Some(b_boxes))
}
