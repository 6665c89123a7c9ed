//! `texgeo render MODEL -o OUT.png`: an offscreen picture of a mesh (optionally
//! subdivided, coloured by valence, with its wireframe) or of a voxel volume, from an
//! orbit camera. The viewer (`texgeo view`) shows the same pictures in a window.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use texgeo::boolean::Operation;
use texgeo::render::{Camera, Content, Look, Model, Renderer, Scene, Shading, View, colour};
use texgeo::voxel::aspect::{Aspect, Material};
use texgeo::voxel::binvox;

use crate::mesh::MeshArg;

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
    pub input: MeshArg,
    /// More meshes shown with the first, each in its own colour (no subdivision levels).
    pub others: Vec<MeshArg>,
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
    /// Show a Boolean operation of the input (A) and this solid (B), with --op: the two
    /// operands with their cut curve and, beside them, the result coloured by operand
    /// (2006 thesis, Figs. 6-9 … 6-12).
    #[arg(long, value_name = "B", requires = "op")]
    pub boolean: Option<MeshArg>,
    /// The operation for --boolean: union, intersection, difference, symmetric-difference.
    #[arg(long, requires = "boolean", value_parser = parse_operation)]
    pub op: Option<Operation>,
}

fn parse_operation(s: &str) -> Result<Operation, String> {
    s.parse()
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
        self.input.file().is_some_and(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("binvox")))
    }

    /// Checks option combinations before anything is loaded.
    pub fn check(&self) -> anyhow::Result<()> {
        if !(-89.0..=89.0).contains(&self.pitch) || !self.yaw.is_finite() {
            bail!("--pitch must be within -89..=89 degrees and --yaw finite");
        }
        let voxels = self.voxels || self.is_binvox();
        if !self.others.is_empty() && (voxels || self.level > 0) {
            bail!("several models are shown as meshes, without --voxels or --level");
        }
        if voxels && self.level > 0 {
            bail!("--level applies to meshes, not to voxel volumes");
        }
        if voxels && self.valence {
            bail!("--valence applies to meshes, not to voxel volumes");
        }
        if self.aspect.is_some() && !voxels {
            bail!("--aspect colours voxels: add --voxels or give a .binvox file");
        }
        if self.boolean.is_some() && (voxels || self.level > 0 || !self.others.is_empty()) {
            bail!("--boolean shows two solids as meshes: no other models, --voxels or --level");
        }
        Ok(())
    }

    /// What to show: a .binvox volume, a mesh (voxelized with --voxels), or several meshes.
    pub fn content(&self) -> anyhow::Result<Content> {
        if let (true, Some(path)) = (self.is_binvox(), self.input.file()) {
            let (grid, volume) = binvox::read(path)?;
            return Ok(Content::Voxels(grid, volume));
        }
        if !self.voxels && self.boolean.is_none() && self.others.is_empty() {
            // One mesh, with the sharp features of its OBJ tags (drawn as crease edges).
            let tagged = crate::mesh::load_tagged(&self.input)?;
            return Ok(Content::Surface(tagged.surface(Default::default())));
        }
        let mesh = crate::mesh::load(&self.input)?;
        if let (Some(b), Some(op)) = (&self.boolean, self.op) {
            let other = crate::mesh::load(b)?;
            let (a, b) = (self.input.to_string(), b.to_string());
            let names = texgeo::boolean::Names { a: &a, b: &b };
            let ev = texgeo::boolean::evaluate(&mesh, &other, names, &Default::default(), None)?;
            return Ok(texgeo::render::boolean::content(&ev, op, true)?);
        }
        if self.voxels {
            return Ok(Content::Voxelize(mesh, self.res));
        }
        let mut meshes = vec![(mesh, PALETTE[0])];
        for (i, other) in self.others.iter().enumerate() {
            meshes.push((crate::mesh::load(other)?, PALETTE[(i + 1) % PALETTE.len()]));
        }
        Ok(Content::Meshes(meshes, Vec::new()))
    }

    /// The Perlin aspect parameters, when asked for.
    pub fn aspect(&self) -> Option<Aspect> {
        self.aspect.as_ref().map(|_| Aspect { material: self.material, ..Aspect::default() })
    }

    /// The files read (for "never overwrite an input").
    pub fn inputs(&self) -> Vec<&std::path::Path> {
        MeshArg::files(std::iter::once(&self.input).chain(&self.others).chain(&self.boolean))
    }

    /// All inputs, for titles and messages.
    pub fn name(&self) -> String {
        if let (Some(b), Some(op)) = (&self.boolean, self.op) {
            return format!("{} {} {b}", self.input, op.symbol());
        }
        std::iter::once(&self.input)
            .chain(&self.others)
            .map(MeshArg::to_string)
            .collect::<Vec<_>>()
            .join(" + ")
    }

    pub fn camera(&self, scene: &Scene) -> anyhow::Result<Camera> {
        let (lo, hi) = scene.bounds().context("nothing to show: the model is empty")?;
        let aspect = f64::from(self.size[0]) / f64::from(self.size[1]);
        Ok(Camera::fit(lo, hi, self.yaw.to_radians(), self.pitch.to_radians(), aspect))
    }
}

/// Colours of several meshes shown together.
const PALETTE: [colour::Rgba; 4] = [colour::FIRST, colour::SECOND, colour::SURFACE, [120, 200, 120, 255]];

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let show = &args.show;
    show.check()?;
    texgeo::output::check_extension(&args.output, &["png"], "the picture is written as PNG")?;
    texgeo::output::check_output(&args.output, &show.inputs())?;
    let content = show.content()?;
    let ctx = crate::open_context(device)?;
    let mut model = Model::new(&ctx, content, show.level, show.look(), show.aspect())?;
    let (vertices, faces) = model.counts();
    if model.is_voxels() {
        say!("{}: {faces} voxels", show.name());
    } else {
        say!("{}: level {}, {vertices} vertices, {faces} faces", show.name(), model.level);
    }
    let scene = model.scene(&ctx)?;
    let mut renderer = Renderer::new(&ctx, show.samples)?;
    let prepared = renderer.prepare(&scene)?;
    if prepared.triangles() + prepared.segments() == 0 {
        bail!("nothing to show: the model has no faces");
    }
    let view = View {
        camera: show.camera(&scene)?,
        width: show.size[0],
        height: show.size[1],
        background: colour::BACKGROUND,
    };
    let picture = renderer.render(&prepared, &view)?;
    picture.save_png(&args.output)?;
    say!(
        "wrote {} ({}×{}, {} triangles)",
        args.output.display(),
        view.width,
        view.height,
        prepared.triangles()
    );
    Ok(())
}
