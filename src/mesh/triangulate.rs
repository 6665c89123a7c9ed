//! Triangles for formats and renderers that only know triangles (STL, a rasterizer):
//! every polygon face split into n − 2 triangles that tile it exactly, non-convex ones
//! included (a fan from the first vertex folds over a non-convex polygon, which keeps the
//! signed area but not the area).
//!
//! Convex faces (the common case) get the fan (v0, vᵢ, vᵢ₊₁), as before; other faces are
//! ear-clipped in the plane they project to best (along the dominant axis of their vector
//! area), with exact orientation tests ([`crate::exact::orient2d`]). A polygon that has no
//! ear left (self-intersecting, or with repeated or collinear vertices that leave no
//! proper ear) has its remaining vertices fanned.
//!
//! The simplicial covering (SPEC §2) is a different thing — the centroid fan with signed
//! triangles that the algorithms use, never a tessellation — and stays in
//! [`super::covering`].

use glam::DVec3;

use super::Mesh;
use crate::exact::orient2d;

/// The triangles of face `face` (vertex indices, oriented like the face).
pub fn face_triangles(positions: &[DVec3], face: &[u32]) -> Vec<[u32; 3]> {
    let n = face.len();
    if n == 3 {
        return vec![[face[0], face[1], face[2]]];
    }
    let fan = || (1..n - 1).map(|i| [face[0], face[i], face[i + 1]]).collect();
    // Projection along the dominant axis of the vector area, turned so the face is
    // counter-clockwise in the plane.
    let p0 = positions[face[0] as usize];
    let normal = (1..n - 1).fold(DVec3::ZERO, |s, i| {
        s + (positions[face[i] as usize] - p0).cross(positions[face[i + 1] as usize] - p0)
    });
    let axis = normal.abs().max_position();
    let (u, v) = [(1, 2), (2, 0), (0, 1)][axis];
    let flip = normal[axis] < 0.0;
    let at = |i: u32| {
        let p = positions[i as usize];
        if flip { [p[v], p[u]] } else { [p[u], p[v]] }
    };
    let turn = |a: u32, b: u32, c: u32| orient2d(at(a), at(b), at(c));
    if (0..n).all(|i| turn(face[i], face[(i + 1) % n], face[(i + 2) % n]) >= 0) {
        return fan();
    }
    // Ear clipping: cut a convex corner whose triangle holds no other vertex.
    let mut ring: Vec<u32> = face.to_vec();
    let mut out = Vec::with_capacity(n - 2);
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            turn(a, b, c) > 0
                && ring.iter().all(|&q| {
                    q == a || q == b || q == c || turn(a, b, q) < 0 || turn(b, c, q) < 0 || turn(c, a, q) < 0
                })
        });
        let Some(i) = ear else {
            // No proper ear (a self-intersecting or degenerate polygon): fan the rest.
            out.extend((1..m - 1).map(|k| [ring[0], ring[k], ring[k + 1]]));
            return out;
        };
        out.push([ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]]);
        ring.remove(i);
    }
    out.push([ring[0], ring[1], ring[2]]);
    out
}

/// The triangles of every face, in face order.
pub fn triangles(mesh: &Mesh) -> impl Iterator<Item = [u32; 3]> + '_ {
    mesh.faces().flat_map(|f| face_triangles(mesh.positions(), f))
}

/// `mesh` with every face triangulated (same vertices).
pub fn triangulated(mesh: &Mesh) -> Mesh {
    let faces = triangles(mesh).map(|t| t.to_vec()).collect();
    Mesh::new(mesh.positions().to_vec(), faces)
        .unwrap_or_else(|e| unreachable!("triangles of a valid mesh form a valid mesh: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::covering::Covering;
    use crate::mesh::procedural;

    /// Σ |area| of the triangles, and their signed volume.
    fn measures(mesh: &Mesh) -> (f64, f64) {
        let c = Covering::new(mesh);
        (c.area(), c.volume())
    }

    #[test]
    fn non_convex_faces_keep_area_and_volume() {
        for name in procedural::BUILTIN_NAMES {
            let m = procedural::by_name(name).unwrap();
            let t = triangulated(&m);
            assert!(t.is_triangle_mesh());
            assert_eq!(t.num_faces(), m.faces().map(|f| f.len() - 2).sum::<usize>(), "{name}");
            let ((a0, v0), (a1, v1)) = (measures(&m), measures(&t));
            assert!(
                (a0 - a1).abs() <= 1e-12 * a0 && (v0 - v1).abs() <= 1e-12 * v0.abs(),
                "{name}: {a0} {a1} {v0} {v1}"
            );
            assert!(t.report().is_closed(), "{name}");
        }
        // A comb: a fan from its first vertex folds over the teeth.
        let comb = [
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, 2.0),
            (4.0, 2.0),
            (4.0, 1.0),
            (3.0, 1.0),
            (3.0, 2.0),
            (2.0, 2.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let m = procedural::prism(&comb, 1.0).unwrap();
        let ((a0, v0), (a1, v1)) = (measures(&m), measures(&triangulated(&m)));
        assert!((a0 - a1).abs() < 1e-12 * a0 && (v0 - v1).abs() < 1e-12 * v0, "{a0} {a1} {v0} {v1}");
    }
}
