//! Polygon faces to triangles for drawing: ear clipping in the face's own plane, so
//! non-convex faces (the L-prism's caps) are drawn right; a fan where the polygon is
//! degenerate enough that no ear is found.

use glam::{DVec2, DVec3};

/// The Newell normal of a polygon (twice its vector area; zero for a degenerate one).
pub(crate) fn newell(points: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for (i, p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        n += DVec3::new((p.y - q.y) * (p.z + q.z), (p.z - q.z) * (p.x + q.x), (p.x - q.x) * (p.y + q.y));
    }
    n
}

/// Triangles covering the polygon `points` (in order), as corner indices into `points`,
/// each oriented like the polygon.
pub fn triangulate_face(points: &[DVec3]) -> Vec<[usize; 3]> {
    let n = points.len();
    if n < 3 {
        return Vec::new();
    }
    if n == 3 {
        return vec![[0, 1, 2]];
    }
    let fan = || (1..n - 1).map(|i| [0, i, i + 1]).collect();
    let normal = newell(points);
    if normal.length_squared() == 0.0 || !normal.is_finite() {
        return fan();
    }
    // 2D coordinates in the face plane, counter-clockwise seen along the normal.
    let w = normal.normalize();
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    let origin = points[0];
    let flat: Vec<DVec2> =
        points.iter().map(|&p| DVec2::new((p - origin).dot(u), (p - origin).dot(v))).collect();
    let cross = |a: DVec2, b: DVec2, c: DVec2| (b - a).perp_dot(c - a);
    let convex = (0..n).all(|i| cross(flat[i], flat[(i + 1) % n], flat[(i + 2) % n]) >= 0.0);
    if convex {
        return fan();
    }
    let mut ring: Vec<usize> = (0..n).collect();
    let mut out = Vec::with_capacity(n - 2);
    while ring.len() > 3 {
        let m = ring.len();
        let ear = (0..m).find(|&i| {
            let (a, b, c) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]);
            let (pa, pb, pc) = (flat[a], flat[b], flat[c]);
            if cross(pa, pb, pc) <= 0.0 {
                return false;
            }
            // No other corner inside the ear (closed triangle).
            ring.iter().all(|&o| {
                o == a
                    || o == b
                    || o == c
                    || cross(pa, pb, flat[o]) < 0.0
                    || cross(pb, pc, flat[o]) < 0.0
                    || cross(pc, pa, flat[o]) < 0.0
            })
        });
        let Some(i) = ear else { return fan() };
        out.push([ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]]);
        ring.remove(i);
    }
    out.push([ring[0], ring[1], ring[2]]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(points: &[DVec3], tris: &[[usize; 3]]) -> f64 {
        tris.iter().map(|t| newell(&[points[t[0]], points[t[1]], points[t[2]]]).z * 0.5).sum()
    }

    #[test]
    fn l_shape_is_covered_exactly() {
        let l: Vec<DVec3> = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        let tris = triangulate_face(&l);
        assert_eq!(tris.len(), 4);
        assert!((area(&l, &tris) - 3.0).abs() < 1e-12, "{tris:?}");
        // Every triangle keeps the polygon's orientation.
        assert!(tris.iter().all(|t| newell(&[l[t[0]], l[t[1]], l[t[2]]]).z > 0.0));
    }

    #[test]
    fn convex_faces_fan() {
        let sq: Vec<DVec3> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, 0.0))
            .collect();
        assert_eq!(triangulate_face(&sq), vec![[0, 1, 2], [0, 2, 3]]);
    }
}
