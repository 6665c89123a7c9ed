//! Exact geometric predicates on f64 inputs, and the tie rule they decide.
//!
//! `orient2d` / `orient3d` first evaluate the determinant in floating point with a
//! forward error bound (the filter); only when the sign is in doubt do they recompute it
//! exactly with floating-point expansions (error-free two-sum / two-product, Shewchuk's
//! grow, scale and sum), so the answer is the sign of the exact real determinant.
//!
//! **The tie rule.** A voxel centre p on the surface is decided as the point
//! p + (ε, ε³, ε²) for an infinitesimal ε > 0: pushed first along +x, then +z, then +y.
//! In a slice (x across, z down, like Vulkan's framebuffer) that is the top-left rule —
//! a centre on a left edge, or on a horizontal top edge, is in — and along y it is the
//! half-open interval A.y > y_s ≥ D.y of SPEC §4.2 (a centre on a horizontal face
//! belongs to what lies above it). Every method, and every exact test, follows it.

use glam::DVec3;

/// Sign of a real number: −1, 0 or 1.
pub type Sign = i8;

fn sign_of(x: f64) -> Sign {
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

/// The normal (b − a) × (c − a) of a triangle, as exact signs of its components.
pub fn normal_signs(a: DVec3, b: DVec3, c: DVec3) -> [Sign; 3] {
    [
        orient2d([a.y, a.z], [b.y, b.z], [c.y, c.z]),
        orient2d([a.z, a.x], [b.z, b.x], [c.z, c.x]),
        orient2d([a.x, a.y], [b.x, b.y], [c.x, c.y]),
    ]
}

/// Sign of ((b − a) × (c − a)) · (p' − a) for the perturbed point p' = p + (ε, ε³, ε²)
/// (the tie rule): zero only when the triangle is degenerate.
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

/// Sign of (v − u) × (p' − u) in the (y, z) plane for p' = p + (ε³, ε²) in (y, z), the
/// perturbation of the tie rule seen along x.
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

/// Whether the line through the perturbed p along +x meets triangle abc, and if so
/// whether the crossing lies ahead (x greater than p's, after perturbation).
/// Returns `None` when the line misses the triangle.
pub fn ray_x_crossing(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> Option<bool> {
    let nx = orient2d([a.y, a.z], [b.y, b.z], [c.y, c.z]);
    if nx == 0 {
        return None; // the triangle is parallel to x: the perturbed line misses it
    }
    if !inside_yz(a, b, c, p, nx) {
        return None;
    }
    Some(crossing_ahead(a, b, c, p, nx))
}

/// Whether the perturbed (y, z) of p lies inside the yz projection of abc, whose
/// orientation there is `nx` (non-zero).
pub fn inside_yz(a: DVec3, b: DVec3, c: DVec3, p: DVec3, nx: Sign) -> bool {
    orient_yz_perturbed(a, b, p) == nx
        && orient_yz_perturbed(b, c, p) == nx
        && orient_yz_perturbed(c, a, p) == nx
}

/// For a line along x through the perturbed p that meets abc: is the crossing ahead?
/// n·(p + t·x − a) = 0 has t > 0 iff n·(p − a) and n_x have opposite signs.
pub fn crossing_ahead(a: DVec3, b: DVec3, c: DVec3, p: DVec3, nx: Sign) -> bool {
    let s = match orient3d(a, b, c, p) {
        0 => nx, // p on the plane: pushed by ε along x it is past the crossing
        s => s,
    };
    s == -nx
}

/// Exact occupancy of point p (tie rule applied) by the parity of the crossings of the
/// ray from p along +x with the covering triangles: the Jordan-curve test (§4.2), exact.
pub fn inside_by_ray(triangles: &[[DVec3; 3]], p: DVec3) -> bool {
    let mut parity = false;
    for t in triangles {
        if ray_x_crossing(t[0], t[1], t[2], p) == Some(true) {
            parity = !parity;
        }
    }
    parity
}

/// Exact occupancy of point p (tie rule applied) by the parity of the covering tetras
/// (O, A, B, C) that contain it (the XOR of §5.3.1, evaluated exactly): an oracle
/// independent of [`inside_by_ray`].
pub fn inside_by_tetras(triangles: &[[DVec3; 3]], apex: DVec3, p: DVec3) -> bool {
    let mut parity = false;
    for t in triangles {
        let [a, b, c] = *t;
        let side = orient3d(a, b, c, apex);
        if side == 0 {
            continue; // flat tetra: contains no perturbed point
        }
        // Each face with the vertex opposite to it: p must be on that vertex's side.
        let faces = [(a, b, c, apex), (apex, b, c, a), (a, apex, c, b), (a, b, apex, c)];
        let inside = faces.iter().all(|&(f0, f1, f2, opposite)| {
            let s = orient3d(f0, f1, f2, opposite);
            s != 0 && orient3d_perturbed(f0, f1, f2, p) == s
        });
        if inside {
            parity = !parity;
        }
    }
    parity
}

// ---- Expansion arithmetic (components non-overlapping, increasing magnitude). ----

fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let err = (a - (s - bb)) + (b - bb);
    (s, err)
}

fn two_prod(a: f64, b: f64) -> (f64, f64) {
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
            let nx = normal_signs(a, b, c)[0];
            let up = DVec3::new(d.x.next_up(), d.y, d.z);
            let down = DVec3::new(d.x.next_down(), d.y, d.z);
            assert_eq!(orient3d(a, b, c, up), nx);
            assert_eq!(orient3d(a, b, c, down), -nx);
            assert_eq!(orient3d_perturbed(a, b, c, d), nx);
        }
        // Collinear in exact arithmetic despite the rounding of every difference.
        let t = 1.0 + 1e-3;
        assert_eq!(orient2d([t, 3.0 * t], [2.0 * t, 6.0 * t], [4.0 * t, 12.0 * t]), 0);
        assert_eq!(orient2d([t, 3.0 * t], [2.0 * t, 6.0 * t], [4.0 * t, (12.0 * t).next_up()]), 1);
    }

    #[test]
    fn ray_and_tetra_parity_agree_on_a_cube_with_ties() {
        // Unit cube [0,2]³ as 12 triangles; points on faces, edges and corners.
        let v = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let c = [
            v(0., 0., 0.),
            v(2., 0., 0.),
            v(2., 2., 0.),
            v(0., 2., 0.),
            v(0., 0., 2.),
            v(2., 0., 2.),
            v(2., 2., 2.),
            v(0., 2., 2.),
        ];
        let quads = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
        let tris: Vec<[DVec3; 3]> =
            quads.iter().flat_map(|q| [[c[q[0]], c[q[1]], c[q[2]]], [c[q[0]], c[q[2]], c[q[3]]]]).collect();
        let apex = v(0.7, 1.1, 0.9);
        for x in [-1.0, 0.0, 1.0, 2.0, 3.0] {
            for y in [-1.0, 0.0, 1.0, 2.0, 3.0] {
                for z in [-1.0, 0.0, 1.0, 2.0, 3.0] {
                    let p = v(x, y, z);
                    let ray = inside_by_ray(&tris, p);
                    assert_eq!(ray, inside_by_tetras(&tris, apex, p), "{p}");
                    // The tie rule: the closed-below, open-above box [0,2) in every axis.
                    let expect = [x, y, z].iter().all(|&t| (0.0..2.0).contains(&t));
                    assert_eq!(ray, expect, "{p}");
                }
            }
        }
    }
}
