//! What a Boolean operand must be, checked before any work: a closed, consistently
//! oriented solid of positive volume whose faces do not cross each other. Non-manifold
//! solids (two cubes sharing an edge), cavities and polygon faces are fine.
//!
//! Each refusal names the operand and the reason; the command exits with status 2 and
//! writes nothing. (NaN and infinite coordinates never get this far: the mesh readers
//! refuse them.)

use rayon::prelude::*;

use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::mesh::intersect::{TriangleSoup, is_degenerate, soup_self_intersections};
use crate::mesh::triangulate::TriangulateError;

/// Why an operand is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InputError {
    #[error("it has no faces")]
    Empty,
    #[error("face {face} cannot be triangulated in its plane: {reason}")]
    Face { face: usize, reason: TriangulateError },
    #[error("face {face} has no area (its corners are collinear)")]
    Degenerate { face: usize },
    #[error("it is open: {edges} edge(s) have a face on one side only")]
    Open { edges: usize },
    #[error("it is not consistently oriented: {edges} edge(s) are used twice in the same direction")]
    Inconsistent { edges: usize },
    #[error("it is inverted (its faces point inwards): volume {volume}")]
    Inverted { volume: f64 },
    #[error("it encloses no volume")]
    Flat,
    #[error(
        "it intersects itself: faces {0} and {1} cross (pass --allow-self-intersections to go on anyway)"
    )]
    SelfIntersecting(usize, usize),
}

/// Checks one operand and returns its triangles (polygon faces tessellated, vertices
/// welded by position). `allow_self_intersections` skips the crossing test.
pub fn check(mesh: &Mesh, allow_self_intersections: bool) -> Result<TriangleSoup, InputError> {
    if mesh.num_faces() == 0 {
        return Err(InputError::Empty);
    }
    let (boundary, misoriented) = edge_balance(mesh);
    if boundary > 0 {
        return Err(InputError::Open { edges: boundary });
    }
    if misoriented > 0 {
        return Err(InputError::Inconsistent { edges: misoriented });
    }
    let soup = TriangleSoup::new(mesh);
    if let Some((face, reason)) = soup.failed.first().cloned() {
        return Err(if reason == TriangulateError::Degenerate {
            InputError::Degenerate { face: face as usize }
        } else {
            InputError::Face { face: face as usize, reason }
        });
    }
    if let Some(t) = (0..soup.triangles.len()).find(|&t| is_degenerate(soup.triangle(t))) {
        return Err(InputError::Degenerate { face: soup.face_of[t] as usize });
    }
    let volume = Covering::new(mesh).volume();
    let (lo, hi) = mesh.bounds();
    let scale = (hi - lo).max_element().powi(3);
    if volume.abs() <= 1e-12 * scale {
        return Err(InputError::Flat);
    }
    if volume < 0.0 {
        return Err(InputError::Inverted { volume });
    }
    if !allow_self_intersections {
        if let Some(&(f, g)) = soup_self_intersections(&soup, 1).first() {
            return Err(InputError::SelfIntersecting(f, g));
        }
    }
    Ok(soup)
}

/// Edges with one face (boundary) and edges used unequally in the two directions
/// (misoriented), counted as [`crate::mesh::Report`] counts them, by sorting half-edges
/// (the full report also finds fans and components, which are not needed here).
fn edge_balance(mesh: &Mesh) -> (usize, usize) {
    let (offsets, indices) = mesh.face_parts();
    let mut half: Vec<(u64, bool)> = Vec::with_capacity(indices.len());
    for w in offsets.windows(2) {
        let face = &indices[w[0]..w[1]];
        for (k, &a) in face.iter().enumerate() {
            let b = face[(k + 1) % face.len()];
            if a != b {
                half.push(((a.min(b) as u64) << 32 | a.max(b) as u64, a < b));
            }
        }
    }
    half.par_sort_unstable();
    let (mut boundary, mut misoriented) = (0, 0);
    let mut i = 0;
    while i < half.len() {
        let mut j = i;
        let mut forward = 0usize;
        while j < half.len() && half[j].0 == half[i].0 {
            forward += usize::from(half[j].1);
            j += 1;
        }
        let n = j - i;
        if n == 1 {
            boundary += 1;
        } else if 2 * forward != n {
            misoriented += 1;
        }
        i = j;
    }
    (boundary, misoriented)
}

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::mesh::procedural;

    fn flipped(m: &Mesh, which: impl Fn(usize) -> bool) -> Mesh {
        let faces = m
            .faces()
            .enumerate()
            .map(|(f, face)| if which(f) { face.iter().rev().copied().collect() } else { face.to_vec() })
            .collect();
        Mesh::new(m.positions().to_vec(), faces).unwrap()
    }

    #[test]
    fn refusals_name_the_reason() {
        let cube = procedural::cube();
        assert!(check(&cube, false).is_ok());
        for m in [procedural::cube(), procedural::two_cubes_sharing_edge(), procedural::torus(1.0, 0.3, 8, 6)]
        {
            let r = m.report();
            assert_eq!(edge_balance(&m), (r.boundary_edges, r.misoriented_edges));
        }
        assert!(check(&procedural::two_cubes_sharing_edge(), false).is_ok());
        assert!(check(&procedural::cube_with_cavity(), false).is_ok());
        assert!(check(&procedural::l_prism(), false).is_ok());
        let open = Mesh::new(cube.positions().to_vec(), cube.faces().skip(1).map(<[u32]>::to_vec).collect())
            .unwrap();
        assert_eq!(check(&open, false).unwrap_err(), InputError::Open { edges: 4 });
        assert_eq!(
            check(&flipped(&cube, |f| f == 2), false).unwrap_err(),
            InputError::Inconsistent { edges: 4 }
        );
        assert!(
            matches!(check(&flipped(&cube, |_| true), false), Err(InputError::Inverted { volume }) if (volume + 8.0).abs() < 1e-12)
        );
        let s = procedural::sphere(6, 8);
        let two = {
            let mut p = s.positions().to_vec();
            let n = p.len() as u32;
            p.extend(s.positions().iter().map(|&x| x + DVec3::new(0.5, 0.0, 0.0)));
            let mut f: Vec<Vec<u32>> = s.faces().map(<[u32]>::to_vec).collect();
            f.extend(s.faces().map(|x| x.iter().map(|&i| i + n).collect::<Vec<_>>()));
            Mesh::new(p, f).unwrap()
        };
        assert!(matches!(check(&two, false), Err(InputError::SelfIntersecting(..))));
        assert!(check(&two, true).is_ok());
    }
}
