//! How texgeo shows a model by default, shared by `texgeo render` and the viewer: a
//! surface in one colour or coloured by valence, flat or smooth, with or without its
//! wireframe; a voxel volume as its boundary faces, grey or in Perlin aspect colours.

use super::colour::{self, Rgba};
use super::error::Result;
use super::scene::{Colours, SceneMesh, Shading};
use super::voxels;
use crate::mesh::Mesh;
use crate::voxel::{Grid, Volume};

/// Display options of a model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    /// Vertices coloured by valence (2010 thesis, Figs. 27–30) instead of `colour`.
    pub valence: bool,
    pub wireframe: bool,
    pub shading: Shading,
    pub colour: Rgba,
}

impl Default for Look {
    fn default() -> Look {
        Look { valence: false, wireframe: false, shading: Shading::Flat, colour: colour::SURFACE }
    }
}

impl Look {
    /// `mesh` as this look shows it.
    pub fn mesh<'a>(&self, mesh: &'a Mesh) -> SceneMesh<'a> {
        self.dress(SceneMesh::new(mesh, self.colour))
    }

    /// A voxel volume's boundary faces, coloured by its aspect slices (as
    /// `voxel::aspect::render` makes them) when given. Valence colours do not apply.
    pub fn voxels(
        &self,
        grid: &Grid,
        volume: &Volume,
        aspect: Option<&[Vec<u8>]>,
    ) -> Result<SceneMesh<'static>> {
        let (mesh, colours) = match aspect {
            Some(slices) => {
                voxels::surface(grid, volume, voxels::aspect_colour(slices, volume.n(), self.colour))?
            }
            None => voxels::surface(grid, volume, |_, _, _| self.colour)?,
        };
        let look = Look { valence: false, ..*self };
        Ok(look.dress(SceneMesh::owned(mesh, self.colour).colours(Colours::PerFace(colours))))
    }

    fn dress<'a>(&self, mut item: SceneMesh<'a>) -> SceneMesh<'a> {
        if self.valence {
            item = item.by_valence();
        }
        if self.wireframe {
            item = item.wireframe(colour::EDGE);
        }
        item.shading(self.shading)
    }
}
