//! The correctly rounded (round-to-nearest, ties to even) f64 of a quotient X / W of two
//! exact values, as implicit points need for their output coordinates: the same real
//! point reached through two definitions must round to the same f64s, and the rounded
//! value must be the nearest one so that what is written stays as close as f64 allows.
//!
//! The fast path evaluates X and W in double-double with a proven error radius ([`Ball`]),
//! takes the f64 quotient of their leading parts as the candidate r, and checks that X / W
//! lies strictly between the two rounding midpoints around r — the signs of X − m·W for
//! m = (r + r⁻) / 2 and (r + r⁺) / 2, decided when the ball excludes zero. When a ball is
//! too wide (the value sits within about 2⁻¹⁰⁰ of a midpoint, or X or W cancel badly) the
//! exact path ([`quotient_exact`]) divides their exact values.
//!
//! Like the rest of [`crate::exact`], it assumes coordinates in a normalized frame: no
//! product overflows or falls below f64's normal range.

use super::dyadic::Dyadic;
use super::expansion::{Exact, two_prod, two_sum};

/// u = 2⁻⁵³, the unit roundoff of f64.
const U: f64 = 1.0 / 9007199254740992.0;

/// Relative error bound of one double-double operation below: Joldes, Muller & Popescu
/// (2017, "Tight and rigorous error bounds for basic building blocks of double-word
/// arithmetic") prove 3u² for AccurateDWPlusDW and 5u² for DWTimesDW3; 16u² leaves margin.
const DD_ERR: f64 = 16.0 * U * U;

/// Widening of a radius computed in f64 from non-negative terms with at most eight
/// roundings (each at most a factor 1 + u): the result times this is an upper bound.
const RADIUS_UP: f64 = 1.0 + 4.0 * 8.0 * U;

/// Fast-Two-Sum: a + b = s + e exactly when |a| ≥ |b| (or a = 0).
#[inline(always)]
fn fast_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// A real number known to lie within `rad` of the double-double `hi + lo`
/// (`|lo| ≤ ulp(hi) / 2`).
#[derive(Clone, Copy, Debug)]
pub struct Ball {
    hi: f64,
    lo: f64,
    rad: f64,
}

impl Ball {
    /// An f64, exactly.
    #[inline]
    pub fn of(x: f64) -> Ball {
        Ball { hi: x, lo: 0.0, rad: 0.0 }
    }

    /// An upper bound of |hi + lo|.
    #[inline]
    fn magnitude(&self) -> f64 {
        self.hi.abs() + self.lo.abs()
    }

    /// AccurateDWPlusDW (Joldes et al. 2017, Algorithm 6).
    #[inline]
    pub fn add(&self, o: &Ball) -> Ball {
        let (sh, sl) = two_sum(self.hi, o.hi);
        let (th, tl) = two_sum(self.lo, o.lo);
        let c = sl + th;
        let (vh, vl) = fast_two_sum(sh, c);
        let w = tl + vl;
        let (hi, lo) = fast_two_sum(vh, w);
        // The exact sum of the midpoints is at most |x| + |y|; the double-double sum is
        // within DD_ERR of it, relatively.
        let rad = (self.rad + o.rad + DD_ERR * (self.magnitude() + o.magnitude())) * RADIUS_UP;
        Ball { hi, lo, rad }
    }

    #[inline]
    pub fn neg(&self) -> Ball {
        Ball { hi: -self.hi, lo: -self.lo, rad: self.rad }
    }

    #[inline]
    pub fn sub(&self, o: &Ball) -> Ball {
        self.add(&o.neg())
    }

    /// DWTimesDW3 (Joldes et al. 2017, Algorithm 12, with fused multiply-add).
    #[inline]
    pub fn mul(&self, o: &Ball) -> Ball {
        let (ch, cl1) = two_prod(self.hi, o.hi);
        let tl0 = self.lo * o.lo;
        let tl1 = self.hi.mul_add(o.lo, tl0);
        let cl2 = self.lo.mul_add(o.hi, tl1);
        let cl3 = cl1 + cl2;
        let (hi, lo) = fast_two_sum(ch, cl3);
        // (x + δx)(y + δy) − xy = x·δy + y·δx + δx·δy, plus the double-double rounding.
        let (mx, my) = (self.magnitude(), o.magnitude());
        let rad = (mx * o.rad + my * self.rad + self.rad * o.rad + DD_ERR * (mx * my)) * RADIUS_UP;
        Ball { hi, lo, rad }
    }

    /// The double-double sum of an expansion's components (smallest first), with its
    /// radius: a ball around an exact value, a few 2⁻¹⁰⁶ of it wide.
    pub fn of_exact(e: &Exact) -> Ball {
        e.components().iter().fold(Ball::of(0.0), |s, &c| s.add(&Ball::of(c)))
    }

    /// The same ball with its radius grown by r ≥ 0 (rounded up).
    #[inline]
    pub fn widened(&self, r: f64) -> Ball {
        Ball { hi: self.hi, lo: self.lo, rad: (self.rad + r) * RADIUS_UP }
    }

    /// The f64 nearest the midpoint `hi + lo`.
    #[inline]
    pub fn value(&self) -> f64 {
        self.hi + self.lo
    }

    /// The radius around `hi + lo`.
    #[inline]
    pub fn radius(&self) -> f64 {
        self.rad
    }

    /// An upper bound of how far every value of the ball lies from [`Ball::value`]: the
    /// radius plus the rounding of `hi + lo` to f64 (at most u·|value|).
    pub fn error(&self) -> f64 {
        (self.rad + U * self.value().abs()) * RADIUS_UP
    }

    /// The quotient of every value of this ball by every value of `w`, as a ball: a
    /// double-double quotient (the f64 one corrected by its residual) whose radius bounds
    /// |X − q·W| / |W| over both balls. None when `w` holds zero (or a value too close to
    /// it for the bound) or the quotient is not finite.
    pub fn div(&self, w: &Ball) -> Option<Ball> {
        // A lower bound of |W| over the ball: |hi + lo| ≥ |hi|·(1 − u) for a normalized
        // pair; the last factor covers the rounding of the subtraction.
        let w_low = (w.hi.abs() * (1.0 - 8.0 * U) - w.rad) * (1.0 - 4.0 * U);
        if w_low.is_nan() || w_low <= 0.0 {
            return None;
        }
        let q0 = self.hi / w.hi;
        let q1 = self.sub(&w.mul(&Ball::of(q0))).hi / w.hi;
        let (hi, lo) = two_sum(q0, q1);
        // The residual X − (hi + lo)·W over both balls, products and differences each
        // with its own radius.
        let r = self.sub(&w.mul(&Ball::of(hi))).sub(&w.mul(&Ball::of(lo)));
        let rad = (r.magnitude() + r.rad) / w_low * RADIUS_UP;
        (hi.is_finite() && lo.is_finite() && rad.is_finite()).then_some(Ball { hi, lo, rad })
    }

    /// Times a power of two: exact (no underflow in a normalized frame).
    #[inline]
    fn scaled(&self, two_power: f64) -> Ball {
        Ball { hi: self.hi * two_power, lo: self.lo * two_power, rad: self.rad * two_power.abs() }
    }

    /// The sign of every value in the ball, when they share one (never 0: a ball around
    /// zero cannot vouch for it).
    #[inline]
    fn sign(&self) -> Option<i32> {
        // |hi + lo| ≥ |hi|·(1 − u) for a normalized pair.
        if self.hi.abs() * (1.0 - 8.0 * U) > self.rad {
            Some(if self.hi > 0.0 { 1 } else { -1 })
        } else {
            None
        }
    }
}

/// One ulp up and down (`f64::next_up`/`next_down`, newer than the toolchain texgeo
/// supports); finite non-zero inputs.
fn next_up(x: f64) -> f64 {
    if x > 0.0 { f64::from_bits(x.to_bits() + 1) } else { f64::from_bits(x.to_bits() - 1) }
}

fn next_down(x: f64) -> f64 {
    -next_up(-x)
}

/// Below this magnitude the candidate's neighbours' half gaps could underflow; the exact
/// path takes over (it never happens in a normalized frame, but costs nothing to check).
const TINY: f64 = 1e-290;

/// X / W rounded to nearest when double-double balls decide it, else None.
pub fn quotient_fast(x: &Ball, w: &Ball) -> Option<f64> {
    let sw = w.sign()?;
    // The leading parts' quotient is off by up to about 1.5 ulp; one Newton-like
    // correction with the double-double residual makes it the nearest f64 except within
    // the balls' width of a midpoint.
    let r0 = x.hi / w.hi;
    if !r0.is_finite() || r0.abs() < TINY {
        return None;
    }
    let r = r0 + x.sub(&w.mul(&Ball::of(r0))).hi / w.hi;
    if !r.is_finite() || r.abs() < TINY {
        return None;
    }
    // X/W < m ⟺ sign(X − m·W)·sign(W) < 0, with m = r ± half the gap to a neighbour.
    let t = x.sub(&w.mul(&Ball::of(r)));
    let half_up = (next_up(r) - r) * 0.5;
    let half_down = (r - next_down(r)) * 0.5;
    let below_upper = t.sub(&w.scaled(half_up)).sign()? * sw < 0;
    let above_lower = t.add(&w.scaled(half_down)).sign()? * sw > 0;
    (below_upper && above_lower).then_some(r)
}

/// X / W rounded to nearest, ties to even, W ≠ 0; exact 0 gives +0: the expansions'
/// exact values divided as big dyadics ([`super::dyadic::quotient`]).
pub fn quotient_exact(x: &Exact, w: &Exact) -> f64 {
    super::dyadic::quotient(&Dyadic::of_exact(x), &Dyadic::of_exact(w))
}

/// [`quotient_exact`] found another way, the reference of the tests: from the f64 quotient
/// of the leading parts, stepping by one ulp while X / W lies beyond a rounding midpoint
/// (decided exactly with expansions).
#[cfg(test)]
pub(crate) fn quotient_by_midpoints(x: &Exact, w: &Exact) -> f64 {
    let sw = w.sign();
    if x.sign() == 0 || sw == 0 {
        return 0.0;
    }
    // Where X/W sits against r + h: the sign of (X − (r + h)·W)·sign(W).
    let against = |r: f64, h: f64| {
        let m = &Exact::from_f64(r) + &Exact::from_f64(h);
        (x - &(&m * w)).sign() * sw
    };
    let even = |a: f64, b: f64| if a.to_bits() & 1 == 0 { a } else { b };
    let mut r = x.approx() / w.approx();
    if !r.is_finite() || r == 0.0 {
        // Not reached with W ≠ 0 in a normalized frame; start from the smallest normal.
        r = f64::MIN_POSITIVE * f64::from(x.sign() * sw);
    }
    loop {
        let up = next_up(r);
        match against(r, (up - r) * 0.5) {
            1 => {
                r = up;
                continue;
            }
            0 => return even(r, up),
            _ => {}
        }
        let down = next_down(r);
        match against(r, -(r - down) * 0.5) {
            -1 => r = down,
            0 => return even(down, r),
            _ => return r,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_round_to_even_and_exact_quotients_stay() {
        // Both exact ways: the big-dyadic division and the midpoint steps.
        let ways: [fn(&Exact, &Exact) -> f64; 2] = [quotient_exact, quotient_by_midpoints];
        for quotient in ways {
            // (1 + 2⁻⁵²)/2 + 1/2 is the midpoint 1 + 2⁻⁵³, a tie: it rounds to even, 1.
            let x = &Exact::from_f64(1.0) + &Exact::from_f64(1.0 + f64::EPSILON);
            let w = Exact::from_f64(2.0);
            assert_eq!(quotient(&x, &w), 1.0);
            // Three halves of an ulp above 1 rounds to 1 + 2ulp (even).
            let x = &Exact::from_f64(2.0) + &Exact::from_f64(3.0 * f64::EPSILON);
            assert_eq!(quotient(&x, &w), 1.0 + 2.0 * f64::EPSILON);
            // Exact quotients, of either sign.
            assert_eq!(quotient(&Exact::from_f64(-3.0), &Exact::from_f64(4.0)), -0.75);
            assert_eq!(quotient(&Exact::from_f64(1.0), &Exact::from_f64(-3.0)), -1.0 / 3.0);
            assert_eq!(quotient(&Exact::default(), &Exact::from_f64(-3.0)).to_bits(), 0);
        }
        let bx = Ball::of(1.0).add(&Ball::of(1.0 + f64::EPSILON));
        assert_eq!(quotient_fast(&bx, &Ball::of(2.0)), None);
        assert_eq!(quotient_fast(&Ball::of(-3.0), &Ball::of(4.0)), Some(-0.75));
        assert_eq!(quotient_fast(&Ball::of(1.0), &Ball::of(-3.0)), Some(-1.0 / 3.0));
    }
}
