//! OFF (geomview Object File Format), the format of the 2010 thesis and of CGAL's data.
//!
//! Accepted headers: `OFF`, `COFF`, `NOFF`, `CNOFF` (extra per-vertex values such as
//! colours or normals are ignored), with the counts on the header line or the next one.
//! One vertex per line, one face per line (`n i0 … in-1`, trailing colour values ignored).

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::text::{Lines, fast, parse_coord, parse_index, write_vertices_and_faces};
use crate::mesh::{Mesh, Result};

pub fn read(bytes: &[u8], path: &Path) -> Result<Mesh> {
    if let Some(mesh) = read_fast(bytes) {
        return Ok(mesh);
    }
    read_lines(bytes, path)
}

/// The fast path: plain ASCII read in one pass ([`fast::Cursor`]); `None` sends the file
/// to [`read_lines`], which reads the same files into the same mesh and words every error.
fn read_fast(bytes: &[u8]) -> Option<Mesh> {
    let mut c = fast::Cursor::new(bytes);
    if !c.next_line() || !matches!(c.word()?, b"OFF" | b"COFF" | b"NOFF" | b"CNOFF") {
        return None;
    }
    if c.at_line_end() {
        c.end_line()?;
        if !c.next_line() {
            return None;
        }
    }
    let (nv, nf) = (c.index()?, c.index()?);
    c.end_line()?;
    if nv > u32::MAX as u64 {
        return None;
    }
    // Sized by what the file can hold, never by the counts alone.
    let mut positions = Vec::with_capacity((nv as usize).min(bytes.len() / 6));
    for _ in 0..nv {
        if !c.next_line() {
            return None;
        }
        positions.push(DVec3::new(c.coord()?, c.coord()?, c.coord()?));
        c.end_line()?;
    }
    let mut offsets = Vec::with_capacity((nf as usize).min(bytes.len() / 8) + 1);
    offsets.push(0usize);
    let mut indices = Vec::with_capacity(offsets.capacity() * 3);
    for _ in 0..nf {
        if !c.next_line() {
            return None;
        }
        let n = c.index()?;
        if n < 3 {
            return None;
        }
        for _ in 0..n {
            let i = c.index()?;
            if i >= nv {
                return None;
            }
            indices.push(i as u32);
        }
        c.end_line()?;
        offsets.push(indices.len());
    }
    Mesh::from_parts(positions, offsets, indices).ok()
}

/// The line-by-line reader: every accepted file, every error with its line.
fn read_lines(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let mut lines = Lines::new(bytes, path)?;
    let Some((hline, header)) = lines.next_content() else {
        return Err(lines.error(1, "no OFF header (the file holds only comments or blanks)"));
    };
    let mut tokens = header.split_whitespace();
    let keyword = tokens.next().unwrap_or("");
    if !matches!(keyword, "OFF" | "COFF" | "NOFF" | "CNOFF") {
        return Err(lines.error(hline, format!("expected an OFF header, found '{keyword}'")));
    }
    let rest: Vec<&str> = tokens.collect();
    let (cline, counts) = if rest.is_empty() {
        match lines.next_content() {
            Some((l, c)) => (l, c.split_whitespace().collect::<Vec<_>>()),
            None => {
                return Err(lines.error(lines.last_line, "the file ends before the vertex and face counts"));
            }
        }
    } else {
        (hline, rest)
    };
    if counts.len() < 2 {
        return Err(lines.error(cline, "expected 'vertices faces [edges]' counts"));
    }
    let nv = parse_index(counts[0], "vertex count").map_err(|m| lines.error(cline, m))?;
    let nf = parse_index(counts[1], "face count").map_err(|m| lines.error(cline, m))?;
    if nv > u32::MAX as u64 {
        return Err(lines.error(cline, format!("vertex count {nv} exceeds 2^32")));
    }

    let mut positions = Vec::new();
    for k in 0..nv {
        let Some((l, line)) = lines.next_content() else {
            return Err(lines.error(lines.last_line, format!("the file ends after {k} of {nv} vertices")));
        };
        let mut p = [0.0; 3];
        let mut it = line.split_whitespace();
        for c in &mut p {
            let tok = it.next().ok_or_else(|| lines.error(l, "a vertex needs three coordinates"))?;
            *c = parse_coord(tok).map_err(|m| lines.error(l, m))?;
        }
        positions.push(DVec3::from_array(p));
    }

    let mut offsets = vec![0usize];
    let mut indices = Vec::new();
    for k in 0..nf {
        let Some((l, line)) = lines.next_content() else {
            return Err(lines.error(lines.last_line, format!("the file ends after {k} of {nf} faces")));
        };
        let mut it = line.split_whitespace();
        let n = parse_index(it.next().unwrap_or(""), "face size").map_err(|m| lines.error(l, m))?;
        if n < 3 {
            return Err(lines.error(l, format!("a face needs at least 3 vertices, this one has {n}")));
        }
        for j in 0..n {
            let tok = it
                .next()
                .ok_or_else(|| lines.error(l, format!("face declares {n} vertices but lists {j}")))?;
            let i = parse_index(tok, "vertex index").map_err(|m| lines.error(l, m))?;
            if i >= nv {
                return Err(
                    lines.error(l, format!("vertex index {i} is out of range (the file has {nv} vertices)"))
                );
            }
            indices.push(i as u32);
        }
        offsets.push(indices.len());
    }
    Mesh::from_parts(positions, offsets, indices).map_err(|e| lines.error(lines.last_line, e.to_string()))
}

/// Writes OFF with shortest round-trip decimal coordinates (reading it back is exact).
pub fn write(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.num_vertices(), mesh.num_faces())?;
    write_vertices_and_faces(&mut w, mesh)?;
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// The fast path reads what the line reader reads, or leaves the file to it: on valid
    /// files, on files with comments and odd spacing, and on thousands of byte mutations.
    #[test]
    fn fast_path_agrees_with_the_line_reader() {
        let p = Path::new("m.off");
        let mut texts: Vec<Vec<u8>> = Vec::new();
        for name in crate::mesh::procedural::BUILTIN_NAMES {
            let m = crate::mesh::procedural::by_name(name).unwrap();
            let mut out = Vec::new();
            write(&mut out, &m).unwrap();
            assert_eq!(read_fast(&out).as_ref(), Some(&m), "{name}");
            texts.push(out);
        }
        texts.push(
            b"OFF 4 4\n0 0 0\n1 0 0 # c\n0 1 0\n\n0 0 1 9 9\n3 0 2 1\n3 0 1 3\n3 1 2 3 7\n3 2 0 3\n".to_vec(),
        );
        texts.push(b"# lead\nCOFF\n 4\t4 6\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n".to_vec());
        let mut rng = Rng::new(5);
        let alphabet = b"0123456789 .-+e#\n\x0bx";
        for base in texts.clone() {
            assert_eq!(read_fast(&base), read_lines(&base, p).ok());
            for _ in 0..300 {
                let mut t = base.clone();
                for _ in 0..1 + rng.below(3) {
                    let at = rng.below(t.len() as u64) as usize;
                    match rng.below(3) {
                        0 => t[at] = alphabet[rng.below(alphabet.len() as u64) as usize],
                        1 => {
                            t.remove(at);
                        }
                        _ => t.insert(at, alphabet[rng.below(alphabet.len() as u64) as usize]),
                    }
                }
                if let Some(m) = read_fast(&t) {
                    assert_eq!(Some(m), read_lines(&t, p).ok(), "{}", String::from_utf8_lossy(&t));
                }
            }
        }
    }
}
