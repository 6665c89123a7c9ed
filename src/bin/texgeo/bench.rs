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
    }
}
