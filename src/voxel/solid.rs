//! The solid as the voxelizer sees it (SPEC §2, §4.1): its simplicial covering. Every
//! face becomes covering triangles oriented like the face (a triangle is itself; an
//! n-gon is the fan (C, Pᵢ, Pᵢ₊₁) around its centroid C), and every covering triangle
//! ABC becomes the tetra OABC with the common apex O = the solid's centroid (§5.3.1:
//! small tetras).
//!
//! All methods and the exact tests use these same covering triangles (the same rounded
//! centroids C), so "the surface" means one thing everywhere.
//!
//! TODO(covering): switch to `mesh::covering::Covering` once it lands on main.

use std::collections::HashMap;

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::Grid;
use crate::mesh::Mesh;

/// The covering of a closed mesh: surface triangles and the apex of the tetras.
#[derive(Clone, Debug)]
pub struct Solid {
    /// Covering triangles, world coordinates, oriented like their faces.
    pub triangles: Vec<[DVec3; 3]>,
    /// The common apex O of the tetras (world coordinates).
    pub apex: DVec3,
}

impl Solid {
    /// The covering of `mesh`, which must be closed: every directed edge a→b needs a twin
    /// b→a (non-manifold edges are fine as long as they pair up).
    pub fn new(mesh: &Mesh) -> Result<Solid> {
        if mesh.num_faces() == 0 {
            return Err(VoxelError::Mesh("the mesh has no faces".into()));
        }
        check_closed(mesh)?;
        let p = mesh.positions();
        let mut triangles = Vec::with_capacity(mesh.num_faces());
        for face in mesh.faces() {
            if face.len() == 3 {
                triangles.push([p[face[0] as usize], p[face[1] as usize], p[face[2] as usize]]);
            } else {
                let c = face.iter().map(|&v| p[v as usize]).sum::<DVec3>() / face.len() as f64;
                for (a, b) in face.iter().zip(face.iter().cycle().skip(1)) {
                    triangles.push([c, p[*a as usize], p[*b as usize]]);
                }
            }
        }
        let apex = centroid_or_centre(&triangles, mesh.bounds());
        Ok(Solid { triangles, apex })
    }

    /// Signed volume Σ det(A−O, B−O, C−O)/6 over the covering (Alg. 3-1).
    pub fn volume(&self) -> f64 {
        self.triangles.iter().map(|t| signed_volume(self.apex, t)).sum()
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
}

/// Sorts four points by y, highest first; ties by x, then z (any fixed order works: the
/// slicing only interpolates edges whose ends have different y).
pub fn sort_by_y(mut v: [DVec3; 4]) -> [DVec3; 4] {
    v.sort_by(|a, b| b.y.total_cmp(&a.y).then(b.x.total_cmp(&a.x)).then(b.z.total_cmp(&a.z)));
    v
}

fn signed_volume(o: DVec3, t: &[DVec3; 3]) -> f64 {
    (t[0] - o).dot((t[1] - o).cross(t[2] - o)) / 6.0
}

/// The volume centroid of the solid; the bounding box centre if the volume is (nearly)
/// zero or the centroid falls outside the box (any apex gives the same voxels; a central
/// one gives small tetras).
fn centroid_or_centre(triangles: &[[DVec3; 3]], (lo, hi): (DVec3, DVec3)) -> DVec3 {
    let c = (lo + hi) * 0.5;
    let (mut volume, mut moment) = (0.0, DVec3::ZERO);
    for t in triangles {
        let v = signed_volume(c, t);
        volume += v;
        moment += v * (t[0] + t[1] + t[2] - 3.0 * c) / 4.0;
    }
    let box_volume = (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE)).element_product();
    let centroid = c + moment / volume;
    let inside = centroid.cmpge(lo).all() && centroid.cmple(hi).all();
    if volume.abs() > 1e-9 * box_volume && centroid.is_finite() && inside { centroid } else { c }
}

/// Every directed edge a→b must have a twin b→a (counted with multiplicity).
fn check_closed(mesh: &Mesh) -> Result<()> {
    let mut balance: HashMap<(u32, u32), i64> = HashMap::new();
    for face in mesh.faces() {
        for (&a, &b) in face.iter().zip(face.iter().cycle().skip(1)) {
            if a == b {
                continue;
            }
            let (key, d) = if a < b { ((a, b), 1) } else { ((b, a), -1) };
            *balance.entry(key).or_insert(0) += d;
        }
    }
    let open: Vec<_> = balance.iter().filter(|(_, d)| **d != 0).collect();
    if let Some(((a, b), _)) = open.first() {
        return Err(VoxelError::Mesh(format!(
            "it is not closed: {} edge(s) lack a twin traversed the other way (e.g. between vertices {a} and {b})",
            open.len()
        )));
    }
    Ok(())
}
