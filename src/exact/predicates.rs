//! The exact orientation predicates every geometric decision in texgeo goes through, with
//! one sign convention and one result type ([`Sign`]):
//!
//! - [`orient2d`] is positive when a, b, c turn counter-clockwise;
//! - [`orient3d`] is positive when d lies on the side the normal (b − a) × (c − a) of the
//!   triangle abc points to (abc counter-clockwise seen from d).
//!
//! Each one evaluates the determinant in f64 first with Shewchuk's error bound (the
//! filter, inline); only when the bound cannot vouch for the sign does it recompute the
//! determinant exactly with expansions ([`super::expansion`]), on the stack.
//!
//! [`orient2d_approx`] and [`orient3d_approx`] give the determinant itself, with the same
//! exact sign, and [`plane_crossing`] and [`line_crossing`] where a segment crosses a
//! plane or a line, accurate however close to parallel they are: for constructions,
//! never for decisions. The perturbed predicates decide at p + (ε, ε³, ε²) for an infinitesimal ε > 0 (the
//! voxelizers' tie rule, [`crate::voxel::exact`]): they are never zero for a proper
//! triangle.

use glam::{DVec2, DVec3};

use super::expansion::Stack;

/// Sign of a real number: −1, 0 or 1.
pub type Sign = i8;

#[inline(always)]
pub fn sign_of(x: f64) -> Sign {
    (x > 0.0) as Sign - (x < 0.0) as Sign
}

/// Unit roundoff, 2⁻⁵³.
const EPS: f64 = f64::EPSILON * 0.5;
/// Ozaki et al.'s bound for the 2D determinant's sign, relative to |l + r|.
const O2D_BOUND: f64 = 3.330_669_062_177_372_2e-16;
/// Shewchuk's o3derrboundA, relative to the permanent.
const O3D_BOUND: f64 = (7.0 + 56.0 * EPS) * EPS;
/// What products that fall below f64's normal range can lose, in absolute terms: a
/// determinant this small is always recomputed exactly.
const UNDERFLOW: f64 = 1e-290;

/// The 2D determinant in f64 when its sign is certain: (a − c) × (b − c).
#[inline(always)]
fn orient2d_filter(a: DVec2, b: DVec2, c: DVec2) -> Option<f64> {
    let l = (a.x - c.x) * (b.y - c.y);
    let r = (a.y - c.y) * (b.x - c.x);
    let det = l - r;
    (det.abs() >= O2D_BOUND * (l + r).abs() + UNDERFLOW).then_some(det)
}

/// The 2D determinant in f64 and a bound on its error (the differences, the products and
/// the subtraction each round once).
#[inline(always)]
fn orient2d_float(a: DVec2, b: DVec2, c: DVec2) -> (f64, f64) {
    let l = (a.x - c.x) * (b.y - c.y);
    let r = (a.y - c.y) * (b.x - c.x);
    (l - r, 8.0 * EPS * (l.abs() + r.abs()) + UNDERFLOW)
}

fn orient2d_exact(a: DVec2, b: DVec2, c: DVec2) -> Stack<16> {
    let d = Stack::<2>::diff;
    let (acx, acy, bcx, bcy) = (d(a.x, c.x), d(a.y, c.y), d(b.x, c.x), d(b.y, c.y));
    Stack::sum(&Stack::<8>::product(&acx, &bcy), &Stack::<8>::product(&acy, &bcx).negated())
}

/// Sign of (b − a) × (c − a): positive when a, b, c turn counter-clockwise, zero when
/// they are collinear.
#[inline]
pub fn orient2d(a: impl Into<DVec2>, b: impl Into<DVec2>, c: impl Into<DVec2>) -> Sign {
    let (a, b, c) = (a.into(), b.into(), c.into());
    match orient2d_filter(a, b, c) {
        Some(det) => sign_of(det),
        None => orient2d_exact(a, b, c).sign(),
    }
}

/// The value of [`orient2d`]'s determinant: its f64 evaluation when the filter vouches
/// for its sign, else the exact value rounded. For constructions only.
#[inline]
pub fn orient2d_approx(a: impl Into<DVec2>, b: impl Into<DVec2>, c: impl Into<DVec2>) -> f64 {
    let (a, b, c) = (a.into(), b.into(), c.into());
    orient2d_filter(a, b, c).unwrap_or_else(|| orient2d_exact(a, b, c).estimate())
}

/// The 3D determinant in f64 when its sign is certain, in [`orient3d`]'s convention.
#[inline(always)]
fn orient3d_filter(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<f64> {
    let (det, bound) = orient3d_float(a, b, c, d);
    (det.abs() > bound).then_some(det)
}

/// The 3D determinant in f64, in [`orient3d`]'s convention, and Shewchuk's bound on its
/// error.
#[inline(always)]
fn orient3d_float(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let (bc1, bc2) = (bd.x * cd.y, cd.x * bd.y);
    let (ca1, ca2) = (cd.x * ad.y, ad.x * cd.y);
    let (ab1, ab2) = (ad.x * bd.y, bd.x * ad.y);
    let det = ad.z * (bc1 - bc2) + bd.z * (ca1 - ca2) + cd.z * (ab1 - ab2);
    let permanent = (bc1.abs() + bc2.abs()) * ad.z.abs()
        + (ca1.abs() + ca2.abs()) * bd.z.abs()
        + (ab1.abs() + ab2.abs()) * cd.z.abs();
    // det((a−d, b−d, c−d)) is positive when d lies below abc: texgeo's sign is the opposite.
    (-det, O3D_BOUND * permanent + UNDERFLOW)
}

/// det((a−d, b−d, c−d)) exactly (the opposite of [`orient3d`]'s sign).
fn orient3d_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Stack<192> {
    let diff =
        |p: DVec3| [Stack::<2>::diff(p.x, d.x), Stack::<2>::diff(p.y, d.y), Stack::<2>::diff(p.z, d.z)];
    let (ad, bd, cd) = (diff(a), diff(b), diff(c));
    // The 2×2 minor u.x·v.y − v.x·u.y, times w.z.
    let term = |u: &[Stack<2>; 3], v: &[Stack<2>; 3], w: &[Stack<2>; 3]| -> Stack<64> {
        let minor = Stack::<16>::sum(
            &Stack::<8>::product(&u[0], &v[1]),
            &Stack::<8>::product(&v[0], &u[1]).negated(),
        );
        Stack::product(&minor, &w[2])
    };
    let ab = Stack::<128>::sum(&term(&bd, &cd, &ad), &term(&cd, &ad, &bd));
    Stack::sum(&ab, &term(&ad, &bd, &cd))
}

/// Sign of ((b − a) × (c − a)) · (d − a): positive when d lies on the side the normal of
/// the triangle abc points to, zero when the four points are coplanar.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    match orient3d_filter(a, b, c, d) {
        Some(det) => sign_of(det),
        None if in_axis_plane(a, b, c, d) => 0,
        None => -orient3d_exact_sign(a, b, c, d),
    }
}

/// The sign of det((a−d, b−d, c−d)), exactly. When the nine differences round to
/// nothing (points close together, as the near-coplanar ones the filter leaves are), the
/// determinant is a sum of three products of a 2×2 minor and one difference: at most
/// 3 · 8 components, on small fixed buffers. Otherwise the full expansion of
/// [`orient3d_exact`].
fn orient3d_exact_sign(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Sign {
    use super::expansion::{scale_into, sign, sum_into, two_prod, two_sum};
    let exact_diff = |p: DVec3| -> Option<DVec3> {
        let tails = [two_sum(p.x, -d.x).1, two_sum(p.y, -d.y).1, two_sum(p.z, -d.z).1];
        (tails == [0.0; 3]).then(|| p - d)
    };
    let (Some(ad), Some(bd), Some(cd)) = (exact_diff(a), exact_diff(b), exact_diff(c)) else {
        return orient3d_exact(a, b, c, d).sign();
    };
    // w.z · (u.x·v.y − v.x·u.y), exactly, into `h` (8 slots); returns the length.
    let term = |u: DVec3, v: DVec3, w: DVec3, h: &mut [f64; 8]| -> usize {
        let (p1, e1) = two_prod(u.x, v.y);
        let (p2, e2) = two_prod(v.x, u.y);
        let mut minor = [0.0; 4];
        let m = sum_into(&[e1, p1], &[-e2, -p2], &mut minor);
        scale_into(&minor[..m], w.z, h)
    };
    let (mut t1, mut t2, mut t3) = ([0.0; 8], [0.0; 8], [0.0; 8]);
    let n1 = term(bd, cd, ad, &mut t1);
    let n2 = term(cd, ad, bd, &mut t2);
    let n3 = term(ad, bd, cd, &mut t3);
    let mut s12 = [0.0; 16];
    let n12 = sum_into(&t1[..n1], &t2[..n2], &mut s12);
    let mut det = [0.0; 24];
    let n = sum_into(&s12[..n12], &t3[..n3], &mut det);
    sign(&det[..n])
}

/// The four points have one coordinate in common, so they lie in a plane normal to an axis
/// and the determinant has a zero column: exactly zero, which the filter cannot vouch for
/// (its bound is never zero). Flat faces of CAD models and flat caps lie in such planes;
/// the check saves the exact expansion there.
#[inline]
fn in_axis_plane(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
    (0..3).any(|k| a[k] == d[k] && b[k] == d[k] && c[k] == d[k])
}

/// The value of [`orient3d`]'s determinant (six times the signed volume of abcd): its
/// f64 evaluation when the filter vouches for its sign, else the exact value rounded.
#[inline]
pub fn orient3d_approx(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    orient3d_filter(a, b, c, d).unwrap_or_else(|| -orient3d_exact(a, b, c, d).estimate())
}

/// Relative accuracy of [`plane_crossing`] and [`line_crossing`]: a point they place lies
/// within this fraction of its segment's length of the exact crossing, far below any
/// tolerance of the constructions that use them.
pub const CROSSING_ACCURACY: f64 = 1.0 / (1u64 << 44) as f64;

/// Where segment pq crosses the plane of abc (p and q strictly on opposite sides), as the
/// fraction of the way from p to q: d(p) / (d(p) − d(q)) of the [`orient3d`]
/// determinants, within [`CROSSING_ACCURACY`]. From the f64 determinants when their error
/// bounds allow, else from the exact ones: an approximate determinant may be off by its
/// whole size where the segment runs almost along the plane (near-coplanar triangles),
/// and the point with it, by a good part of the segment.
pub fn plane_crossing(a: DVec3, b: DVec3, c: DVec3, p: DVec3, q: DVec3) -> f64 {
    let ((dp, ep), (dq, eq)) = (orient3d_float(a, b, c, p), orient3d_float(a, b, c, q));
    if ep + eq <= CROSSING_ACCURACY * (dp - dq).abs() {
        return dp / (dp - dq);
    }
    // Both exact determinants have the opposite sign: the ratio is the same.
    let (xp, xq) = (orient3d_exact(a, b, c, p), orient3d_exact(a, b, c, q));
    xp.estimate() / Stack::<384>::sum(&xp, &xq.negated()).estimate()
}

/// Where segment pq crosses the line ab in the plane (p and q strictly on opposite
/// sides), as the fraction of the way from p to q: [`plane_crossing`] in 2D.
pub fn line_crossing(a: DVec2, b: DVec2, p: DVec2, q: DVec2) -> f64 {
    let ((dp, ep), (dq, eq)) = (orient2d_float(a, b, p), orient2d_float(a, b, q));
    if ep + eq <= CROSSING_ACCURACY * (dp - dq).abs() {
        return dp / (dp - dq);
    }
    let (xp, xq) = (orient2d_exact(a, b, p), orient2d_exact(a, b, q));
    xp.estimate() / Stack::<32>::sum(&xp, &xq.negated()).estimate()
}

/// The exact signs of the components of the normal (b − a) × (c − a): the orientations
/// of the triangle's projections on the yz, zx and xy planes.
pub fn normal_signs(a: DVec3, b: DVec3, c: DVec3) -> [Sign; 3] {
    let o = |u: usize, v: usize| {
        let q = |p: DVec3| DVec2::new(p[u], p[v]);
        orient2d(q(a), q(b), q(c))
    };
    [o(1, 2), o(2, 0), o(0, 1)]
}

/// [`orient3d`] of the perturbed point p + (ε, ε³, ε²): zero only when the triangle
/// abc is degenerate.
pub fn orient3d_perturbed(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> Sign {
    match orient3d(a, b, c, p) {
        0 => {
            // n·(ε, ε³, ε²): the x component decides, then z, then y.
            let [nx, ny, nz] = normal_signs(a, b, c);
            if nx != 0 {
                nx
            } else if nz != 0 {
                nz
            } else {
                ny
            }
        }
        s => s,
    }
}

/// [`orient2d`] in the (y, z) plane of u, v and the perturbed point p + (ε³, ε²) (the
/// perturbation of [`orient3d_perturbed`] seen along x).
pub fn orient_yz_perturbed(u: DVec3, v: DVec3, p: DVec3) -> Sign {
    match orient2d([u.y, u.z], [v.y, v.z], [p.y, p.z]) {
        0 => {
            // (v.y − u.y)·ε² − (v.z − u.z)·ε³
            let dy = sign_of(v.y - u.y);
            if dy != 0 { dy } else { -sign_of(v.z - u.z) }
        }
        s => s,
    }
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
    fn sign_conventions() {
        assert_eq!(orient3d(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z), 1);
        assert_eq!(orient3d(DVec3::ZERO, DVec3::Y, DVec3::X, DVec3::Z), -1);
        assert_eq!(orient3d(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(3.0, -7.0, 0.0)), 0);
        assert_eq!(orient3d_approx(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z * 2.0), 2.0);
        assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1);
        assert_eq!(orient2d(DVec2::ZERO, DVec2::Y, DVec2::X), -1);
        assert_eq!(orient2d_approx([0.0, 0.0], [2.0, 0.0], [0.0, 1.0]), 2.0);
        assert_eq!(normal_signs(DVec3::ZERO, DVec3::X, DVec3::Y), [0, 0, 1]);
    }

    #[test]
    fn points_in_an_axis_plane_are_coplanar_and_the_next_float_is_not() {
        let (a, b, c) = (DVec3::new(1e15, 0.1, 0.3), DVec3::new(-3.7, 1e-9, 0.3), DVec3::new(0.2, -5e7, 0.3));
        let d = DVec3::new(7.0, 11.0, 0.3);
        assert!(in_axis_plane(a, b, c, d));
        assert_eq!(orient3d(a, b, c, d), 0);
        let above = DVec3::new(d.x, d.y, f64::from_bits(d.z.to_bits() + 1));
        assert!(!in_axis_plane(a, b, c, above));
        assert_eq!(orient3d(a, b, c, above), -orient3d_exact(a, b, c, above).sign());
        assert_eq!(orient3d_exact_sign(a, b, c, above), orient3d_exact(a, b, c, above).sign());
        assert_ne!(orient3d(a, b, c, above), 0);
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
            let want = orient3d_i128(a, b, c, d);
            assert_eq!(orient3d(f(a), f(b), f(c), f(d)), want, "{a:?} {b:?} {c:?} {d:?}");
            assert_eq!(sign_of(orient3d_approx(f(a), f(b), f(c), f(d))), want);
            // Far from the origin (still exact integers): same sign.
            let t = DVec3::new(2f64.powi(40), -(2f64.powi(45)), 2f64.powi(50));
            assert_eq!(orient3d(f(a) + t, f(b) + t, f(c) + t, f(d) + t), want);
            assert_eq!(-orient3d_exact_sign(f(a) + t, f(b) + t, f(c) + t, f(d) + t), want);
            // The 2D predicate on the xy projections.
            let o2 = (a[0] as i128 - c[0] as i128) * (b[1] as i128 - c[1] as i128)
                - (a[1] as i128 - c[1] as i128) * (b[0] as i128 - c[0] as i128);
            let xy = |q: [i64; 3]| [q[0] as f64, q[1] as f64];
            assert_eq!(orient2d(xy(a), xy(b), xy(c)), o2.signum() as Sign);
        }
    }

    #[test]
    fn crossings_of_segments_almost_in_the_plane_are_accurate() {
        // p and q are exactly coplanar with abc, then moved kp ulps up and kq ulps down
        // along x: their determinants are kp·u·n_x and −kq·u·n_x, so the segment crosses
        // the plane at kp / (kp + kq) of the way. The f64 determinants are a few times
        // their error bound here, so their ratio may be far off.
        let mut rng = Rng::new(7);
        let mut worst = 0.0f64;
        for trial in 0..2000 {
            let a = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 0.25 + 1.0;
            let b = a + DVec3::new(0.25, 0.5, -0.125);
            let c = a + DVec3::new(-0.5, 0.125, 0.75);
            let (kp, kq) = (1 + trial % 97, 1 + (trial * 7) % 89);
            let step = |x: f64, k: usize, up: bool| {
                (0..k).fold(x, |x, _| if up { x.next_up() } else { x.next_down() })
            };
            let p = a + DVec3::new(0.0, 0.28125, 0.125);
            let q = a + DVec3::new(0.0, 0.140625, 0.0625);
            let (p, q) =
                (DVec3::new(step(p.x, kp, true), p.y, p.z), DVec3::new(step(q.x, kq, false), q.y, q.z));
            let want = kp as f64 / (kp + kq) as f64;
            let got = plane_crossing(a, b, c, p, q);
            worst = worst.max((got - want).abs());
            // The same in 2D: the xy projections against the line ab.
            let (a2, b2) = (DVec2::new(1.0, 1.0), DVec2::new(1.5, 2.0));
            let on = |s: f64| a2 + (b2 - a2) * s;
            let (p2, q2) = (on(0.25), on(0.75));
            let (p2, q2) = (DVec2::new(step(p2.x, kp, false), p2.y), DVec2::new(step(q2.x, kq, true), q2.y));
            let got2 = line_crossing(a2, b2, p2, q2);
            worst = worst.max((got2 - want).abs());
        }
        assert!(worst <= 4.0 * CROSSING_ACCURACY, "{worst:e}");
    }

    #[test]
    fn near_degenerate_floats_are_exact() {
        // d = a + s(b − a) + t(c − a) with dyadic s, t: exactly coplanar, though the
        // points have full 53-bit mantissas; moving d by one ulp along x gives the sign of n_x.
        let mut rng = Rng::new(5);
        for _ in 0..2000 {
            // Coordinates in [1, 1.25) with full mantissas; every sum below stays in
            // [0.5, 2), so it is exact, and d − a = ½(b − a) + ¼(c − a) exactly.
            let a = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * 0.25 + 1.0;
            let b = a + DVec3::new(0.25, 0.5, -0.125);
            let c = a + DVec3::new(-0.5, 0.125, 0.75);
            let d = a + DVec3::new(0.0, 0.28125, 0.125);
            assert_eq!(orient3d(a, b, c, d), 0);
            assert_eq!(orient3d_approx(a, b, c, d), 0.0);
            let nx = normal_signs(a, b, c)[0];
            let up = DVec3::new(d.x.next_up(), d.y, d.z);
            let down = DVec3::new(d.x.next_down(), d.y, d.z);
            assert_eq!(orient3d(a, b, c, up), nx);
            assert_eq!(orient3d(a, b, c, down), -nx);
            for e in [d, up, down, a + DVec3::new(0.1, 0.2, 0.3)] {
                assert_eq!(orient3d_exact_sign(a, b, c, e), orient3d_exact(a, b, c, e).sign());
            }
            assert_eq!(orient3d_perturbed(a, b, c, d), nx);
        }
        // Collinear in exact arithmetic despite the rounding of every difference.
        let t = 1.0 + 1e-3;
        assert_eq!(orient2d([t, 3.0 * t], [2.0 * t, 6.0 * t], [4.0 * t, 12.0 * t]), 0);
        assert_eq!(orient2d([t, 3.0 * t], [2.0 * t, 6.0 * t], [4.0 * t, (12.0 * t).next_up()]), 1);
        assert_eq!(orient_yz_perturbed(DVec3::ZERO, DVec3::Y, DVec3::Y * 0.5), 1);
    }
}
