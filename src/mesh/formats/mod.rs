//! Mesh file formats. Readers never panic and never return a half-read mesh: a file is
//! either read whole and checked, or rejected with an error naming file, line (or byte
//! offset) and the problem. No allocation is sized from a count the file claims before
//! the data behind it has been seen, and a file is read in bounded blocks that stop at the
//! first byte the format cannot hold ([`bounded`]): a pipe or a device that never ends is
//! refused, not read forever.
//!
//! A well-formed file without faces is a valid empty mesh (texgeo writes one for an empty
//! result in every format); only a file without any bytes is refused.
//!
//! | format | read | write |
//! |---|---|---|
//! | OBJ | `v`/`f` via `tobj`, polygons kept, groups merged | `v`/`f`, exact decimals |
//! | OFF | OFF/COFF/NOFF/CNOFF | OFF, exact decimals |
//! | PLY | ascii, binary little/big endian | binary little endian, `double` (exact) |
//! | STL | ascii, binary; vertices welded | binary (f32; planar polygons triangulated in their plane, non-planar ones fanned from their centroid) |

use std::path::Path;

use super::{Mesh, MeshError, Result, error::Location};

pub mod bounded;
pub mod obj;
pub mod off;
pub mod ply;
pub mod stl;
pub(crate) mod text;

/// A file format texgeo reads and writes, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Off,
    Ply,
    Stl,
}

impl Format {
    /// The format of `path`, from its extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("obj") => Ok(Format::Obj),
            Some("off") => Ok(Format::Off),
            Some("ply") => Ok(Format::Ply),
            Some("stl") => Ok(Format::Stl),
            other => Err(MeshError::parse(
                path,
                Location::File,
                match other {
                    Some(e) => format!("unknown mesh format '.{e}' (expected .obj, .off, .ply or .stl)"),
                    None => "no file extension; expected .obj, .off, .ply or .stl".to_string(),
                },
            )),
        }
    }
}

/// Reads a mesh, choosing the format from the file extension.
pub fn read(path: impl AsRef<Path>) -> Result<Mesh> {
    let path = path.as_ref();
    let format = Format::from_path(path)?;
    let bytes = read_file(path, format)?;
    read_bytes(&bytes, format, path)
}

/// The bytes of a mesh file, read in bounded blocks that stop where the format cannot go
/// on ([`bounded`]).
pub fn read_file(path: &Path, format: Format) -> Result<Vec<u8>> {
    match format {
        Format::Obj => bounded::read(path, &mut bounded::Text::new("OBJ")),
        Format::Off => bounded::read(path, &mut bounded::Text::new("OFF")),
        Format::Ply => bounded::read(path, &mut ply::Guard::default()),
        Format::Stl => bounded::read(path, &mut stl::Guard::default()),
    }
}

/// Reads a mesh from memory; `path` is only used to name the source in errors.
///
/// An empty file is an error (no format allows it); a file that holds no faces is a
/// valid empty mesh (no faces, any unused vertices it lists).
pub fn read_bytes(bytes: &[u8], format: Format, path: &Path) -> Result<Mesh> {
    if bytes.is_empty() {
        return Err(MeshError::parse(path, Location::File, "the file is empty"));
    }
    match format {
        Format::Obj => obj::read(bytes, path),
        Format::Off => off::read(bytes, path),
        Format::Ply => ply::read(bytes, path),
        Format::Stl => stl::read(bytes, path),
    }
}

/// Writes a mesh, choosing the format from the file extension. The file is written
/// atomically ([`crate::output`]): a failure leaves any previous file at `path` intact.
pub fn write(path: impl AsRef<Path>, mesh: &Mesh) -> Result<()> {
    let path = path.as_ref();
    let format = Format::from_path(path)?;
    Ok(crate::output::write_with(path, |w| write_to(w, mesh, format))?)
}

/// Writes a mesh in `format` to any writer.
pub fn write_to(out: &mut impl std::io::Write, mesh: &Mesh, format: Format) -> std::io::Result<()> {
    match format {
        Format::Obj => obj::write(out, mesh),
        Format::Off => off::write(out, mesh),
        Format::Ply => ply::write(out, mesh),
        Format::Stl => stl::write(out, mesh),
    }
}
