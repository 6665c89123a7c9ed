//! PLY (Stanford polygon file format): `ascii`, `binary_little_endian`, `binary_big_endian`.
//!
//! Read: the `vertex` element's scalar `x`, `y`, `z` (any scalar type) and the `face`
//! element's list `vertex_indices` (or `vertex_index`; any integer count and index types).
//! Every other element and property is skipped by its declared type. Header errors name
//! the line, binary data errors the byte offset, ascii data errors the line. ASCII data is
//! one element entry per line; content after the last entry is an error (the header's
//! counts are then wrong), trailing bytes after binary data are ignored (some writers pad).
//!
//! Write: [`write`] gives `binary_little_endian` with `double` coordinates, so a round trip
//! is exact and compact; [`write_ascii`] the same in `ascii` with shortest round-trip
//! decimals (also exact).

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::text::utf8;
use crate::mesh::{Mesh, MeshError, Result, error::Location};

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    /// The PLY name.
    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn size(self) -> u64 {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }

    /// The range of an integer type.
    fn range(self) -> (i64, i64) {
        match self {
            Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
            Scalar::U8 => (0, u8::MAX.into()),
            Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
            Scalar::U16 => (0, u16::MAX.into()),
            Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
            Scalar::U32 => (0, u32::MAX.into()),
            Scalar::F32 | Scalar::F64 => (i64::MIN, i64::MAX),
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    /// Header line declaring the element.
    line: usize,
    props: Vec<Property>,
}

impl Element {
    /// The fewest bytes one binary entry can take (lists may be empty). Never 0 for an
    /// element with entries: the header parser refuses elements without properties.
    fn min_size(&self) -> u64 {
        self.props
            .iter()
            .map(|p| match p.kind {
                Kind::Scalar(s) => s.size(),
                Kind::List { count, .. } => count.size(),
            })
            .sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Binary { big_endian: bool },
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset where the data starts.
    data_start: usize,
    /// Number of header lines (the data's first line is this + 1).
    lines: usize,
}

fn parse_header(bytes: &[u8], path: &Path) -> Result<Header> {
    let err = |line: usize, m: String| MeshError::parse(path, Location::Line(line), m);
    // A byte-order mark before the magic line is skipped; offsets stay those of the file.
    let mut pos = super::text::strip_bom(bytes).1;
    let mut line_no = 0usize;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line_no += 1;
        let rest = bytes.get(pos..).unwrap_or_default();
        if rest.is_empty() {
            let m = if line_no == 1 { "the file is empty" } else { "the header has no 'end_header' line" };
            return Err(err(line_no - 1, m.into()));
        }
        let (raw, next) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], pos + n + 1),
            None => (rest, bytes.len()),
        };
        pos = next;
        let Ok(line) = std::str::from_utf8(raw) else {
            let m = if line_no == 1 { "not a PLY file (no 'ply' line)" } else { "header line is not text" };
            return Err(err(line_no, m.into()));
        };
        let line = line.trim_end_matches('\r');
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        if line_no == 1 {
            if keyword != "ply" || words.next().is_some() {
                return Err(err(1, "not a PLY file (the first line must be 'ply')".into()));
            }
            continue;
        }
        match keyword {
            "" | "comment" | "obj_info" => {}
            "format" => {
                if encoding.is_some() {
                    return Err(err(line_no, "a second 'format' line".into()));
                }
                encoding = Some(format_line(&mut words).map_err(|m| err(line_no, m))?);
            }
            "element" => {
                let element = element_line(&mut words, &elements, line_no).map_err(|(l, m)| err(l, m))?;
                elements.push(element);
            }
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(err(line_no, "a property before any element".into()));
                };
                let words: Vec<&str> = words.collect();
                let property = property_line(&words, element).map_err(|m| err(line_no, m))?;
                element.props.push(property);
            }
            "end_header" => break,
            other => return Err(err(line_no, format!("unknown header keyword '{other}'"))),
        }
    }
    let Some(encoding) = encoding else {
        return Err(err(line_no, "the header has no 'format' line".into()));
    };
    if let Some(last) = elements.last()
        && last.props.is_empty()
        && last.count > 0
    {
        return Err(err(last.line, format!("element '{}' has no properties", last.name)));
    }
    Ok(Header { encoding, elements, data_start: pos, lines: line_no })
}

/// `format <encoding> 1.0`: the encoding (the words after `format`).
fn format_line(words: &mut std::str::SplitWhitespace) -> std::result::Result<Encoding, String> {
    let encoding = match words.next() {
        Some("ascii") => Encoding::Ascii,
        Some("binary_little_endian") => Encoding::Binary { big_endian: false },
        Some("binary_big_endian") => Encoding::Binary { big_endian: true },
        other => {
            return Err(format!(
                "unknown format '{}' (expected ascii, binary_little_endian or binary_big_endian)",
                other.unwrap_or("")
            ));
        }
    };
    if !matches!(words.next(), Some("1.0" | "1")) {
        return Err("only PLY version 1.0 is supported".into());
    }
    Ok(encoding)
}

/// `element <name> <count>` on line `line_no` (the words after `element`), after
/// `elements`: the element before must have properties, and no two share a name.
/// `Err`: (line, message).
fn element_line(
    words: &mut std::str::SplitWhitespace,
    elements: &[Element],
    line_no: usize,
) -> std::result::Result<Element, (usize, String)> {
    let (Some(name), Some(count), None) = (words.next(), words.next(), words.next()) else {
        return Err((line_no, "expected 'element <name> <count>'".into()));
    };
    let count = count
        .parse::<u64>()
        .map_err(|_| (line_no, format!("element count '{count}' is not a non-negative integer")))?;
    if let Some(prev) = elements.last()
        && prev.props.is_empty()
        && prev.count > 0
    {
        return Err((prev.line, format!("element '{}' has no properties", prev.name)));
    }
    if elements.iter().any(|e| e.name == name) {
        return Err((line_no, format!("a second element '{name}'")));
    }
    Ok(Element { name: name.to_string(), count, line: line_no, props: Vec::new() })
}

/// `property <type> <name>` or `property list <count type> <item type> <name>` (the
/// words after `property`) of `element`, whose properties' names differ.
fn property_line(words: &[&str], element: &Element) -> std::result::Result<Property, String> {
    let ty = |name: &str| Scalar::parse(name).ok_or_else(|| format!("unknown property type '{name}'"));
    let (kind, name) = match words {
        ["list", count, item, name] => {
            let (count, item) = (ty(count)?, ty(item)?);
            if !count.is_integer() {
                return Err("a list count type must be an integer type".into());
            }
            (Kind::List { count, item }, *name)
        }
        [t, name] if *t != "list" => (Kind::Scalar(ty(t)?), *name),
        _ => {
            return Err(
                "expected 'property <type> <name>' or 'property list <count type> <item type> <name>'".into(),
            );
        }
    };
    if element.props.iter().any(|p| p.name == name) {
        return Err(format!("a second property '{name}' in element '{}'", element.name));
    }
    Ok(Property { name: name.to_string(), kind })
}

/// A value read from the data.
#[derive(Clone, Copy, Debug)]
enum Value {
    Int(i64),
    Float(f64),
}

impl Value {
    fn as_f64(self) -> f64 {
        match self {
            Value::Int(i) => i as f64,
            Value::Float(f) => f,
        }
    }
}

/// Why a value could not be read.
enum Fault {
    /// The data ended (the line, for ascii; the file, for binary).
    End,
    Bad(String),
}

/// The data section, ascii or binary.
trait Source {
    /// Moves to the next entry; false when the data has ended.
    fn next_entry(&mut self) -> bool;
    fn value(&mut self, ty: Scalar) -> Result<Value, Fault>;
    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), Fault>;
    /// Called after an entry's last property.
    fn end_entry(&mut self) -> Result<(), Fault>;
    /// Where the last value started (ascii: its line).
    fn location(&self) -> Location;
    /// Makes the current position the error location (binary).
    fn mark(&mut self) {}
    /// Bytes left, for binary data (checked before anything is sized from a count).
    fn left(&self) -> Option<u64>;
    /// What running out of data means here.
    fn end_message(&self) -> &'static str;
    /// Called after the last element.
    fn finish(&mut self) -> Result<(), Fault>;
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Where the last value started.
    at: usize,
    big_endian: bool,
}

impl Binary<'_> {
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fault> {
        self.at = self.pos;
        let end = self.pos.checked_add(N).ok_or(Fault::End)?;
        let chunk = self.bytes.get(self.pos..end).ok_or(Fault::End)?;
        self.pos = end;
        chunk.try_into().map_err(|_| Fault::End)
    }
}

impl Source for Binary<'_> {
    fn next_entry(&mut self) -> bool {
        true
    }

    fn value(&mut self, ty: Scalar) -> Result<Value, Fault> {
        macro_rules! num {
            ($t:ty, $n:literal) => {{
                let b = self.take::<$n>()?;
                if self.big_endian { <$t>::from_be_bytes(b) } else { <$t>::from_le_bytes(b) }
            }};
        }
        Ok(match ty {
            Scalar::I8 => Value::Int(num!(i8, 1).into()),
            Scalar::U8 => Value::Int(num!(u8, 1).into()),
            Scalar::I16 => Value::Int(num!(i16, 2).into()),
            Scalar::U16 => Value::Int(num!(u16, 2).into()),
            Scalar::I32 => Value::Int(num!(i32, 4).into()),
            Scalar::U32 => Value::Int(num!(u32, 4).into()),
            Scalar::F32 => Value::Float(num!(f32, 4).into()),
            Scalar::F64 => Value::Float(num!(f64, 8)),
        })
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), Fault> {
        check_room(self, n, ty.size(), "a list of")?;
        self.pos += (n * ty.size()) as usize;
        Ok(())
    }

    fn end_entry(&mut self) -> Result<(), Fault> {
        Ok(())
    }

    fn location(&self) -> Location {
        Location::Byte(self.at as u64)
    }

    fn left(&self) -> Option<u64> {
        Some(self.bytes.len().saturating_sub(self.pos) as u64)
    }

    fn mark(&mut self) {
        self.at = self.pos;
    }

    fn end_message(&self) -> &'static str {
        "the file ends early"
    }

    fn finish(&mut self) -> Result<(), Fault> {
        Ok(())
    }
}

struct Ascii<'a> {
    lines: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Lines before the data.
    offset: usize,
    line: usize,
    words: std::str::SplitWhitespace<'a>,
}

impl Source for Ascii<'_> {
    fn next_entry(&mut self) -> bool {
        for (i, line) in self.lines.by_ref() {
            self.line = self.offset + i + 1;
            if !line.trim().is_empty() {
                self.words = line.split_whitespace();
                return true;
            }
        }
        false
    }

    fn value(&mut self, ty: Scalar) -> Result<Value, Fault> {
        let token = self.words.next().ok_or(Fault::End)?;
        if ty.is_integer() {
            let (lo, hi) = ty.range();
            match token.parse::<i64>() {
                Ok(v) if (lo..=hi).contains(&v) => Ok(Value::Int(v)),
                Ok(v) => Err(Fault::Bad(format!("{v} is out of range for {}", ty.name()))),
                Err(_) => Err(Fault::Bad(format!("'{token}' is not an integer"))),
            }
        } else {
            token
                .parse::<f64>()
                .map(Value::Float)
                .map_err(|_| Fault::Bad(format!("'{token}' is not a number")))
        }
    }

    fn skip(&mut self, ty: Scalar, n: u64) -> Result<(), Fault> {
        for _ in 0..n {
            self.value(ty)?;
        }
        Ok(())
    }

    fn end_entry(&mut self) -> Result<(), Fault> {
        match self.words.next() {
            None => Ok(()),
            Some(t) => Err(Fault::Bad(format!("unexpected extra value '{t}' at the end of the line"))),
        }
    }

    fn location(&self) -> Location {
        Location::Line(self.line)
    }

    fn left(&self) -> Option<u64> {
        // Nothing is allocated from ascii counts; a short file fails where it ends.
        None
    }

    fn end_message(&self) -> &'static str {
        "the line ends early"
    }

    fn finish(&mut self) -> Result<(), Fault> {
        if self.next_entry() {
            return Err(Fault::Bad(
                "content after the last element (the header's counts do not match the data)".into(),
            ));
        }
        Ok(())
    }
}

/// Fails when `n` items of at least `size` bytes do not fit in the binary data left; the
/// message starts with `what`.
fn check_room(src: &impl Source, n: u64, size: u64, what: &str) -> Result<(), Fault> {
    match (src.left(), n.checked_mul(size)) {
        (None, _) => Ok(()),
        (Some(left), Some(need)) if need <= left => Ok(()),
        (Some(left), need) => Err(Fault::Bad(format!(
            "{what} {n} × {size} bytes = {} bytes, but only {left} bytes are left",
            need.map_or("more than 2^64".to_string(), |b| b.to_string())
        ))),
    }
}

/// Which properties of the vertex and face elements texgeo keeps.
struct Layout {
    vertex: usize,
    xyz: [usize; 3],
    /// The face element and its index-list property.
    face: Option<(usize, usize)>,
}

fn layout(header: &Header, path: &Path) -> Result<Layout> {
    let err = |line: usize, m: String| MeshError::parse(path, Location::Line(line), m);
    let Some(vertex) = header.elements.iter().position(|e| e.name == "vertex") else {
        return Err(err(header.lines, "the header declares no 'vertex' element".into()));
    };
    let ve = &header.elements[vertex];
    if ve.count > u32::MAX.into() {
        return Err(err(ve.line, format!("{} vertices are more than 2^32", ve.count)));
    }
    let mut xyz = [0; 3];
    for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = ve
            .props
            .iter()
            .position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
            .ok_or_else(|| err(ve.line, format!("the vertex element has no scalar property '{name}'")))?;
    }
    let face = match header.elements.iter().position(|e| e.name == "face") {
        None => None,
        Some(f) => {
            let fe = &header.elements[f];
            let list = fe
                .props
                .iter()
                .position(|p| matches!(p.name.as_str(), "vertex_indices" | "vertex_index"))
                .ok_or_else(|| {
                    err(fe.line, "the face element has no 'vertex_indices' or 'vertex_index' property".into())
                })?;
            match fe.props[list].kind {
                Kind::List { item, .. } if item.is_integer() => {}
                _ => {
                    return Err(err(
                        fe.line,
                        format!("face property '{}' must be a list of integers", fe.props[list].name),
                    ));
                }
            }
            Some((f, list))
        }
    };
    Ok(Layout { vertex, xyz, face })
}

/// What [`super::bounded`] lets through of a PLY file: a text header that starts with
/// the line `ply` and ends with `end_header` within [`super::bounded::MAX_HEADER`] bytes,
/// then text again for `format ascii` (binary data is bounded by the memory only).
pub(crate) struct Guard {
    header: super::bounded::Header,
    body: Option<super::bounded::Text>,
}

impl Default for Guard {
    fn default() -> Guard {
        Guard { header: super::bounded::Header::new("a PLY header's", b"end_header"), body: None }
    }
}

impl super::bounded::Guard for Guard {
    fn check(&mut self, bytes: &[u8], from: usize) -> Result<(), super::bounded::Stop> {
        if let Some(body) = &mut self.body {
            return body.check(bytes, from);
        }
        if self.header.header_end.is_some() {
            return Ok(());
        }
        let (text, skipped) = super::text::strip_bom(bytes);
        if let Some(n) = text.iter().position(|&b| b == b'\n')
            && text[..n].trim_ascii() != b"ply"
        {
            return Err(super::bounded::Stop {
                at: skipped as u64,
                why: "not a PLY file (the first line must be 'ply')".into(),
            });
        }
        self.header.check(bytes, from)?;
        if let Some(end) = self.header.header_end {
            let ascii = bytes[..end].split(|&b| b == b'\n').any(|l| {
                l.split(u8::is_ascii_whitespace)
                    .filter(|w| !w.is_empty())
                    .take(2)
                    .eq([&b"format"[..], b"ascii"])
            });
            if ascii {
                let mut body = super::bounded::Text::starting_at("ASCII PLY", end);
                body.check(bytes, end)?;
                self.body = Some(body);
            }
        }
        Ok(())
    }
}

/// Reads a PLY file; `path` only names the source in errors.
pub fn read(bytes: &[u8], path: &Path) -> Result<Mesh> {
    let header = parse_header(bytes, path)?;
    let layout = layout(&header, path)?;
    let data = bytes.get(header.data_start..).unwrap_or_default();
    match header.encoding {
        Encoding::Binary { big_endian } => {
            let mut src = Binary { bytes, pos: header.data_start, at: header.data_start, big_endian };
            read_data(&mut src, &header, &layout, path)
        }
        Encoding::Ascii => {
            let text = utf8(data, path, header.lines, header.data_start)?;
            let mut src = Ascii {
                lines: text.lines().enumerate(),
                offset: header.lines,
                line: header.lines,
                words: "".split_whitespace(),
            };
            read_data(&mut src, &header, &layout, path)
        }
    }
}

fn read_data(src: &mut impl Source, header: &Header, layout: &Layout, path: &Path) -> Result<Mesh> {
    let nv = header.elements[layout.vertex].count;
    let mut out = Collected { positions: Vec::new(), offsets: vec![0], indices: Vec::new() };
    for (ei, el) in header.elements.iter().enumerate() {
        src.mark();
        if let Err(Fault::Bad(m)) = check_room(src, el.count, el.min_size(), "") {
            let m = format!("element '{}' (header line {}) claims{m}", el.name, el.line);
            return Err(MeshError::parse(path, src.location(), m));
        }
        let role = if ei == layout.vertex {
            // Safe now: a binary count was just checked against the bytes left.
            if matches!(header.encoding, Encoding::Binary { .. }) {
                out.positions.reserve_exact(el.count as usize);
            }
            Role::Vertex(layout.xyz)
        } else if let Some((_, list)) = layout.face.filter(|&(f, _)| f == ei) {
            Role::Face { list, nv }
        } else {
            Role::Other
        };
        for k in 0..el.count {
            if !src.next_entry() {
                return Err(MeshError::parse(
                    path,
                    src.location(),
                    format!("the file ends after {k} of {} '{}' entries", el.count, el.name),
                ));
            }
            let mut prop = 0;
            if let Err(fault) = read_entry(src, el, role, &mut prop, &mut out) {
                let m = match fault {
                    Fault::End => src.end_message().to_string(),
                    Fault::Bad(m) => m,
                };
                let name = el.props.get(prop).map_or("", |p| p.name.as_str());
                return Err(MeshError::parse(
                    path,
                    src.location(),
                    format!("{} {k}, property '{name}': {m}", el.name),
                ));
            }
        }
    }
    if let Err(Fault::Bad(m)) = src.finish() {
        return Err(MeshError::parse(path, src.location(), m));
    }
    Mesh::from_parts(out.positions, out.offsets, out.indices)
        .map_err(|e| MeshError::parse(path, Location::File, e.to_string()))
}

/// What an element's entries contribute to the mesh.
#[derive(Clone, Copy)]
enum Role {
    /// Property indices of x, y, z.
    Vertex([usize; 3]),
    /// Property index of the vertex list; number of vertices.
    Face {
        list: usize,
        nv: u64,
    },
    Other,
}

struct Collected {
    positions: Vec<DVec3>,
    offsets: Vec<usize>,
    indices: Vec<u32>,
}

/// Reads one entry of `el`; `prop` tracks the property being read, for error messages.
/// On error, `out` may hold part of the entry: the caller then drops everything.
fn read_entry(
    src: &mut impl Source,
    el: &Element,
    role: Role,
    prop: &mut usize,
    out: &mut Collected,
) -> Result<(), Fault> {
    let mut p = [0.0; 3];
    for (pi, property) in el.props.iter().enumerate() {
        *prop = pi;
        match property.kind {
            Kind::Scalar(ty) => {
                let v = src.value(ty)?;
                if let Role::Vertex(xyz) = role
                    && let Some(c) = xyz.iter().position(|&x| x == pi)
                {
                    let v = v.as_f64();
                    if !v.is_finite() {
                        return Err(Fault::Bad(format!("coordinate {v} is not finite")));
                    }
                    p[c] = v;
                }
            }
            Kind::List { count, item } => {
                let n = match src.value(count)? {
                    Value::Int(n) if n >= 0 => n as u64,
                    v => return Err(Fault::Bad(format!("list length {} is negative", v.as_f64()))),
                };
                let Role::Face { list, nv } = role else {
                    src.skip(item, n)?;
                    continue;
                };
                if list != pi {
                    src.skip(item, n)?;
                    continue;
                }
                if n < 3 {
                    return Err(Fault::Bad(format!("a face needs at least 3 vertices, this one has {n}")));
                }
                check_room(src, n, item.size(), "a list of")?;
                for _ in 0..n {
                    match src.value(item)? {
                        Value::Int(i) if i < 0 => {
                            return Err(Fault::Bad(format!("vertex index {i} is negative")));
                        }
                        Value::Int(i) if (i as u64) < nv => out.indices.push(i as u32),
                        v => {
                            return Err(Fault::Bad(format!(
                                "vertex index {} is out of range (the file has {nv} vertices)",
                                v.as_f64()
                            )));
                        }
                    }
                }
                out.offsets.push(out.indices.len());
            }
        }
    }
    src.end_entry()?;
    if let Role::Vertex(_) = role {
        out.positions.push(DVec3::from_array(p));
    }
    Ok(())
}

/// Writes `binary_little_endian` PLY with `double` coordinates (exact round trip).
pub fn write(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    let count8 = write_header(&mut w, mesh, "binary_little_endian")?;
    for p in mesh.positions() {
        for c in p.to_array() {
            w.write_all(&c.to_le_bytes())?;
        }
    }
    for f in mesh.faces() {
        if count8 {
            w.write_all(&[f.len() as u8])?;
        } else {
            w.write_all(&(f.len() as u32).to_le_bytes())?;
        }
        // `int` and `uint` have the same bytes for indices below 2^31.
        for &i in f {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    w.flush()
}

/// Writes `ascii` PLY with shortest round-trip decimals (exact round trip).
pub fn write_ascii(out: &mut impl Write, mesh: &Mesh) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    write_header(&mut w, mesh, "ascii")?;
    super::text::write_vertices_and_faces(&mut w, mesh)?;
    w.flush()
}

/// Writes the header; returns whether face sizes are written as `uchar` (else `uint`).
/// Indices are `int`, the common choice, unless there are more than 2^31 vertices.
fn write_header(w: &mut impl Write, mesh: &Mesh, format: &str) -> std::io::Result<bool> {
    let count8 = mesh.faces().all(|f| f.len() <= u8::MAX as usize);
    let index32 = mesh.num_vertices() > i32::MAX as usize;
    writeln!(w, "ply")?;
    writeln!(w, "format {format} 1.0")?;
    writeln!(w, "comment written by texgeo")?;
    writeln!(w, "element vertex {}", mesh.num_vertices())?;
    for c in ["x", "y", "z"] {
        writeln!(w, "property double {c}")?;
    }
    writeln!(w, "element face {}", mesh.num_faces())?;
    writeln!(
        w,
        "property list {} {} vertex_indices",
        if count8 { "uchar" } else { "uint" },
        if index32 { "uint" } else { "int" }
    )?;
    writeln!(w, "end_header")?;
    Ok(count8)
}
