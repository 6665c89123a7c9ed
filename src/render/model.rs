//! What a picture or the viewer shows, and its state: the current subdivision level
//! (refined on the GPU, live in the viewer), the look, the aspect colours, and the scene
//! made from them. `texgeo render` and `texgeo view` build their scenes here, so a
//! window's screenshot and an offscreen picture of the same model are the same picture.

use std::time::Instant;

use crate::gpu::Context;
use crate::mesh::Mesh;
use glam::DVec3;

use crate::render::{Look, Polyline, Rgba, Scene, Shading, colour};
use crate::subdiv::Surface;
use crate::subdiv::cpu::SharpEdge;
use crate::subdiv::gpu::{Options, Subdivider};
use crate::voxel::aspect::{self, Aspect};
use crate::voxel::{self, Grid, Volume};

use super::error::{RenderError, Result};

/// What to show.
pub enum Content {
    /// A polygon mesh, refined live to the current level (GPU fragment passes).
    Mesh(Mesh),
    /// A voxel volume on its grid (a .binvox file or a voxelized mesh).
    Voxels(Grid, Volume),
    /// A mesh voxelized at `res` voxels per side on the viewer's device.
    Voxelize(Mesh, usize),
    /// A mesh with sharp features (OpenSubdiv's OBJ tags: creases, corners, holes),
    /// refined live with them; its crease edges are drawn over the surface, coloured by
    /// sharpness ([`super::colour::crease_colour`]).
    Surface(Surface),
    /// Several meshes in their colours, and polylines (e.g. the operands and result of a
    /// Boolean with its cut curve).
    Meshes(Vec<(Mesh, Rgba)>, Vec<Polyline>),
}

/// Width of crease edges, in pixels.
const CREASE_WIDTH: f32 = 2.5;

/// The sharp edges of a control mesh (its tagged creases), as a refinement reports them.
fn control_creases(surface: &Surface) -> Vec<SharpEdge> {
    surface
        .features
        .creases
        .iter()
        .filter(|c| c.sharpness > 0.0)
        .map(|c| SharpEdge {
            vertices: c.vertices,
            sharpness: c.sharpness,
            boundary: false,
            non_manifold: false,
        })
        .collect()
}

/// Most faces a live level may have (beyond this, memory and frame time explode).
const MAX_LEVEL_FACES: usize = 8 << 20;

/// A model being shown (see the module docs).
pub struct Model {
    content: Content,
    pub level: u32,
    /// The mesh at `level` (a single mesh only) and its crease edges.
    refined: Option<Mesh>,
    creases: Vec<SharpEdge>,
    subdivider: Option<Subdivider>,
    pub look: Look,
    aspect: Option<Aspect>,
    /// Aspect colours of the volume, computed when first shown.
    slices: Option<Vec<Vec<u8>>>,
    pub show_aspect: bool,
}

impl Model {
    pub fn new(
        ctx: &Context,
        content: Content,
        level: u32,
        look: Look,
        aspect: Option<Aspect>,
    ) -> Result<Model> {
        let content = match content {
            Content::Voxelize(mesh, res) => {
                let v = voxel::voxelize(Some(ctx), &mesh, res, voxel::Method::Zoned)?;
                Content::Voxels(v.grid, v.volume)
            }
            // One path for single meshes: a mesh is a surface without sharp features.
            Content::Mesh(mesh) => Content::Surface(Surface::from(mesh)),
            c => c,
        };
        if level > 0 && !matches!(content, Content::Surface(_)) {
            return Err(RenderError::Usage("subdivision levels apply to a single mesh".into()));
        }
        let subdivider = match content {
            Content::Surface(_) => Some(Subdivider::new(ctx)?),
            _ => None,
        };
        let show_aspect = aspect.is_some();
        let creases = match &content {
            Content::Surface(surface) => control_creases(surface),
            _ => Vec::new(),
        };
        let mut model = Model {
            content,
            level: 0,
            refined: None,
            creases,
            subdivider,
            look,
            aspect,
            slices: None,
            show_aspect,
        };
        if level > 0 {
            model.set_level(ctx, level)?;
        }
        Ok(model)
    }

    /// Whether `+`/`-` change anything.
    pub fn has_levels(&self) -> bool {
        matches!(self.content, Content::Surface(_))
    }

    pub fn is_voxels(&self) -> bool {
        matches!(self.content, Content::Voxels(..))
    }

    /// Refines the base mesh to `level` on the GPU; returns a line for the console.
    pub fn set_level(&mut self, ctx: &Context, level: u32) -> Result<String> {
        let (Content::Surface(surface), Some(subdivider)) = (&self.content, self.subdivider.as_mut()) else {
            return Err(RenderError::Usage("only a single mesh has subdivision levels".into()));
        };
        let base = &surface.mesh;
        if level == 0 {
            self.refined = None;
            self.creases = control_creases(surface);
            self.level = 0;
            return Ok(format!("level 0: {} vertices, {} faces", base.num_vertices(), base.num_faces()));
        }
        // Every face becomes one quad per corner at level 1, four quads per level after.
        let corners = base.face_parts().1.len();
        let faces = 4usize.checked_pow(level - 1).and_then(|f| f.checked_mul(corners));
        if faces.is_none_or(|f| f > MAX_LEVEL_FACES) {
            return Err(RenderError::Usage(format!(
                "level {level} would have over {MAX_LEVEL_FACES} faces; the viewer stops here \
                 (`texgeo subdivide` writes bigger levels)"
            )));
        }
        let start = Instant::now();
        let run = subdivider.refine_surface(ctx, surface, level, &Options::default())?;
        let line = format!(
            "level {level}: {} vertices, {} faces ({} fragment pass(es) on the GPU, {:.1} ms)",
            run.mesh.num_vertices(),
            run.mesh.num_faces(),
            run.gpu_levels,
            start.elapsed().as_secs_f64() * 1e3
        );
        self.refined = Some(run.mesh);
        self.creases = run.sharp_edges;
        self.level = level;
        Ok(line)
    }

    /// The mesh on screen (a single mesh only).
    pub fn shown_mesh(&self) -> Option<&Mesh> {
        match &self.content {
            Content::Surface(base) => Some(self.refined.as_ref().unwrap_or(&base.mesh)),
            _ => None,
        }
    }

    /// The crease edges on screen (interior sharp edges; boundaries are drawn by the
    /// surface's own outline), as segments with their control sharpness.
    pub fn creases(&self) -> impl Iterator<Item = ([DVec3; 2], f32)> + '_ {
        let mesh = self.shown_mesh();
        self.creases.iter().filter(|e| !e.boundary).filter_map(move |e| {
            let p = mesh?.positions();
            Some((e.vertices.map(|v| p[v as usize]), e.sharpness))
        })
    }

    /// Vertices and faces on screen.
    pub fn counts(&self) -> (usize, usize) {
        match &self.content {
            Content::Mesh(_) | Content::Surface(_) => {
                self.shown_mesh().map_or((0, 0), |m| (m.num_vertices(), m.num_faces()))
            }
            Content::Meshes(meshes, _) => {
                meshes.iter().fold((0, 0), |(v, f), (m, _)| (v + m.num_vertices(), f + m.num_faces()))
            }
            Content::Voxels(_, volume) => (0, volume.count() as usize),
            Content::Voxelize(..) => (0, 0),
        }
    }

    pub fn toggle_shading(&mut self) {
        self.look.shading = match self.look.shading {
            Shading::Flat => Shading::Smooth,
            _ => Shading::Flat,
        };
    }

    /// The scene of the current state.
    pub fn scene(&mut self, ctx: &Context) -> Result<Scene<'_>> {
        if self.show_aspect
            && self.slices.is_none()
            && let Content::Voxels(_, volume) = &self.content
        {
            let params = self.aspect.unwrap_or_default();
            self.slices = Some(aspect::render(ctx, volume, &params)?);
        }
        let look = self.look;
        Ok(match &self.content {
            Content::Mesh(base) => Scene::new().with_mesh(look.mesh(base)),
            Content::Surface(base) => {
                let mut scene =
                    Scene::new().with_mesh(look.mesh(self.refined.as_ref().unwrap_or(&base.mesh)));
                scene.lines.extend(self.creases().map(|([p, q], sharpness)| {
                    Polyline::new(vec![p, q], colour::crease_colour(sharpness), CREASE_WIDTH)
                }));
                scene
            }
            Content::Voxels(grid, volume) => {
                let slices = if self.show_aspect { self.slices.as_deref() } else { None };
                Scene::new().with_mesh(look.voxels(grid, volume, slices)?)
            }
            Content::Meshes(meshes, lines) => {
                let mut scene = Scene::new();
                for (mesh, colour) in meshes {
                    scene = scene.with_mesh(Look { colour: *colour, ..look }.mesh(mesh));
                }
                scene.lines.extend(lines.iter().cloned());
                scene
            }
            Content::Voxelize(..) => Scene::new(),
        })
    }
}
