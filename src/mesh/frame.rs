//! The frame every command computes in: the input's coordinates scaled by a power of two so
//! that the largest magnitude lies in [1, 2).
//!
//! Products of coordinates (determinants, distances, areas, volumes) underflow for a mesh
//! of size 1e-120 and overflow for one of size 1e160, although its coordinates are
//! ordinary f64 numbers. Scaling by 2^k changes only exponents: every predicate's sign and
//! every rounding stay what they are at unit size, so a command answers the same for a
//! mesh and for the mesh scaled by any power of two. Only scaling, never translation
//! (that would round). The scale is chosen once per command over all its meshes
//! ([`Frame::of`]): [`crate::mesh::solidity::require_solid`] and [`crate::boolean::evaluate`]
//! apply it, query points enter it by [`Frame::point_in`], and every number or mesh a
//! command reports leaves it by the `*_out` functions.
//!
//! Exactness: scaling up is exact. Scaling down is exact unless a coordinate would fall
//! into f64's subnormal range with bits to lose; the frame is then scaled down only as far
//! as stays exact (a mesh spanning more than about 2^1000 between its largest and its
//! smallest non-zero coordinate). A query point scaled down may lose bits that way: it
//! moves by less than 2^−1074 in the frame, where the mesh measures about 1 and points
//! within 10^−9 of the surface are on the boundary. A query coordinate beyond ±2^32 in
//! the frame (far outside the mesh, whose box is within ±2) is taken at ±2^32: still
//! outside, and its products stay finite.

use std::borrow::Cow;

use glam::DVec3;

use super::Mesh;
use crate::exact::lowest_bit;

/// Query coordinates beyond this magnitude in the frame are taken at it.
const FAR: f64 = 4294967296.0;

/// A scale by 2^`exponent`: frame coordinates = input coordinates · 2^exponent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Frame {
    exponent: i32,
}

impl Frame {
    /// The unit frame (coordinates as they are).
    pub const IDENTITY: Frame = Frame { exponent: 0 };

    /// The frame that brings the largest |coordinate| of `meshes` into [1, 2), as far as
    /// scaling stays exact (see the module docs). The identity for meshes without vertices
    /// or with every coordinate zero.
    pub fn of(meshes: &[&Mesh]) -> Frame {
        let coordinates = || meshes.iter().flat_map(|m| m.positions()).flat_map(|p| p.to_array());
        let largest = coordinates().fold(0.0f64, |m, c| m.max(c.abs()));
        if largest == 0.0 {
            return Frame::IDENTITY;
        }
        let mut exponent = -binary_exponent(largest);
        if exponent < 0 {
            // The lowest set bit of any coordinate must stay at or above 2^−1074.
            let lowest = coordinates().filter(|&c| c != 0.0).map(lowest_bit).min().unwrap_or(0);
            exponent = exponent.max(-1074 - lowest).min(0);
        }
        Frame { exponent }
    }

    /// Frame coordinates = input coordinates · 2^exponent.
    pub fn exponent(&self) -> i32 {
        self.exponent
    }

    pub fn is_identity(&self) -> bool {
        self.exponent == 0
    }

    /// `mesh` in this frame (exact, see [`Frame::of`]).
    pub fn mesh_in(&self, mesh: Mesh) -> Mesh {
        if self.is_identity() {
            return mesh;
        }
        // The frame's coordinates are within ±2: finite.
        mesh.map_positions(|p| scale_point(p, self.exponent))
            .unwrap_or_else(|e| unreachable!("a frame keeps coordinates within ±2: {e}"))
    }

    /// [`Frame::mesh_in`] of a borrowed mesh: no copy in the unit frame.
    pub fn mesh_in_ref<'m>(&self, mesh: &'m Mesh) -> Cow<'m, Mesh> {
        if self.is_identity() { Cow::Borrowed(mesh) } else { Cow::Owned(self.mesh_in(mesh.clone())) }
    }

    /// A mesh of this frame back in the input's units (an error if a coordinate overflows).
    pub fn mesh_out(&self, mesh: Mesh) -> super::Result<Mesh> {
        if self.is_identity() {
            return Ok(mesh);
        }
        mesh.map_positions(|p| scale_point(p, -self.exponent))
    }

    /// A query point in this frame: exact but for the underflow and the far clamp of the
    /// module docs.
    pub fn point_in(&self, p: DVec3) -> DVec3 {
        let q = scale_point(p, self.exponent);
        q.clamp(DVec3::splat(-FAR), DVec3::splat(FAR))
    }

    /// A point of this frame in the input's units.
    pub fn point_out(&self, p: DVec3) -> DVec3 {
        scale_point(p, -self.exponent)
    }

    /// A length of this frame in the input's units.
    pub fn length_out(&self, x: f64) -> f64 {
        scale(x, -self.exponent)
    }

    /// An area of this frame in the input's units (infinite when it overflows f64).
    pub fn area_out(&self, x: f64) -> f64 {
        scale(x, -2 * self.exponent)
    }

    /// A volume of this frame in the input's units (infinite when it overflows f64).
    pub fn volume_out(&self, x: f64) -> f64 {
        scale(x, -3 * self.exponent)
    }

    /// A volume in the input's units in this frame (exact when `x` is a normal number and
    /// the result is one).
    pub fn volume_in(&self, x: f64) -> f64 {
        scale(x, 3 * self.exponent)
    }
}

/// e with 2^e ≤ |x| < 2^(e+1), for finite non-zero x.
fn binary_exponent(x: f64) -> i32 {
    let bits = x.abs().to_bits();
    let biased = (bits >> 52) as i32;
    if biased == 0 {
        // Subnormal: 2^−1074 times the mantissa.
        -1074 + 63 - bits.leading_zeros() as i32
    } else {
        biased - 1023
    }
}

/// x · 2^e, in steps whose factors are normal f64 numbers; rounds only where the result
/// leaves f64's normal range (overflow gives ±∞).
fn scale(x: f64, e: i32) -> f64 {
    let (mut x, mut e) = (x, e);
    while e > 1000 {
        x *= 2f64.powi(1000);
        e -= 1000;
    }
    while e < -1000 {
        x *= 2f64.powi(-1000);
        e += 1000;
    }
    x * 2f64.powi(e)
}

fn scale_point(p: DVec3, e: i32) -> DVec3 {
    DVec3::new(scale(p.x, e), scale(p.y, e), scale(p.z, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;

    #[test]
    fn powers_of_two_bring_a_mesh_to_unit_size_exactly() {
        let cube = procedural::cube();
        assert!(Frame::of(&[&cube]).is_identity());
        for k in [-1000, -300, -1, 1, 300, 1000] {
            let m = cube.map_positions(|p| p * 2f64.powi(k)).unwrap();
            let f = Frame::of(&[&m]);
            assert_eq!(f.exponent(), -k);
            assert_eq!(f.mesh_in(m.clone()), cube);
            assert_eq!(f.mesh_out(cube.clone()).unwrap(), m);
            assert_eq!(f.volume_out(8.0), 8.0 * 2f64.powi(k).powi(3));
        }
        // 1e80: the largest coordinate in [1, 2); the volume 8e240 is finite.
        let m = cube.map_positions(|p| p * 1e80).unwrap();
        let f = Frame::of(&[&m]);
        let c = f.mesh_in(m).positions()[0].abs().max_element();
        assert!((1.0..2.0).contains(&c), "{c}");
        let x = 1e80f64;
        assert_eq!(f.volume_out(8.0 * (c * c * c)), 8.0 * (x * x * x));
        assert_eq!(f.volume_out(8.0 * (c * c * c) * 1e80), f64::INFINITY);
    }

    #[test]
    fn scaling_down_stops_where_it_would_round() {
        // 4 and 2^−1074: scaling down by 2² would lose the smallest one.
        let m = Mesh::new(
            vec![DVec3::new(4.0, 0.0, 0.0), DVec3::new(0.0, 5e-324, 0.0), DVec3::new(0.0, 0.0, 1.0)],
            vec![vec![0, 1, 2]],
        )
        .unwrap();
        let f = Frame::of(&[&m]);
        assert!(f.is_identity());
        assert_eq!(f.mesh_out(f.mesh_in(m.clone())).unwrap(), m);
    }

    #[test]
    fn query_points_underflow_or_clamp_honestly() {
        let big = procedural::cube().map_positions(|p| p * 2f64.powi(600)).unwrap();
        let f = Frame::of(&[&big]);
        assert_eq!(f.point_in(DVec3::new(1e-300, 2f64.powi(600), 0.0)), DVec3::new(0.0, 1.0, 0.0));
        let tiny = procedural::cube().map_positions(|p| p * 2f64.powi(-600)).unwrap();
        let f = Frame::of(&[&tiny]);
        assert_eq!(f.point_in(DVec3::new(1e300, -1.0, 2f64.powi(-601))), DVec3::new(FAR, -FAR, 0.5));
    }
}
