//! Boolean evaluation (§6.5.2): the triangles of each operation picked by class
//! (§6.2.2), then compaction into a mesh.
//!
//! | operation | from A | from B |
//! |---|---|---|
//! | A ∪ B | out, on-same | out |
//! | A ∩ B | in, on-same (regularized) / in, on (plain) | in |
//! | A − B | out, on-opposite (regularized) / out (plain) | in, reversed |
//! | A ⊖ B | out, in reversed | out, in reversed |
//!
//! Keeping one copy of the "on-same" faces is what makes A ∪ A = A closed; the thesis'
//! union and symmetric difference are the same regularized or not. Non-regularized
//! results keep (∩) or drop (−) the faces where A touches B from outside, so they
//! differ from the regularized ones exactly there and may be open along them (a
//! lower-dimensional part, as in the thesis).

use std::fmt;
use std::str::FromStr;

use glam::DVec3;

use super::classify::Class;
use super::operand::{ExactSolid, Solid};
use super::refine::{Refined, Refinement};
use crate::mesh::Mesh;

/// A Boolean operation (`--op`), named as [`Operation::name`] says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Operation {
    Union,
    Intersection,
    Difference,
    SymmetricDifference,
}

impl Operation {
    pub const ALL: [Operation; 4] =
        [Operation::Union, Operation::Intersection, Operation::Difference, Operation::SymmetricDifference];

    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            Operation::Union => "union",
            Operation::Intersection => "intersection",
            Operation::Difference => "difference",
            Operation::SymmetricDifference => "symmetric-difference",
        }
    }

    /// The mathematical symbol, for reports.
    pub fn symbol(self) -> &'static str {
        match self {
            Operation::Union => "∪",
            Operation::Intersection => "∩",
            Operation::Difference => "−",
            Operation::SymmetricDifference => "⊖",
        }
    }

    /// Whether a triangle of A (`from_a`) with class `c` is kept, and reversed.
    pub fn keeps(self, from_a: bool, c: Class, regularized: bool) -> Option<bool> {
        use Class::*;
        let keep = |k: bool| k.then_some(false);
        let flip = |k: bool| k.then_some(true);
        match (self, from_a) {
            (Operation::Union, true) => keep(matches!(c, Out | OnSame)),
            (Operation::Union, false) => keep(c == Out),
            (Operation::Intersection, true) => {
                keep(matches!(c, In | OnSame) || (!regularized && c == OnOpposite))
            }
            (Operation::Intersection, false) => keep(c == In),
            (Operation::Difference, true) => keep(c == Out || (regularized && c == OnOpposite)),
            (Operation::Difference, false) => flip(c == In),
            (Operation::SymmetricDifference, _) => match c {
                Out => Some(false),
                In => Some(true),
                _ => None,
            },
        }
    }
}

impl fmt::Display for Operation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Operation {
    type Err = String;
    fn from_str(s: &str) -> Result<Operation, String> {
        crate::choice::parse(s).ok_or_else(|| {
            format!(
                "unknown operation '{s}' (expected one of: {})",
                Operation::ALL.map(|o| o.name()).join(", ")
            )
        })
    }
}

/// The triangles of `op` from both refined meshes (over the refinement's point ids): those
/// from A first, then those from B; the second value is how many come from A.
pub fn select(
    op: Operation,
    regularized: bool,
    a: (&[[u32; 3]], &[Class]),
    b: (&[[u32; 3]], &[Class]),
) -> (Vec<[u32; 3]>, usize) {
    let mut out = Vec::new();
    let mut from_a_count = 0;
    for (from_a, (tris, classes)) in [(true, a), (false, b)] {
        for (t, &c) in tris.iter().zip(classes) {
            match op.keeps(from_a, c, regularized) {
                Some(false) => out.push(*t),
                Some(true) => out.push([t[0], t[2], t[1]]),
                None => {}
            }
        }
        if from_a {
            from_a_count = out.len();
        }
    }
    (out, from_a_count)
}

/// A mesh of `triangles` over `points`, keeping only the points used (in order of
/// first use, so the output does not depend on thread timing).
pub fn assemble(points: &[DVec3], triangles: &[[u32; 3]]) -> Mesh {
    let mut map = vec![u32::MAX; points.len()];
    let mut positions = Vec::new();
    let mut indices = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        for &v in t {
            if map[v as usize] == u32::MAX {
                map[v as usize] = positions.len() as u32;
                positions.push(points[v as usize]);
            }
            indices.push(map[v as usize]);
        }
    }
    let offsets = (0..=triangles.len()).map(|i| 3 * i).collect();
    Mesh::from_parts(positions, offsets, indices)
        .unwrap_or_else(|e| unreachable!("assembled triangles index their own points: {e}"))
}

/// The support of every triangle [`select`] picks, in its order: the support of its
/// parent in its operand ([`Refined::parent`], [`Solid::support`]), two corners swapped
/// where the selection reverses the triangle (as `select` swaps them).
pub fn selected_supports<A: Solid, B: Solid>(
    op: Operation,
    regularized: bool,
    r: &Refinement,
    (a, class_a): (&A, &[Class]),
    (b, class_b): (&B, &[Class]),
) -> Vec<[DVec3; 3]> {
    let mut out = Vec::new();
    let mut side =
        |from_a: bool, refined: &Refined, classes: &[Class], support: &dyn Fn(u32) -> [DVec3; 3]| {
            for (&parent, &c) in refined.parent.iter().zip(classes) {
                match op.keeps(from_a, c, regularized) {
                    Some(false) => out.push(support(parent)),
                    Some(true) => {
                        let [x, y, z] = support(parent);
                        out.push([x, z, y]);
                    }
                    None => {}
                }
            }
        };
    side(true, &r.a, class_a, &|t| a.support(t));
    side(false, &r.b, class_b, &|t| b.support(t));
    out
}

/// The exact operand made of `triangles` over the refinement's points (as [`assemble`]
/// gets them from [`select`]) and their `support` ([`selected_supports`]): the points used,
/// exactly ([`Refinement::point`]) and rounded, numbered in order of first use like
/// [`assemble`]'s, so that the result does not depend on thread timing.
pub fn assemble_exact(r: &Refinement, triangles: &[[u32; 3]], support: Vec<[DVec3; 3]>) -> ExactSolid {
    debug_assert_eq!(triangles.len(), support.len());
    let mut map = vec![u32::MAX; r.points.len()];
    let mut points = Vec::new();
    let mut rounded = Vec::new();
    let mut tris = Vec::with_capacity(triangles.len());
    for t in triangles {
        tris.push(t.map(|v| {
            if map[v as usize] == u32::MAX {
                map[v as usize] = points.len() as u32;
                points.push(r.point(v).into_owned());
                rounded.push(r.points[v as usize]);
            }
            map[v as usize]
        }));
    }
    ExactSolid { points, rounded, triangles: tris, support }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_symmetric_difference_flips_inside_parts() {
        for op in Operation::ALL {
            assert_eq!(op.name().parse::<Operation>().unwrap(), op);
            assert_eq!(crate::choice::name(&op), op.name());
            assert_eq!(serde_json::to_string(&op).unwrap(), format!("\"{}\"", op.name()));
        }
        assert_eq!(<Operation as clap::ValueEnum>::value_variants(), Operation::ALL);
        assert!("xor".parse::<Operation>().unwrap_err().contains("symmetric-difference"));
        assert_eq!(Operation::SymmetricDifference.keeps(true, Class::In, true), Some(true));
        assert_eq!(Operation::SymmetricDifference.keeps(false, Class::OnSame, false), None);
        // Regularized and plain differ only on faces where the solids touch.
        for op in Operation::ALL {
            for from_a in [true, false] {
                for c in [Class::In, Class::Out] {
                    assert_eq!(op.keeps(from_a, c, true), op.keeps(from_a, c, false));
                }
            }
        }
    }
}
