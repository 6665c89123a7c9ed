//! Generalized winding number: the independent oracle (SPEC §3.4 comparisons).
//!
//! w(P) = Σ Ω(t) / 4π over the covering triangles, Ω the signed solid angle of a triangle
//! seen from P (Van Oosterom & Strackee 1983). Negative triangles of non-convex faces
//! subtract what their positive partners add, so the covering works as is. Inside iff
//! w ≥ ½ (the rule of [`crate::mesh::solidity`]: on a valid solid w is 0 or 1; on an open
//! surface, accepted with `--allow-open`, it is the generalized winding number); within ε
//! of a face, OnBoundary (the shared rule of [`crate::inclusion`]).

use glam::DVec3;

use super::classifier::{BuildStats, Class, Classifier};
use super::error::Result;
use super::surface::Surface;
use crate::mesh::Mesh;

pub use crate::mesh::covering::solid_angle;

/// Winding number of the covering around `p` (≈ integer away from the boundary).
pub fn winding_number(surface: &Surface, p: DVec3) -> f64 {
    let covering = surface.covering();
    covering.winding_number(0..covering.triangles.len(), p)
}

/// The last word of the Feito-Torres and Jordan methods when their own passes stay
/// ambiguous: OnBoundary within ε of a face, else their rule, Inside iff w is non-zero
/// (|w| ≥ ½). On a valid solid this is [`classify`]'s answer.
pub fn classify_nonzero(surface: &Surface, p: DVec3) -> Class {
    match surface.off_boundary(p, 0..surface.covering().triangles.len()) {
        Some(p) if winding_number(surface, p).abs() >= 0.5 => Class::Inside,
        Some(_) => Class::Outside,
        None => Class::OnBoundary,
    }
}

/// OnBoundary within ε of a face, else Inside iff w ≥ ½ (measured from a point moved
/// off the plane of a non-convex face if `p` lies in one, see [`Surface::off_polygon_planes`]).
pub fn classify(surface: &Surface, p: DVec3) -> Class {
    match surface.off_boundary(p, 0..surface.covering().triangles.len()) {
        Some(p) if winding_number(surface, p) >= 0.5 => Class::Inside,
        Some(_) => Class::Outside,
        None => Class::OnBoundary,
    }
}

/// The winding-number oracle as a [`Classifier`].
#[derive(Clone, Debug)]
pub struct WindingNumber {
    surface: Surface,
    stats: BuildStats,
}

impl WindingNumber {
    pub fn new(mesh: &Mesh) -> Result<WindingNumber> {
        WindingNumber::with_policy(mesh, false)
    }

    /// `allow_open` accepts open surfaces (see [`Surface::with_policy`]).
    pub fn with_policy(mesh: &Mesh, allow_open: bool) -> Result<WindingNumber> {
        let (surface, stats) = Surface::timed(mesh, allow_open)?;
        Ok(WindingNumber { surface, stats })
    }

    pub fn surface(&self) -> &Surface {
        &self.surface
    }

    pub fn winding_number(&self, p: DVec3) -> f64 {
        winding_number(&self.surface, p)
    }
}

impl Classifier for WindingNumber {
    fn name(&self) -> &str {
        "winding"
    }

    fn classify(&self, p: DVec3) -> Class {
        classify(&self.surface, p)
    }

    fn build_stats(&self) -> BuildStats {
        self.stats
    }
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use super::*;

    #[test]
    fn solid_angle_of_an_octant() {
        // The triangle X, Y, Z subtends one eighth of the sphere from the origin, which
        // sees it counter-clockwise (its normal (1,1,1) points away from the origin).
        let w = solid_angle(DVec3::X, DVec3::Y, DVec3::Z);
        assert!((w - 4.0 * PI / 8.0).abs() < 1e-15);
        assert!((solid_angle(DVec3::X, DVec3::Z, DVec3::Y) + 4.0 * PI / 8.0).abs() < 1e-15);
    }
}
