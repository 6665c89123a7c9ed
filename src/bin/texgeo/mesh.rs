//! `texgeo mesh stats|convert|builtins`.

use std::path::PathBuf;

use anyhow::Context as _;
use texgeo::mesh::covering::Covering;
use texgeo::mesh::{Mesh, formats, procedural};

#[derive(clap::Subcommand)]
pub enum Command {
    /// Vertices, faces, face degrees, closed/manifold/oriented, volume, area, centroid.
    Stats {
        /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
        mesh: String,
    },
    /// Convert between formats (chosen by extension).
    Convert {
        /// A mesh file or `builtin:NAME`.
        input: String,
        output: PathBuf,
    },
    /// List the built-in procedural models (use them as `builtin:NAME`).
    Builtins,
}

/// Reads a mesh file, or a built-in model given as `builtin:NAME`.
pub fn load(spec: &str) -> anyhow::Result<Mesh> {
    if let Some(name) = spec.strip_prefix("builtin:") {
        return procedural::by_name(name).with_context(|| {
            format!("no built-in model '{name}' (built-ins: {})", procedural::BUILTIN_NAMES.join(", "))
        });
    }
    Ok(formats::read(spec)?)
}

pub fn run(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Stats { mesh } => {
            let m = load(&mesh)?;
            println!("{mesh}");
            println!("{}", m.report());
            print_measures(&m);
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
        Command::Builtins => {
            for name in procedural::BUILTIN_NAMES {
                if let Some(m) = procedural::by_name(name) {
                    println!(
                        "builtin:{name:<12} {:>6} vertices {:>6} faces",
                        m.num_vertices(),
                        m.num_faces()
                    );
                }
            }
            Ok(())
        }
    }
}

/// Volume, area and centroids from the simplicial covering (SPEC §2).
fn print_measures(m: &Mesh) {
    let c = Covering::new(m);
    let (lo, hi) = m.bounds();
    println!("bounding box           {lo} .. {hi}");
    println!("area                   {}", c.area());
    match c.unbalanced_edge() {
        None => {
            println!("volume                 {} (signed tetrahedra, Alg. 3-1)", c.volume());
            if let Some(g) = c.centroid() {
                println!("centroid               {g} (volume)");
            }
        }
        Some(e) => println!(
            "volume                 undefined: the surface is not closed and consistently oriented \
             (edge {}-{} used {}x forward, {}x backward)",
            e.a, e.b, e.forward, e.backward
        ),
    }
    if let Some(g) = c.face_weighted_centroid() {
        println!("centroid               {g} (face vertices, thesis §3.6.1)");
    }
}
