//! `cargo bench --bench reduce`: the same suite as `texgeo bench reduce`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    let report = texgeo::report::bench::reduce::run(&ctx, texgeo::report::bench::reduce::DEFAULT_SIDES, 5)?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}
