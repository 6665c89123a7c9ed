//! Exact dyadic numbers m·2ᵉ with a big-integer m: the exact arithmetic of implicit points
//! made from points ([`super::implicit`]), whose polynomials are of a degree where
//! expansions of f64 lose exactness. A product of k input coordinates of 53 significant
//! bits has about 53·k of them, and an expansion holds only the bits between 2¹⁰²³ and
//! 2⁻¹⁰⁷⁴: with coordinates near 1 its error terms fall below f64's range from k ≈ 20 on,
//! which a point two levels deep already reaches in one determinant. Here nothing is
//! rounded at any degree; the cost grows with the number of bits, so this arithmetic
//! serves only where the interval filter cannot decide.

use num_bigint::{BigInt, BigUint, Sign as BigSign};

use super::expansion::Exact;
use super::predicates::Sign;
use super::rounding::Ball;

/// m·2ᵉ exactly, kept with m odd (or m = 0 and e = 0), so that one value has one form.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Dyadic {
    m: BigInt,
    e: i64,
}

/// 2ᵏ as an f64 for |k| ≤ 1000 (exact: a power of two in the normal range).
fn two_to(k: i64) -> f64 {
    debug_assert!(k.abs() <= 1000);
    2f64.powi(k as i32)
}

/// v·2ᵏ, exact when the result is an f64 (each step's intermediate is then one too).
fn ldexp(mut v: f64, mut k: i64) -> f64 {
    while k > 1000 {
        v *= two_to(1000);
        k -= 1000;
    }
    while k < -1000 {
        v *= two_to(-1000);
        k += 1000;
    }
    v * two_to(k)
}

impl Dyadic {
    fn normalized(m: BigInt, e: i64) -> Dyadic {
        match m.trailing_zeros() {
            None => Dyadic::default(),
            Some(0) => Dyadic { m, e },
            Some(t) => Dyadic { m: m >> t, e: e + t as i64 },
        }
    }

    /// A finite f64, exactly.
    pub fn from_f64(x: f64) -> Dyadic {
        debug_assert!(x.is_finite());
        if x == 0.0 {
            return Dyadic::default();
        }
        let bits = x.to_bits();
        let exp = ((bits >> 52) & 0x7ff) as i64;
        let frac = bits & ((1u64 << 52) - 1);
        let (mant, e) = if exp == 0 { (frac, -1074) } else { (frac | (1u64 << 52), exp - 1075) };
        let m = BigInt::from(mant);
        Dyadic::normalized(if x < 0.0 { -m } else { m }, e)
    }

    /// The exact value of an expansion.
    pub fn of_exact(e: &Exact) -> Dyadic {
        e.components().iter().fold(Dyadic::default(), |s, &c| s.add(&Dyadic::from_f64(c)))
    }

    pub fn add(&self, o: &Dyadic) -> Dyadic {
        if self.sign() == 0 {
            return o.clone();
        }
        if o.sign() == 0 {
            return self.clone();
        }
        let (hi, lo) = if self.e >= o.e { (self, o) } else { (o, self) };
        Dyadic::normalized((&hi.m << (hi.e - lo.e) as u64) + &lo.m, lo.e)
    }

    pub fn neg(&self) -> Dyadic {
        Dyadic { m: -&self.m, e: self.e }
    }

    pub fn sub(&self, o: &Dyadic) -> Dyadic {
        self.add(&o.neg())
    }

    /// The product (of odd mantissas: odd, already in normal form).
    pub fn mul(&self, o: &Dyadic) -> Dyadic {
        if self.sign() == 0 || o.sign() == 0 {
            return Dyadic::default();
        }
        Dyadic { m: &self.m * &o.m, e: self.e + o.e }
    }

    /// −1, 0 or 1.
    pub fn sign(&self) -> Sign {
        match self.m.sign() {
            BigSign::Minus => -1,
            BigSign::NoSign => 0,
            BigSign::Plus => 1,
        }
    }

    /// The exponent of the leading bit: 2ᵗ ≤ |self| < 2ᵗ⁺¹ (None for 0).
    pub fn top(&self) -> Option<i64> {
        (self.sign() != 0).then(|| self.m.bits() as i64 - 1 + self.e)
    }

    /// self·2^scale as a double-double ball: its leading 159 bits in three f64 chunks, the
    /// rest (less than the last chunk's unit) and any rounding of a chunk below f64's
    /// normal range in the radius.
    pub fn ball(&self, scale: i64) -> Ball {
        if self.sign() == 0 {
            return Ball::of(0.0);
        }
        let mag = self.m.magnitude();
        let drop = (mag.bits() as i64 - 159).max(0);
        let top: BigUint = mag >> drop as u64;
        let digits = top.to_u64_digits();
        let bit = |i: u64| -> u64 {
            let (word, at) = ((i / 64) as usize, i % 64);
            digits.get(word).map_or(0, |w| (w >> at) & 1)
        };
        let chunk = |from: u64| (0..53).fold(0u64, |c, i| c | (bit(from + i) << i));
        let unit = self.e + drop + scale;
        let s = f64::from(self.sign());
        let ball = [106u64, 53, 0].iter().fold(Ball::of(0.0), |b, &from| {
            b.add(&Ball::of(s * ldexp(chunk(from) as f64, unit + from as i64)))
        });
        // The rest is below one unit; chunks rounded below 2⁻¹⁰²² err by at most 2⁻¹⁰⁷⁵ each.
        ball.widened(ldexp(1.0, unit) + ldexp(1.0, -1070))
    }
}

/// x / w rounded to the nearest f64, ties to even (x = 0 gives +0); w ≠ 0. The integer
/// quotient of the mantissas is taken to 56 or 57 bits, its remainder kept as a sticky
/// bit, and rounded to f64's precision at the result's exponent (subnormal ones included).
pub fn quotient(x: &Dyadic, w: &Dyadic) -> f64 {
    let s = x.sign() * w.sign();
    if s == 0 {
        return 0.0;
    }
    let (xm, wm) = (x.m.magnitude(), w.m.magnitude());
    // xm·2^shift / wm lies in [2⁵⁵, 2⁵⁷).
    let shift = 56 + wm.bits() as i64 - xm.bits() as i64;
    let (n, d) =
        if shift >= 0 { (xm << shift as u64, wm.clone()) } else { (xm.clone(), wm << (-shift) as u64) };
    let t = &n / &d;
    let sticky = (&n % &d).bits() != 0;
    let t = t.to_u64_digits().first().copied().unwrap_or(0);
    // x / w = (t + a fraction)·2^e1.
    let e1 = x.e - w.e - shift;
    let bits = 64 - i64::from(t.leading_zeros());
    let lead = bits - 1 + e1;
    // Bits of t below the result's last place (at least 3).
    let drop = if lead >= -1022 { bits - 53 } else { -1074 - e1 };
    if drop > bits {
        // Below half the smallest subnormal (not reached in a normalized frame).
        return f64::from(s) * 0.0;
    }
    let (kept, rem) = if drop >= 64 { (0, t) } else { (t >> drop, t & ((1u64 << drop) - 1)) };
    let half = 1u64 << (drop - 1);
    let up = rem > half || (rem == half && (sticky || kept & 1 == 1));
    f64::from(s) * ldexp((kept + up as u64) as f64, e1 + drop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::rounding::quotient_by_midpoints;
    use crate::random::Rng;

    fn rand_f64(rng: &mut Rng) -> f64 {
        rng.range_f64(-1.0, 1.0) * 2f64.powi(rng.below(81) as i32 - 40)
    }

    /// Sums, differences and products agree with the expansions' exact values, and the
    /// normal form makes equal values equal.
    #[test]
    fn arithmetic_agrees_with_expansions() {
        let mut rng = Rng::new(3);
        for _ in 0..2000 {
            let v: Vec<f64> = (0..6).map(|_| rand_f64(&mut rng)).collect();
            let (d, e): (Vec<Dyadic>, Vec<Exact>) =
                v.iter().map(|&x| (Dyadic::from_f64(x), Exact::from_f64(x))).unzip();
            let dd = d[0].mul(&d[1]).sub(&d[2].mul(&d[3])).add(&d[4].mul(&d[5]).mul(&d[0]));
            let ee = &(&(&e[0] * &e[1]) - &(&e[2] * &e[3])) + &(&(&e[4] * &e[5]) * &e[0]);
            assert_eq!(dd, Dyadic::of_exact(&ee));
            assert_eq!(dd.sign(), ee.sign());
            assert_eq!(d[0].sub(&d[0]), Dyadic::default());
            assert_eq!(d[1].add(&d[2]), d[2].add(&d[1]));
        }
        // Subnormals and extremes are exact too.
        for x in [f64::from_bits(1), -f64::from_bits(3), f64::MIN_POSITIVE, f64::MAX, -0.1] {
            assert_eq!(quotient(&Dyadic::from_f64(x), &Dyadic::from_f64(1.0)).to_bits(), x.to_bits());
        }
    }

    /// The quotient rounds like the expansions' rounding, ties to even included, and far
    /// beyond f64's exponent range in its operands.
    #[test]
    fn quotients_round_to_nearest_even() {
        let mut rng = Rng::new(9);
        for round in 0..3000 {
            let (x, w) = (rand_f64(&mut rng), rand_f64(&mut rng));
            let (y, z) = (rand_f64(&mut rng), rand_f64(&mut rng));
            if w == 0.0 || z == 0.0 {
                continue;
            }
            // X = x·z + y·w, W = w·z: X / W = x/w + y/z, often not an f64.
            let (ex, ew) = (
                &(&Exact::from_f64(x) * &Exact::from_f64(z)) + &(&Exact::from_f64(y) * &Exact::from_f64(w)),
                &Exact::from_f64(w) * &Exact::from_f64(z),
            );
            let (dx, dw) = (Dyadic::of_exact(&ex), Dyadic::of_exact(&ew));
            let want = quotient_by_midpoints(&ex, &ew);
            assert_eq!(quotient(&dx, &dw).to_bits(), want.to_bits(), "{x} {w} {y} {z}");
            // Scaling both by 2^±3000 changes nothing.
            let k = Dyadic::normalized(BigInt::from(1), if round % 2 == 0 { 3000 } else { -3000 });
            assert_eq!(quotient(&dx.mul(&k), &dw.mul(&k)).to_bits(), want.to_bits());
            // The ball holds the value.
            let b = dx.ball(0);
            assert!((b.value() - ex.approx()).abs() <= b.error() + ex.approx().abs() * 1e-15);
        }
        // Ties: halfway between 1 and its neighbours goes to the even one.
        let ulp = f64::EPSILON;
        let half = |a: f64, b: f64| Dyadic::from_f64(a).add(&Dyadic::from_f64(b));
        let two = Dyadic::from_f64(2.0);
        assert_eq!(quotient(&half(1.0, 1.0 + ulp), &two), 1.0);
        assert_eq!(quotient(&half(1.0 + ulp, 1.0 + 2.0 * ulp), &two), 1.0 + 2.0 * ulp);
        assert_eq!(quotient(&half(-1.0 - ulp, -1.0 - 2.0 * ulp), &two), -1.0 - 2.0 * ulp);
        // 1/3 and a subnormal quotient.
        let q = quotient(&Dyadic::from_f64(1.0), &Dyadic::from_f64(3.0));
        assert_eq!(q, 1.0 / 3.0);
        let tiny = quotient(&Dyadic::from_f64(f64::from_bits(5)), &two);
        assert_eq!(tiny, f64::from_bits(2));
        assert_eq!(quotient(&Dyadic::from_f64(f64::from_bits(7)), &two), f64::from_bits(4));
    }
}
