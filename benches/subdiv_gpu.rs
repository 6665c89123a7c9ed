//! `cargo bench --bench subdiv_gpu`: the same suite as `texgeo bench subdivide` (built-in
//! models, and `models/knot1.off` when `tools/fetch-models` has fetched it).

use texgeo::report::bench::subdiv::{Settings, default_models, run};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    let models = default_models(std::path::Path::new("models"))?;
    let report = run(&ctx, &models, Settings { level: 5, runs: 5, validate: false })?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}
