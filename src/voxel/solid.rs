//! The solid as the voxelizer sees it (SPEC §2, §4.1): its simplicial covering. Every
//! face becomes covering triangles oriented like the face (a triangle is itself; an
//! n-gon is the fan (C, Pᵢ, Pᵢ₊₁) around its centroid C), and every covering triangle
//! ABC becomes the tetra OABC with the common apex O = the solid's centroid (§5.3.1:
//! small tetras).
//!
//! All methods and the exact tests use these same covering triangles (the same rounded
//! centroids C, from [`Covering`]), so "the surface" means one thing everywhere.

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::Grid;
use crate::mesh::Mesh;
use crate::mesh::covering::Covering;

/// The covering of a closed mesh: surface triangles and the apex of the tetras.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Covering triangles, world coordinates, oriented like their faces.
    pub triangles: Vec<[DVec3; 3]>,
    /// The common apex O of the tetras (world coordinates).
    pub apex: DVec3,
}

impl Solid {
    /// The covering of `mesh`, which must be closed and consistently oriented: every
    /// directed edge a→b needs a twin b→a (non-manifold edges are fine as long as they
    /// pair up). A mesh without faces is the empty solid (no triangles).
    pub fn new(mesh: &Mesh) -> Result<Solid> {
        let covering = Covering::new(mesh);
        if let Some(e) = covering.unbalanced_edge() {
            return Err(VoxelError::Mesh(format!(
                "it is not closed and consistently oriented: edge {}–{} is used {} time(s) as {0}→{1} but {} time(s) as {1}→{0}",
                e.a, e.b, e.forward, e.backward
            )));
        }
        let triangles: Vec<[DVec3; 3]> =
            (0..covering.triangles.len()).map(|t| covering.triangle(t)).collect();
        let (lo, hi) = mesh.bounds();
        // The volume centroid (§5.3.1: small tetras), or the box centre when the volume is
        // about zero or the centroid falls outside the box; any apex gives the same voxels.
        let apex = covering
            .centroid()
            .filter(|c| c.is_finite() && c.cmpge(lo).all() && c.cmple(hi).all())
            .unwrap_or((lo + hi) * 0.5);
        Ok(Solid { triangles, apex })
    }

    /// The tetras (O, A, B, C) in grid units, vertices sorted by y, highest first (ties
    /// by x, then z), as the slicing of SPEC §4.2 wants them.
    pub fn sorted_tetras(&self, grid: &Grid) -> Vec<[DVec3; 4]> {
        let o = grid.to_grid(self.apex);
        self.triangles
            .iter()
            .map(|t| sort_by_y([o, grid.to_grid(t[0]), grid.to_grid(t[1]), grid.to_grid(t[2])]))
            .collect()
    }

    /// The covering triangles in grid units.
    pub fn grid_triangles(&self, grid: &Grid) -> Vec<[DVec3; 3]> {
        self.triangles.iter().map(|t| t.map(|p| grid.to_grid(p))).collect()
    }

    /// The tetras (O, A, B, C) in world coordinates.
    pub fn tetras(&self) -> Vec<[DVec3; 4]> {
        self.triangles.iter().map(|t| [self.apex, t[0], t[1], t[2]]).collect()
    }
}

/// Sorts four points by y, highest first; ties by x, then z (any fixed order works: the
/// slicing only interpolates edges whose ends have different y).
pub fn sort_by_y(mut v: [DVec3; 4]) -> [DVec3; 4] {
    v.sort_by(|a, b| b.y.total_cmp(&a.y).then(b.x.total_cmp(&a.x)).then(b.z.total_cmp(&a.z)));
    v
}
