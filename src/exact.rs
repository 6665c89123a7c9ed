//! Exact arithmetic on f64 inputs: the sign of a polynomial in the input coordinates, and
//! the predicates texgeo decides with it, so that a decision never depends on rounding —
//! on which method asks, or on where the mesh sits.
//!
//! Inputs are f64 numbers, i.e. exact dyadic rationals. Every predicate first evaluates in
//! floating point with an error bound (the *filter*); only when the answer is in doubt does
//! it recompute with floating-point expansions (sums of non-overlapping f64 components
//! built with error-free two-sum / two-product: Shewchuk's grow, scale and sum), whose sign
//! is the sign of the exact real value. [`Exact`] wraps an expansion with `+ − ×`.
//! Polynomials of high degree (implicit points made from points) are evaluated with big
//! dyadic numbers instead ([`dyadic::Dyadic`]), which an expansion's exponent range cannot
//! hold.
//!
//! | module | holds |
//! |---|---|
//! | [`expansion`] | the expansion arithmetic: [`Exact`], [`Exact3`], stack expansions |
//! | [`predicates`] | [`orient2d`], [`orient3d`] (one sign convention, one result type [`Sign`]), their perturbed forms |
//! | [`implicit`] | implicit points (an edge crossing a plane, two coplanar edges crossing, a segment between points crossing a plane through points, to any depth) and exact predicates on them: [`orient3d_implicit`](implicit::orient3d_implicit), [`orient2d_implicit`](implicit::orient2d_implicit), [`compare_implicit`](implicit::compare_implicit) |
//! | [`dyadic`] | exact dyadic numbers with a big-integer mantissa, for implicit points made from points, whose degree expansions cannot hold |
//! | [`rounding`] | the correctly rounded f64 of a quotient X / W (implicit points' output coordinates) |
//! | [`volume`] | the certified volume of a surface whose vertices are exact or implicit (double-double, with an error bound) |
//! | [`distance`] | [`segment_within`], [`triangle_within`]: distance from a point ≤ ε, and closest points |
//!
//! Every mesh check, triangulation, voxel tie, inclusion test and Boolean decision calls
//! these predicates; none has its own.

pub mod distance;
pub mod dyadic;
pub mod expansion;
pub mod implicit;
pub mod predicates;
pub mod rounding;
pub mod volume;

pub use distance::{closest_point_on_segment, closest_point_on_triangle, segment_within, triangle_within};
pub use expansion::{Exact, Exact3, lowest_bit, two_prod, two_sum};
pub use predicates::{
    Sign, line_crossing, normal_signs, orient_yz_perturbed, orient2d, orient2d_approx, orient3d,
    orient3d_perturbed, plane_crossing, sign_of,
};
