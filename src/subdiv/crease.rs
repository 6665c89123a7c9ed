//! Sharpness arithmetic of semi-sharp creases: the rules OpenSubdiv's `Sdc::Crease` fixes
//! for Catmull-Clark (`CATMARK`), written from its documentation and headers. Sharpness is
//! an `f32`, as in OpenSubdiv, and every operation here is the same `f32` operation in the
//! same order, so sharpness values and blending weights come out bit for bit equal — a
//! rule that flips (crease → smooth) on a last-bit difference would move a vertex by far
//! more than any tolerance.
//!
//! - an edge or vertex of sharpness 0 is smooth, ≥ [`INFINITE`] (10) infinitely sharp,
//!   anything between semi-sharp;
//! - each level a semi-sharp value loses 1 ([`decrement`]; values ≤ 1 become 0), or, with
//!   Chaikin's method, an edge takes ¾ of its own and ¼ of the mean of the other semi-sharp
//!   edges at the end vertex of the child edge, minus 1 ([`chaikin`]);
//! - the vertex rule follows from the vertex's sharpness and its number of sharp edges
//!   ([`Rule::of`]): smooth (0), dart (1), crease (2), corner (3 or more, or a sharp vertex);
//! - where the rule of a vertex changes from one level to the next, the two masks are
//!   blended by the mean of the sharpness values that decayed ([`fractional_weight`]).

/// Sharpness of a smooth edge or vertex.
pub const SMOOTH: f32 = 0.0;
/// Sharpness at and above which an edge or vertex is infinitely sharp (OpenSubdiv's
/// `SHARPNESS_INFINITE`).
pub const INFINITE: f32 = 10.0;

/// How sharpness decays from level to level (OpenSubdiv's `Sdc::Options::CreasingMethod`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Every semi-sharp value loses 1 per level (`CREASE_UNIFORM`).
    #[default]
    Uniform,
    /// Chaikin's rule along chains of semi-sharp edges (`CREASE_CHAIKIN`).
    Chaikin,
}

pub fn is_sharp(s: f32) -> bool {
    s > SMOOTH
}

pub fn is_infinite(s: f32) -> bool {
    s >= INFINITE
}

pub fn is_semi_sharp(s: f32) -> bool {
    SMOOTH < s && s < INFINITE
}

/// One level of uniform decay: smooth stays smooth, infinite stays infinite, values above
/// 1 lose 1, the rest become smooth.
pub fn decrement(s: f32) -> f32 {
    if s <= SMOOTH {
        SMOOTH
    } else if s >= INFINITE {
        INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        SMOOTH
    }
}

/// The semi-sharp values around a vertex, summed in the vertex's edge order (the order
/// matters for the last bit of the `f32` sum): what Chaikin's rule averages.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SemiSharpSum {
    pub sum: f32,
    pub count: u32,
}

impl SemiSharpSum {
    /// Sums the semi-sharp values of `edges`, in order.
    pub fn of(edges: impl IntoIterator<Item = f32>) -> SemiSharpSum {
        let mut acc = SemiSharpSum::default();
        for s in edges {
            acc.add(s);
        }
        acc
    }

    pub fn add(&mut self, s: f32) {
        if is_semi_sharp(s) {
            self.sum += s;
            self.count += 1;
        }
    }
}

/// Child sharpness of an edge of sharpness `s` at one of its end vertices, where
/// `around` sums the semi-sharp edges of that vertex (`s` among them) and `edges` counts
/// all its edges (OpenSubdiv's `SubdivideEdgeSharpnessAtVertex`).
pub fn chaikin(s: f32, around: SemiSharpSum, edges: u32) -> f32 {
    if edges < 2 {
        return decrement(s);
    }
    if s <= SMOOTH {
        return SMOOTH;
    }
    if s >= INFINITE {
        return INFINITE;
    }
    let mut s = s;
    if around.count > 1 {
        let others = (around.sum - s) / (around.count - 1) as f32;
        s = 0.75 * s + 0.25 * others;
    }
    s -= 1.0;
    if s > SMOOTH { s } else { SMOOTH }
}

/// Child sharpness of an edge at one of its ends with `method`.
pub fn child_edge(method: Method, s: f32, around: SemiSharpSum, edges: u32) -> f32 {
    match method {
        Method::Uniform => decrement(s),
        Method::Chaikin => chaikin(s, around, edges),
    }
}

/// The subdivision rule of a vertex (OpenSubdiv's `Sdc::Crease::Rule`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Rule {
    Smooth,
    /// One sharp edge: the smooth mask.
    Dart,
    /// Two sharp edges: ¾ of the vertex, ⅛ of each crease neighbour.
    Crease,
    /// A sharp vertex or three sharp edges or more: the vertex stays.
    Corner,
}

impl Rule {
    /// The rule of a vertex of sharpness `vertex` with `sharp_edges` sharp edges.
    pub fn of(vertex: f32, sharp_edges: usize) -> Rule {
        if is_sharp(vertex) {
            return Rule::Corner;
        }
        match sharp_edges {
            0 => Rule::Smooth,
            1 => Rule::Dart,
            2 => Rule::Crease,
            _ => Rule::Corner,
        }
    }

    /// Smooth and dart vertices take the smooth mask.
    pub fn is_smooth(self) -> bool {
        matches!(self, Rule::Smooth | Rule::Dart)
    }
}

/// The weight of the parent's mask when a vertex's rule changes between levels: the mean
/// of the sharpness values that decayed to 0, at most 1 (OpenSubdiv's
/// `ComputeFractionalWeightAtVertex`). `edges` yields (parent, child) sharpness of each
/// edge, in the vertex's edge order.
pub fn fractional_weight(
    method: Method,
    vertex: f32,
    child_vertex: f32,
    edges: impl IntoIterator<Item = (f32, f32)>,
) -> f32 {
    let mut count = 0u32;
    let mut sum = 0.0f32;
    if is_sharp(vertex) && !is_sharp(child_vertex) {
        count = 1;
        sum = vertex;
    }
    for (parent, child) in edges {
        let decays = match method {
            Method::Uniform => is_sharp(parent) && parent <= 1.0,
            Method::Chaikin => is_sharp(parent) && !is_sharp(child),
        };
        if decays {
            sum += parent;
            count += 1;
        }
    }
    if count == 0 {
        return 0.0;
    }
    let weight = sum / count as f32;
    if weight > 1.0 { 1.0 } else { weight }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_decay() {
        assert_eq!(decrement(0.0), 0.0);
        assert_eq!(decrement(0.5), 0.0);
        assert_eq!(decrement(1.0), 0.0);
        assert_eq!(decrement(2.5), 1.5);
        assert_eq!(decrement(10.0), 10.0);
        assert_eq!(decrement(42.0), 10.0);
    }

    #[test]
    fn chaikin_averages_the_other_semi_sharp_edges() {
        // Alone at its vertex (besides smooth edges): plain decrement.
        let alone = SemiSharpSum::of([3.0, 0.0, 0.0, 10.0]);
        assert_eq!(chaikin(3.0, alone, 4), 2.0);
        // Next to an edge of 1: ¾·3 + ¼·1 − 1 = 1.5.
        let pair = SemiSharpSum::of([3.0, 1.0, 0.0, 0.0]);
        assert_eq!(chaikin(3.0, pair, 4), 1.5);
        assert_eq!(chaikin(1.0, pair, 4), 0.5);
        assert_eq!(chaikin(10.0, pair, 4), 10.0);
    }

    #[test]
    fn rules_and_weights() {
        assert_eq!(Rule::of(0.0, 0), Rule::Smooth);
        assert_eq!(Rule::of(0.0, 1), Rule::Dart);
        assert_eq!(Rule::of(0.0, 2), Rule::Crease);
        assert_eq!(Rule::of(0.0, 3), Rule::Corner);
        assert_eq!(Rule::of(0.5, 0), Rule::Corner);
        // Two crease edges of 0.5 decaying: weight 0.5; an infinite one does not count.
        let w = fractional_weight(Method::Uniform, 0.0, 0.0, [(0.5, 0.0), (0.5, 0.0), (10.0, 10.0)]);
        assert_eq!(w, 0.5);
        // A vertex of 3 decays in one step only when it reaches ≤ 1; clamped at 1.
        assert_eq!(fractional_weight(Method::Uniform, 3.0, 0.0, [(0.0, 0.0)]), 1.0);
    }
}
