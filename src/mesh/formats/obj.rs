//! Wavefront OBJ, read through `tobj` with polygons kept (not triangulated).
//!
//! `tobj` reports errors without line numbers and renumbers vertices per group, so
//! reading is two steps:
//!
//! 1. a line-numbered check of every statement (numbers parse and are finite, indices are
//!    in range, relative indices resolved, faces have ≥ 3 vertices) that also records, for
//!    every face corner, the file's vertex index. Statements texgeo does not need (`l`,
//!    `usemtl`, `mtllib`, `s`, free-form geometry, …) and trailing `#` comments are blanked
//!    from the text handed to `tobj`, so `tobj` only sees what was checked;
//! 2. `tobj` parses the text; its groups and objects are merged into one mesh by mapping
//!    each corner back to the file's vertex index, so a vertex shared between groups stays
//!    shared and a closed OBJ reads as a closed mesh.
//!
//! Vertices no face uses are dropped (`tobj` does not return them); the others keep their
//! file order. Tags (`t` lines, the sharp features of subdivision surfaces) are kept as
//! data ([`Tags`], from [`read_with_tags`]) with the renumbering their indices need;
//! `subdiv::tags` interprets them. Texture coordinates, normals and colours are checked
//! but not kept. A face
//! may only use vertices defined before it (positive or relative indices), as written
//! by every exporter; a forward reference is reported as out of range.

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::text::{parse_coord, utf8};
use crate::mesh::{Mesh, MeshError, Result, error::Location};

/// Statements of the OBJ format that texgeo accepts but ignores.
#[rustfmt::skip]
const IGNORED: &[&str] = &[
    "l", "p", "s", "usemtl", "mtllib", "vp", "cstype", "deg", "bmat", "step", "curv", "curv2",
    "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "mg", "bevel", "c_interp",
    "d_interp", "lod", "shadow_obj", "trace_obj", "ctech", "stech", "maplib", "usemap", "call",
    "csh",
];

/// What the line-numbered check learned about a file.
struct Checked {
    /// File vertex index (0-based, relative indices resolved) of every face corner, in order.
    corners: Vec<u32>,
    /// Number of `v` statements.
    vertices: usize,
    /// The text to give `tobj` when it differs from the file.
    cleaned: Option<String>,
    /// The `t` lines.
    tags: Vec<Tag>,
}

/// One `t` line, uninterpreted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tag {
    /// 1-based line number in the file.
    pub line: usize,
    /// The words after `t`.
    pub words: Vec<String>,
}

/// An OBJ file's tags as read: the mesh does not interpret them (subdivision does).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Tags {
    pub tags: Vec<Tag>,
    /// File vertex (0-based, as tags count them) → mesh vertex, `u32::MAX` for a vertex no
    /// face uses (dropped).
    pub vertices: Vec<u32>,
}

/// Reads an OBJ file; `path` only names the source in errors.
pub fn read(bytes: &[u8], path: &Path) -> Result<Mesh> {
    Ok(read_with_tags(bytes, path)?.0)
}

/// Reads an OBJ file with its tags.
pub fn read_with_tags(bytes: &[u8], path: &Path) -> Result<(Mesh, Tags)> {
    if bytes.is_empty() {
        return Err(MeshError::parse(path, Location::File, "the file is empty"));
    }
    let text = utf8(bytes, path, 0, 0)?;
    let checked = check(text, path)?;
    let source = checked.cleaned.as_deref().unwrap_or(text);
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _materials) =
        tobj::load_obj_buf(&mut source.as_bytes(), &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| MeshError::parse(path, Location::File, format!("tobj: {e}")))?;
    let (mesh, vertices) = assemble(&models, &checked, path)?;
    Ok((mesh, Tags { tags: checked.tags, vertices }))
}

/// Merges `tobj`'s models into one mesh, using the checked corner list for vertex identity;
/// also returns the file-to-mesh vertex renumbering.
fn assemble(models: &[tobj::Model], checked: &Checked, path: &Path) -> Result<(Mesh, Vec<u32>)> {
    let disagree = |what: &str| {
        MeshError::parse(path, Location::File, format!("tobj and texgeo's check disagree about {what}"))
    };
    // New vertex numbers: the used file vertices, in file order (first marked with 0).
    let mut renumber = vec![u32::MAX; checked.vertices];
    for &g in &checked.corners {
        if let Some(slot) = renumber.get_mut(g as usize) {
            *slot = 0;
        }
    }
    let mut used = 0u32;
    for slot in renumber.iter_mut().filter(|s| **s == 0) {
        *slot = used;
        used += 1;
    }
    let mut positions = vec![DVec3::ZERO; used as usize];
    let mut seen = vec![false; used as usize];

    let mut offsets = vec![0usize];
    let mut indices = Vec::with_capacity(checked.corners.len());
    let mut corner = 0usize;
    for model in models {
        let mesh = &model.mesh;
        let arities: Box<dyn Iterator<Item = usize>> = if mesh.face_arities.is_empty() {
            if mesh.indices.len() % 3 != 0 {
                return Err(disagree("a triangle list"));
            }
            Box::new(std::iter::repeat_n(3, mesh.indices.len() / 3))
        } else {
            Box::new(mesh.face_arities.iter().map(|&a| a as usize))
        };
        let mut local = mesh.indices.iter();
        for arity in arities {
            if arity < 3 {
                return Err(disagree("a face with fewer than 3 vertices"));
            }
            for _ in 0..arity {
                let (Some(&l), Some(&g)) = (local.next(), checked.corners.get(corner)) else {
                    return Err(disagree("the number of face corners"));
                };
                corner += 1;
                let l = l as usize;
                let p = match mesh.positions.get(3 * l..3 * l + 3) {
                    Some(&[x, y, z]) => DVec3::new(x, y, z),
                    _ => return Err(disagree("a vertex index")),
                };
                let Some(&v) = renumber.get(g as usize) else {
                    return Err(disagree("a vertex index"));
                };
                let v = v as usize;
                if seen[v] && positions[v] != p {
                    return Err(disagree("a vertex position"));
                }
                positions[v] = p;
                seen[v] = true;
                indices.push(v as u32);
            }
            offsets.push(indices.len());
        }
        if local.next().is_some() {
            return Err(disagree("the number of face corners"));
        }
    }
    if corner != checked.corners.len() {
        return Err(disagree("the number of face corners"));
    }
    let mesh = Mesh::from_parts(positions, offsets, indices)
        .map_err(|e| MeshError::parse(path, Location::File, e.to_string()))?;
    Ok((mesh, renumber))
}

/// The line-numbered check (step 1 of the module doc).
fn check(text: &str, path: &Path) -> Result<Checked> {
    let mut corners = Vec::new();
    let (mut nv, mut nvt, mut nvn) = (0usize, 0usize, 0usize);
    let mut cleaned: Option<String> = None;
    let mut tags = Vec::new();
    let mut start = 0usize;
    for (number, raw) in text.split_inclusive('\n').enumerate() {
        let line_no = number + 1;
        let err = |m: String| MeshError::parse(path, Location::Line(line_no), m);
        let line = raw.trim_end_matches(['\n', '\r']);
        if line.ends_with('\\') {
            return Err(err("line continuations ('\\' at the end of a line) are not supported".into()));
        }
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let keyword = words.next().unwrap_or("");
        // Some(replacement) when the text tobj sees must differ from the file.
        let mut replace: Option<String> = None;
        match keyword {
            "" => {}
            "v" => {
                let mut p = [0.0; 3];
                for c in &mut p {
                    let tok = words.next().ok_or_else(|| err("a vertex needs three coordinates".into()))?;
                    *c = parse_coord(tok).map_err(err)?;
                }
                let rest: Vec<&str> = words.collect();
                match rest.as_slice() {
                    [] => {}
                    [w] => {
                        let w = parse_coord(w).map_err(|m| err(format!("weight w: {m}")))?;
                        if w == 0.0 {
                            return Err(err("vertex weight w is zero".into()));
                        }
                        if p.iter().any(|c| !(c / w).is_finite()) {
                            return Err(err("a coordinate divided by the weight w is not finite".into()));
                        }
                    }
                    [_, _, _] => {
                        // Colours: checked loosely, dropped so tobj never mixes coloured and
                        // uncoloured vertices.
                        for c in &rest {
                            c.parse::<f64>().map_err(|_| err(format!("colour '{c}' is not a number")))?;
                        }
                        replace = Some(format!("v {} {} {}", p[0], p[1], p[2]));
                    }
                    _ => {
                        return Err(err(format!(
                            "a vertex has 3 coordinates, optionally followed by a weight or by r g b; \
                             this one has {} values",
                            3 + rest.len()
                        )));
                    }
                }
                if nv == u32::MAX as usize {
                    return Err(err("more than 2^32 vertices".into()));
                }
                nv += 1;
            }
            "vt" | "vn" => {
                let need = if keyword == "vt" { 2 } else { 3 };
                let mut got = 0;
                for tok in words {
                    tok.parse::<f64>().map_err(|_| err(format!("'{tok}' is not a number")))?;
                    got += 1;
                }
                if got < need {
                    return Err(err(format!("'{keyword}' needs at least {need} numbers, found {got}")));
                }
                if keyword == "vt" { nvt += 1 } else { nvn += 1 }
            }
            "f" => {
                let before = corners.len();
                for tok in words {
                    corners.push(face_vertex(tok, nv, nvt, nvn).map_err(err)?);
                }
                let n = corners.len() - before;
                if n < 3 {
                    return Err(err(format!("a face needs at least 3 vertices, this one has {n}")));
                }
            }
            "o" | "g" => {}
            "t" => {
                tags.push(Tag { line: line_no, words: words.map(str::to_string).collect() });
                replace = Some(String::new());
            }
            k if IGNORED.contains(&k) => replace = Some(String::new()),
            k => return Err(err(format!("unknown OBJ statement '{k}'"))),
        }
        if replace.is_none() && !keyword.is_empty() && content.len() != line.len() {
            // A trailing comment: tobj would read it as values.
            replace = Some(content.to_string());
        }
        match (&mut cleaned, replace) {
            (Some(out), Some(r)) => {
                out.push_str(&r);
                out.push('\n');
            }
            (Some(out), None) => out.push_str(raw),
            (None, Some(r)) => {
                let mut out = text[..start].to_string();
                out.push_str(&r);
                out.push('\n');
                cleaned = Some(out);
            }
            (None, None) => {}
        }
        start += raw.len();
    }
    Ok(Checked { corners, vertices: nv, cleaned, tags })
}

/// One `v`, `v/vt`, `v//vn` or `v/vt/vn` reference of a face, checked against the
/// counts so far; returns the 0-based vertex index.
fn face_vertex(token: &str, nv: usize, nvt: usize, nvn: usize) -> std::result::Result<u32, String> {
    let mut parts = token.split('/');
    let v = parts.next().unwrap_or("");
    let vt = parts.next().unwrap_or("");
    let vn = parts.next().unwrap_or("");
    if parts.next().is_some() {
        return Err(format!("'{token}' is not a face vertex (expected v, v/vt, v//vn or v/vt/vn)"));
    }
    if v.is_empty() {
        return Err(format!("face vertex '{token}' has no vertex index"));
    }
    let i = resolve(v, nv, "vertex")?;
    if !vt.is_empty() {
        resolve(vt, nvt, "texture coordinate")?;
    }
    if !vn.is_empty() {
        resolve(vn, nvn, "normal")?;
    }
    Ok(i as u32)
}

/// Resolves a 1-based or negative (relative) OBJ index against the `count` defined so far.
fn resolve(token: &str, count: usize, what: &str) -> std::result::Result<usize, String> {
    let i: i64 = token.parse().map_err(|_| format!("{what} index '{token}' is not an integer"))?;
    let resolved = match i {
        0 => return Err(format!("{what} index 0 is not allowed (OBJ indices start at 1)")),
        i if i > 0 => (i - 1) as u64,
        i => (count as u64).checked_sub(i.unsigned_abs()).ok_or_else(|| {
            format!("relative {what} index {i} reaches before the first {what} ({count} defined so far)")
        })?,
    };
    if resolved >= count as u64 {
        return Err(format!("{what} index {i} is out of range ({count} defined before this line)"));
    }
    Ok(resolved as usize)
}

/// Writes `v` and `f` lines; coordinates use the shortest decimal that reads back to the
/// same f64, so a write → read round trip is exact.
pub fn write(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "# texgeo: {} vertices, {} faces", mesh.num_vertices(), mesh.num_faces())?;
    super::text::write_vertices(&mut w, mesh, "v ")?;
    super::text::write_faces(&mut w, mesh, |_, out| {
        out.push(b'f');
        1
    })?;
    w.flush()
}
