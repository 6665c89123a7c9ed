//! The voxelizers' tie rule, decided with the shared exact predicates
//! ([`crate::exact`]).
//!
//! **The tie rule.** A voxel centre p on the surface is decided as the point
//! p + (ε, ε³, ε²) for an infinitesimal ε > 0: pushed first along +x, then +z, then +y
//! ([`orient3d_perturbed`], [`orient_yz_perturbed`]). In a slice (x across, z down, like
//! Vulkan's framebuffer) that is the top-left rule — a centre on a left edge, or on a
//! horizontal top edge, is in — and along y it is the half-open interval A.y > y_s ≥ D.y
//! of SPEC §4.2 (a centre on a horizontal face belongs to what lies above it). Every
//! method, and every exact test, follows it.

use glam::DVec3;

use crate::exact::{Sign, orient_yz_perturbed, orient2d, orient3d, orient3d_perturbed};

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
