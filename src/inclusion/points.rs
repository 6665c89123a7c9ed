//! Query point files for `texgeo inclusion --points FILE`: one point per line, `x y z`,
//! blank lines and `#` comments allowed. Errors name the file and line.

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use crate::mesh::MeshError;
use crate::mesh::error::Location;
use crate::mesh::formats::text::{Lines, parse_coord};

/// Reads a point file.
pub fn read(path: impl AsRef<Path>) -> Result<Vec<DVec3>, MeshError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|error| MeshError::Io { path: path.into(), error })?;
    parse(&bytes, path)
}

/// Parses point-file contents; `path` only names the source in errors.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Vec<DVec3>, MeshError> {
    let mut lines = Lines::new(bytes, path)?;
    let mut points = Vec::new();
    while let Some((l, line)) = lines.next_content() {
        let tokens: Vec<&str> = line.split_whitespace().collect();
        if tokens.len() != 3 {
            return Err(lines.error(l, format!("expected 'x y z', found {} values", tokens.len())));
        }
        let mut p = [0.0; 3];
        for (c, t) in p.iter_mut().zip(&tokens) {
            *c = parse_coord(t).map_err(|m| lines.error(l, m))?;
        }
        points.push(DVec3::from_array(p));
    }
    if points.is_empty() {
        return Err(MeshError::parse(path, Location::File, "no points in the file"));
    }
    Ok(points)
}

/// Writes one class per line (`1` inside, `0` outside, `2` on the boundary).
pub fn write_classes(out: &mut impl Write, classes: &[super::classifier::Class]) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    for c in classes {
        writeln!(w, "{}", *c as u8)?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_points_and_reports_lines() {
        let p = Path::new("pts.txt");
        let pts = parse(b"# header\n1 2 3\n\n  4.5 -6 7e1 # trailing\n", p).unwrap();
        assert_eq!(pts, vec![DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.5, -6.0, 70.0)]);
        let e = parse(b"1 2 3\n1 2\n", p).unwrap_err().to_string();
        assert!(e.contains("pts.txt:2") && e.contains("expected 'x y z'"), "{e}");
        let e = parse(b"1 2 nan\n", p).unwrap_err().to_string();
        assert!(e.contains("pts.txt:1") && e.contains("not finite"), "{e}");
        let e = parse(b"1 2 x\n", p).unwrap_err().to_string();
        assert!(e.contains("'x' is not a number"), "{e}");
        let e = parse(b"# nothing\n", p).unwrap_err().to_string();
        assert_eq!(e, "pts.txt: no points in the file");
        let e = parse(&[0xff, 0xfe], p).unwrap_err().to_string();
        assert_eq!(e, "pts.txt:1: not a text file (invalid UTF-8 at byte 0)");
    }
}
