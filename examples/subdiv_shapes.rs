//! Writes the subdivision test-shape set (`tests/common/shapes.rs`) as OFF files, and the
//! sharp shapes with committed references as OBJ files with tags: the inputs of
//! `reference/subdiv/` (see its README):
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
    for (name, _) in shapes::committed_sharp_references() {
        let shape = shapes::sharp().into_iter().find(|s| s.name == name).expect("a sharp shape");
        let path = std::path::Path::new(&dir).join(format!("{name}.obj"));
        let mut text = Vec::new();
        texgeo::subdiv::tags::write_obj(&mut text, &shape.surface)?;
        std::fs::write(&path, text)?;
        println!("{}", path.display());
    }
    Ok(())
}
