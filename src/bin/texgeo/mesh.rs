//! `texgeo mesh stats|convert|builtins`, and how every command reads its mesh.

use std::path::{Path, PathBuf};

use texgeo::mesh::covering::Covering;
use texgeo::mesh::frame::Frame;
use texgeo::mesh::solidity::{self, Accepted, Defect, Policy};
use texgeo::mesh::spec::MeshSpec;
use texgeo::mesh::stats::Stats;
use texgeo::mesh::{Mesh, formats, procedural};
use texgeo::subdiv::tags::{self, Tagged};

#[derive(clap::Subcommand)]
pub enum Command {
    /// Vertices, faces, face degrees, edges, closed/oriented/manifold, Euler characteristic,
    /// shells and whether it is a solid (and why not), area, volume, centroids.
    Stats {
        /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
        mesh: MeshArg,
        /// Print one JSON object instead (the same keys as Python's `Mesh.stats()`).
        #[arg(long)]
        json: bool,
    },
    /// Convert between formats (chosen by extension); polygons are triangulated for STL.
    Convert {
        /// A mesh file (.obj .off .ply .stl) or `builtin:NAME` (see `texgeo mesh builtins`).
        input: MeshArg,
        /// The output file (.obj .off .ply .stl), written atomically.
        #[arg(short = 'o', long, value_name = "OUTPUT", required_unless_present = "output_positional")]
        output: Option<PathBuf>,
        /// The output file given without -o (the older spelling, still accepted).
        #[arg(value_name = "OUTPUT", conflicts_with = "output", hide = true)]
        output_positional: Option<PathBuf>,
    },
    /// List the built-in procedural models (use them as `builtin:NAME`).
    Builtins,
}

/// A mesh on the command line: a file path or `builtin:NAME` ([`texgeo::mesh::spec`]).
pub type MeshArg = MeshSpec;

/// Reads a mesh file, or a built-in model given as `builtin:NAME`.
pub fn load(spec: &MeshArg) -> anyhow::Result<Mesh> {
    Ok(spec.load()?)
}

/// Reads a mesh with its sharp-feature tags (OpenSubdiv's `t crease`, … in an OBJ file;
/// other formats and built-in models have none).
pub fn load_tagged(spec: &MeshArg) -> anyhow::Result<Tagged> {
    let (mesh, t) = spec.load_with_tags()?;
    // Built-in models have no tags, hence no file to name.
    Ok(tags::interpret(mesh, &t, spec.file().unwrap_or(Path::new("")))?)
}

/// Reads a mesh and lets it through only if it is a solid ([`solidity::require_solid`]),
/// or what `policy` accepts; the error names the reason and, among `flags` (the command's
/// own), the one that would accept it.
pub fn load_solid(spec: &MeshArg, policy: Policy, flags: &[&str]) -> anyhow::Result<Accepted> {
    let mesh = load(spec)?;
    solidity::require_solid(mesh, policy).map_err(|e| {
        let hint = match e.defect.remedy().filter(|f| flags.contains(f)) {
            Some(f @ "--flip-inverted") if flags.contains(&"--allow-open") => {
                format!(" ({f} reverses every face; --allow-open takes any mesh by its winding number)")
            }
            Some(f @ "--flip-inverted") => format!(" ({f} reverses every face)"),
            _ if flags.contains(&"--allow-open") && !matches!(e.defect, Defect::Overflow { .. }) => {
                " (--allow-open classifies it by the generalized winding number: inside iff w ≥ ½)"
                    .to_string()
            }
            _ => String::new(),
        };
        anyhow::anyhow!("{spec}: {e}{hint}")
    })
}

/// The one warning on stderr for a mesh accepted under `--allow-open` although it is not
/// a solid: its defect and the rule its points follow.
pub fn warn_non_solid(spec: &MeshArg, defect: &Defect) {
    let inverted = if matches!(defect, Defect::Inverted { .. } | Defect::InvertedShell { .. }) {
        "; the winding number is −1 inside an inverted shell, so none of it is inside \
         (--flip-inverted reverses the faces of an inverted solid)"
    } else {
        ""
    };
    note!(
        "texgeo: warning: {spec} is not a solid: {defect}; with --allow-open a point is inside iff the \
         generalized winding number of its faces is at least ½{inverted}"
    );
}

/// What `--allow-open` does with a mesh that is not a solid, for `mesh stats`.
fn allow_open_line(m: &Mesh, defect: &Defect) -> String {
    let what = match defect {
        Defect::Open(_) => {
            let (edges, loops) = solidity::boundary_loops(m);
            let s = |n: usize| if n == 1 { "" } else { "s" };
            format!("open: {edges} boundary edge{} in {loops} loop{}", s(edges), s(loops))
        }
        d => d.slug().replace('-', " "),
    };
    format!("{what}; {}", solidity::allow_open_note(defect))
}

pub fn run(cmd: Command) -> anyhow::Result<()> {
    match cmd {
        Command::Stats { mesh, json } => {
            let m = load(&mesh)?;
            let report = m.report();
            let solidity = solidity::check(&m);
            if !json {
                say!("{mesh}");
                say!("{report}");
                say!("{solidity}");
                if let Some(d) = solidity.defects.first() {
                    say!("with --allow-open       {}", allow_open_line(&m, d));
                }
            }
            if let Some(Defect::Overflow { .. }) = solidity.defects.first() {
                anyhow::bail!("{mesh}: cannot measure it: {}", solidity.defects[0]);
            }
            let stats = Stats::new(&m, report, &solidity);
            if json {
                texgeo::json::print(&stats);
            } else {
                print_measures(&m, &stats);
            }
            Ok(())
        }
        Command::Convert { input, output, output_positional } => {
            let Some(output) = output.or(output_positional) else {
                anyhow::bail!("mesh convert: name the output file with -o OUTPUT")
            };
            formats::Format::from_path(&output)?;
            texgeo::output::check_output(&output, &MeshArg::files([&input]))?;
            let m = load(&input)?;
            formats::write(&output, &m)?;
            say!("{input} -> {}: {} vertices, {} faces", output.display(), m.num_vertices(), m.num_faces());
            Ok(())
        }
        Command::Builtins => {
            for name in procedural::BUILTIN_NAMES {
                if let Some(m) = procedural::by_name(name) {
                    say!("builtin:{name:<12} {:>6} vertices {:>6} faces", m.num_vertices(), m.num_faces());
                }
            }
            Ok(())
        }
    }
}

/// Volume, area and centroids from the simplicial covering (SPEC §2).
fn print_measures(m: &Mesh, stats: &Stats) {
    let v3 = |a: [f64; 3]| glam::DVec3::from_array(a);
    say!("bounding box           {} .. {}", v3(stats.bbox[0]), v3(stats.bbox[1]));
    say!("area                   {}", stats.area);
    match stats.volume {
        Some(v) => {
            say!("volume                 {v} (signed tetrahedra, Alg. 3-1)");
            if let Some(g) = stats.centroid {
                say!("centroid               {} (volume)", v3(g));
            }
        }
        None => {
            let frame = Frame::of(&[m]);
            let c = Covering::new(&frame.mesh_in_ref(m));
            let why = c.unbalanced_edge().map(|e| e.to_string()).unwrap_or_default();
            say!(
                "volume                 undefined: the surface is not closed and consistently oriented ({why})"
            )
        }
    }
    if let Some(g) = stats.face_centroid {
        say!("centroid               {} (face vertices, thesis §3.6.1)", v3(g));
    }
}
