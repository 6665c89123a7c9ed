//! STL, ascii and binary. STL is a triangle soup; reading welds vertices whose
//! coordinates are bitwise identical (after turning −0 into +0), so a closed STL reads as
//! a closed mesh.
//!
//! A file is binary when its size is exactly 84 + 50·n bytes for the triangle count n
//! stored at byte 80 (even if its header starts with `solid`, as some writers do); else
//! ascii when it starts with `solid`; else it is rejected. ASCII keywords are matched
//! case-insensitively, several `solid … endsolid` blocks are merged, and an
//! `outer loop` of more than three vertices is read as one polygon face.

use std::collections::HashMap;
use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::text::{parse_coord, utf8};
use crate::mesh::triangulate::triangulated;
use crate::mesh::{Mesh, MeshError, Result, error::Location};

const HEADER: usize = 80;
const TRIANGLE: usize = 50;

/// Reads a binary or ascii STL file; `path` only names the source in errors.
pub fn read(bytes: &[u8], path: &Path) -> Result<Mesh> {
    if bytes.is_empty() {
        return Err(MeshError::parse(path, Location::File, "the file is empty"));
    }
    // (claimed triangle count, the file size that count implies)
    let claimed = match bytes.get(HEADER..HEADER + 4) {
        Some(&[a, b, c, d]) => {
            let n = u64::from(u32::from_le_bytes([a, b, c, d]));
            Some((n, (HEADER + 4) as u64 + TRIANGLE as u64 * n))
        }
        _ => None,
    };
    if let Some((n, size)) = claimed
        && size == bytes.len() as u64
    {
        return read_binary(bytes, n as usize, path);
    }
    let looks_ascii = super::text::strip_bom(bytes)
        .0
        .trim_ascii_start()
        .get(..5)
        .is_some_and(|s| s.eq_ignore_ascii_case(b"solid"));
    let size_note = match claimed {
        Some((n, size)) => format!(
            "as binary STL its header claims {n} triangles, which take {size} bytes, but the file has {}",
            bytes.len()
        ),
        None => format!("it is too short ({} bytes) for a binary STL header", bytes.len()),
    };
    if !looks_ascii {
        return Err(MeshError::parse(
            path,
            if claimed.is_some() { Location::Byte(HEADER as u64) } else { Location::File },
            format!("not an STL file: it does not start with 'solid' (ascii STL), and {size_note}"),
        ));
    }
    if std::str::from_utf8(bytes).is_err() && claimed.is_some() {
        // Binary writers often start the header with "solid" too: say both things.
        return Err(MeshError::parse(
            path,
            Location::Byte(HEADER as u64),
            format!("starts with 'solid' but is not text, and {size_note} (truncated binary STL?)"),
        ));
    }
    read_ascii(bytes, path)
}

/// What [`super::bounded`] lets through of an STL file: bytes that can still be ASCII STL
/// (text starting with `solid`) or binary STL (no more bytes than the header's triangle
/// count takes, every vertex coordinate finite so far). Reading stops when neither holds.
#[derive(Default)]
pub(crate) struct Guard {
    /// Why it cannot be ASCII STL (`None`: it still can).
    not_text: Option<super::bounded::Stop>,
    text: Option<super::bounded::Text>,
    /// Why it cannot be binary STL.
    not_binary: Option<super::bounded::Stop>,
    /// Triangles whose coordinates were checked.
    checked: usize,
}

impl super::bounded::Guard for Guard {
    fn check(&mut self, bytes: &[u8], from: usize) -> Result<(), super::bounded::Stop> {
        use super::bounded::Stop;
        if self.not_text.is_none() {
            let (text, skipped) = super::text::strip_bom(bytes);
            let start = text.len() - text.trim_ascii_start().len();
            if let Some(first) = text.get(start..start + 5)
                && !first.eq_ignore_ascii_case(b"solid")
            {
                self.not_text = Some(Stop {
                    at: (skipped + start) as u64,
                    why: "as ASCII STL it must start with 'solid'".into(),
                });
            } else if let Err(stop) =
                self.text.get_or_insert_with(|| super::bounded::Text::new("ASCII STL")).check(bytes, from)
            {
                self.not_text = Some(stop);
            }
        }
        if self.not_binary.is_none()
            && let Some(&[a, b, c, d]) = bytes.get(HEADER..HEADER + 4)
        {
            let n = u32::from_le_bytes([a, b, c, d]) as usize;
            let size = (HEADER + 4) as u64 + TRIANGLE as u64 * n as u64;
            if bytes.len() as u64 > size {
                self.not_binary = Some(Stop {
                    at: size,
                    why: format!(
                        "as binary STL its header's {n} triangles end at byte {size}, but more bytes follow"
                    ),
                });
            }
            while self.not_binary.is_none() && self.checked < n {
                let base = HEADER + 4 + TRIANGLE * self.checked;
                let Some(record) = bytes.get(base..base + TRIANGLE) else { break };
                let bad = (12..48).step_by(4).find(|&k| {
                    !f32::from_le_bytes([record[k], record[k + 1], record[k + 2], record[k + 3]]).is_finite()
                });
                if let Some(k) = bad {
                    self.not_binary = Some(Stop {
                        at: (base + k) as u64,
                        why: format!(
                            "as binary STL triangle {} has a coordinate that is not finite",
                            self.checked
                        ),
                    });
                }
                self.checked += 1;
            }
        }
        match (self.not_text.take(), self.not_binary.take()) {
            (Some(t), Some(b)) => Err(Stop {
                at: t.at.max(b.at),
                why: format!("not an STL file: {} (byte {}), and {} (byte {})", t.why, t.at, b.why, b.at),
            }),
            (t, b) => {
                (self.not_text, self.not_binary) = (t, b);
                Ok(())
            }
        }
    }
}

/// Welds vertices by their coordinates' bits.
struct Welder {
    map: HashMap<[u64; 3], u32>,
    positions: Vec<DVec3>,
}

impl Welder {
    fn new(capacity: usize) -> Welder {
        Welder { map: HashMap::with_capacity(capacity), positions: Vec::with_capacity(capacity) }
    }

    fn index(&mut self, p: DVec3) -> Option<u32> {
        // +0.0 turns −0 into +0, the same point.
        let key = (p + DVec3::ZERO).to_array().map(f64::to_bits);
        if let Some(&i) = self.map.get(&key) {
            return Some(i);
        }
        let i = u32::try_from(self.positions.len()).ok()?;
        self.positions.push(p + DVec3::ZERO);
        self.map.insert(key, i);
        Some(i)
    }
}

fn read_binary(bytes: &[u8], n: usize, path: &Path) -> Result<Mesh> {
    // `n` was checked against the file size, so these allocations are bounded by it.
    let mut welder = Welder::new(n / 2 + 3);
    let mut indices = Vec::with_capacity(3 * n);
    let f32_at = |at: usize| -> Result<f32> {
        match bytes.get(at..at + 4) {
            Some(&[a, b, c, d]) => Ok(f32::from_le_bytes([a, b, c, d])),
            _ => Err(MeshError::parse(path, Location::Byte(at as u64), "the file ends early")),
        }
    };
    for t in 0..n {
        let base = HEADER + 4 + TRIANGLE * t;
        for v in 0..3 {
            let mut p = [0.0; 3];
            for (c, slot) in p.iter_mut().enumerate() {
                let at = base + 12 + 12 * v + 4 * c;
                let x = f32_at(at)?;
                if !x.is_finite() {
                    return Err(MeshError::parse(
                        path,
                        Location::Byte(at as u64),
                        format!("triangle {t}, vertex {v}: coordinate {x} is not finite"),
                    ));
                }
                *slot = f64::from(x);
            }
            let i = welder.index(DVec3::from_array(p)).ok_or_else(|| {
                MeshError::parse(path, Location::Byte(base as u64), "more than 2^32 distinct vertices")
            })?;
            indices.push(i);
        }
    }
    let offsets = (0..=n).map(|t| 3 * t).collect();
    Mesh::from_parts(welder.positions, offsets, indices)
        .map_err(|e| MeshError::parse(path, Location::File, e.to_string()))
}

/// Where the ascii reader is in the `solid`/`facet`/`outer loop` nesting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    Outside,
    Solid,
    Facet,
    Loop,
    LoopDone,
}

fn read_ascii(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let text = utf8(bytes, path, 0, 0)?;
    let mut welder = Welder::new(0);
    let mut offsets = vec![0usize];
    let mut indices = Vec::new();
    let mut state = State::Outside;
    let mut last_line = 0;
    let mut solids = 0usize;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        last_line = line_no;
        let err = |m: String| MeshError::parse(path, Location::Line(line_no), m);
        let mut words = line.split_whitespace();
        let Some(keyword) = words.next() else { continue };
        let keyword = keyword.to_ascii_lowercase();
        let expected = |what: &str| err(format!("expected {what}, found '{keyword}'"));
        state = match (state, keyword.as_str()) {
            (State::Outside, "solid") => {
                solids += 1;
                State::Solid
            }
            (State::Outside, _) => return Err(expected("'solid'")),
            (State::Solid, "facet") => {
                if !words.next().is_some_and(|w| w.eq_ignore_ascii_case("normal")) {
                    return Err(err("expected 'facet normal nx ny nz'".into()));
                }
                for k in 0..3 {
                    let tok = words.next().ok_or_else(|| err("a facet normal needs three numbers".into()))?;
                    tok.parse::<f64>()
                        .map_err(|_| err(format!("normal component {k} '{tok}' is not a number")))?;
                }
                State::Facet
            }
            (State::Solid, "endsolid") => State::Outside,
            (State::Solid, _) => return Err(expected("'facet' or 'endsolid'")),
            (State::Facet, "outer") => {
                if !words.next().is_some_and(|w| w.eq_ignore_ascii_case("loop")) {
                    return Err(err("expected 'outer loop'".into()));
                }
                State::Loop
            }
            (State::Facet, _) => return Err(expected("'outer loop'")),
            (State::Loop, "vertex") => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let tok = words.next().ok_or_else(|| err("a vertex needs three coordinates".into()))?;
                    *c = parse_coord(tok).map_err(err)?;
                }
                let i = welder
                    .index(DVec3::from_array(p))
                    .ok_or_else(|| err("more than 2^32 distinct vertices".into()))?;
                indices.push(i);
                State::Loop
            }
            (State::Loop, "endloop") => {
                let n = indices.len() - offsets.last().copied().unwrap_or(0);
                if n < 3 {
                    return Err(err(format!("a facet needs at least 3 vertices, this one has {n}")));
                }
                offsets.push(indices.len());
                State::LoopDone
            }
            (State::Loop, _) => return Err(expected("'vertex' or 'endloop'")),
            (State::LoopDone, "endfacet") => State::Solid,
            (State::LoopDone, _) => return Err(expected("'endfacet'")),
        };
    }
    if state != State::Outside || solids == 0 {
        let inside = match state {
            State::Outside | State::Solid => "before 'endsolid'",
            State::Facet | State::LoopDone => "inside a facet",
            State::Loop => "inside a facet's vertex loop",
        };
        return Err(MeshError::parse(path, Location::Line(last_line), format!("the file ends {inside}")));
    }
    Mesh::from_parts(welder.positions, offsets, indices)
        .map_err(|e| MeshError::parse(path, Location::File, e.to_string()))
}

/// The triangles STL gets: planar polygons triangulated in their plane, non-planar ones
/// as the fan from their centroid ([`triangulated`]), so the file holds the surface every
/// command measures.
fn triangles(mesh: &Mesh) -> Vec<[DVec3; 3]> {
    let t = triangulated(mesh);
    t.faces().map(|f| [f[0], f[1], f[2]].map(|v| t.positions()[v as usize])).collect()
}

/// Writes binary STL. Polygon faces are triangulated ([`triangles`]); STL stores f32,
/// so coordinates are rounded to f32 and a round trip is exact only to f32.
pub fn write(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let tris = triangles(mesh);
    let count_triangles = tris.len();
    let count = u32::try_from(count_triangles).map_err(|_| {
        std::io::Error::other(format!("{count_triangles} triangles are too many for binary STL"))
    })?;
    if let Some(p) = mesh.positions().iter().find(|p| p.abs().max_element() > f64::from(f32::MAX)) {
        return Err(std::io::Error::other(format!(
            "vertex {p} does not fit binary STL's 32-bit floats (up to {:e}); write OBJ, OFF or PLY",
            f32::MAX
        )));
    }
    let mut w = std::io::BufWriter::new(out);
    let mut header = [b' '; HEADER];
    let note = b"binary STL written by texgeo";
    header[..note.len()].copy_from_slice(note);
    w.write_all(&header)?;
    w.write_all(&count.to_le_bytes())?;
    for [a, b, c] in tris {
        let n = (b - a).cross(c - a).normalize_or_zero();
        for v in [n, a, b, c] {
            for x in v.to_array() {
                w.write_all(&(x as f32).to_le_bytes())?;
            }
        }
        w.write_all(&[0, 0])?;
    }
    w.flush()
}

/// Writes ascii STL. Coordinates are written as shortest round-trip f64 decimals, so
/// texgeo reads them back exactly; other readers round them to f32.
pub fn write_ascii(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "solid texgeo")?;
    for [a, b, c] in triangles(mesh) {
        let n = (b - a).cross(c - a).normalize_or_zero();
        writeln!(w, "facet normal {} {} {}", n.x as f32, n.y as f32, n.z as f32)?;
        writeln!(w, "  outer loop")?;
        for v in [a, b, c] {
            writeln!(w, "    vertex {} {} {}", v.x, v.y, v.z)?;
        }
        writeln!(w, "  endloop")?;
        writeln!(w, "endfacet")?;
    }
    writeln!(w, "endsolid texgeo")?;
    w.flush()
}
