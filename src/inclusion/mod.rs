//! Point in solid (SPEC §3, thesis Ch. 4): the exact Feito-Torres test on the simplicial
//! covering, its optimizers, and the baselines it is compared with.
//!
//! Every method answers the same question the same way, so their outputs can be compared
//! point by point:
//!
//! - **Inside** iff the winding number w of the surface around P is non-zero. For a
//!   valid solid ([`crate::mesh::solidity`]) w ∈ {0, 1} and this is the thesis'
//!   `acc == 2`. The commands refuse meshes that are not valid solids; with
//!   `--allow-open` such a mesh (open, self-intersecting, nested, inverted) is classified
//!   by the one rule of [`crate::mesh::solidity`] — inside iff its generalized winding
//!   number is at least ½ — whichever CPU method is asked for, by the certified
//!   hierarchical evaluation of [`fast_winding`] ([`multipole`]); the GPU methods refuse it.
//! - **OnBoundary** iff P is within ε of some face polygon ([`surface::Surface::on_face`]).
//!
//! ## The tolerance rule (one rule, used everywhere)
//!
//! ε = [`surface::REL_TOL`] · D with `REL_TOL = 1e-9` and D the length of the mesh's
//! bounding-box diagonal. Distances are Euclidean, computed in f64 with unit normals:
//!
//! - *on the boundary*: distance from P to a face polygon ≤ ε. For an n-gon that means
//!   within ε of one of its edges, or of a covering triangle at a point the polygon winds
//!   around — the parts of the fan that a non-convex face's negative triangles cancel are
//!   not boundary ([`surface::Surface::on_face`]). Every method calls this one predicate
//!   for every face that may be within ε of P, so they agree on OnBoundary;
//! - *on a tetra's face* (Feito-Torres): distance from P to that face's plane ≤ ε; *on an
//!   apex edge*: on two faces through the apex; *at the apex*: on all three, or within
//!   `1e-4·D` (max-norm) of it;
//! - a tetra is *flat* when its apex is within ε of its base plane or nearly collinear with
//!   a base edge (sine < 1e-6, [`tetra::SIN_MIN`]), and *degenerate* when its base
//!   triangle's smallest height is ≤ ε;
//! - points outside the mesh's bounding box grown by ε are Outside without further work.
//!
//! "Within ε of a face" is decided **exactly** ([`crate::exact`]: a filtered f64 distance,
//! recomputed in exact arithmetic when it is within the filter's margin of ε), on the
//! covering points as they are. So every method gives a point the same OnBoundary label,
//! and a solid translated by any amount that keeps its coordinates exact (1e7, 1e12: a
//! shift by a multiple of the coordinates' unit in the last place) labels the translated
//! points as at the origin (`tests/inclusion_placement.rs`). (For an n-gon whose centroid
//! rounds differently after the translation, the covering itself moves by that rounding.)
//!
//! The other decisions are taken on coordinates relative to the apex or to a triangle's
//! corner, whose differences are exact far from the origin, and ε is far above f64
//! rounding at the scale D (≈1e-16·D): a decision taken with a margin larger than ε is
//! geometrically right; a decision within ε is either shared bit for bit by the two tetras
//! it concerns or sends the point to an exact fallback (see [`cpu`]). The Jordan baselines
//! add their own re-cast triggers (barycentric 1e-9, grazing 1e-7, [`jordan`]); they only
//! choose when to cast another ray, never a class.
//!
//! Which meshes count as solids, and what the commands do with the others, is
//! [`crate::mesh::solidity`]'s: on a valid solid the winding number is 0 or 1, so the
//! non-zero rule here, the parity of the voxelizers and "w ≥ ½" agree.

pub mod auto;
pub mod bvh;
pub mod cells;
pub mod classifier;
pub mod cpu;
pub mod error;
pub mod fast_winding;
pub mod gpu;
pub mod gpu_grid;
pub mod jordan;
pub mod method;
pub mod multipole;
pub mod octants;
pub mod octree;
pub mod points;
pub mod solver;
pub mod surface;
pub mod tetra;
pub mod tetragrid;
pub mod voxel_space;
pub mod winding;

pub use classifier::{BuildStats, Class, Classifier};
pub use cpu::{EdgeRule, FeitoTorres, Trace};
pub use error::{InclusionError, Result};
pub use method::{Choice, Method, Options};
pub use solver::{Solver, build};
pub use surface::Surface;
