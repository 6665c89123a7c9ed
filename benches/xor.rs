//! `cargo bench --bench xor`: the same suite as `texgeo bench xor`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    let report = texgeo::report::bench::xor::run(&ctx, texgeo::report::bench::xor::DEFAULT_SIDES, 20_000, 5)?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}
