//! Implicit points: a point that is not stored as coordinates but as the input
//! primitives that define it, so that predicates on it stay exact (Attene's indirect
//! predicates). An intersection point rounded to f64 moves off the segment and the plane
//! that define it; kept implicit, it lies on both exactly, and every orientation or
//! order decided on it is the one of the real point.
//!
//! A point ([`Definition`]) is one of
//!
//! - **explicit**: an f64 input vertex, (X, Y, Z, W) = (x, y, z, 1);
//! - **an edge crossing a plane**: segment pq between two input vertices crossing the
//!   plane through three input vertices a, b, c, written in homogeneous coordinates
//!
//!   ```text
//!   (X, Y, Z, W) = (dp·q − dq·p, dp − dq),   dp = ((b − a) × (c − a))·(p − a), same for dq,
//!   ```
//!
//!   whose entries are polynomials in the input coordinates;
//! - **a segment crossing a plane, from points**: segment PQ between two points of any
//!   kind crossing the plane through three points A, B, C of any kind (so a point of a
//!   point of a point, to any depth). With homogeneous rows and the linear form
//!   L(H) = det [A; B; C; H] (zero exactly for H on the plane),
//!
//!   ```text
//!   (X, Y, Z, W) = L(P)·Q − L(Q)·P,
//!   ```
//!
//!   a combination of P and Q (on line PQ) with L(X, Y, Z, W) = L(P)·L(Q) − L(Q)·L(P) = 0
//!   (on the plane). Over the points' real coordinates, L(P) = K·W_P·f(p) with
//!   K = W_A·W_B·W_C and f(x) = det [a 1; b 1; c 1; x 1], so dividing by the common
//!   factor K·W_P·W_Q the real point is (f(p)·q − f(q)·p) / (f(p) − f(q)): weights
//!   f(p) / (f(p) − f(q)) and −f(q) / (f(p) − f(q)), both positive, hence strictly
//!   between p and q, exactly when p and q lie strictly on opposite sides of the plane
//!   (which also makes W ≠ 0). The entries are computed from the children's homogeneous
//!   coordinates as each point keeps them (intervals, double-double, big dyadics), so a
//!   level of depth costs one such evaluation per point, not a re-expansion of the tree
//!   below it. When all five points are explicit, [`Point::segment_plane`] makes the
//!   cheaper edge-crossing-a-plane point.
//!
//! Two coplanar segments that cross are the same kind of point: pq against the plane
//! through r, s and any point off their common plane ([`Point::edge_edge`] for input
//! vertices, [`Point::segment_segment`] for points of any kind).
//!
//! Each predicate evaluates its determinant first with interval arithmetic rounded
//! outward (the filter: decided when the interval excludes zero), else exactly: with
//! expansions ([`Exact`]) when every point is explicit or an edge crossing a plane, with
//! big dyadics ([`Dyadic`]) when one is made from points. The homogeneous coordinates
//! are computed once per point for each. The sign convention is that of
//! [`super::predicates`]: the predicates here agree with [`orient2d`](super::orient2d)
//! and [`orient3d`](super::orient3d) on explicit points.
//!
//! Expansions are exact while no product overflows (inputs are assumed below 2^60 in
//! magnitude: [`crate::mesh::frame`] brings the largest coordinate into [1, 2)) and every
//! product is an integer multiple of f64's smallest step 2⁻¹⁰⁷⁴. The second is checked:
//! a product of input coordinates is a multiple of 2 to the sum of their lowest set bits,
//! so a sign or a rounding whose products could fall below it (tiny coordinates beside
//! large ones, where some terms would underflow and others not) is computed with big
//! dyadics instead. Points made from points always take big dyadics: their degree in the
//! input coordinates grows with depth (W has degree 0 for an explicit point, 3 for an
//! edge crossing a plane, deg W_P + deg W_Q + 3 for a crossing of segment PQ with a plane
//! of explicit points), past what expansions hold, and big dyadics round nothing at any
//! degree. Their intervals and
//! double-double coordinates are scaled by a power of two per point (the homogeneous
//! coordinates of a point are defined up to a factor) so that depth does not carry
//! them out of f64's range; the double-double ones carry an allowance for underflow.

use std::borrow::Cow;
use std::cmp::Ordering;
use std::fmt;
use std::sync::atomic::{AtomicUsize, Ordering as AtomicOrdering};
use std::sync::{Arc, OnceLock};

use glam::DVec3;

use super::dyadic::{self, Dyadic};
use super::expansion::{Exact, lowest_bit};
use super::predicates::{Sign, orient3d};
use super::rounding::{Ball, quotient_exact, quotient_fast};

/// A closed interval [lo, hi] that contains the exact value of what it was computed from:
/// every operation rounds its ends outward by one ulp. NaN (∞ − ∞, 0·∞) never decides.
#[derive(Clone, Copy, Debug)]
struct Interval {
    lo: f64,
    hi: f64,
}

impl Interval {
    fn point(x: f64) -> Interval {
        Interval { lo: x, hi: x }
    }

    fn add(self, o: Interval) -> Interval {
        Interval { lo: (self.lo + o.lo).down(), hi: (self.hi + o.hi).up() }
    }

    fn sub(self, o: Interval) -> Interval {
        Interval { lo: (self.lo - o.hi).down(), hi: (self.hi - o.lo).up() }
    }

    fn mul(self, o: Interval) -> Interval {
        let p = [self.lo * o.lo, self.lo * o.hi, self.hi * o.lo, self.hi * o.hi];
        let lo = p.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = p.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // An exact product (a point times a point with no rounding) needs no widening,
        // but telling costs more than the ulp.
        Interval { lo: lo.down(), hi: hi.up() }
    }

    /// The sign when the interval vouches for it.
    fn sign(self) -> Option<Sign> {
        if self.lo > 0.0 {
            Some(1)
        } else if self.hi < 0.0 {
            Some(-1)
        } else if self.lo == 0.0 && self.hi == 0.0 {
            Some(0)
        } else {
            None
        }
    }
}

/// One ulp outward (`f64::next_up`/`next_down`, newer than the toolchain texgeo supports).
trait Ulp {
    fn up(self) -> f64;
    fn down(self) -> f64;
}

impl Ulp for f64 {
    fn up(self) -> f64 {
        if self.is_nan() || self == f64::INFINITY {
            self
        } else if self == 0.0 {
            f64::from_bits(1)
        } else if self > 0.0 {
            f64::from_bits(self.to_bits() + 1)
        } else {
            f64::from_bits(self.to_bits() - 1)
        }
    }

    fn down(self) -> f64 {
        -(-self).up()
    }
}

/// The arithmetic the determinants are written in once: intervals for the filter,
/// double-double balls for rounding, expansions for the exact value.
trait Ring: Clone {
    fn of(x: f64) -> Self;
    fn plus(&self, o: &Self) -> Self;
    fn minus(&self, o: &Self) -> Self;
    fn times(&self, o: &Self) -> Self;
}

/// The rings points made from points are computed in: intervals, double-double with an
/// underflow allowance ([`Deep`]) and big dyadics (not expansions, see the module
/// documentation).
trait Nest: Ring {
    /// A point's homogeneous coordinates in this ring, as the point keeps them (computed
    /// once per point), so that a point made from points takes them without going down
    /// its children's definitions.
    fn of_point(p: &Point) -> Cow<'_, [Self; 4]>;
}

impl Ring for Interval {
    fn of(x: f64) -> Self {
        Interval::point(x)
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(*o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(*o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(*o)
    }
}

impl Nest for Interval {
    fn of_point(p: &Point) -> Cow<'_, [Self; 4]> {
        Cow::Borrowed(&p.approx)
    }
}

impl Ring for Ball {
    fn of(x: f64) -> Self {
        Ball::of(x)
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(o)
    }
}

/// 2⁻¹⁰⁰⁰: what [`Deep`] adds to each radius, far more than the roundings below 2⁻¹⁰²²
/// of one double-double operation can cost (each at most 2⁻¹⁰⁷⁵ beyond the relative
/// bounds [`Ball`] proves for normal numbers, a few per operation, none multiplied by
/// more than the operation's own operands).
const DEEP_ALLOWANCE: f64 = 9.332636185032189e-302;

/// Double-double for points made from points: [`Ball`]'s operations with
/// [`DEEP_ALLOWANCE`] added to each radius, so that a ball holds its exact value even
/// where a product falls below f64's normal range (a deep point's coordinates are
/// products of many, and nothing bounds how small a plane's form gets near a point).
#[derive(Clone, Copy, Debug)]
struct Deep(Ball);

impl Ring for Deep {
    fn of(x: f64) -> Self {
        Deep(Ball::of(x))
    }
    fn plus(&self, o: &Self) -> Self {
        Deep(self.0.add(&o.0).widened(DEEP_ALLOWANCE))
    }
    fn minus(&self, o: &Self) -> Self {
        Deep(self.0.sub(&o.0).widened(DEEP_ALLOWANCE))
    }
    fn times(&self, o: &Self) -> Self {
        Deep(self.0.mul(&o.0).widened(DEEP_ALLOWANCE))
    }
}

impl Nest for Deep {
    fn of_point(p: &Point) -> Cow<'_, [Self; 4]> {
        Cow::Owned(p.balls().map(Deep))
    }
}

impl Ring for Exact {
    fn of(x: f64) -> Self {
        Exact::from_f64(x)
    }
    fn plus(&self, o: &Self) -> Self {
        self + o
    }
    fn minus(&self, o: &Self) -> Self {
        self - o
    }
    fn times(&self, o: &Self) -> Self {
        self * o
    }
}

impl Ring for Dyadic {
    fn of(x: f64) -> Self {
        Dyadic::from_f64(x)
    }
    fn plus(&self, o: &Self) -> Self {
        self.add(o)
    }
    fn minus(&self, o: &Self) -> Self {
        self.sub(o)
    }
    fn times(&self, o: &Self) -> Self {
        self.mul(o)
    }
}

impl Nest for Dyadic {
    fn of_point(p: &Point) -> Cow<'_, [Self; 4]> {
        p.big()
    }
}

/// The power of two that brings the largest magnitude `max` into [1, 2), where `max` is
/// finite and within 10^±270 (about 2^±897), else 1 (no scaling).
fn normalizing_power(max: f64) -> f64 {
    if !(max.is_finite() && (1e-270..=1e270).contains(&max)) {
        return 1.0;
    }
    let exponent = ((max.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    2f64.powi(-exponent)
}

/// A point's homogeneous coordinates for the plain f64 filter ([`orient2d_fast`]): per
/// coordinate an f64 `mid` within `rad` of the exact value, `mag` ≥ |mid| + rad (so
/// |exact| ≤ mag), and one `rho` with rad ≤ rho·mag for all four; `ok` when every `mag` is at
/// most 2^256 (the filter's underflow allowance assumes it). Derived once from the
/// intervals, each step rounded so that the inequalities hold (see [`Fast::of`]).
#[derive(Clone, Copy, Debug)]
struct Fast {
    mid: [f64; 4],
    mag: [f64; 4],
    rho: f64,
    ok: bool,
}

/// 1 + 2⁻⁵⁰: a product by it, rounded to nearest, is at least the exact value times
/// 1 + 2⁻⁵¹ ≥ 1/(1 − u) (u = 2⁻⁵³) for a normal result, and never below the value
/// itself: it turns an f64 computed with one rounding to nearest into an upper bound.
const UP: f64 = 1.0 + 1.0 / 1125899906842624.0;

impl Fast {
    /// From intervals [lo, hi] that hold the exact values. mid is any f64 near the middle;
    /// rad = max(hi − mid, mid − lo) bounds |exact − mid| (even if rounding put mid
    /// outside [lo, hi]); each difference is exact below 2⁻¹⁰²² (subtraction does not
    /// underflow) and within one rounding above, which `UP` covers. mag = (|mid| + rad)·UP
    /// the same way (a sum of non-negative numbers). rho = max rad/mag, rounded up by `UP`
    /// and at least 2⁻¹⁰²² where rad > 0: a quotient that underflows loses its relative
    /// accuracy, but is then below 2⁻¹⁰²².
    fn of(approx: &[Interval; 4]) -> Fast {
        let mut f = Fast { mid: [0.0; 4], mag: [0.0; 4], rho: 0.0, ok: true };
        for (i, x) in approx.iter().enumerate() {
            let mid = 0.5 * x.lo + 0.5 * x.hi;
            let rad = (x.hi - mid).max(mid - x.lo).max(0.0) * UP;
            let mag = (mid.abs() + rad) * UP;
            if rad > 0.0 {
                f.rho = f.rho.max(((rad / mag) * UP).max(f64::MIN_POSITIVE));
            }
            // NaN fails the test too.
            f.ok &= mag <= TWO_256;
            f.mid[i] = mid;
            f.mag[i] = mag;
        }
        f
    }
}

/// 2²⁵⁶: the largest `Fast::mag` the f64 filter takes.
const TWO_256: f64 = 1.157920892373162e77;

/// γ₅ = 5u/(1 − 5u) (u = 2⁻⁵³) rounded up generously: 6u = 3·2⁻⁵².
const GAMMA5: f64 = 3.0 / 4503599627370496.0;

/// 1 + 2⁻⁴⁰, the margin that turns the f64-computed bound into an upper bound.
const MARGIN: f64 = 1.0 + 1.0 / 1099511627776.0;

/// 2⁻⁸⁰⁰, more than all underflow can cost the f64 filter with entries below 2²⁵⁶.
const UNDERFLOW: f64 = 1.499696813895631e-241;

/// The sign of det [[a.u a.v a.w] [b.u b.v b.w] [c.u c.v c.w]] (homogeneous coordinates
/// u, v and W of three points) in plain f64, or `None` when the bound below does not vouch
/// for it (never decides a zero).
///
/// The bound assumes of the points only that each one's intervals (`Point::approx`) hold
/// its exact homogeneous coordinates, which outward rounding guarantees for every kind of
/// point: an explicit one's are exact, the others' are interval evaluations of
/// polynomials (in the input coordinates, or in the children's coordinates, whose
/// intervals hold theirs by the same argument one level down). Nothing below depends on
/// the kind or the depth of a point; a deep point's wide intervals only make `rho` or
/// `mag` large, and the filter then declines.
///
/// Error bound. Write each exact entry as mid + e with |e| ≤ rho·mag and |mid|, |exact| ≤
/// mag (per point, [`Fast`]). The determinant is a signed sum of six products of one entry
/// per row (point), and |xyz − x̃ỹz̃| ≤ (ρx + ρy + ρz)·mx·my·mz, so the exact determinant
/// differs from det(mid) by at most (ρa + ρb + ρc)·perm(mag) (perm: the same sum with all
/// signs +). Evaluating det(mid) as a0·(b1c2 − b2c1) − a1·(b0c2 − b2c0) + a2·(b0c1 − b1c0)
/// puts at most five roundings on each product's path, so its f64 value is within
/// γ₅·perm(|mid|) ≤ γ₅·perm(mag) of det(mid) (Higham, Lemma 3.1; no contraction into FMA
/// in Rust). Together: |det − fl(det(mid))| ≤ (ρa + ρb + ρc + γ₅)·perm(mag) + the
/// underflow allowance. The bound is computed in f64 on non-negative numbers: perm(mag)
/// with five roundings per path, the sum of the ρ's and γ₅ with three, their product, the
/// product by `MARGIN` and the last sum with one each. Each rounding loses at most a
/// factor (1 − u), eleven in all, and `MARGIN`·(1 − u)¹¹ > 1, so the computed bound is at
/// least the exact one plus the allowance. Underflow: a product that falls below 2⁻¹⁰²² is off
/// by at most 2⁻¹⁰⁷⁵ (sums are exact there) and the later products scale that by at most
/// 2²⁵⁶ (`Fast::ok`) a few times, in det(mid) and in perm(mag): far below 2⁻⁸⁰⁰, which
/// is added twice over (the last sum may round down by a factor 1 − u).
fn orient2d_fast(axes: [usize; 2], a: &Fast, b: &Fast, c: &Fast) -> Option<Sign> {
    if !(a.ok && b.ok && c.ok) {
        return None;
    }
    let [u, v] = axes;
    let (a0, a1, a2) = (a.mid[u], a.mid[v], a.mid[3]);
    let (b0, b1, b2) = (b.mid[u], b.mid[v], b.mid[3]);
    let (c0, c1, c2) = (c.mid[u], c.mid[v], c.mid[3]);
    let det = a0 * (b1 * c2 - b2 * c1) - a1 * (b0 * c2 - b2 * c0) + a2 * (b0 * c1 - b1 * c0);
    let (a0, a1, a2) = (a.mag[u], a.mag[v], a.mag[3]);
    let (b0, b1, b2) = (b.mag[u], b.mag[v], b.mag[3]);
    let (c0, c1, c2) = (c.mag[u], c.mag[v], c.mag[3]);
    let perm = a0 * (b1 * c2 + b2 * c1) + a1 * (b0 * c2 + b2 * c0) + a2 * (b0 * c1 + b1 * c0);
    let bound = ((a.rho + b.rho + c.rho + GAMMA5) * perm) * MARGIN + 2.0 * UNDERFLOW;
    if det > bound {
        Some(1)
    } else if det < -bound {
        Some(-1)
    } else {
        None
    }
}

/// What defines a point.
#[derive(Clone, Debug, PartialEq)]
pub enum Definition {
    /// An input vertex.
    Explicit(DVec3),
    /// Where segment pq crosses the plane through the three points (p and q strictly on
    /// opposite sides of it).
    EdgePlane { p: DVec3, q: DVec3, plane: [DVec3; 3] },
    /// Where the segment between two points crosses the plane through three points, all
    /// of any kind (shared: a clone of the point is a reference count).
    SegmentPlane(Arc<SegmentPlane>),
}

/// Segment pq, between two points, crossing the plane through three points (p and q
/// strictly on opposite sides of it): the children of a [`Definition::SegmentPlane`].
pub struct SegmentPlane {
    p: Point,
    q: Point,
    plane: [Point; 3],
    /// The point's homogeneous coordinates in double-double (scaled, see [`Point::balls`])
    /// and exactly, once computed: its parents take them from here.
    balls: OnceLock<[Ball; 4]>,
    big: OnceLock<[Dyadic; 4]>,
}

impl SegmentPlane {
    /// The segment's ends.
    pub fn segment(&self) -> [&Point; 2] {
        [&self.p, &self.q]
    }

    /// The three points the plane goes through.
    pub fn plane(&self) -> &[Point; 3] {
        &self.plane
    }
}

/// The same definitions (the caches aside).
impl PartialEq for SegmentPlane {
    fn eq(&self, o: &SegmentPlane) -> bool {
        std::ptr::eq(self, o)
            || (self.p.definition == o.p.definition
                && self.q.definition == o.q.definition
                && (0..3).all(|i| self.plane[i].definition == o.plane[i].definition))
    }
}

impl fmt::Debug for SegmentPlane {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SegmentPlane")
            .field("p", &self.p.definition)
            .field("q", &self.q.definition)
            .field("plane", &self.plane.each_ref().map(|x| &x.definition))
            .finish()
    }
}

/// A point with exact predicates; see the module documentation.
#[derive(Debug)]
pub struct Point {
    definition: Definition,
    approx: [Interval; 4],
    fast: Fast,
    exact: OnceLock<[Exact; 4]>,
}

impl Clone for Point {
    fn clone(&self) -> Point {
        Point {
            definition: self.definition.clone(),
            approx: self.approx,
            fast: self.fast,
            exact: self.exact.clone(),
        }
    }
}

/// Why a point could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ImplicitError {
    #[error("the segment does not cross the plane: its ends are not strictly on opposite sides")]
    NoCrossing,
    #[error("the segments are not coplanar")]
    NotCoplanar,
    #[error("the point that should lie off the segments' plane lies in it")]
    OffInPlane,
}

impl Point {
    /// An input vertex.
    pub fn explicit(p: DVec3) -> Point {
        Point::new(Definition::Explicit(p))
    }

    /// Where segment pq crosses the plane through `plane` (exact test that p and q lie
    /// strictly on opposite sides).
    pub fn edge_plane(p: DVec3, q: DVec3, plane: [DVec3; 3]) -> Result<Point, ImplicitError> {
        let [a, b, c] = plane;
        if orient3d(a, b, c, p) * orient3d(a, b, c, q) >= 0 {
            return Err(ImplicitError::NoCrossing);
        }
        Ok(Point::new(Definition::EdgePlane { p, q, plane }))
    }

    /// Where the coplanar segments pq and rs cross, `off` being any point off their common
    /// plane (e.g. a vertex of the other mesh, or a point moved along the plane's normal):
    /// pq against the plane through r, s and `off`. The segments must properly cross
    /// (each one's ends strictly on opposite sides of the other's line).
    pub fn edge_edge(p: DVec3, q: DVec3, r: DVec3, s: DVec3, off: DVec3) -> Result<Point, ImplicitError> {
        if orient3d(p, q, r, s) != 0 {
            return Err(ImplicitError::NotCoplanar);
        }
        if orient3d(p, q, r, off) == 0 {
            return Err(ImplicitError::OffInPlane);
        }
        Point::edge_plane(p, q, [r, s, off])
    }

    /// Where segment pq crosses the plane through `plane`, all five points of any kind
    /// (exact test that p and q lie strictly on opposite sides). When all five are
    /// explicit, the point is the same as [`Point::edge_plane`]'s, and of its kind.
    pub fn segment_plane(p: &Point, q: &Point, plane: [&Point; 3]) -> Result<Point, ImplicitError> {
        let [a, b, c] = plane;
        if orient3d_implicit(a, b, c, p) * orient3d_implicit(a, b, c, q) >= 0 {
            return Err(ImplicitError::NoCrossing);
        }
        let explicit = |x: &Point| match x.definition {
            Definition::Explicit(x) => Some(x),
            _ => None,
        };
        if let [Some(p), Some(q), Some(a), Some(b), Some(c)] = [p, q, a, b, c].map(explicit) {
            return Ok(Point::new(Definition::EdgePlane { p, q, plane: [a, b, c] }));
        }
        Ok(Point::new(Definition::SegmentPlane(Arc::new(SegmentPlane {
            p: p.clone(),
            q: q.clone(),
            plane: plane.map(Point::clone),
            balls: OnceLock::new(),
            big: OnceLock::new(),
        }))))
    }

    /// Where the coplanar segments pq and rs cross, all points of any kind, `off` being
    /// any point off their common plane: pq against the plane through r, s and `off`, as
    /// [`Point::edge_edge`] for input vertices. The segments must properly cross (each
    /// one's ends strictly on opposite sides of the other's line).
    pub fn segment_segment(
        p: &Point,
        q: &Point,
        r: &Point,
        s: &Point,
        off: &Point,
    ) -> Result<Point, ImplicitError> {
        if orient3d_implicit(p, q, r, s) != 0 {
            return Err(ImplicitError::NotCoplanar);
        }
        if orient3d_implicit(p, q, r, off) == 0 {
            return Err(ImplicitError::OffInPlane);
        }
        Point::segment_plane(p, q, [r, s, off])
    }

    fn new(definition: Definition) -> Point {
        let mut approx = homogeneous::<Interval>(&definition);
        if let Definition::SegmentPlane(_) = definition {
            // Scaled by a power of two (outward: it may fall below the normal range).
            let max = approx.iter().fold(0.0f64, |m, x| m.max(x.lo.abs()).max(x.hi.abs()));
            let k = Interval::point(normalizing_power(max));
            approx = approx.map(|x| x.mul(k));
        }
        Point { definition, approx, fast: Fast::of(&approx), exact: OnceLock::new() }
    }

    pub fn definition(&self) -> &Definition {
        &self.definition
    }

    /// The homogeneous coordinates in double-double; a point made from points keeps them
    /// once computed (its parents need them), scaled by a power of two so that the
    /// largest is near 1 (only quotients X/W are taken of them).
    fn balls(&self) -> [Ball; 4] {
        match &self.definition {
            Definition::SegmentPlane(node) => *node.balls.get_or_init(|| {
                let h = homogeneous::<Deep>(&self.definition);
                let max = h.iter().fold(0.0f64, |m, x| m.max(x.0.value().abs()));
                let k = Deep::of(normalizing_power(max));
                h.map(|x| x.times(&k).0)
            }),
            &Definition::Explicit(p) => explicit_row(p),
            &Definition::EdgePlane { p, q, plane } => edge_plane_row(p, q, plane),
        }
    }

    /// The homogeneous coordinates in expansions, for explicit points and edges crossing
    /// a plane (None for a point made from points: see [`Point::big`]).
    fn exact(&self) -> Option<&[Exact; 4]> {
        if let Some(e) = self.exact.get() {
            return Some(e);
        }
        if self.granularity()? < EXPANSION_FLOOR {
            return None;
        }
        let row = match self.definition {
            Definition::Explicit(p) => explicit_row(p),
            Definition::EdgePlane { p, q, plane } => edge_plane_row(p, q, plane),
            Definition::SegmentPlane(_) => return None,
        };
        Some(self.exact.get_or_init(|| row))
    }

    /// The power of two every homogeneous coordinate of the point in expansions (and every
    /// product computing them) is an integer multiple of: an edge crossing a plane has
    /// entries of degree at most 4 in its input coordinates, each a multiple of 2^m, m the
    /// lowest bit among them (at most 0: the explicit W is 1). `None` for a point made
    /// from points, which has no expansions.
    fn granularity(&self) -> Option<i32> {
        let low = |c: &[DVec3]| {
            c.iter()
                .flat_map(|p| p.to_array())
                .filter(|&x| x != 0.0)
                .map(lowest_bit)
                .min()
                .unwrap_or(0)
                .min(0)
        };
        match &self.definition {
            Definition::Explicit(p) => Some(low(&[*p])),
            Definition::EdgePlane { p, q, plane } => Some(4 * low(&[*p, *q, plane[0], plane[1], plane[2]])),
            Definition::SegmentPlane(_) => None,
        }
    }

    /// The homogeneous coordinates exactly as big dyadics, for a point of any kind; a
    /// point made from points keeps them once computed.
    fn big(&self) -> Cow<'_, [Dyadic; 4]> {
        match &self.definition {
            Definition::SegmentPlane(node) => {
                Cow::Borrowed(node.big.get_or_init(|| homogeneous::<Dyadic>(&self.definition)))
            }
            d => Cow::Owned(homogeneous::<Dyadic>(d)),
        }
    }

    /// The sign of W (never zero): homogeneous determinants are multiplied by it.
    fn w_sign(&self) -> Sign {
        match self.approx[3].sign() {
            Some(s) => s,
            None => exact_sign([self], |r| r[0][3].clone(), |r| r[0][3].clone()),
        }
    }

    /// The coordinates, each X/W rounded to the nearest f64 (ties to even), so that one
    /// real point has one rounded position however it is defined: for output and for
    /// constructions, never for decisions. Double-double first; the exact values
    /// (expansions, big dyadics for a point made from points) only for a coordinate
    /// within about 2⁻¹⁰⁰ of a rounding midpoint (see [`super::rounding`]).
    pub fn position(&self) -> DVec3 {
        if let Definition::Explicit(p) = self.definition {
            return p;
        }
        let fast = rounded_fast(self);
        if fast.iter().all(Option::is_some) {
            return DVec3::from_array(fast.map(|c| c.unwrap_or_default()));
        }
        EXACT_ROUNDINGS.fetch_add(1, AtomicOrdering::Relaxed);
        DVec3::from_array(match self.exact() {
            Some(e) => std::array::from_fn(|i| fast[i].unwrap_or_else(|| quotient_exact(&e[i], &e[3]))),
            None => {
                let b = self.big();
                std::array::from_fn(|i| fast[i].unwrap_or_else(|| dyadic::quotient(&b[i], &b[3])))
            }
        })
    }

    /// A box that certainly holds the exact point: the point itself when explicit, else
    /// one ulp either side of its correctly rounded [`Point::position`] (the exact value
    /// lies within half an ulp of it), for spatial indexes of implicit points.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let p = self.position();
        if let Definition::Explicit(_) = self.definition {
            return (p, p);
        }
        (p.to_array().map(Ulp::down).into(), p.to_array().map(Ulp::up).into())
    }
}

impl Point {
    /// The coordinates X/W as double-double balls ([`Ball`]) that certainly hold the exact
    /// ones, each at most 2⁻⁸⁴·(|x| + 1) wide (a few 2⁻¹⁰⁶ of it where expansions serve):
    /// for measures of an exact result (its volume), never for decisions. Explicit points
    /// are exact; an implicit one takes its homogeneous coordinates in double-double, or
    /// from the exact values (expansions; big dyadics, scaled, for a point made from
    /// points) where that ball is wider (a segment grazing its plane makes X and W small
    /// differences of large products) or W's ball cannot be divided by.
    pub fn coordinates(&self) -> [Ball; 3] {
        if let Definition::Explicit(p) = self.definition {
            return p.to_array().map(Ball::of);
        }
        let divide = |h: &[Ball; 4]| -> Option<[Ball; 3]> {
            let [x, y, z] = [h[0].div(&h[3])?, h[1].div(&h[3])?, h[2].div(&h[3])?];
            Some([x, y, z])
        };
        let narrow = |c: &[Ball; 3]| c.iter().all(|b| b.radius() <= NARROW * (b.value().abs() + 1.0));
        match divide(&self.balls()) {
            Some(c) if narrow(&c) => c,
            _ => {
                let exact = match self.exact() {
                    Some(e) => e.each_ref().map(Ball::of_exact),
                    None => {
                        // Scaled so that the largest is near 1: X/W stays, nothing falls
                        // out of f64's range.
                        let b = self.big();
                        let top = b.iter().filter_map(Dyadic::top).max().unwrap_or(0);
                        b.each_ref().map(|d| d.ball(-top))
                    }
                };
                divide(&exact)
                    .unwrap_or_else(|| unreachable!("W ≠ 0 for a crossing point, and its ball is narrow"))
            }
        }
    }
}

/// The widest coordinate ball [`Point::coordinates`] takes from double-double, relative to
/// |x| + 1 (frame coordinates are at most 2): 2⁻⁸⁴. Generic crossings of small triangles
/// come out near 2⁻⁹³ (differences of coordinates near 1 that are 2⁻⁷ apart lose 7 bits);
/// a segment grazing its plane loses more and takes the expansions.
const NARROW: f64 = 1.0 / 19342813113834066795298816.0;

/// Each coordinate X/W rounded to nearest where double-double decides it.
fn rounded_fast(x: &Point) -> [Option<f64>; 3] {
    let h = x.balls();
    std::array::from_fn(|i| quotient_fast(&h[i], &h[3]))
}

/// Each coordinate X/W rounded to nearest with the exact values only (expansions, or big
/// dyadics for a point made from points).
#[cfg(test)]
fn rounded_exact(x: &Point) -> [f64; 3] {
    match x.exact() {
        Some(h) => std::array::from_fn(|i| quotient_exact(&h[i], &h[3])),
        None => {
            let h = x.big();
            std::array::from_fn(|i| dyadic::quotient(&h[i], &h[3]))
        }
    }
}

/// (X, Y, Z, W) of a definition, in the ring R; a point made from points takes its
/// children's from them ([`Nest::of_point`]).
fn homogeneous<R: Nest>(d: &Definition) -> [R; 4] {
    match d {
        &Definition::Explicit(p) => explicit_row(p),
        &Definition::EdgePlane { p, q, plane } => edge_plane_row(p, q, plane),
        Definition::SegmentPlane(node) => {
            let [a, b, c] = node.plane.each_ref().map(R::of_point);
            crossing(&R::of_point(&node.p), &R::of_point(&node.q), [&a, &b, &c])
        }
    }
}

/// (x, y, z, 1).
fn explicit_row<R: Ring>(p: DVec3) -> [R; 4] {
    [R::of(p.x), R::of(p.y), R::of(p.z), R::of(1.0)]
}

/// (dp·q − dq·p, dp − dq) of segment pq and the plane through a, b, c (see the module
/// documentation).
fn edge_plane_row<R: Ring>(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> [R; 4] {
    let v = |x: DVec3| [R::of(x.x), R::of(x.y), R::of(x.z)];
    let diff = |x: &[R; 3], y: &[R; 3]| -> [R; 3] { std::array::from_fn(|i| x[i].minus(&y[i])) };
    let (a3, b3, c3, p3, q3) = (v(a), v(b), v(c), v(p), v(q));
    let (u, w) = (diff(&b3, &a3), diff(&c3, &a3));
    let n: [R; 3] = std::array::from_fn(|i| {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        u[j].times(&w[k]).minus(&u[k].times(&w[j]))
    });
    let dot = |x: &[R; 3]| n[0].times(&x[0]).plus(&n[1].times(&x[1])).plus(&n[2].times(&x[2]));
    let dp = dot(&diff(&p3, &a3));
    let dq = dot(&diff(&q3, &a3));
    let coord = |i: usize| dp.times(&q3[i]).minus(&dq.times(&p3[i]));
    [coord(0), coord(1), coord(2), dp.minus(&dq)]
}

/// The crossing L(P)·Q − L(Q)·P of segment PQ with the plane through A, B, C, from
/// homogeneous rows, L(H) = det [A; B; C; H] (see the module documentation). L is
/// expanded along its last row, whose cofactors are the plane's coefficients:
/// L(H) = −m₀·H₀ + m₁·H₁ − m₂·H₂ + m₃·H₃, mⱼ the minor of [A; B; C] without column j.
fn crossing<R: Ring>(p: &[R; 4], q: &[R; 4], plane: [&[R; 4]; 3]) -> [R; 4] {
    let [a, b, c] = plane;
    let minor = |skip: usize| {
        let [i, j, k] = match skip {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        det3([&a[i], &a[j], &a[k]], [&b[i], &b[j], &b[k]], [&c[i], &c[j], &c[k]])
    };
    let m = [minor(0), minor(1), minor(2), minor(3)];
    let form = |h: &[R; 4]| {
        let plus = m[1].times(&h[1]).plus(&m[3].times(&h[3]));
        let minus = m[0].times(&h[0]).plus(&m[2].times(&h[2]));
        plus.minus(&minus)
    };
    let (lp, lq) = (form(p), form(q));
    std::array::from_fn(|i| lp.times(&q[i]).minus(&lq.times(&p[i])))
}

fn det2<R: Ring>(a: &R, b: &R, c: &R, d: &R) -> R {
    a.times(d).minus(&b.times(c))
}

/// det [[a0 a1 a2] [b0 b1 b2] [c0 c1 c2]].
fn det3<R: Ring>(a: [&R; 3], b: [&R; 3], c: [&R; 3]) -> R {
    let m0 = det2(b[1], b[2], c[1], c[2]);
    let m1 = det2(b[0], b[2], c[0], c[2]);
    let m2 = det2(b[0], b[1], c[0], c[1]);
    a[0].times(&m0).minus(&a[1].times(&m1)).plus(&a[2].times(&m2))
}

/// det of the 4×4 matrix with rows a, b, c, d, expanded along the last column (W, which
/// is 1 for explicit points); no allocation, as the filter runs on every call.
fn det4<R: Ring>(r: [&[R; 4]; 4]) -> R {
    let xyz = |i: usize| [&r[i][0], &r[i][1], &r[i][2]];
    let minor = |skip: usize| {
        let [p, q, s] = match skip {
            0 => [1, 2, 3],
            1 => [0, 2, 3],
            2 => [0, 1, 3],
            _ => [0, 1, 2],
        };
        det3(xyz(p), xyz(q), xyz(s))
    };
    let term = |i: usize| r[i][3].times(&minor(i));
    term(1).minus(&term(0)).plus(&term(3).minus(&term(2)))
}

/// f64's smallest step is 2^EXPANSION_FLOOR: expansions are exact while every product
/// they form is an integer multiple of it (fused multiply-add keeps a product's error
/// exactly then; sums never round).
const EXPANSION_FLOOR: i32 = -1074;

/// How many points' positions needed expansions, process-wide (for `--stats`).
static EXACT_ROUNDINGS: AtomicUsize = AtomicUsize::new(0);

/// The number of points whose rounded position needed the exact path so far in this
/// process.
pub fn exact_roundings() -> usize {
    EXACT_ROUNDINGS.load(AtomicOrdering::Relaxed)
}

/// How many signs the filter left to the exact path, process-wide (for `--stats`).
static EXACT_SIGNS: AtomicUsize = AtomicUsize::new(0);

/// The number of signs decided by the exact path so far in this process: read it before
/// and after a computation to see how often its filter failed.
pub fn exact_signs() -> usize {
    EXACT_SIGNS.load(AtomicOrdering::Relaxed)
}

/// The exact sign of a polynomial in the points' homogeneous coordinates, given twice
/// (`flat` in expansions, `big` in big dyadics, the same expression): in expansions
/// when every point is explicit or an edge crossing a plane, else in big dyadics.
fn exact_sign<const N: usize>(
    points: [&Point; N],
    flat: impl FnOnce(&[&[Exact; 4]]) -> Exact,
    big: impl FnOnce(&[&[Dyadic; 4]]) -> Dyadic,
) -> Sign {
    EXACT_SIGNS.fetch_add(1, AtomicOrdering::Relaxed);
    // Each term multiplies one coordinate of every point: a multiple of 2 to the sum of
    // their granularities, which expansions hold only from f64's smallest step up.
    let fine = points.iter().try_fold(0i32, |sum, p| Some(sum + p.granularity()?));
    let rows: Option<Vec<&[Exact; 4]>> = match fine {
        Some(g) if g >= EXPANSION_FLOOR => points.iter().map(|p| p.exact()).collect(),
        _ => None,
    };
    match rows {
        Some(rows) => flat(&rows).sign(),
        None => {
            let owned: Vec<Cow<'_, [Dyadic; 4]>> = points.iter().map(|p| p.big()).collect();
            let rows: Vec<&[Dyadic; 4]> = owned.iter().map(|r| r.as_ref()).collect();
            big(&rows).sign()
        }
    }
}

/// Decides a determinant's sign: the filter first, the exact sign when it cannot.
fn decide(filter: impl FnOnce() -> Interval, exact: impl FnOnce() -> Sign) -> Sign {
    filter().sign().unwrap_or_else(exact)
}

/// [`orient3d`] on implicit points: positive when d lies on the side the normal
/// (b − a) × (c − a) points to, zero when the four points are coplanar.
pub fn orient3d_implicit(a: &Point, b: &Point, c: &Point, d: &Point) -> Sign {
    let w = a.w_sign() * b.w_sign() * c.w_sign() * d.w_sign();
    // det4 of rows (x, y, z, 1) is −((b − a) × (c − a))·(d − a); homogeneous rows scale it
    // by the product of the W's.
    let points = [a, b, c, d];
    -w * decide(
        || det4([&a.approx, &b.approx, &c.approx, &d.approx]),
        || exact_sign(points, |r| det4([r[0], r[1], r[2], r[3]]), |r| det4([r[0], r[1], r[2], r[3]])),
    )
}

/// [`orient2d`](super::orient2d) of the projections of three implicit points on the
/// plane of coordinates `axes` = [u, v]: positive when they turn counter-clockwise.
pub fn orient2d_implicit(axes: [usize; 2], a: &Point, b: &Point, c: &Point) -> Sign {
    let [u, v] = axes;
    let w = a.w_sign() * b.w_sign() * c.w_sign();
    if let Some(s) = orient2d_fast(axes, &a.fast, &b.fast, &c.fast) {
        return w * s;
    }
    let rows = |p: &[Interval; 4]| [p[u], p[v], p[3]];
    let (ra, rb, rc) = (rows(&a.approx), rows(&b.approx), rows(&c.approx));
    w * decide(
        || det3([&ra[0], &ra[1], &ra[2]], [&rb[0], &rb[1], &rb[2]], [&rc[0], &rc[1], &rc[2]]),
        || exact_sign([a, b, c], |r| orient2d_rows(axes, r), |r| orient2d_rows(axes, r)),
    )
}

/// det [[a.u a.v a.w] [b.u b.v b.w] [c.u c.v c.w]] of homogeneous rows a, b, c.
fn orient2d_rows<R: Ring>(axes: [usize; 2], r: &[&[R; 4]]) -> R {
    let [u, v] = axes;
    let (a, b, c) = (r[0], r[1], r[2]);
    det3([&a[u], &a[v], &a[3]], [&b[u], &b[v], &b[3]], [&c[u], &c[v], &c[3]])
}

/// X_a·W_b − X_b·W_a along `axis` (a = r[0], b = r[1]).
fn compare_rows<R: Ring>(axis: usize, r: &[&[R; 4]]) -> R {
    let (a, b) = (r[0], r[1]);
    a[axis].times(&b[3]).minus(&b[axis].times(&a[3]))
}

/// The order of two points along coordinate `axis`.
pub fn compare_implicit(axis: usize, a: &Point, b: &Point) -> Ordering {
    let w = a.w_sign() * b.w_sign();
    let s = w * decide(
        || a.approx[axis].mul(b.approx[3]).sub(b.approx[axis].mul(a.approx[3])),
        || exact_sign([a, b], |r| compare_rows(axis, r), |r| compare_rows(axis, r)),
    );
    s.cmp(&0)
}

/// True when two points are the same point.
pub fn same_point(a: &Point, b: &Point) -> bool {
    (0..3).all(|axis| compare_implicit(axis, a, b) == Ordering::Equal)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The filter's constants are the powers of two their comments name.
    #[test]
    fn fast_filter_constants() {
        assert_eq!(DEEP_ALLOWANCE, 2f64.powi(-1000));
        let u = 2f64.powi(-53);
        assert_eq!(UP, 1.0 + 2f64.powi(-50));
        assert_eq!(MARGIN, 1.0 + 2f64.powi(-40));
        assert_eq!(GAMMA5, 6.0 * u);
        assert!(GAMMA5 >= 5.0 * u / (1.0 - 5.0 * u));
        assert_eq!(TWO_256, 2f64.powi(256));
        assert_eq!(UNDERFLOW, 2f64.powi(-800));
    }
    use crate::exact::orient2d;
    use crate::random::Rng;

    fn rand_point(rng: &mut Rng) -> DVec3 {
        rng.point_in_box(DVec3::splat(-1.0), DVec3::splat(1.0))
    }

    /// Points on one plane with coordinates of very different sizes (x near 1, y and z
    /// near 10⁻⁶⁰): products of their coordinates fall below f64's smallest step in some
    /// terms and not in others, so expansions would round; the signs and roundings are
    /// still exact (big dyadics take over).
    #[test]
    fn tiny_coordinates_beside_large_ones_stay_exact() {
        let mut rng = Rng::new(11);
        let t = 1e-60;
        let mut undecided = 0;
        for _ in 0..200 {
            let mut r = || {
                DVec3::new(rng.range_f64(0.1, 0.9), rng.range_f64(0.1, 0.9) * t, rng.range_f64(0.1, 0.9) * t)
            };
            let plane = [r(), r(), r()];
            let mut crossing = || loop {
                let (p, q) = (r() + DVec3::new(0.0, 0.0, t), r() - DVec3::new(0.0, 0.0, t));
                if let Ok(x) = Point::edge_plane(p, q, plane) {
                    break x;
                }
            };
            let x = [crossing(), crossing(), crossing(), crossing()];
            let before = exact_signs();
            assert_eq!(orient3d_implicit(&x[0], &x[1], &x[2], &x[3]), 0);
            undecided += exact_signs() - before;
            // The plane's own points with the crossings: on it too.
            let [a, b, c] = plane.map(Point::explicit);
            assert_eq!(orient3d_implicit(&a, &b, &x[0], &x[1]), 0);
            assert_eq!(orient3d_implicit(&a, &b, &c, &x[2]), 0);
            assert_eq!(x[3].position().to_array(), rounded_exact(&x[3]));
        }
        assert!(undecided > 0);
    }

    #[test]
    fn explicit_points_agree_with_the_explicit_predicates() {
        let mut rng = Rng::new(7);
        for _ in 0..2000 {
            let p: Vec<DVec3> = (0..4).map(|_| rand_point(&mut rng)).collect();
            let e: Vec<Point> = p.iter().map(|&x| Point::explicit(x)).collect();
            assert_eq!(orient3d_implicit(&e[0], &e[1], &e[2], &e[3]), orient3d(p[0], p[1], p[2], p[3]));
            for axes in [[0, 1], [1, 2], [2, 0]] {
                let q = |x: DVec3| [x[axes[0]], x[axes[1]]];
                assert_eq!(orient2d_implicit(axes, &e[0], &e[1], &e[2]), orient2d(q(p[0]), q(p[1]), q(p[2])));
            }
        }
        // Degenerate explicit cases, which only the exact path decides.
        let (a, b) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.7, 0.5, 0.3));
        let mid = Point::explicit(a + (b - a) * 0.5);
        let (ea, eb) = (Point::explicit(a), Point::explicit(b));
        assert_eq!(
            orient2d_implicit([0, 1], &ea, &eb, &mid),
            orient2d([a.x, a.y], [b.x, b.y], [mid.position().x, mid.position().y])
        );
    }

    /// The plain f64 filter decides only signs the expansions confirm, on points near a
    /// line through two others (implicit points on a segment, nudged by an ulp or more)
    /// and off it, and it leaves the exact zeros alone.
    #[test]
    fn the_f64_filter_decides_only_true_signs() {
        let exact = |axes: [usize; 2], a: &Point, b: &Point, c: &Point| {
            let [u, v] = axes;
            let w = a.w_sign() * b.w_sign() * c.w_sign();
            let (ea, eb, ec) = (a.exact().unwrap(), b.exact().unwrap(), c.exact().unwrap());
            w * det3([&ea[u], &ea[v], &ea[3]], [&eb[u], &eb[v], &eb[3]], [&ec[u], &ec[v], &ec[3]]).sign()
        };
        let mut rng = Rng::new(23);
        let (mut decided, mut zeros) = (0, 0);
        for _ in 0..400 {
            let plane = [rand_point(&mut rng), rand_point(&mut rng), rand_point(&mut rng)];
            let (p, q) = (rand_point(&mut rng), rand_point(&mut rng));
            let Ok(x) = Point::edge_plane(p, q, plane) else { continue };
            let at = x.position();
            let mut points = vec![x, Point::explicit(at)];
            for k in 0..3 {
                let mut near = at;
                near[k] = f64::from_bits(near[k].to_bits() + 1 + rng.below(4));
                points.push(Point::explicit(near));
            }
            // And points off the line, which the filter should decide.
            points.push(Point::explicit(rand_point(&mut rng)));
            let other = [rand_point(&mut rng), rand_point(&mut rng), rand_point(&mut rng)];
            points.extend(Point::edge_plane(p, rand_point(&mut rng), other));
            let (ep, eq) = (Point::explicit(p), Point::explicit(q));
            for axes in [[0, 1], [1, 2], [2, 0], [1, 0]] {
                for c in &points {
                    let want = exact(axes, &ep, &eq, c);
                    let w = ep.w_sign() * eq.w_sign() * c.w_sign();
                    if let Some(s) = orient2d_fast(axes, &ep.fast, &eq.fast, &c.fast) {
                        assert_eq!(w * s, want);
                        decided += 1;
                    }
                    zeros += (want == 0) as usize;
                    assert_eq!(orient2d_implicit(axes, &ep, &eq, c), want);
                    assert_eq!(orient2d_implicit(axes, c, &ep, &eq), want);
                }
            }
        }
        assert!(decided > 800 && zeros > 300, "{decided} {zeros}");
    }

    /// The crossing of pq with a plane lies exactly on line pq and exactly on the plane,
    /// although its rounded coordinates do neither.
    #[test]
    fn an_edge_plane_point_lies_exactly_on_its_segment_and_its_plane() {
        let mut rng = Rng::new(11);
        let mut rounded_off = 0;
        for _ in 0..500 {
            let plane = [rand_point(&mut rng), rand_point(&mut rng), rand_point(&mut rng)];
            let (p, q) = (rand_point(&mut rng), rand_point(&mut rng));
            let Ok(x) = Point::edge_plane(p, q, plane) else { continue };
            let [a, b, c] = plane.map(Point::explicit);
            let (ep, eq) = (Point::explicit(p), Point::explicit(q));
            assert_eq!(orient3d_implicit(&a, &b, &c, &x), 0);
            for axes in [[0, 1], [1, 2], [2, 0]] {
                assert_eq!(orient2d_implicit(axes, &ep, &eq, &x), 0);
            }
            let r = rand_point(&mut rng);
            assert_eq!(orient3d_implicit(&ep, &eq, &Point::explicit(r), &x), 0);
            // Strictly between p and q along every axis where they differ.
            for axis in 0..3 {
                let (lo, hi) = if p[axis] < q[axis] { (&ep, &eq) } else { (&eq, &ep) };
                if p[axis] != q[axis] {
                    assert_eq!(compare_implicit(axis, lo, &x), Ordering::Less);
                    assert_eq!(compare_implicit(axis, &x, hi), Ordering::Less);
                }
            }
            let at = x.position();
            rounded_off += (orient3d(plane[0], plane[1], plane[2], at) != 0) as usize;
        }
        // The rounded points mostly miss the plane: that is what the implicit ones fix.
        assert!(rounded_off > 100, "{rounded_off}");
    }

    #[test]
    fn the_same_point_reached_two_ways_is_the_same() {
        // Segment pq crosses the plane z = 0 at (0.25, 0.5, 0) — a dyadic point — and so
        // does segment rs, through two different planes holding that point.
        let p = DVec3::new(0.0, 0.0, -1.0);
        let q = DVec3::new(0.5, 1.0, 1.0);
        let flat = [DVec3::new(-3.0, 0.1, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(0.3, 5.0, 0.0)];
        let x = Point::edge_plane(p, q, flat).unwrap();
        let target = Point::explicit(DVec3::new(0.25, 0.5, 0.0));
        assert!(same_point(&x, &target));
        assert_eq!(x.position(), DVec3::new(0.25, 0.5, 0.0));
        let tilted = [DVec3::new(0.25, 0.5, 0.0), DVec3::new(1.0, 0.0, 0.375), DVec3::new(-0.5, 0.75, -2.0)];
        let y = Point::edge_plane(p, q, tilted).unwrap();
        assert!(same_point(&x, &y));
        assert_eq!(orient3d_implicit(&x, &y, &Point::explicit(p), &Point::explicit(q)), 0);
        // Nearby but not the same.
        let near = Point::explicit(DVec3::new(0.25, 0.5f64.up(), 0.0));
        assert!(!same_point(&x, &near));
        assert_eq!(compare_implicit(1, &x, &near), Ordering::Less);
    }

    #[test]
    fn coplanar_segments_cross_at_one_exact_point() {
        // Two segments in the plane x + y + z = 1 (not axis-aligned; dyadic coordinates,
        // so that the inputs are exactly in it), crossing.
        let on = |x: f64, y: f64| DVec3::new(x, y, 1.0 - x - y);
        let (p, q) = (on(0.125, 0.25), on(0.75, 0.1875));
        let (r, s) = (on(0.375, 0.0), on(0.3125, 0.625));
        let off = DVec3::new(5.0, 5.0, 5.0);
        let x = Point::edge_edge(p, q, r, s, off).unwrap();
        let (ep, eq, er, es) =
            (Point::explicit(p), Point::explicit(q), Point::explicit(r), Point::explicit(s));
        assert_eq!(orient3d_implicit(&ep, &eq, &er, &x), 0);
        for axes in [[0, 1], [1, 2], [2, 0]] {
            assert_eq!(orient2d_implicit(axes, &ep, &eq, &x), 0);
            assert_eq!(orient2d_implicit(axes, &er, &es, &x), 0);
        }
        // Another point off the plane names the same crossing.
        let y = Point::edge_edge(r, s, p, q, DVec3::new(-2.0, 1.0, 0.5)).unwrap();
        assert!(same_point(&x, &y));
        assert_eq!(Point::edge_edge(p, q, r, s, on(0.875, 0.5)).unwrap_err(), ImplicitError::OffInPlane);
        assert_eq!(Point::edge_edge(p, q, r, off, s).unwrap_err(), ImplicitError::NotCoplanar);
        assert_eq!(Point::edge_plane(p, p, [r, s, off]).unwrap_err(), ImplicitError::NoCrossing);
    }

    /// The double-double rounding agrees bit for bit with the exact one, on generic points
    /// and on the near-degenerate ones where its balls are too wide and it must hand over:
    /// segments grazing their plane, coordinates near zero, mixed scales, dyadic inputs
    /// whose crossings are exact or rounding ties, coplanar segment pairs.
    #[test]
    fn rounded_positions_are_the_exact_ones_bit_for_bit() {
        let mut rng = Rng::new(21);
        // (points, handed over) per kind of input.
        let mut counts = [(0, 0); 6];
        let mut check = |x: &Point, kind: usize| {
            let want = rounded_exact(x);
            let fast = rounded_fast(x);
            for i in 0..3 {
                if let Some(f) = fast[i] {
                    assert_eq!(f.to_bits(), want[i].to_bits(), "{:?} axis {i}", x.definition());
                }
            }
            counts[kind].1 += fast.iter().any(Option::is_none) as usize;
            counts[kind].0 += 1;
            assert_eq!(x.position().to_array().map(f64::to_bits), want.map(f64::to_bits));
        };
        let dyadic = |rng: &mut Rng| DVec3::from_array([0; 3].map(|_| (rng.below(33) as f64 - 16.0) / 8.0));
        for round in 0..3000 {
            let (plane, p, q) = match round % 6 {
                // Generic.
                0 => ([0; 3].map(|_| rand_point(&mut rng)), rand_point(&mut rng), rand_point(&mut rng)),
                // Dyadic: many crossings are exact or exact midpoints between two f64.
                1 => ([0; 3].map(|_| dyadic(&mut rng)), dyadic(&mut rng), dyadic(&mut rng)),
                // Grazing: p and q within 1e-12 .. 1e-15 of the plane.
                2 => {
                    let plane = [0; 3].map(|_| rand_point(&mut rng));
                    let [a, b, c] = plane;
                    let n = (b - a).cross(c - a).normalize_or_zero();
                    let on = |rng: &mut Rng| a + (b - a) * rng.next_f64() + (c - a) * rng.next_f64();
                    let (p, q) = (on(&mut rng) + n * 1e-12, on(&mut rng) - n * 1e-15);
                    (plane, p, q)
                }
                // A coordinate of the crossing near zero.
                3 => {
                    let tiny = |rng: &mut Rng| rng.range_f64(-1e-14, 1e-14);
                    let mut plane = [0; 3].map(|_| rand_point(&mut rng));
                    for v in &mut plane {
                        v.x = tiny(&mut rng);
                    }
                    (plane, DVec3::new(-1.0, 0.3, 0.2), DVec3::new(1.0, -0.1, 0.7))
                }
                // Mixed scales.
                4 => {
                    let s = |rng: &mut Rng| rand_point(rng) * 2f64.powi(rng.below(41) as i32 - 20);
                    ([0; 3].map(|_| s(&mut rng)), s(&mut rng), s(&mut rng))
                }
                // Ties: pq crosses z = 0 halfway, between coordinates one ulp apart.
                _ => {
                    let x = rng.range_f64(0.5, 1.0);
                    let flat =
                        [DVec3::new(-3.0, 0.1, 0.0), DVec3::new(2.0, -1.0, 0.0), DVec3::new(0.3, 5.0, 0.0)];
                    (flat, DVec3::new(x, -x, -1.0), DVec3::new(x.up(), (-x).down(), 1.0))
                }
            };
            if let Ok(x) = Point::edge_plane(p, q, plane) {
                check(&x, round % 6);
                if round % 6 == 5 {
                    // The exact midpoint ties to the even neighbour.
                    let even = |a: f64, b: f64| if a.to_bits() & 1 == 0 { a } else { b };
                    assert_eq!(x.position().x, even(p.x, q.x));
                }
            }
            // Coplanar segment pairs (in z = const, crossing).
            if round % 6 == 1 {
                let z = p.z;
                let (r, s) = (dyadic(&mut rng), dyadic(&mut rng));
                let flat = |v: DVec3| DVec3::new(v.x, v.y, z);
                if let Ok(x) = Point::edge_edge(flat(p), flat(q), flat(r), flat(s), flat(p) + DVec3::Z) {
                    check(&x, 1);
                }
            }
        }
        // Both paths ran: generic points hardly ever need expansions (mixed scales seldom,
        // 9 of 223 with seed 21), every tie does.
        assert!(counts[0].0 > 50 && counts[0].1 * 50 < counts[0].0, "{counts:?}");
        assert!(counts[4].0 > 50 && counts[4].1 * 10 < counts[4].0, "{counts:?}");
        assert!(counts[5].0 > 400 && counts[5].1 == counts[5].0, "{counts:?}");
    }

    /// Orientation tests among several implicit points agree with a direct evaluation on
    /// points far enough from degenerate that rounding cannot matter.
    #[test]
    fn orientations_of_implicit_points_agree_with_their_rounded_positions_when_far_from_zero() {
        let mut rng = Rng::new(3);
        let mut pts = Vec::new();
        while pts.len() < 40 {
            let plane = [rand_point(&mut rng), rand_point(&mut rng), rand_point(&mut rng)];
            if let Ok(x) = Point::edge_plane(rand_point(&mut rng), rand_point(&mut rng), plane) {
                pts.push(x);
            }
        }
        let mut decided = 0;
        for w in pts.windows(4) {
            let [a, b, c, d] = [&w[0], &w[1], &w[2], &w[3]].map(Point::position);
            let v = ((b - a).cross(c - a)).dot(d - a);
            let scale = (b - a).length() * (c - a).length() * (d - a).length();
            if v.abs() > 1e-9 * scale && scale < 1e6 {
                decided += 1;
                assert_eq!(orient3d_implicit(&w[0], &w[1], &w[2], &w[3]), v.signum() as Sign);
            }
        }
        assert!(decided > 20);
    }
}

/// Points made from points ([`Point::segment_plane`], [`Point::segment_segment`]): their
/// geometry checked against what they are defined to be, to any depth.
#[cfg(test)]
mod nested_tests {
    use super::*;
    use crate::random::Rng;

    fn rand_point(rng: &mut Rng) -> DVec3 {
        rng.point_in_box(DVec3::splat(-1.0), DVec3::splat(1.0))
    }

    fn rand_triangle(rng: &mut Rng, half: f64) -> [DVec3; 3] {
        [0; 3].map(|_| rng.point_in_box(DVec3::splat(-half), DVec3::splat(half)))
    }

    /// Where the plane of `cut` crosses two edges of triangle `tri`: the ends of a segment
    /// (the chord) that lies exactly on the line where the two planes meet.
    fn chord(tri: [DVec3; 3], cut: [DVec3; 3]) -> Option<[Point; 2]> {
        let ends: Vec<Point> =
            (0..3).filter_map(|i| Point::edge_plane(tri[i], tri[(i + 1) % 3], cut).ok()).collect();
        <[Point; 2]>::try_from(ends).ok()
    }

    /// [`Point::segment_plane`] on explicit points of a plane given as coordinates.
    fn cut(p: &Point, q: &Point, plane: [DVec3; 3]) -> Result<Point, ImplicitError> {
        let [a, b, c] = plane.map(Point::explicit);
        Point::segment_plane(p, q, [&a, &b, &c])
    }

    fn on_plane(plane: [DVec3; 3], x: &Point) -> Sign {
        let [a, b, c] = plane.map(Point::explicit);
        orient3d_implicit(&a, &b, &c, x)
    }

    /// [`orient2d_implicit`], checked against the determinant in expansions; the plain f64
    /// filter must decide only that sign. Returns the sign and whether the filter decided.
    fn orient2d_checked(axes: [usize; 2], a: &Point, b: &Point, c: &Point) -> (Sign, bool) {
        let [u, v] = axes;
        let w = a.w_sign() * b.w_sign() * c.w_sign();
        let (ea, eb, ec) = (a.big(), b.big(), c.big());
        let want =
            w * det3([&ea[u], &ea[v], &ea[3]], [&eb[u], &eb[v], &eb[3]], [&ec[u], &ec[v], &ec[3]]).sign();
        let fast = orient2d_fast(axes, &a.fast, &b.fast, &c.fast);
        if let Some(s) = fast {
            assert_eq!(w * s, want, "f64 filter on {axes:?}");
        }
        assert_eq!(orient2d_implicit(axes, a, b, c), want);
        (want, fast.is_some())
    }

    /// x lies on line pq (all three projections) and strictly between p and q.
    fn assert_strictly_inside(p: &Point, q: &Point, x: &Point) {
        for axes in [[0, 1], [1, 2], [2, 0]] {
            assert_eq!(orient2d_checked(axes, p, q, x).0, 0);
        }
        let mut differ = 0;
        for axis in 0..3 {
            let order = compare_implicit(axis, p, q);
            if order != Ordering::Equal {
                differ += 1;
                assert_eq!(compare_implicit(axis, p, x), order);
                assert_eq!(compare_implicit(axis, x, q), order);
            }
        }
        assert!(differ > 0);
    }

    /// The position is the exact quotient rounded to nearest (the expansions' path), bit
    /// for bit, and the certified coordinates hold it.
    fn assert_rounded_exactly(x: &Point) -> bool {
        let want = rounded_exact(x);
        let fast = rounded_fast(x);
        for i in 0..3 {
            if let Some(f) = fast[i] {
                assert_eq!(f.to_bits(), want[i].to_bits(), "{:?} axis {i}", x.definition());
            }
        }
        assert_eq!(x.position().to_array().map(f64::to_bits), want.map(f64::to_bits));
        for (ball, w) in x.coordinates().iter().zip(want) {
            // The exact value is within half an ulp of its rounding.
            assert!((ball.value() - w).abs() <= ball.error() + w.abs() * f64::EPSILON, "{ball:?} {w}");
        }
        fast.iter().any(Option::is_none)
    }

    /// With five explicit points the point is the edge crossing a plane, of that (cheaper)
    /// kind; the same five points forced into the general kind make the same point.
    #[test]
    fn a_segment_plane_point_of_explicit_points_is_the_edge_plane_point() {
        let mut rng = Rng::new(5);
        let mut made = 0;
        for _ in 0..300 {
            let plane = rand_triangle(&mut rng, 1.0);
            let (p, q) = (rand_point(&mut rng), rand_point(&mut rng));
            let [ep, eq] = [p, q].map(Point::explicit);
            let direct = Point::edge_plane(p, q, plane);
            let general = cut(&ep, &eq, plane);
            assert_eq!(direct.is_ok(), general.is_ok());
            let (Ok(direct), Ok(general)) = (direct, general) else { continue };
            made += 1;
            assert_eq!(general.definition(), direct.definition());
            let forced = Point::new(Definition::SegmentPlane(Arc::new(SegmentPlane {
                p: ep.clone(),
                q: eq.clone(),
                plane: plane.map(Point::explicit),
                balls: OnceLock::new(),
                big: OnceLock::new(),
            })));
            assert!(same_point(&forced, &direct));
            assert_eq!(forced.position(), direct.position());
            assert_eq!(on_plane(plane, &forced), 0);
            assert_strictly_inside(&ep, &eq, &forced);
            assert_rounded_exactly(&forced);
        }
        assert!(made > 50, "{made}");
    }

    /// The point where three random planes meet, reached as line a∩b cut by plane c, as
    /// line a∩c cut by plane b, as line b∩c cut by plane a, and as the crossing of the
    /// two coplanar chords in plane a: one point, one rounded position, exactly on the
    /// three planes and on the chords, strictly between their ends.
    #[test]
    fn a_triple_point_built_several_ways_is_one_point() {
        let mut rng = Rng::new(17);
        let (mut made, mut third, mut decided) = (0, 0, 0);
        for _ in 0..600 {
            let a = rand_triangle(&mut rng, 3.0);
            let (b, c) = (rand_triangle(&mut rng, 1.0), rand_triangle(&mut rng, 1.0));
            let (Some([x1, x2]), Some([y1, y2])) = (chord(a, b), chord(a, c)) else { continue };
            let t1 = cut(&x1, &x2, c);
            let t2 = cut(&y1, &y2, b);
            // Both exist exactly when the triple point lies inside triangle a.
            assert_eq!(t1.is_ok(), t2.is_ok());
            let off = Point::explicit(b.into_iter().find(|&v| orient3d(a[0], a[1], a[2], v) != 0).unwrap());
            let t4 = Point::segment_segment(&x1, &x2, &y1, &y2, &off);
            assert_eq!(t1.is_ok(), t4.is_ok());
            let (Ok(t1), Ok(t2), Ok(t4)) = (t1, t2, t4) else { continue };
            made += 1;
            assert!(matches!(t1.definition(), Definition::SegmentPlane(_)));
            for t in [&t1, &t2, &t4] {
                assert!(same_point(t, &t1));
                assert_eq!(
                    t.position().to_array().map(f64::to_bits),
                    t1.position().to_array().map(f64::to_bits)
                );
                for plane in [a, b, c] {
                    assert_eq!(on_plane(plane, t), 0);
                }
                assert_strictly_inside(&x1, &x2, t);
                assert_strictly_inside(&y1, &y2, t);
                assert_rounded_exactly(t);
            }
            if let Some([z1, z2]) = chord(b, c) {
                if let Ok(t3) = cut(&z1, &z2, a) {
                    third += 1;
                    assert!(same_point(&t3, &t1));
                    assert_eq!(t3.position(), t1.position());
                }
            }
            // Off the line: the f64 filter decides on points made from points, rightly;
            // points a few ulps from the triple point's rounding are decided either way.
            let at = t1.position();
            let mut near = vec![Point::explicit(rand_point(&mut rng)), Point::explicit(at)];
            for k in 0..3 {
                let mut n = at;
                n[k] = f64::from_bits(n[k].to_bits() + 1 + rng.below(4));
                near.push(Point::explicit(n));
            }
            for n in &near {
                for axes in [[0, 1], [1, 2], [2, 0], [1, 0]] {
                    decided += orient2d_checked(axes, &x1, &t1, n).1 as usize;
                    decided += orient2d_checked(axes, n, &t2, &t4).1 as usize;
                }
            }
            // And orientations far from zero agree with the rounded positions.
            let d = rand_triangle(&mut rng, 1.0);
            let v = (d[1] - d[0]).cross(d[2] - d[0]).dot(at - d[0]);
            if v.abs() > 1e-6 {
                assert_eq!(on_plane(d, &t1), orient3d(d[0], d[1], d[2], at));
                assert_eq!(on_plane(d, &t1), if v > 0.0 { 1 } else { -1 });
            }
        }
        assert!(made > 60 && third > 10 && decided > 100, "{made} {third} {decided}");
    }

    /// Points on one line, each cutting the segment between two earlier ones with a plane:
    /// depth after depth, the point is the one the plane cuts from the line directly, it
    /// exists exactly when that one lies strictly between the segment's ends, and it lies
    /// on its plane, on both planes of the line and on the line.
    #[test]
    fn points_from_points_nest_to_any_depth() {
        let mut rng = Rng::new(29);
        let mut deepest = 0;
        let mut refused = 0;
        for _ in 0..60 {
            let a = rand_triangle(&mut rng, 3.0);
            let b = rand_triangle(&mut rng, 1.0);
            let Some([x1, x2]) = chord(a, b) else { continue };
            let axis = (0..3).find(|&i| compare_implicit(i, &x1, &x2) != Ordering::Equal).unwrap();
            let planes: Vec<[DVec3; 3]> = (0..8).map(|_| rand_triangle(&mut rng, 1.0)).collect();
            // The points the planes cut from the chord directly (depth 2), where they do.
            let direct: Vec<Option<Point>> = planes.iter().map(|&c| cut(&x1, &x2, c).ok()).collect();
            // (point, depth): the chord's ends are depth 1.
            let mut line: Vec<(Point, usize)> = vec![(x1.clone(), 1), (x2.clone(), 1)];
            for _ in 0..40 {
                let i = rng.below(line.len() as u64) as usize;
                let j = rng.below(line.len() as u64) as usize;
                let k = rng.below(planes.len() as u64) as usize;
                if i == j {
                    continue;
                }
                let (p, q) = (&line[i].0, &line[j].0);
                let between = direct[k].as_ref().is_some_and(|d| {
                    let (lo, hi) =
                        if compare_implicit(axis, p, q) == Ordering::Less { (p, q) } else { (q, p) };
                    compare_implicit(axis, lo, d) == Ordering::Less
                        && compare_implicit(axis, d, hi) == Ordering::Less
                });
                let made = cut(p, q, planes[k]);
                assert_eq!(made.is_ok(), between, "{made:?}");
                let Ok(x) = made else {
                    refused += 1;
                    continue;
                };
                let d = direct[k].as_ref().unwrap();
                assert!(same_point(&x, d));
                assert_eq!(x.position(), d.position());
                for plane in [a, b, planes[k]] {
                    assert_eq!(on_plane(plane, &x), 0);
                }
                assert_strictly_inside(p, q, &x);
                assert_strictly_inside(&x1, &x2, &x);
                assert_rounded_exactly(&x);
                let depth = 1 + line[i].1.max(line[j].1);
                deepest = deepest.max(depth);
                line.push((x, depth));
            }
        }
        assert!(deepest >= 5 && refused > 50, "{deepest} {refused}");
    }

    /// A plane given by points made from points that lie in it exactly: the interval
    /// filter cannot tell their orientation from zero, the exact path says 0, and segments
    /// cut by that plane give the points the input plane gives.
    #[test]
    fn a_plane_through_points_made_from_points_is_decided_exactly() {
        let mut rng = Rng::new(41);
        let (mut made, mut undecided) = (0, 0);
        for _ in 0..300 {
            let a = rand_triangle(&mut rng, 3.0);
            let (b, c) = (rand_triangle(&mut rng, 1.0), rand_triangle(&mut rng, 1.0));
            let Some([x1, x2]) = chord(a, b) else { continue };
            let Ok(t) = cut(&x1, &x2, c) else { continue };
            let [a0, a1, a2] = a.map(Point::explicit);
            // Plane a through t (depth 2), x1 (depth 1) and a vertex: all exactly in it.
            let vertex = if orient2d_implicit([0, 1], &t, &x1, &a2) != 0
                || orient2d_implicit([1, 2], &t, &x1, &a2) != 0
            {
                &a2
            } else {
                &a0
            };
            let implicit_plane = [&t, &x1, vertex];
            for v in [&a0, &a1, &a2] {
                undecided +=
                    det4([&t.approx, &x1.approx, &vertex.approx, &v.approx]).sign().is_none() as usize;
                assert_eq!(orient3d_implicit(&t, &x1, vertex, v), 0);
            }
            undecided += det4([&a0.approx, &a1.approx, &a2.approx, &t.approx]).sign().is_none() as usize;
            assert_eq!(orient3d_implicit(&a0, &a1, &a2, &t), 0);
            // Collinear points make no plane: nothing crosses it.
            let (p, q) = (Point::explicit(rand_point(&mut rng)), Point::explicit(rand_point(&mut rng)));
            assert_eq!(Point::segment_plane(&p, &q, [&x1, &t, &x2]).unwrap_err(), ImplicitError::NoCrossing);
            let direct = cut(&p, &q, a);
            let through = Point::segment_plane(&p, &q, implicit_plane);
            assert_eq!(direct.is_ok(), through.is_ok());
            let (Ok(direct), Ok(through)) = (direct, through) else { continue };
            made += 1;
            assert!(same_point(&through, &direct));
            assert_eq!(through.position(), direct.position());
            assert_eq!(orient3d_implicit(&t, &x1, vertex, &through), 0);
            assert_eq!(on_plane(a, &through), 0);
            assert_strictly_inside(&p, &q, &through);
            assert_rounded_exactly(&through);
            // A point of a segment between points made from points, cut by a plane through
            // points made from points: the segment from `through` to the far side of b.
            if let Some(far) = [&p, &q].into_iter().find(|e| on_plane(b, e) * on_plane(b, &through) < 0) {
                let [b0, b1, b2] = b.map(Point::explicit);
                let on_b = Point::segment_plane(&through, far, [&b0, &b1, &b2]).unwrap();
                assert_eq!(on_plane(b, &on_b), 0);
                assert_strictly_inside(&through, far, &on_b);
                assert_rounded_exactly(&on_b);
            }
        }
        assert!(made > 20 && undecided > 100, "{made} {undecided}");
    }

    /// Rounding ties and exact values among points made from points: the line where the
    /// planes x = 1 and y = 0 meet, cut by a plane that crosses it halfway between two
    /// neighbouring f64 (a tie: to the even one, by the expansions) or at an f64.
    #[test]
    fn nested_points_round_ties_to_even_by_the_exact_path() {
        let mut rng = Rng::new(53);
        let a = [DVec3::new(1.0, -3.0, -3.0), DVec3::new(1.0, 3.0, -2.0), DVec3::new(1.0, 0.5, 4.0)];
        let b = [DVec3::new(-3.0, 0.0, -3.0), DVec3::new(3.0, 0.0, -2.5), DVec3::new(0.25, 0.0, 4.0)];
        let [x1, x2] = chord(a, b).unwrap();
        let mut handed_over = 0;
        for round in 0..200 {
            let z1 = rng.range_f64(-1.0, 1.0);
            let z2 = if round % 2 == 0 { z1.up() } else { z1 };
            // Through (0, y, z1) and (2, 0, z2): at x = 1, z = (z1 + z2) / 2.
            let c = [DVec3::new(0.0, 0.0, z1), DVec3::new(0.0, 1.0, z1), DVec3::new(2.0, 0.0, z2)];
            let t = cut(&x1, &x2, c).unwrap();
            handed_over += assert_rounded_exactly(&t) as usize;
            let even = if z1.to_bits() & 1 == 0 { z1 } else { z2 };
            assert_eq!(t.position(), DVec3::new(1.0, 0.0, if round % 2 == 0 { even } else { z1 }));
            if round % 2 == 0 {
                assert!(rounded_fast(&t)[2].is_none());
                assert!(!same_point(&t, &Point::explicit(DVec3::new(1.0, 0.0, even))));
            } else {
                assert!(same_point(&t, &Point::explicit(DVec3::new(1.0, 0.0, z1))));
            }
        }
        assert!(handed_over >= 100, "{handed_over}");
    }

    /// Segments that do not cross their plane, and coplanar segment pairs that are not, or
    /// whose third point is not off their plane, are refused.
    #[test]
    fn segments_that_do_not_cross_are_refused() {
        let mut rng = Rng::new(61);
        let mut checked = 0;
        for _ in 0..300 {
            let a = rand_triangle(&mut rng, 3.0);
            let (b, c) = (rand_triangle(&mut rng, 1.0), rand_triangle(&mut rng, 1.0));
            let (Some([x1, x2]), Some([y1, y2])) = (chord(a, b), chord(a, c)) else { continue };
            let Ok(t) = cut(&x1, &x2, c) else { continue };
            checked += 1;
            // An end on the plane: t lies on c.
            assert_eq!(cut(&t, &x1, c).unwrap_err(), ImplicitError::NoCrossing);
            assert_eq!(cut(&x2, &t, c).unwrap_err(), ImplicitError::NoCrossing);
            // Both ends on one side: x1 and t are on one side of c's crossing... of any plane
            // through x2 and off the chord's line.
            let d = [x2.position(), rand_point(&mut rng), rand_point(&mut rng)];
            if on_plane(d, &x1) * on_plane(d, &t) > 0 {
                assert_eq!(cut(&x1, &t, d).unwrap_err(), ImplicitError::NoCrossing);
            }
            // A segment lying in the plane.
            assert_eq!(cut(&x1, &x2, a).unwrap_err(), ImplicitError::NoCrossing);
            let [a0, a1, a2] = a.map(Point::explicit);
            assert_eq!(
                Point::segment_segment(&x1, &x2, &y1, &y2, &a0).unwrap_err(),
                ImplicitError::OffInPlane
            );
            let off = Point::explicit(rand_point(&mut rng));
            if orient3d_implicit(&a0, &a1, &a2, &off) != 0 {
                assert_eq!(
                    Point::segment_segment(&x1, &x2, &y1, &off, &a1).unwrap_err(),
                    ImplicitError::NotCoplanar
                );
            }
        }
        assert!(checked > 30, "{checked}");
    }
}
