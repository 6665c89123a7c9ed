//! OFF (geomview Object File Format), the format of the 2010 thesis and of CGAL's data.
//!
//! Accepted headers: `OFF`, `COFF`, `NOFF`, `CNOFF` (extra per-vertex values such as
//! colours or normals are ignored), with the counts on the header line or the next one.
//! One vertex per line, one face per line (`n i0 … in-1`, trailing colour values ignored).

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::text::{Lines, parse_coord, parse_index, write_vertices_and_faces};
use crate::mesh::{Mesh, Result};

pub fn read(bytes: &[u8], path: &Path) -> Result<Mesh> {
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
