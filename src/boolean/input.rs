//! What a Boolean operand must be, checked before any work: a closed, consistently
//! oriented solid of positive volume whose faces do not cross each other, or the empty
//! solid (no faces). Non-manifold solids (two cubes sharing an edge), cavities, polygon
//! faces and faces of no area (left out exactly: they carry no volume) are fine, as they
//! are for every other command.
//!
//! Each refusal names the operand and the reason; the command exits with status 2 and
//! writes nothing. (NaN and infinite coordinates never get this far: the mesh readers
//! refuse them.)

use glam::DVec3;

use crate::mesh::Mesh;
use crate::mesh::covering::Covering;
use crate::mesh::disjoint_sets::UnionFind;
use crate::mesh::frame::Frame;
use crate::mesh::intersect::TriangleSoup;
use crate::mesh::solidity::{self, NotSolid, Policy};
use crate::mesh::triangulate::TriangulateError;

/// Why an operand is refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum InputError {
    /// Not a valid solid by the rule every command follows ([`crate::mesh::solidity`]):
    /// open, inconsistently oriented, inverted, badly nested or self-intersecting.
    #[error("{}{}", .0.defect, remedy(&.0.defect))]
    NotSolid(#[from] NotSolid),
    #[error("face {face} cannot be triangulated in its plane: {reason}")]
    Face { face: usize, reason: TriangulateError },
    /// Faces of no area are left out (they carry no volume); these are stacked along one
    /// line so that leaving them out would open the surface.
    #[error(
        "face {face} has no area, and leaving it out would open the surface (faces of no area overlap along one line)"
    )]
    Degenerate { face: usize },
    #[error("it encloses no volume")]
    Flat,
}

/// The `boolean` flag that accepts a defect, as a hint.
fn remedy(defect: &solidity::Defect) -> &'static str {
    match defect {
        solidity::Defect::SelfIntersecting { .. } | solidity::Defect::CrossingShells { .. } => {
            " (pass --allow-self-intersections to go on anyway)"
        }
        solidity::Defect::Inverted { .. } => " (pass --flip-inverted to reverse its faces)",
        _ => "",
    }
}

/// Checks one operand, given in `frame`, and returns its triangles (polygon faces tessellated
/// as every command sees them, [`TriangleSoup::new`]; vertices welded by position; triangles
/// of no area left out, [`TriangleSoup::without_zero_area`]): the shared solid check of
/// every command, then what refinement needs on top (faces it can triangulate, a volume). `allow_self_intersections` excuses faces that
/// cross; an inverted operand is refused (the command flips it first when asked).
pub fn check(mesh: &Mesh, frame: Frame, allow_self_intersections: bool) -> Result<TriangleSoup, InputError> {
    check_known(mesh, frame, allow_self_intersections, None).map(|(soup, _)| soup)
}

/// [`check`], with the solid check's verdict on `mesh` when it is already known (a valid
/// solid's, remembered from an earlier run: [`solidity::Memory`]); also returns the
/// verdict, in the operand's units, so that a caller can remember it (none for the empty
/// solid, which needs no check).
pub fn check_known(
    mesh: &Mesh,
    frame: Frame,
    allow_self_intersections: bool,
    known: Option<solidity::Solidity>,
) -> Result<(TriangleSoup, Option<solidity::Solidity>), InputError> {
    if mesh.num_faces() == 0 {
        // The empty solid: A ∪ ∅ = A, A ∩ ∅ = ∅, and so on, from the same steps.
        return Ok((TriangleSoup::new(mesh), None));
    }
    let solid = known.unwrap_or_else(|| solidity::check_in(mesh, frame));
    let policy = Policy { allow_self_intersections, ..Policy::default() };
    if let Some(defect) = solidity::first_refusal(&solid, policy) {
        return Err(NotSolid { defect: defect.clone() }.into());
    }
    let soup = TriangleSoup::new(mesh);
    if let Some((face, reason)) = soup.failed.first().cloned() {
        return Err(InputError::Face { face: face as usize, reason });
    }
    // Triangles of no area carry no volume: the surface without them is the one every
    // command sees (mesh stats, inclusion and voxelize measure and test it the same).
    let soup =
        soup.without_zero_area().map_err(|face| InputError::Degenerate { face: face as usize })?.into_owned();
    // In the frame: the volume in the input's units may underflow. The solid check's
    // volume serves where it is a normal number clearly above the bound (the same sum up
    // to rounding); near the bound it is measured again here.
    let known = solid.volume.filter(|v| v.is_normal()).map(|v| frame.volume_in(v));
    if known.is_some_and(|v| v.is_normal() && v.abs() > 2.0 * coarse_flatness_bound(&soup)) {
        // Clearly above the bound below (which it bounds from above): not flat, and the
        // same verdict without finding the pieces.
        return Ok((soup, Some(solid)));
    }
    let bound = flatness_bound(piece_boxes(&soup));
    let volume = match known {
        Some(v) if v.is_normal() && v.abs() > 2.0 * bound => v,
        _ => Covering::new(mesh).volume(),
    };
    if volume.abs() <= bound {
        return Err(InputError::Flat);
    }
    Ok((soup, Some(solid)))
}

/// "It encloses no volume": |`volume`| at most 1e-12 × the cube of the largest extent of
/// the box `lo`..`hi` (a solid flattened to a sheet, whatever its size).
pub fn is_flat(volume: f64, lo: DVec3, hi: DVec3) -> bool {
    volume.abs() <= 1e-12 * (hi - lo).max_element().powi(3)
}

/// The volume at or below which a whole mesh encloses none: the sum of [`is_flat`]'s bound
/// over its connected pieces' boxes (the box around all of them would call two small
/// solids far apart flat).
pub fn flatness_bound(piece_boxes: impl IntoIterator<Item = (DVec3, DVec3)>) -> f64 {
    piece_boxes.into_iter().map(|(lo, hi)| 1e-12 * (hi - lo).max_element().powi(3)).sum()
}

/// An upper bound of `flatness_bound(piece_boxes(soup))` as computed, from one pass over
/// the positions: each piece's box lies in the box of all positions (so its term is at most
/// T, the term of that box, the same f64 operations being monotone), there are at most as
/// many pieces as triangles (N), and a sum of N terms at most T, rounded N times, is at
/// most N·T·(1 + u)^N ≤ N·T·(1 + 2⁻²⁰) for N < 2³¹; the factor 1 + 2⁻¹⁹ covers that and the
/// two roundings here.
fn coarse_flatness_bound(soup: &TriangleSoup) -> f64 {
    let Some(&first) = soup.positions.first() else {
        return 0.0;
    };
    let (lo, hi) = soup.positions.iter().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let term = flatness_bound([(lo, hi)]);
    soup.triangles.len() as f64 * term * (1.0 + 1.0 / 524288.0)
}

/// The boxes of the connected pieces of a triangle soup.
pub fn piece_boxes(soup: &TriangleSoup) -> Vec<(DVec3, DVec3)> {
    let mut sets = UnionFind::new(soup.positions.len());
    for t in &soup.triangles {
        sets.union(t[0], t[1]);
        sets.union(t[0], t[2]);
    }
    // Per root (a vertex id): its piece's box, in the order of the roots' ids.
    let mut boxes: Vec<Option<(DVec3, DVec3)>> = vec![None; soup.positions.len()];
    for t in &soup.triangles {
        let e = boxes[sets.find(t[0]) as usize].get_or_insert((DVec3::INFINITY, DVec3::NEG_INFINITY));
        for &v in t {
            let p = soup.positions[v as usize];
            *e = (e.0.min(p), e.1.max(p));
        }
    }
    boxes.into_iter().flatten().collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::procedural;
    use crate::mesh::solidity::Defect;

    fn flipped(m: &Mesh, which: impl Fn(usize) -> bool) -> Mesh {
        let faces = m
            .faces()
            .enumerate()
            .map(|(f, face)| if which(f) { face.iter().rev().copied().collect() } else { face.to_vec() })
            .collect();
        Mesh::new(m.positions().to_vec(), faces).unwrap()
    }

    fn check_unit(m: &Mesh, allow: bool) -> Result<TriangleSoup, InputError> {
        check(m, Frame::IDENTITY, allow)
    }

    fn defect(r: Result<TriangleSoup, InputError>) -> Defect {
        match r {
            Err(InputError::NotSolid(e)) => e.defect,
            other => panic!("expected a refusal by the solid check, got {:?}", other.map(|_| ())),
        }
    }

    #[test]
    fn refusals_name_the_reason() {
        let cube = procedural::cube();
        assert!(check_unit(&cube, false).is_ok());
        assert!(check_unit(&procedural::two_cubes_sharing_edge(), false).is_ok());
        assert!(check_unit(&procedural::cube_with_cavity(), false).is_ok());
        assert!(check_unit(&procedural::l_prism(), false).is_ok());
        let open = Mesh::new(cube.positions().to_vec(), cube.faces().skip(1).map(<[u32]>::to_vec).collect())
            .unwrap();
        assert!(matches!(defect(check_unit(&open, false)), Defect::Open(_)));
        assert!(matches!(defect(check_unit(&flipped(&cube, |f| f == 2), false)), Defect::Open(_)));
        assert!(
            matches!(defect(check_unit(&flipped(&cube, |_| true), false)), Defect::Inverted { volume } if (volume + 8.0).abs() < 1e-12)
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
        let e = check_unit(&two, false).unwrap_err();
        assert!(
            matches!(&e, InputError::NotSolid(n) if matches!(n.defect, Defect::SelfIntersecting { .. } | Defect::CrossingShells { .. })),
            "{e}"
        );
        assert!(e.to_string().contains("--allow-self-intersections"), "{e}");
        assert!(check_unit(&two, true).is_ok());
    }

    /// The one-pass bound is never below the bound over the pieces, for one piece, pieces
    /// far apart (where it is much larger) and every built-in model.
    #[test]
    fn the_coarse_flatness_bound_is_above_the_pieces_bound() {
        let s = procedural::sphere(6, 8);
        let mut apart = s.positions().to_vec();
        let n = apart.len() as u32;
        apart.extend(s.positions().iter().map(|&x| x * 1e-3 + DVec3::new(1e3, 0.0, 0.0)));
        let mut faces: Vec<Vec<u32>> = s.faces().map(<[u32]>::to_vec).collect();
        faces.extend(s.faces().map(|x| x.iter().map(|&i| i + n).collect::<Vec<_>>()));
        let mut meshes = vec![Mesh::new(apart, faces).unwrap()];
        meshes.extend(procedural::BUILTIN_NAMES.iter().map(|name| procedural::by_name(name).unwrap()));
        for m in &meshes {
            let soup = TriangleSoup::new(m);
            let (coarse, fine) = (coarse_flatness_bound(&soup), flatness_bound(piece_boxes(&soup)));
            assert!(coarse >= fine && fine > 0.0, "{coarse} {fine}");
        }
    }
}
