//! A Boolean operand whose vertices may be implicit points: the result of one step of a
//! CSG expression kept exact for the next (its points are never rounded in between).
//!
//! Every triangle lies in the plane of an input triangle (a piece of it), its *support*:
//! three explicit points, oriented like the piece. Planes of such an operand are therefore
//! always explicit, so a later step's edge of an input mesh crosses it at an edge–plane
//! point of input data; only its own edges are segments between implicit points.

use std::borrow::Cow;

use glam::DVec3;
use rayon::prelude::*;

use crate::exact::implicit::Point;
use crate::mesh::intersect::TriangleSoup;

/// A closed, oriented surface over exact points.
#[derive(Clone, Debug, Default)]
pub struct ExactSolid {
    /// One exact point per vertex id, no two ids the same point.
    pub points: Vec<Point>,
    /// Each point rounded ([`Point::position`]): for shapes and output, never for
    /// decisions.
    pub rounded: Vec<DVec3>,
    /// Triangles over vertex ids, oriented outward.
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle, the input triangle whose plane holds it, in the same orientation.
    pub support: Vec<[DVec3; 3]>,
}

impl ExactSolid {
    /// A file operand as it is: every point explicit, each triangle its own support.
    pub fn from_soup(soup: &TriangleSoup) -> ExactSolid {
        ExactSolid {
            points: soup.positions.iter().map(|&p| Point::explicit(p)).collect(),
            rounded: soup.positions.clone(),
            triangles: soup.triangles.clone(),
            support: soup.triangles.iter().map(|t| t.map(|i| soup.positions[i as usize])).collect(),
        }
    }

    /// The corners of triangle `t` as exact points.
    pub fn corners(&self, t: u32) -> [&Point; 3] {
        self.triangles[t as usize].map(|i| &self.points[i as usize])
    }

    /// Per triangle, a box that certainly holds it ([`Point::bounds`] of its corners).
    pub fn boxes(&self) -> Vec<(DVec3, DVec3)> {
        let bounds: Vec<(DVec3, DVec3)> =
            self.points.par_iter().with_min_len(4096).map(Point::bounds).collect();
        self.triangles
            .par_iter()
            .with_min_len(4096)
            .map(|t| {
                let [a, b, c] = t.map(|i| bounds[i as usize]);
                (a.0.min(b.0).min(c.0), a.1.max(b.1).max(c.1))
            })
            .collect()
    }
}

/// What the refinement and the classification ask of an operand: a file's mesh
/// ([`TriangleSoup`], every point explicit: the f64 predicates decide, as fast as
/// before) or an exact intermediate result ([`ExactSolid`]). Generic code branches on
/// [`Solid::EXPLICIT`], a constant, so the explicit path compiles to today's code.
pub trait Solid: Sync {
    /// True when every point is explicit ([`Solid::point`] is [`Point::explicit`] of
    /// [`Solid::rounded`]).
    const EXPLICIT: bool;
    /// Triangles over vertex ids (welded: one id per exact point), oriented outward.
    fn triangles(&self) -> &[[u32; 3]];
    /// Each vertex's position: exact for explicit points, else rounded (for shapes only).
    fn rounded(&self) -> &[DVec3];
    /// Vertex `v` as an exact point.
    fn point(&self, v: u32) -> Cow<'_, Point>;
    /// The plane triangle `t` lies in, as three explicit points oriented like it.
    fn support(&self, t: u32) -> [DVec3; 3];
    /// Per triangle, a box that certainly holds it.
    fn boxes(&self) -> Vec<(DVec3, DVec3)>;
    /// The number messages give triangle `t`: the file's face it comes from, or the
    /// triangle itself for an exact result.
    fn face(&self, t: u32) -> u32 {
        t
    }
}

impl Solid for TriangleSoup {
    const EXPLICIT: bool = true;
    fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    fn rounded(&self) -> &[DVec3] {
        &self.positions
    }
    fn point(&self, v: u32) -> Cow<'_, Point> {
        Cow::Owned(Point::explicit(self.positions[v as usize]))
    }
    fn support(&self, t: u32) -> [DVec3; 3] {
        self.triangle(t as usize)
    }
    fn boxes(&self) -> Vec<(DVec3, DVec3)> {
        TriangleSoup::boxes(self)
    }
    fn face(&self, t: u32) -> u32 {
        self.face_of[t as usize]
    }
}

impl Solid for ExactSolid {
    const EXPLICIT: bool = false;
    fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
    fn rounded(&self) -> &[DVec3] {
        &self.rounded
    }
    fn point(&self, v: u32) -> Cow<'_, Point> {
        Cow::Borrowed(&self.points[v as usize])
    }
    fn support(&self, t: u32) -> [DVec3; 3] {
        self.support[t as usize]
    }
    fn boxes(&self) -> Vec<(DVec3, DVec3)> {
        ExactSolid::boxes(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::implicit::orient3d_implicit;

    #[test]
    fn a_file_operand_keeps_its_points_and_is_its_own_support() {
        let positions = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let soup = TriangleSoup { positions, triangles, face_of: vec![0, 1, 2, 3], failed: Vec::new() };
        let s = ExactSolid::from_soup(&soup);
        assert_eq!(Solid::boxes(&s), Solid::boxes(&soup));
        for t in 0..4 {
            let [a, b, c] = s.support[t as usize].map(Point::explicit);
            assert!(s.corners(t).iter().all(|p| orient3d_implicit(&a, &b, &c, p) == 0));
        }
    }

    #[test]
    fn boxes_hold_implicit_points() {
        let p = Point::edge_plane(
            DVec3::ZERO,
            DVec3::new(1.0, 1.0, 1.0),
            [DVec3::new(0.3, 0.0, 0.0), DVec3::new(0.3, 1.0, 0.0), DVec3::new(0.3, 0.0, 1.0)],
        )
        .unwrap();
        let (lo, hi) = p.bounds();
        assert!(lo.cmplt(hi).all());
        for (i, c) in p.coordinates().iter().enumerate() {
            assert!(c.value() - c.radius() >= lo[i] && c.value() + c.radius() <= hi[i]);
        }
    }
}
