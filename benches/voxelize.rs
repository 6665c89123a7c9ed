//! `cargo bench --bench voxelize`: the same suite as `texgeo bench voxelize` (Table 5-2)
//! on the built-in torus knot and, when fetched, CGAL's armadillo.

use texgeo::report::bench::voxelize::{Config, DEFAULT_RESOLUTIONS, Model, run};
use texgeo::voxel::Method;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let ctx = texgeo::gpu::Context::from_env()?;
    let mut models = vec![Model {
        thesis: "Torusknot",
        name: "builtin:knot".into(),
        mesh: texgeo::mesh::procedural::torus_knot(),
    }];
    if let Ok(mesh) = texgeo::mesh::formats::read("models/armadillo.off") {
        models.push(Model { thesis: "Armadillo", name: "armadillo.off".into(), mesh });
    }
    let cfg = Config {
        resolutions: DEFAULT_RESOLUTIONS.to_vec(),
        methods: Method::ALL.to_vec(),
        runs: 3,
        zone: texgeo::voxel::Zone::Auto,
    };
    let report = run(&ctx, &models, &cfg)?;
    println!("{}", report.to_markdown());
    report.write(std::path::Path::new("out/bench"))?;
    Ok(())
}
