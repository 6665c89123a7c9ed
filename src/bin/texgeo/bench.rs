//! `texgeo bench …`: each suite writes Markdown + CSV into `--out` and prints the Markdown.

use std::path::PathBuf;

use texgeo::report::{Report, bench};

#[derive(clap::Subcommand)]
pub enum Command {
    /// 2×2 ping-pong sum reduction (512², 2048², 4096²) against a plain CPU sum.
    Reduce {
        /// Texture sides to measure.
        #[arg(long, value_delimiter = ',', default_values_t = bench::reduce::DEFAULT_SIDES.to_vec())]
        sizes: Vec<u32>,
        #[command(flatten)]
        common: Common,
    },
    /// The 2010 thesis' Table 5: Catmull-Clark to level 5 with fragment meshes on the GPU
    /// vs the CPU reference and OpenSubdiv, on built-in models and fetched ones.
    Subdivide {
        /// Subdivision level.
        #[arg(long, short, default_value_t = 5)]
        level: u32,
        /// Extra mesh files (or `builtin:NAME`) to measure after the default models.
        #[arg(long = "mesh", value_name = "MESH")]
        meshes: Vec<String>,
        /// Folder of fetched models (tools/fetch-models); those of the default set found
        /// there are measured.
        #[arg(long, default_value = "models")]
        models: PathBuf,
        /// Measure only the given --mesh files.
        #[arg(long)]
        only: bool,
        /// Also compare every GPU result with OpenSubdiv (slow on millions of faces).
        #[arg(long)]
        validate: bool,
        #[command(flatten)]
        common: Common,
    },
}

#[derive(clap::Args)]
pub struct Common {
    /// Timed runs per measurement (the median is reported).
    #[arg(long, default_value_t = 5)]
    runs: usize,
    /// Folder for the Markdown and CSV files.
    #[arg(long, short, default_value = "out/bench")]
    out: PathBuf,
}

fn finish(report: Report, common: &Common) -> anyhow::Result<()> {
    println!("{}", report.to_markdown());
    for f in report.write(&common.out)? {
        eprintln!("wrote {}", f.display());
    }
    Ok(())
}

pub fn run(device: Option<&str>, cmd: Command) -> anyhow::Result<()> {
    let ctx = crate::open_context(device)?;
    match cmd {
        Command::Reduce { sizes, common } => {
            if let Some(bad) = sizes.iter().find(|&&s| s == 0 || s > ctx.info().max_image_2d) {
                anyhow::bail!("size {bad} is outside 1..={}", ctx.info().max_image_2d);
            }
            finish(bench::reduce::run(&ctx, &sizes, common.runs)?, &common)
        }
        Command::Subdivide { level, meshes, models, only, validate, common } => {
            use bench::subdiv::{Model, Settings, default_models};
            let mut list = if only { Vec::new() } else { default_models(&models)? };
            for m in &meshes {
                list.push(Model { name: m.clone(), mesh: crate::mesh::load(m)? });
            }
            anyhow::ensure!(!list.is_empty(), "no models to measure");
            let settings = Settings { level, runs: common.runs, validate };
            finish(bench::subdiv::run(&ctx, &list, settings)?, &common)
        }
    }
}
