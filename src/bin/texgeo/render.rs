//! `texgeo render MODEL -o OUT.png`: an offscreen picture of a mesh (optionally
//! subdivided, coloured by valence, with its wireframe) or of a voxel volume, from an
//! orbit camera. The viewer (`texgeo view`) shows the same pictures in a window.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use texgeo::gpu::Context;
use texgeo::mesh::Mesh;
use texgeo::render::{Camera, Look, Renderer, Scene, Shading, View, colour};
use texgeo::subdiv::gpu::{Options, Subdivider};
use texgeo::voxel::aspect::{self, Aspect, Material};
use texgeo::voxel::{self, Grid, Volume, binvox};

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShadingArg {
    Flat,
    Smooth,
    Unlit,
}

impl From<ShadingArg> for Shading {
    fn from(s: ShadingArg) -> Shading {
        match s {
            ShadingArg::Flat => Shading::Flat,
            ShadingArg::Smooth => Shading::Smooth,
            ShadingArg::Unlit => Shading::Unlit,
        }
    }
}

/// What to show and how: shared by `render` and `view`.
#[derive(clap::Args, Clone, Debug)]
pub struct Show {
    /// A mesh (.obj .off .ply .stl, or `builtin:NAME`) or a voxel volume (.binvox).
    pub input: String,
    /// Catmull-Clark level (GPU fragment passes, as `texgeo subdivide`).
    #[arg(short, long, default_value_t = 0)]
    pub level: u32,
    /// Colour vertices by valence (2010 thesis, Figs. 27–30).
    #[arg(long)]
    pub valence: bool,
    /// Draw the polygon edges.
    #[arg(long)]
    pub wireframe: bool,
    #[arg(long, value_enum, default_value_t = ShadingArg::Flat)]
    pub shading: ShadingArg,
    /// Show the mesh as a voxel volume (voxelized at --res).
    #[arg(long)]
    pub voxels: bool,
    /// Voxels per side for --voxels.
    #[arg(long, default_value_t = 64)]
    pub res: usize,
    /// Colour voxels with the Perlin aspect function (Fig. 5-9).
    #[arg(long, value_parser = ["perlin"])]
    pub aspect: Option<String>,
    /// Perlin material: marble | wood | granite.
    #[arg(long, default_value = "marble", value_parser = parse_material)]
    pub material: Material,
    /// Camera turn about the vertical axis, degrees (0 looks along −z).
    #[arg(long, default_value_t = 35.0, allow_negative_numbers = true)]
    pub yaw: f64,
    /// Camera height above the horizon, degrees (−89..=89).
    #[arg(long, default_value_t = 25.0, allow_negative_numbers = true)]
    pub pitch: f64,
    /// Picture size, WIDTHxHEIGHT pixels.
    #[arg(long, default_value = "800x600", value_parser = parse_size)]
    pub size: [u32; 2],
    /// Samples per pixel (1 = no antialiasing).
    #[arg(long, default_value_t = 4)]
    pub samples: u32,
}

fn parse_material(s: &str) -> Result<Material, String> {
    Material::parse(s).ok_or_else(|| format!("unknown material '{s}' (expected marble, wood or granite)"))
}

fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let parsed =
        s.split_once(['x', 'X']).and_then(|(w, h)| Some([w.trim().parse().ok()?, h.trim().parse().ok()?]));
    match parsed {
        Some([w, h]) if w > 0 && h > 0 => Ok([w, h]),
        _ => Err(format!("'{s}' is not a size like 800x600")),
    }
}

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub show: Show,
    /// Output picture (.png).
    #[arg(short, long)]
    pub output: PathBuf,
}

/// A model as loaded: a polygon mesh, or a voxel volume with its grid.
pub enum Model {
    Mesh(Mesh),
    Voxels(Grid, Volume),
}

impl Show {
    pub fn look(&self) -> Look {
        Look {
            valence: self.valence,
            wireframe: self.wireframe,
            shading: self.shading.into(),
            ..Look::default()
        }
    }

    pub fn is_binvox(&self) -> bool {
        self.input.to_ascii_lowercase().ends_with(".binvox")
    }

    /// Checks option combinations before anything is loaded.
    pub fn check(&self) -> anyhow::Result<()> {
        if !(-89.0..=89.0).contains(&self.pitch) || !self.yaw.is_finite() {
            bail!("--pitch must be within -89..=89 degrees and --yaw finite");
        }
        let voxels = self.voxels || self.is_binvox();
        if voxels && self.level > 0 {
            bail!("--level applies to meshes, not to voxel volumes");
        }
        if voxels && self.valence {
            bail!("--valence applies to meshes, not to voxel volumes");
        }
        if self.aspect.is_some() && !voxels {
            bail!("--aspect colours voxels: add --voxels or give a .binvox file");
        }
        Ok(())
    }

    /// Reads the input: a .binvox volume, a mesh, or a mesh voxelized at `--res`.
    pub fn load(&self, ctx: &Context) -> anyhow::Result<Model> {
        if self.is_binvox() {
            let (grid, volume) = binvox::read(&self.input)?;
            return Ok(Model::Voxels(grid, volume));
        }
        let mesh = crate::mesh::load(&self.input)?;
        if self.voxels {
            let v = voxel::voxelize(Some(ctx), &mesh, self.res, voxel::Method::Zoned)
                .with_context(|| format!("voxelizing {}", self.input))?;
            return Ok(Model::Voxels(v.grid, v.volume));
        }
        Ok(Model::Mesh(mesh))
    }

    /// The Perlin aspect slices of a volume, when asked for.
    pub fn aspect_slices(&self, ctx: &Context, volume: &Volume) -> anyhow::Result<Option<Vec<Vec<u8>>>> {
        if self.aspect.is_none() {
            return Ok(None);
        }
        let params = Aspect { material: self.material, ..Aspect::default() };
        Ok(Some(aspect::render(ctx, volume, &params)?))
    }

    pub fn camera(&self, scene: &Scene) -> anyhow::Result<Camera> {
        let (lo, hi) = scene.bounds().context("nothing to show: the model is empty")?;
        let aspect = f64::from(self.size[0]) / f64::from(self.size[1]);
        Ok(Camera::fit(lo, hi, self.yaw.to_radians(), self.pitch.to_radians(), aspect))
    }
}

/// Refines `mesh` to `level` with the GPU fragment passes (the same path as `subdivide`).
pub fn refine(ctx: &Context, subdivider: &mut Subdivider, mesh: &Mesh, level: u32) -> anyhow::Result<Mesh> {
    if level == 0 {
        return Ok(mesh.clone());
    }
    let run = subdivider
        .refine(ctx, mesh, level, &Options::default())
        .with_context(|| format!("cannot subdivide to level {level}"))?;
    Ok(run.mesh)
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let show = &args.show;
    show.check()?;
    if !args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        bail!("{}: the picture is written as PNG; name it .png", args.output.display());
    }
    let ctx = crate::open_context(device)?;
    let model = show.load(&ctx)?;
    let look = show.look();
    let (shown, item);
    let scene = match &model {
        Model::Mesh(mesh) => {
            shown = refine(&ctx, &mut Subdivider::new(&ctx)?, mesh, show.level)?;
            println!(
                "{}: level {}, {} vertices, {} faces",
                show.input,
                show.level,
                shown.num_vertices(),
                shown.num_faces()
            );
            Scene::new().with_mesh(look.mesh(&shown))
        }
        Model::Voxels(grid, volume) => {
            let slices = show.aspect_slices(&ctx, volume)?;
            item = look.voxels(grid, volume, slices.as_deref())?;
            println!(
                "{}: {}³ voxels, {} occupied, {} boundary faces",
                show.input,
                volume.n(),
                volume.count(),
                item.mesh.num_faces()
            );
            Scene::new().with_mesh(item)
        }
    };
    let mut renderer = Renderer::new(&ctx, show.samples)?;
    let prepared = renderer.prepare(&scene)?;
    let view = View {
        camera: show.camera(&scene)?,
        width: show.size[0],
        height: show.size[1],
        background: colour::BACKGROUND,
    };
    let picture = renderer.render(&prepared, &view)?;
    picture.save_png(&args.output)?;
    println!(
        "wrote {} ({}×{}, {} triangles)",
        args.output.display(),
        view.width,
        view.height,
        prepared.triangles()
    );
    Ok(())
}
