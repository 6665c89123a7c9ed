//! Exact arithmetic on f64 inputs: the sign of a polynomial in the input coordinates, and
//! the predicates texgeo decides with it, so that a decision never depends on rounding —
//! on which method asks, or on where the mesh sits.
//!
//! Inputs are f64 numbers, i.e. exact dyadic rationals. Every predicate first evaluates in
//! floating point with an error bound (the *filter*); only when the answer is in doubt does
//! it recompute with floating-point expansions (sums of non-overlapping f64 components
//! built with error-free two-sum / two-product: Shewchuk's grow, scale and sum), whose sign
//! is the sign of the exact real value. [`Exact`] wraps an expansion with `+ − ×`.
//!
//! | predicate | decides |
//! |---|---|
//! | [`orient2d`], [`orient3d`] | sides of lines and planes |
//! | [`segment_within`], [`triangle_within`] | distance from a point to a segment or triangle ≤ ε |

use std::ops::{Add, Mul, Neg, Sub};

use glam::DVec3;

/// Sign of a real number: −1, 0 or 1.
pub type Sign = i8;

pub fn sign_of(x: f64) -> Sign {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

const EPS: f64 = f64::EPSILON * 0.5; // 2^-53, the unit roundoff

/// Sign of (b − a) × (c − a) for 2D points: positive when a, b, c turn counter-clockwise.
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> Sign {
    let (bax, bay, cax, cay) = (b[0] - a[0], b[1] - a[1], c[0] - a[0], c[1] - a[1]);
    let (l, r) = (bax * cay, bay * cax);
    let det = l - r;
    // Shewchuk's ccwerrboundA is (3 + 16ε)ε; 8ε keeps a margin.
    if det.abs() > 8.0 * EPS * (l.abs() + r.abs()) {
        return sign_of(det);
    }
    let (bax, bay, cax, cay) = (diff(b[0], a[0]), diff(b[1], a[1]), diff(c[0], a[0]), diff(c[1], a[1]));
    expansion_sign(&sum(&mul(&bax, &cay), &negate(&mul(&bay, &cax))))
}

/// Sign of ((b − a) × (c − a)) · (d − a): positive when d lies on the side the normal of
/// the counter-clockwise triangle abc points to.
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    let (u, v, w) = (b - a, c - a, d - a);
    let (m1, m2, m3) = (v.y * w.z - v.z * w.y, v.z * w.x - v.x * w.z, v.x * w.y - v.y * w.x);
    let det = u.x * m1 + u.y * m2 + u.z * m3;
    let permanent = u.x.abs() * ((v.y * w.z).abs() + (v.z * w.y).abs())
        + u.y.abs() * ((v.z * w.x).abs() + (v.x * w.z).abs())
        + u.z.abs() * ((v.x * w.y).abs() + (v.y * w.x).abs());
    // Shewchuk's o3derrboundA is (7 + 56ε)ε; 16ε keeps a margin.
    if det.abs() > 16.0 * EPS * permanent {
        return sign_of(det);
    }
    let d3 = |p: DVec3, q: DVec3| [diff(p.x, q.x), diff(p.y, q.y), diff(p.z, q.z)];
    let (u, v, w) = (d3(b, a), d3(c, a), d3(d, a));
    let minor = |i: usize, j: usize| sum(&mul(&v[i], &w[j]), &negate(&mul(&v[j], &w[i])));
    let det = sum(&sum(&mul(&u[0], &minor(1, 2)), &mul(&u[1], &minor(2, 0))), &mul(&u[2], &minor(0, 1)));
    expansion_sign(&det)
}

pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let err = (a - (s - bb)) + (b - bb);
    (s, err)
}

pub fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// a − b exactly, as a two-component expansion.
fn diff(a: f64, b: f64) -> Vec<f64> {
    let (s, e) = two_sum(a, -b);
    compress(vec![e, s])
}

fn compress(mut e: Vec<f64>) -> Vec<f64> {
    e.retain(|&x| x != 0.0);
    e
}

/// e + b (Shewchuk's Grow-Expansion).
fn grow(e: &[f64], b: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(e.len() + 1);
    let mut q = b;
    for &x in e {
        let (s, err) = two_sum(q, x);
        out.push(err);
        q = s;
    }
    out.push(q);
    compress(out)
}

/// e + f (Expansion-Sum: grow by each component of f).
fn sum(e: &[f64], f: &[f64]) -> Vec<f64> {
    f.iter().fold(e.to_vec(), |acc, &x| grow(&acc, x))
}

fn negate(e: &[f64]) -> Vec<f64> {
    e.iter().map(|x| -x).collect()
}

/// e · b (Shewchuk's Scale-Expansion).
fn scale(e: &[f64], b: f64) -> Vec<f64> {
    let Some((&first, rest)) = e.split_first() else { return Vec::new() };
    let mut out = Vec::with_capacity(2 * e.len());
    let (mut q, h) = two_prod(first, b);
    out.push(h);
    for &x in rest {
        let (hi, lo) = two_prod(x, b);
        let (s, err) = two_sum(q, lo);
        out.push(err);
        let (s2, err2) = two_sum(hi, s);
        out.push(err2);
        q = s2;
    }
    out.push(q);
    compress(out)
}

fn mul(e: &[f64], f: &[f64]) -> Vec<f64> {
    f.iter().fold(Vec::new(), |acc, &x| sum(&acc, &scale(e, x)))
}

/// The sign of a non-overlapping expansion is the sign of its largest component.
fn expansion_sign(e: &[f64]) -> Sign {
    e.iter().copied().fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m }).partial_cmp(&0.0).map_or(
        0,
        |o| match o {
            std::cmp::Ordering::Greater => 1,
            std::cmp::Ordering::Less => -1,
            std::cmp::Ordering::Equal => 0,
        },
    )
}

/// An exact real number: an expansion (non-overlapping f64 components, increasing
/// magnitude), closed under `+ − ×`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Exact(Vec<f64>);

impl Exact {
    pub fn from_f64(x: f64) -> Exact {
        Exact(compress(vec![x]))
    }

    /// a − b, exactly.
    pub fn diff(a: f64, b: f64) -> Exact {
        Exact(diff(a, b))
    }

    /// a · b, exactly.
    pub fn product(a: f64, b: f64) -> Exact {
        let (p, e) = two_prod(a, b);
        Exact(compress(vec![e, p]))
    }

    /// −1, 0 or 1.
    pub fn sign(&self) -> Sign {
        expansion_sign(&self.0)
    }

    /// An f64 close to the value (the largest component).
    pub fn approx(&self) -> f64 {
        self.0.iter().sum()
    }
}

impl Add for &Exact {
    type Output = Exact;
    fn add(self, o: &Exact) -> Exact {
        Exact(sum(&self.0, &o.0))
    }
}

impl Sub for &Exact {
    type Output = Exact;
    fn sub(self, o: &Exact) -> Exact {
        Exact(sum(&self.0, &negate(&o.0)))
    }
}

impl Mul for &Exact {
    type Output = Exact;
    fn mul(self, o: &Exact) -> Exact {
        Exact(mul(&self.0, &o.0))
    }
}

impl Neg for &Exact {
    type Output = Exact;
    fn neg(self) -> Exact {
        Exact(negate(&self.0))
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

/// Relative margin of the distance filters: far above the error of the f64 evaluation
/// (a few units of 2⁻⁵³ of the coordinate differences, for triangles that are not slivers),
/// far below any tolerance texgeo uses.
const DISTANCE_MARGIN: f64 = 1.0 / (1u64 << 40) as f64;

/// Whether the distance from `p` to the segment [a, b] is at most `eps`, decided exactly.
pub fn segment_within(p: DVec3, a: DVec3, b: DVec3, eps: f64) -> bool {
    let (ab, ap) = (b - a, p - a);
    let scale = ab.abs().max_element().max(ap.abs().max_element());
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 { (ap.dot(ab) / len2).clamp(0.0, 1.0) } else { 0.0 };
    let d = (ap - ab * t).length();
    if (d - eps).abs() > DISTANCE_MARGIN * scale + 4.0 * EPS * eps {
        return d <= eps;
    }
    segment_within_exact(
        &Exact3::diff(p, a),
        &Exact3::default(),
        &Exact3::diff(b, a),
        &Exact::product(eps, eps),
    )
}

/// |P − U|² ≤ ε² for the closest point U + t(V − U) of the segment (all relative to one
/// origin), decided exactly.
fn segment_within_exact(p: &Exact3, u: &Exact3, v: &Exact3, eps2: &Exact) -> bool {
    let w = v.sub(u);
    let q = p.sub(u);
    let t = q.dot(&w);
    if t.sign() <= 0 {
        return (&q.norm2() - eps2).sign() <= 0;
    }
    let w2 = w.norm2();
    if (&t - &w2).sign() >= 0 {
        return (&p.sub(v).norm2() - eps2).sign() <= 0;
    }
    // Inside the slab: |q × w|² ≤ ε²·|w|².
    (&q.cross(&w).norm2() - &(eps2 * &w2)).sign() <= 0
}

/// Whether the distance from `p` to the (closed, possibly degenerate) triangle (a, b, c)
/// is at most `eps`, decided exactly: a filtered f64 distance, then exact arithmetic when
/// it lies within the filter's margin of `eps` or the triangle is a sliver.
pub fn triangle_within(p: DVec3, a: DVec3, b: DVec3, c: DVec3, eps: f64) -> bool {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let scale = ab.abs().max_element().max(ac.abs().max_element()).max(ap.abs().max_element());
    let n = ab.cross(ac);
    let longest2 = ab.length_squared().max(ac.length_squared()).max((c - b).length_squared());
    // Not a sliver: the plane and the barycentric split are well conditioned.
    if n.length_squared() > 1e-6 * longest2 * longest2 {
        let d = closest_point_on_triangle(ap, DVec3::ZERO, ab, ac).distance(ap);
        if (d - eps).abs() > DISTANCE_MARGIN * scale + 4.0 * EPS * eps {
            return d <= eps;
        }
    }
    triangle_within_exact(p, a, b, c, eps)
}

/// [`triangle_within`] in exact arithmetic: within ε of the plane over the triangle, or
/// of one of its edges.
fn triangle_within_exact(p: DVec3, a: DVec3, b: DVec3, c: DVec3, eps: f64) -> bool {
    let eps2 = Exact::product(eps, eps);
    let zero = Exact3::default();
    let (pp, bb, cc) = (Exact3::diff(p, a), Exact3::diff(b, a), Exact3::diff(c, a));
    let n = bb.cross(&cc);
    let n2 = n.norm2();
    if n2.sign() > 0 {
        // The projection of p is in the triangle iff it is left of every edge (seen along n).
        let left = |u: &Exact3, v: &Exact3| n.dot(&v.sub(u).cross(&pp.sub(u))).sign() >= 0;
        if left(&zero, &bb) && left(&bb, &cc) && left(&cc, &zero) {
            let h = n.dot(&pp);
            return (&(&h * &h) - &(&eps2 * &n2)).sign() <= 0;
        }
    }
    segment_within_exact(&pp, &zero, &bb, &eps2)
        || segment_within_exact(&pp, &bb, &cc, &eps2)
        || segment_within_exact(&pp, &cc, &zero, &eps2)
}

/// The point of segment [a, b] closest to `p` (a when the segment is a point).
pub fn closest_point_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + ab * ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
}

/// The point of triangle (a, b, c) closest to `p`, by Voronoi regions (in f64); degenerate
/// (zero-area) triangles fall back to their edges.
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vc = d1 * d4 - d3 * d2;
    let vb = d5 * d2 - d1 * d6;
    let va = d3 * d6 - d5 * d4;
    let sum = va + vb + vc;
    if sum <= 0.0 || ab.cross(ac) == DVec3::ZERO {
        return [
            closest_point_on_segment(p, a, b),
            closest_point_on_segment(p, b, c),
            closest_point_on_segment(p, c, a),
        ]
        .into_iter()
        .min_by(|x, y| x.distance_squared(p).total_cmp(&y.distance_squared(p)))
        .unwrap_or(a);
    }
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    a + ab * (vb / sum) + ac * (vc / sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// Exact determinant of small integer points in i128.
    fn orient3d_i128(a: [i64; 3], b: [i64; 3], c: [i64; 3], d: [i64; 3]) -> Sign {
        let s =
            |p: [i64; 3], q: [i64; 3]| [(p[0] - q[0]) as i128, (p[1] - q[1]) as i128, (p[2] - q[2]) as i128];
        let (u, v, w) = (s(b, a), s(c, a), s(d, a));
        let det = u[0] * (v[1] * w[2] - v[2] * w[1])
            + u[1] * (v[2] * w[0] - v[0] * w[2])
            + u[2] * (v[0] * w[1] - v[1] * w[0]);
        det.signum() as Sign
    }

    #[test]
    fn orient3d_matches_integer_arithmetic() {
        let mut rng = Rng::new(11);
        let big = 1i64 << 26; // products reach 2^80: beyond f64's 53 bits, fine for i128
        for _ in 0..20_000 {
            let p = |rng: &mut Rng| -> [i64; 3] {
                std::array::from_fn(|_| rng.below(2 * big as u64) as i64 - big)
            };
            let (a, b, c) = (p(&mut rng), p(&mut rng), p(&mut rng));
            // A third of the time d is coplanar (a + b − c), a third one unit off the plane.
            let d = match rng.below(3) {
                0 => p(&mut rng),
                1 => [a[0] + b[0] - c[0], a[1] + b[1] - c[1], a[2] + b[2] - c[2]],
                _ => [a[0] + b[0] - c[0] + 1, a[1] + b[1] - c[1], a[2] + b[2] - c[2]],
            };
            let f = |q: [i64; 3]| DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64);
            assert_eq!(
                orient3d(f(a), f(b), f(c), f(d)),
                orient3d_i128(a, b, c, d),
                "{a:?} {b:?} {c:?} {d:?}"
            );
        }
    }

    #[test]
    fn closest_points() {
        let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        let at = |p: DVec3, want: DVec3| {
            let q = closest_point_on_triangle(p, a, b, c);
            assert!(q.distance(want) < 1e-15, "{p} -> {q}, want {want}");
        };
        at(DVec3::new(0.2, 0.3, 5.0), DVec3::new(0.2, 0.3, 0.0));
        at(DVec3::new(-1.0, -1.0, 0.0), a);
        at(DVec3::new(2.0, -0.5, 1.0), b);
        at(DVec3::new(-0.5, 3.0, 1.0), c);
        at(DVec3::new(0.5, -3.0, 0.0), DVec3::new(0.5, 0.0, 0.0));
        at(DVec3::new(-3.0, 0.25, 2.0), DVec3::new(0.0, 0.25, 0.0));
        at(DVec3::new(1.0, 1.0, 0.0), DVec3::new(0.5, 0.5, 0.0));
        // Collinear corners: the closest point of the segment they span.
        let q = closest_point_on_triangle(DVec3::new(0.5, 1.0, 0.0), a, DVec3::X, DVec3::X * 2.0);
        assert_eq!(q, DVec3::new(0.5, 0.0, 0.0));
        assert_eq!(closest_point_on_segment(DVec3::ONE, DVec3::X, DVec3::X), DVec3::X);
    }

    #[test]
    fn distances_are_decided_exactly() {
        // A triangle in the plane z = 1 + 2^-30·x (not axis-aligned), points exactly at
        // distance ε from it would need irrational coordinates; instead check points on a
        // fine lattice against the exact predicate and the f64 filter's verdict agreeing.
        let (a, b, c) = (DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 0.0, 1.0), DVec3::new(0.0, 1.0, 1.0));
        let eps = 1.0 / (1u64 << 30) as f64;
        for k in -3i32..=3 {
            let p = DVec3::new(0.25, 0.25, 1.0 + f64::from(k) * eps / 2.0);
            assert_eq!(triangle_within(p, a, b, c, eps), k.abs() <= 2, "{k}");
            assert_eq!(triangle_within_exact(p, a, b, c, eps), k.abs() <= 2, "{k}");
            // Beside edge x = 0 (outside the triangle), distance |k|·ε/2 in x.
            let q = DVec3::new(f64::from(k.abs()) * -eps / 2.0, 0.5, 1.0);
            assert_eq!(triangle_within(q, a, b, c, eps), k.abs() <= 2, "{k}");
            assert_eq!(segment_within(q, a, c, eps), k.abs() <= 2, "{k}");
        }
        // Far from the origin the same geometry gives the same answers.
        let t = DVec3::splat(3.0e9);
        let u = 1.0 / (1u64 << 21) as f64; // ulp at 3e9
        for k in -3i32..=3 {
            let p = DVec3::new(0.25, 0.25, 1.0 + f64::from(k) * u) + t;
            assert_eq!(triangle_within(p, a + t, b + t, c + t, 2.0 * u), k.abs() <= 2, "{k}");
        }
        // The filter agrees with the exact predicate on random points near random triangles.
        let mut rng = Rng::new(3);
        for _ in 0..3000 {
            let q = [0; 3].map(|_| rng.point_in_box(DVec3::splat(-1.0), DVec3::ONE));
            let p = rng.point_in_box(DVec3::splat(-1.2), DVec3::splat(1.2));
            let eps = rng.range_f64(0.0, 0.5);
            assert_eq!(
                triangle_within(p, q[0], q[1], q[2], eps),
                triangle_within_exact(p, q[0], q[1], q[2], eps)
            );
        }
    }
}
