//! What a picture shows: meshes with their colours and shading, polylines and points.

use std::borrow::Cow;

use glam::DVec3;

use super::colour::{self, Rgba};
use super::error::{RenderError, Result};
use crate::mesh::Mesh;

/// How a mesh is lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Shading {
    /// One normal per triangle: facets show.
    #[default]
    Flat,
    /// Vertex normals (area-weighted face normals) interpolated across faces.
    Smooth,
    /// The colours as given, no light (false-colour pictures, exact colour tests).
    Unlit,
}

/// The colours of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum Colours {
    Uniform(Rgba),
    /// One per vertex, interpolated across faces.
    PerVertex(Vec<Rgba>),
    /// One per face.
    PerFace(Vec<Rgba>),
}

/// One mesh of a scene.
#[derive(Clone, Debug)]
pub struct SceneMesh<'a> {
    pub mesh: Cow<'a, Mesh>,
    pub colours: Colours,
    pub shading: Shading,
    /// Draws every polygon edge (not the triangulation's diagonals) in this colour.
    pub wireframe: Option<Rgba>,
    /// Wireframe width in pixels.
    pub edge_width: f32,
}

impl<'a> SceneMesh<'a> {
    /// `mesh` in one colour, flat shaded, without wireframe.
    pub fn new(mesh: &'a Mesh, colour: Rgba) -> SceneMesh<'a> {
        SceneMesh::with(Cow::Borrowed(mesh), colour)
    }

    /// Like [`SceneMesh::new`], owning its mesh.
    pub fn owned(mesh: Mesh, colour: Rgba) -> SceneMesh<'static> {
        SceneMesh::with(Cow::Owned(mesh), colour)
    }

    fn with(mesh: Cow<'a, Mesh>, colour: Rgba) -> SceneMesh<'a> {
        SceneMesh {
            mesh,
            colours: Colours::Uniform(colour),
            shading: Shading::Flat,
            wireframe: None,
            edge_width: 1.0,
        }
    }

    /// A triangle soup (three corners per triangle) as a mesh of its own.
    pub fn triangles(triangles: &[[DVec3; 3]], colour: Rgba) -> Result<SceneMesh<'static>> {
        let positions = triangles.iter().flatten().copied().collect();
        let faces = (0..triangles.len() as u32).map(|t| vec![3 * t, 3 * t + 1, 3 * t + 2]).collect();
        Ok(SceneMesh::owned(Mesh::new(positions, faces)?, colour))
    }

    pub fn colours(mut self, colours: Colours) -> SceneMesh<'a> {
        self.colours = colours;
        self
    }

    /// Vertices coloured by valence (2010 thesis, Figs. 27–30).
    pub fn by_valence(self) -> SceneMesh<'a> {
        let c = colour::by_valence(&self.mesh);
        self.colours(Colours::PerVertex(c))
    }

    pub fn shading(mut self, shading: Shading) -> SceneMesh<'a> {
        self.shading = shading;
        self
    }

    pub fn wireframe(mut self, colour: Rgba) -> SceneMesh<'a> {
        self.wireframe = Some(colour);
        self
    }

    pub(crate) fn check(&self) -> Result<()> {
        let (what, have, want) = match &self.colours {
            Colours::Uniform(_) => return Ok(()),
            Colours::PerVertex(c) => ("vertices", c.len(), self.mesh.num_vertices()),
            Colours::PerFace(c) => ("faces", c.len(), self.mesh.num_faces()),
        };
        if have != want {
            return Err(RenderError::Usage(format!("{have} colours given for a mesh with {want} {what}")));
        }
        Ok(())
    }
}

/// A polyline (a cut curve, a crease, a slice outline).
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    pub points: Vec<DVec3>,
    pub colour: Rgba,
    /// Width in pixels.
    pub width: f32,
    /// Joins the last point to the first.
    pub closed: bool,
}

impl Polyline {
    pub fn new(points: Vec<DVec3>, colour: Rgba, width: f32) -> Polyline {
        Polyline { points, colour, width, closed: false }
    }
}

/// Points drawn as squares `size` pixels wide.
#[derive(Clone, Debug, PartialEq)]
pub struct Points {
    pub positions: Vec<DVec3>,
    pub colour: Rgba,
    pub size: f32,
}

/// Everything a picture shows.
#[derive(Clone, Debug, Default)]
pub struct Scene<'a> {
    pub meshes: Vec<SceneMesh<'a>>,
    pub lines: Vec<Polyline>,
    pub points: Vec<Points>,
}

impl<'a> Scene<'a> {
    pub fn new() -> Scene<'a> {
        Scene::default()
    }

    pub fn with_mesh(mut self, mesh: SceneMesh<'a>) -> Scene<'a> {
        self.meshes.push(mesh);
        self
    }

    pub fn with_line(mut self, line: Polyline) -> Scene<'a> {
        self.lines.push(line);
        self
    }

    pub fn with_points(mut self, points: Points) -> Scene<'a> {
        self.points.push(points);
        self
    }

    /// The bounding box of everything shown; `None` for an empty scene.
    pub fn bounds(&self) -> Option<(DVec3, DVec3)> {
        let meshes = self.meshes.iter().flat_map(|m| m.mesh.positions().iter());
        let lines = self.lines.iter().flat_map(|l| l.points.iter());
        let points = self.points.iter().flat_map(|p| p.positions.iter());
        meshes.chain(lines).chain(points).fold(None, |acc, &p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((p.min(lo), p.max(hi))),
        })
    }
}
