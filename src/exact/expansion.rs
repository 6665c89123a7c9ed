//! Floating-point expansions (Shewchuk 1997): a real number held exactly as a sum of
//! non-overlapping f64 components in increasing magnitude, built with error-free
//! transformations — [`two_sum`], [`two_prod`] — and closed under `+ − ×` by Grow-,
//! Fast-Expansion-Sum and Scale-Expansion. Every routine drops zero components, so the
//! last component of a non-zero expansion is its largest and carries its sign.
//!
//! The slice routines write into a caller's buffer and return the length used: the
//! predicates run them on stack arrays ([`Stack`]), [`Exact`] on vectors. Exactness
//! holds as long as no product falls below f64's normal range (see
//! [`crate::mesh::frame`], which keeps the coordinates every command feeds them there).

use std::ops::{Add, Mul, Neg, Sub};

use glam::DVec3;

use super::predicates::Sign;

/// a + b = s + e exactly, s the rounded sum (Knuth's Two-Sum).
#[inline(always)]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let err = (a - (s - bb)) + (b - bb);
    (s, err)
}

/// The exponent of the lowest set bit of finite non-zero x: x is an integer multiple of
/// 2^lowest_bit(x). A product of numbers that are multiples of 2^l₁, 2^l₂ … is a multiple
/// of 2^(l₁ + l₂ + …), which decides whether expansions hold it exactly (their components
/// must be multiples of 2⁻¹⁰⁷⁴, f64's smallest step).
pub fn lowest_bit(x: f64) -> i32 {
    let bits = x.abs().to_bits();
    let biased = (bits >> 52) as i32;
    let mantissa = bits & ((1 << 52) - 1);
    let (mantissa, base) =
        if biased == 0 { (mantissa, -1074) } else { (mantissa | (1 << 52), biased - 1075) };
    base + mantissa.trailing_zeros() as i32
}

/// a · b = p + e exactly, p the rounded product (fused multiply-add).
#[inline(always)]
pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// a − b exactly, as an expansion of at most two components, into `h`.
#[inline]
pub fn diff_into(a: f64, b: f64, h: &mut [f64]) -> usize {
    let (s, e) = two_sum(a, -b);
    let mut n = 0;
    for x in [e, s] {
        if x != 0.0 {
            h[n] = x;
            n += 1;
        }
    }
    n
}

/// h = e + f (Fast-Expansion-Sum with zero elimination): merges the components by
/// magnitude and accumulates them with Two-Sum. `h` needs `e.len() + f.len()` slots.
pub fn sum_into(e: &[f64], f: &[f64], h: &mut [f64]) -> usize {
    let (mut i, mut j, mut n) = (0, 0, 0);
    // The next component in increasing magnitude, from e or f.
    let next = |i: &mut usize, j: &mut usize| -> f64 {
        let take_e = match (e.get(*i), f.get(*j)) {
            (Some(&x), Some(&y)) => (y > x) == (y > -x),
            (Some(_), None) => true,
            _ => false,
        };
        if take_e {
            *i += 1;
            e[*i - 1]
        } else {
            *j += 1;
            f[*j - 1]
        }
    };
    let total = e.len() + f.len();
    if total == 0 {
        return 0;
    }
    let mut q = next(&mut i, &mut j);
    for _ in 1..total {
        let x = next(&mut i, &mut j);
        let (s, err) = two_sum(q, x);
        if err != 0.0 {
            h[n] = err;
            n += 1;
        }
        q = s;
    }
    if q != 0.0 {
        h[n] = q;
        n += 1;
    }
    n
}

/// h = e · b (Scale-Expansion with zero elimination). `h` needs `2 · e.len()` slots.
pub fn scale_into(e: &[f64], b: f64, h: &mut [f64]) -> usize {
    let Some((&first, rest)) = e.split_first() else { return 0 };
    let mut n = 0;
    let mut push = |h: &mut [f64], x: f64| {
        if x != 0.0 {
            h[n] = x;
            n += 1;
        }
    };
    let (mut q, lo) = two_prod(first, b);
    push(h, lo);
    for &x in rest {
        let (hi, lo) = two_prod(x, b);
        let (s, err) = two_sum(q, lo);
        push(h, err);
        let (s2, err2) = two_sum(hi, s);
        push(h, err2);
        q = s2;
    }
    push(h, q);
    n
}

/// The sign of an expansion: that of its last (largest) component.
#[inline]
pub fn sign(e: &[f64]) -> Sign {
    e.last().map_or(0, |&x| super::predicates::sign_of(x))
}

/// An f64 near the value: the components summed from the smallest.
#[inline]
pub fn estimate(e: &[f64]) -> f64 {
    e.iter().sum()
}

/// An expansion in a fixed-size stack buffer of `N` components (the predicates' exact
/// stage allocates nothing).
#[derive(Clone, Copy)]
pub struct Stack<const N: usize> {
    v: [f64; N],
    len: usize,
}

impl<const N: usize> Stack<N> {
    /// a − b.
    #[inline]
    pub fn diff(a: f64, b: f64) -> Stack<N> {
        let mut s = Stack { v: [0.0; N], len: 0 };
        s.len = diff_into(a, b, &mut s.v);
        s
    }

    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.v[..self.len]
    }

    /// e + f (N ≥ the two lengths together).
    #[inline]
    pub fn sum<const A: usize, const B: usize>(e: &Stack<A>, f: &Stack<B>) -> Stack<N> {
        let mut s = Stack { v: [0.0; N], len: 0 };
        s.len = sum_into(e.as_slice(), f.as_slice(), &mut s.v);
        s
    }

    /// e · f (N ≥ 2 · the two lengths multiplied): Σ e · fᵢ.
    #[inline]
    pub fn product<const A: usize, const B: usize>(e: &Stack<A>, f: &Stack<B>) -> Stack<N> {
        let mut acc = Stack { v: [0.0; N], len: 0 };
        let mut part = Stack::<N> { v: [0.0; N], len: 0 };
        let mut next = Stack::<N> { v: [0.0; N], len: 0 };
        for &x in f.as_slice() {
            part.len = scale_into(e.as_slice(), x, &mut part.v);
            next.len = sum_into(acc.as_slice(), part.as_slice(), &mut next.v);
            std::mem::swap(&mut acc, &mut next);
        }
        acc
    }

    /// −e.
    #[inline]
    pub fn negated(mut self) -> Stack<N> {
        for x in &mut self.v[..self.len] {
            *x = -*x;
        }
        self
    }

    #[inline]
    pub fn sign(&self) -> Sign {
        sign(self.as_slice())
    }

    #[inline]
    pub fn estimate(&self) -> f64 {
        estimate(self.as_slice())
    }
}

/// An exact real number: an expansion (non-overlapping f64 components, increasing
/// magnitude), closed under `+ − ×`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Exact(Vec<f64>);

impl Exact {
    pub fn from_f64(x: f64) -> Exact {
        Exact(if x == 0.0 { Vec::new() } else { vec![x] })
    }

    /// a − b, exactly.
    pub fn diff(a: f64, b: f64) -> Exact {
        let mut v = vec![0.0; 2];
        let n = diff_into(a, b, &mut v);
        v.truncate(n);
        Exact(v)
    }

    /// a · b, exactly.
    pub fn product(a: f64, b: f64) -> Exact {
        &Exact::from_f64(a) * &Exact::from_f64(b)
    }

    /// −1, 0 or 1.
    pub fn sign(&self) -> Sign {
        sign(&self.0)
    }

    /// An f64 close to the value.
    pub fn approx(&self) -> f64 {
        estimate(&self.0)
    }

    /// The components, smallest first.
    pub fn components(&self) -> &[f64] {
        &self.0
    }

    fn sum(e: &[f64], f: &[f64]) -> Exact {
        let mut v = vec![0.0; e.len() + f.len()];
        let n = sum_into(e, f, &mut v);
        v.truncate(n);
        Exact(v)
    }
}

impl Add for &Exact {
    type Output = Exact;
    fn add(self, o: &Exact) -> Exact {
        Exact::sum(&self.0, &o.0)
    }
}

impl Sub for &Exact {
    type Output = Exact;
    fn sub(self, o: &Exact) -> Exact {
        self + &-o
    }
}

impl Mul for &Exact {
    type Output = Exact;
    fn mul(self, o: &Exact) -> Exact {
        let mut part = vec![0.0; 2 * self.0.len()];
        o.0.iter().fold(Exact::default(), |acc, &x| {
            let n = scale_into(&self.0, x, &mut part);
            Exact::sum(&acc.0, &part[..n])
        })
    }
}

impl Neg for &Exact {
    type Output = Exact;
    fn neg(self) -> Exact {
        Exact(self.0.iter().map(|x| -x).collect())
    }
}

/// A vector of three exact coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Exact3(pub [Exact; 3]);

impl Exact3 {
    /// a − b, exactly.
    pub fn diff(a: DVec3, b: DVec3) -> Exact3 {
        Exact3([Exact::diff(a.x, b.x), Exact::diff(a.y, b.y), Exact::diff(a.z, b.z)])
    }

    pub fn add(&self, o: &Exact3) -> Exact3 {
        Exact3(std::array::from_fn(|i| &self.0[i] + &o.0[i]))
    }

    pub fn sub(&self, o: &Exact3) -> Exact3 {
        Exact3(std::array::from_fn(|i| &self.0[i] - &o.0[i]))
    }

    pub fn dot(&self, o: &Exact3) -> Exact {
        let [a, b, c] = &self.0;
        let [x, y, z] = &o.0;
        &(&(a * x) + &(b * y)) + &(c * z)
    }

    pub fn cross(&self, o: &Exact3) -> Exact3 {
        let [a, b, c] = &self.0;
        let [x, y, z] = &o.0;
        Exact3([&(b * z) - &(c * y), &(c * x) - &(a * z), &(a * y) - &(b * x)])
    }

    pub fn norm2(&self) -> Exact {
        self.dot(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// Exact value of an expansion of small dyadic numbers, as an i128 multiple of 2^-60.
    fn fixed(e: &[f64]) -> i128 {
        e.iter().map(|&x| (x * 2f64.powi(60)) as i128).sum()
    }

    #[test]
    fn arithmetic_is_exact_and_non_overlapping() {
        let mut rng = Rng::new(7);
        for _ in 0..5000 {
            // Multiples of 2^-30 below 2^10: every product is a multiple of 2^-60 below 2^20.
            let q = |rng: &mut Rng| (rng.below(1 << 40) as i64 - (1 << 39)) as f64 / 2f64.powi(30);
            let (a, b, c, d) = (q(&mut rng), q(&mut rng), q(&mut rng), q(&mut rng));
            let x = &(&Exact::diff(a, b) * &Exact::diff(c, d)) + &Exact::product(a, d);
            let want = |v: f64| (v * 2f64.powi(30)) as i128;
            let exact = (want(a) - want(b)) * (want(c) - want(d)) + want(a) * want(d);
            assert_eq!(fixed(x.components()), exact);
            assert_eq!(x.sign(), exact.signum() as Sign);
            // Increasing magnitudes, no zero component.
            for w in x.components().windows(2) {
                assert!(w[0] != 0.0 && w[0].abs() < w[1].abs(), "{:?}", x.components());
            }
        }
        assert_eq!(Exact::diff(1.0, 1.0).components(), &[] as &[f64]);
        assert_eq!((&Exact::from_f64(3.0) - &Exact::from_f64(3.0)).sign(), 0);
    }
}
