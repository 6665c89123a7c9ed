//! Polygon meshes: the type every algorithm consumes, file formats, validation,
//! simplicial coverings (SPEC §1–2) and built-in procedural models.

use glam::DVec3;

pub mod boxgrid;
pub mod constrained;
pub mod covering;
pub mod crosstree;
pub mod disjoint_sets;
pub mod error;
pub mod formats;
pub mod frame;
pub mod hash;
pub mod intersect;
pub mod procedural;
pub mod solidity;
pub mod spec;
pub mod stats;
pub mod transform;
pub mod triangulate;
pub mod validate;

pub use error::{MeshError, Result};
pub use validate::Report;

/// A polygon mesh with f64 positions and faces of any degree ≥ 3.
///
/// Faces are stored compressed (CSR): face `f` is
/// `indices[offsets[f]..offsets[f + 1]]`, counter-clockwise seen from outside.
/// A `Mesh` is always valid by construction: every index is in range, every
/// face has at least three vertices, every coordinate is finite, and there are fewer than
/// 2^32 vertices and 2^32 face corners (so both fit in a u32).
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    positions: Vec<DVec3>,
    offsets: Vec<usize>,
    indices: Vec<u32>,
}

impl Mesh {
    /// Builds a mesh from positions and faces, checking indices, degrees and coordinates.
    pub fn new(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Result<Mesh> {
        let mut offsets = Vec::with_capacity(faces.len() + 1);
        let mut indices = Vec::with_capacity(faces.iter().map(Vec::len).sum());
        offsets.push(0);
        for face in faces {
            indices.extend_from_slice(&face);
            offsets.push(indices.len());
        }
        Mesh::from_parts(positions, offsets, indices)
    }

    /// Builds a mesh from CSR parts (`offsets` has one more entry than there are faces).
    pub fn from_parts(positions: Vec<DVec3>, offsets: Vec<usize>, indices: Vec<u32>) -> Result<Mesh> {
        if positions.len() > u32::MAX as usize {
            return Err(MeshError::invalid("more than 2^32 vertices"));
        }
        if let Some((i, p)) = positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(MeshError::invalid(format!("vertex {i} has a non-finite coordinate {p}")));
        }
        if indices.len() > u32::MAX as usize {
            return Err(MeshError::invalid("more than 2^32 face corners"));
        }
        if offsets.first() != Some(&0) || offsets.last() != Some(&indices.len()) {
            return Err(MeshError::invalid("face offsets do not span the index list"));
        }
        for (f, w) in offsets.windows(2).enumerate() {
            if w[1] < w[0] + 3 {
                return Err(MeshError::invalid(format!("face {f} has fewer than 3 vertices")));
            }
            for &i in &indices[w[0]..w[1]] {
                if i as usize >= positions.len() {
                    return Err(MeshError::invalid(format!(
                        "face {f} uses vertex {i}, but there are only {} vertices",
                        positions.len()
                    )));
                }
            }
        }
        Ok(Mesh { positions, offsets, indices })
    }

    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    pub fn num_vertices(&self) -> usize {
        self.positions.len()
    }

    pub fn num_faces(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The vertex indices of face `f`, in order.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.indices[self.offsets[f]..self.offsets[f + 1]]
    }

    pub fn faces(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets.windows(2).map(|w| &self.indices[w[0]..w[1]])
    }

    /// CSR offsets and indices, for code that uploads faces as-is.
    pub fn face_parts(&self) -> (&[usize], &[u32]) {
        (&self.offsets, &self.indices)
    }

    /// True when every face is a triangle.
    pub fn is_triangle_mesh(&self) -> bool {
        self.faces().all(|f| f.len() == 3)
    }

    /// Axis-aligned bounding box (min, max); both zero for an empty mesh.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        if self.positions.is_empty() {
            return (DVec3::ZERO, DVec3::ZERO);
        }
        self.positions
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)))
    }

    /// A copy with every position mapped by `f` (the result is re-checked for finiteness).
    pub fn map_positions(&self, f: impl Fn(DVec3) -> DVec3) -> Result<Mesh> {
        Mesh::from_parts(
            self.positions.iter().map(|&p| f(p)).collect(),
            self.offsets.clone(),
            self.indices.clone(),
        )
    }
}
