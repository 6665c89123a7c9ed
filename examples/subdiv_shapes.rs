//! Writes the subdivision test-shape set (`tests/common/shapes.rs`) as OFF files, the
//! inputs of `reference/subdiv/` (see its README):
//!
//!     cargo run --release --example subdiv_shapes -- reference/subdiv

#[path = "../tests/common/shapes.rs"]
mod shapes;

fn main() -> anyhow::Result<()> {
    let dir = std::env::args().nth(1).unwrap_or_else(|| "reference/subdiv".into());
    std::fs::create_dir_all(&dir)?;
    for shape in shapes::all() {
        let path = std::path::Path::new(&dir).join(format!("{}.off", shape.name));
        texgeo::mesh::formats::write(&path, &shape.mesh)?;
        println!("{}", path.display());
    }
    Ok(())
}
