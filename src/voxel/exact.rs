//! Exact geometric predicates on f64 inputs, and the tie rule they decide.
//!
//! `orient2d` / `orient3d` come from [`crate::exact`] (a filtered floating-point
//! determinant, recomputed exactly with expansions when its sign is in doubt).
//!
//! **The tie rule.** A voxel centre p on the surface is decided as the point
//! p + (ε, ε³, ε²) for an infinitesimal ε > 0: pushed first along +x, then +z, then +y.
//! In a slice (x across, z down, like Vulkan's framebuffer) that is the top-left rule —
//! a centre on a left edge, or on a horizontal top edge, is in — and along y it is the
//! half-open interval A.y > y_s ≥ D.y of SPEC §4.2 (a centre on a horizontal face
//! belongs to what lies above it). Every method, and every exact test, follows it.

use glam::DVec3;

pub use crate::exact::{Sign, orient2d, orient3d};

fn sign_of(x: f64) -> Sign {
    crate::exact::sign_of(x)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

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
