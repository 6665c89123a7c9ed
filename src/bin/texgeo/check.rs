//! `texgeo check`: every shader and pass on small built-in cases against the CPU
//! references, on the device at hand (see `texgeo::check`). Exits 1 when a check fails.

use std::path::PathBuf;

use texgeo::check::{self, Outcome, report::Summary};
use texgeo::gpu::{Context, ContextOptions, DeviceChoice, validation_layer_installed};

#[derive(clap::Args)]
pub struct Args {
    /// Also write the results as JUnit XML (one testcase per check) to this file.
    #[arg(long, value_name = "FILE")]
    junit: Option<PathBuf>,
    /// Run only these checks or groups (comma-separated), e.g. `xor,voxel-pgpu`.
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    only: Vec<String>,
}

/// The validation layer is on when it is installed; TEXGEO_VALIDATION=0 turns it off,
/// TEXGEO_VALIDATION=1 insists on it.
fn validation() -> bool {
    match std::env::var("TEXGEO_VALIDATION") {
        Ok(v) if v == "0" => false,
        Ok(v) if !v.is_empty() => true,
        _ => validation_layer_installed(),
    }
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    let only: Vec<String> =
        args.only.iter().map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
    let checks = check::select(&only).map_err(|e| anyhow::anyhow!("--only: {e}"))?;
    if let Some(path) = &args.junit {
        texgeo::output::check_output(path, &[])?;
    }
    let options =
        ContextOptions { device: DeviceChoice::from_env_or(device), validation: Some(validation()) };
    let ctx = Context::new(&options)?;
    let records: Vec<_> = checks.iter().map(|c| check::run(&ctx, c)).collect();
    let device = ctx.info().label();
    let summary = Summary { device: &device, validation: ctx.validating(), records: &records };
    say!("{}", summary.table());
    if let Some(path) = &args.junit {
        texgeo::output::write_bytes(path, summary.junit().as_bytes())?;
    }
    if records.iter().any(|r| matches!(r.outcome, Outcome::Fail(_))) {
        drop(ctx);
        std::process::exit(1);
    }
    Ok(())
}
