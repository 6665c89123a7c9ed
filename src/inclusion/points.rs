//! Query point files for `texgeo inclusion --points FILE`: text, one point per line
//! (`x y z`, blank lines and `#` comments allowed; errors name the file and line), or NumPy
//! `.npy` (an N×3 array of float64 or float32, either byte order, C or Fortran order).
//! Classes are written as text (one digit per line) or, to a `.npy` path, as an N-element
//! `uint8` array.
//!
//! Text is parsed at disk speed: plain-ASCII files are cut into chunks at line ends and
//! the chunks parsed in parallel, a byte at a time, with a correctly rounded float parser
//! ([`crate::mesh::formats`]' fast path); anything unusual in a chunk sends the whole file
//! to the line-by-line reader, which accepts the same files and words the errors.

use std::io::Write;
use std::path::Path;

use glam::DVec3;
use rayon::prelude::*;

use crate::mesh::MeshError;
use crate::mesh::error::Location;
use crate::mesh::formats::bounded;
use crate::mesh::formats::text::{Lines, fast, parse_coord};
use crate::mesh::frame::Frame;

/// Whether `path` names a NumPy file (by extension).
pub fn is_npy(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("npy"))
}

/// Reads a point file (`.npy` by extension, text otherwise), in bounded blocks that stop
/// at the first byte the format cannot hold ([`bounded`]).
pub fn read(path: impl AsRef<Path>) -> Result<Vec<DVec3>, MeshError> {
    let path = path.as_ref();
    if is_npy(path) {
        let bytes = bounded::read(path, &mut NpyGuard::default())?;
        parse_npy(&bytes, path)
    } else {
        let bytes = bounded::read(path, &mut bounded::Text::new("point-file"))?;
        parse(&bytes, path)
    }
}

/// What [`bounded`] lets through of a `.npy` file: the magic, a text header within
/// [`bounded::MAX_HEADER`] bytes, then no more data than its shape takes.
#[derive(Default)]
struct NpyGuard {
    /// The file's size once the header is read.
    size: Option<u64>,
}

impl bounded::Guard for NpyGuard {
    fn check(&mut self, bytes: &[u8], _from: usize) -> Result<(), bounded::Stop> {
        let stop = |at: usize, why: String| bounded::Stop { at: at as u64, why };
        let magic = b"\x93NUMPY";
        if !magic.starts_with(&bytes[..bytes.len().min(magic.len())]) {
            return Err(stop(0, "not a NumPy .npy file (no \\x93NUMPY magic)".into()));
        }
        if self.size.is_none() {
            // Magic, version, header length (2 or 4 bytes), header.
            let Some(&[major, _]) = bytes.get(6..8) else { return Ok(()) };
            let (len, start) = match major {
                1 => (bytes.get(8..10).map(|b| u16::from_le_bytes([b[0], b[1]]) as usize), 10),
                _ => (bytes.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize), 12),
            };
            let Some(len) = len else { return Ok(()) };
            if len > bounded::MAX_HEADER {
                return Err(stop(
                    8,
                    format!("a .npy header of {len} bytes (at most {} MiB)", bounded::MAX_HEADER >> 20),
                ));
            }
            if bytes.len() < start + len {
                return Ok(());
            }
            let h = npy_header(&bytes[..start + len], Path::new(""))
                .map_err(|e| stop(start, e.to_string().trim_start_matches(": ").to_string()))?;
            let items = h.shape.iter().try_fold(1u64, |n, &d| n.checked_mul(d));
            let size =
                items.and_then(|n| n.checked_mul(h.size as u64)).and_then(|n| n.checked_add(h.data as u64));
            self.size = Some(size.ok_or_else(|| stop(start, "the .npy shape is too large".into()))?);
        }
        match self.size {
            Some(size) if bytes.len() as u64 > size => Err(stop(
                size as usize,
                format!("more bytes than the .npy shape takes ({size} bytes in all)"),
            )),
            _ => Ok(()),
        }
    }
}

/// Parses point-file text; `path` only names the source in errors.
pub fn parse(bytes: &[u8], path: &Path) -> Result<Vec<DVec3>, MeshError> {
    let points = match parse_fast(bytes) {
        Some(points) => points,
        None => parse_lines(bytes, path, 0, 0)?,
    };
    if points.is_empty() {
        return Err(MeshError::parse(path, Location::File, "no points in the file"));
    }
    Ok(points)
}

/// Bytes of text read per block by [`PointReader`]: two parallel chunks per thread (one
/// block is parsed while the next is read, so two are held), between 1 and 4 MiB.
fn block_size() -> usize {
    (2 * CHUNK * rayon::current_num_threads()).clamp(1 << 20, 1 << 22)
}

/// The points of a file a block at a time, so that classifying a file of any size takes
/// bounded memory: text in blocks of whole lines ([`block_size`] bytes), `.npy` in one block.
pub struct PointReader {
    path: std::path::PathBuf,
    source: Source,
    /// Points handed out so far.
    read: usize,
    /// Bytes of text per block.
    block: usize,
    /// The frame the points are handed out in (the mesh's, [`PointReader::in_frame`]).
    frame: Frame,
}

enum Source {
    Text {
        file: std::fs::File,
        /// The size of a regular file (`None`: a pipe, read until it ends).
        len: Option<u64>,
        /// Read and not handed out yet: `buf[..filled]`.
        buf: Vec<u8>,
        filled: usize,
        /// The next block is read into this one while `buf`'s is parsed.
        spare: Vec<u8>,
        lines_before: usize,
        bytes_before: usize,
        eof: bool,
        /// Stops at a byte no point file holds, or at an endless line.
        guard: bounded::Text,
    },
    Whole(Option<Vec<DVec3>>),
}

impl PointReader {
    pub fn open(path: impl AsRef<Path>) -> Result<PointReader, MeshError> {
        PointReader::with_block(path, block_size())
    }

    /// With blocks of about `block` bytes of text.
    pub fn with_block(path: impl AsRef<Path>, block: usize) -> Result<PointReader, MeshError> {
        let path = path.as_ref();
        let io = |error| MeshError::Io { path: path.into(), error };
        let source = if is_npy(path) {
            Source::Whole(Some(read(path)?))
        } else {
            let file = std::fs::File::open(path).map_err(io)?;
            let meta = file.metadata().map_err(io)?;
            // A pipe or a device has no length to size the reads by.
            let len = meta.is_file().then_some(meta.len());
            Source::Text {
                file,
                len,
                buf: Vec::new(),
                filled: 0,
                spare: Vec::new(),
                lines_before: 0,
                bytes_before: 0,
                eof: false,
                guard: bounded::Text::new("point-file"),
            }
        };
        Ok(PointReader { path: path.into(), source, read: 0, block: block.max(1), frame: Frame::IDENTITY })
    }

    /// Points already in memory (random ones), handed out as one block; `name` names them.
    pub fn from_points(points: Vec<DVec3>, name: &str) -> PointReader {
        PointReader {
            path: name.into(),
            source: Source::Whole(Some(points)),
            read: 0,
            block: block_size(),
            frame: Frame::IDENTITY,
        }
    }

    /// Hands the points out in `frame` ([`Frame::point_in`]): the frame of the mesh they
    /// are classified against.
    pub fn in_frame(mut self, frame: Frame) -> PointReader {
        self.frame = frame;
        self
    }

    /// About how many points the file holds: exact for `.npy` and for a text file read
    /// whole, else from the bytes per point so far (at least what was read).
    pub fn estimated_total(&self) -> usize {
        match &self.source {
            Source::Whole(Some(points)) => self.read + points.len(),
            Source::Text { len: Some(len), bytes_before, .. }
                if *bytes_before > 0 && (*bytes_before as u64) < *len =>
            {
                ((*len as f64 / *bytes_before as f64) * self.read as f64).ceil() as usize
            }
            _ => self.read,
        }
    }

    /// The next block of points, `None` after the last (an error if the file held none).
    pub fn next_block(&mut self) -> Result<Option<Vec<DVec3>>, MeshError> {
        Ok(self.next_block_with(|points| points)?.map(|parts| parts.concat()))
    }

    /// The next block, with `f` applied to its points a part at a time (in parallel, each
    /// part in the task that parsed it): `f`'s results in the order of the points.
    pub fn next_block_with<T: Send>(
        &mut self,
        f: impl Fn(Vec<DVec3>) -> T + Sync,
    ) -> Result<Option<Vec<T>>, MeshError> {
        let frame = self.frame;
        let f = |mut points: Vec<DVec3>| {
            if !frame.is_identity() {
                points.iter_mut().for_each(|p| *p = frame.point_in(*p));
            }
            f(points)
        };
        let path = self.path.as_path();
        let io = |error| MeshError::Io { path: path.into(), error };
        let block_size = self.block;
        let (parts, count) = match &mut self.source {
            Source::Whole(points) => match points.take() {
                Some(points) => {
                    let count = points.len();
                    (vec![f(points)], count)
                }
                None => (Vec::new(), 0),
            },
            Source::Text { file, len, buf, filled, spare, lines_before, bytes_before, eof, guard } => loop {
                let stopped = |s: bounded::Stop| {
                    MeshError::parse(path, Location::Byte(s.at), format!("{}; stopped reading", s.why))
                };
                if *eof && *filled == 0 {
                    break (Vec::new(), 0);
                }
                // A whole line at least (or the end of the file) before parsing.
                let last_end = buf[..*filled].iter().rposition(|&b| b == b'\n');
                if !*eof && last_end.is_none() {
                    let before = *filled;
                    *filled = fill(file, buf, *filled, block_size, *len, *bytes_before, eof).map_err(io)?;
                    guard.check_at(&buf[..*filled], before, *bytes_before as u64).map_err(stopped)?;
                    continue;
                }
                let cut = if *eof { *filled } else { last_end.map_or(*filled, |at| at + 1) };
                // Parse this block while the next one is read (after this one's unfinished line).
                let (text, rest) = buf[..*filled].split_at(cut);
                let next_at = *bytes_before + cut;
                let (parsed, next) = rayon::join(
                    || parse_fast_with(text, &f),
                    || -> std::io::Result<usize> {
                        spare.clear();
                        spare.extend_from_slice(rest);
                        fill(file, spare, rest.len(), block_size, *len, next_at, eof)
                    },
                );
                let next = next.map_err(io)?;
                let (parts, count, lines) = match parsed {
                    Some(parts) => {
                        let (count, lines) = parts.iter().fold((0, 0), |(c, l), p| (c + p.1, l + p.2));
                        (parts.into_iter().map(|p| p.0).collect(), count, lines)
                    }
                    None => {
                        let points = parse_lines(text, path, *lines_before, *bytes_before)?;
                        let (count, lines) = (points.len(), text.iter().filter(|&&b| b == b'\n').count());
                        (vec![f(points)], count, lines)
                    }
                };
                // The new bytes, after this block's own errors (which come first in the file).
                let kept = rest.len();
                guard.shift(cut);
                guard.check_at(&spare[..next], kept, next_at as u64).map_err(stopped)?;
                *lines_before += lines;
                *bytes_before += cut;
                std::mem::swap(buf, spare);
                *filled = next;
                if count > 0 {
                    break (parts, count);
                }
            },
        };
        if count > 0 {
            self.read += count;
            Ok(Some(parts))
        } else if self.read == 0 {
            Err(MeshError::parse(path, Location::File, "no points in the file"))
        } else {
            Ok(None)
        }
    }
}

/// Reads from `file` into `buf[held..]` until the buffer — `block` bytes, or twice what it
/// holds — is full or the file ends (`eof` then set); the bytes now held. `buf[0]` is at
/// offset `at` of a file of `len` bytes (`None`: a pipe), so the buffer is never made
/// larger than what is left of it (plus one byte, for the read that sees its end).
fn fill(
    file: &mut std::fs::File,
    buf: &mut Vec<u8>,
    held: usize,
    block: usize,
    len: Option<u64>,
    at: usize,
    eof: &mut bool,
) -> std::io::Result<usize> {
    if *eof {
        return Ok(held);
    }
    let left = len.map_or(usize::MAX / 4, |len| (len as usize).saturating_sub(at + held) + 1);
    buf.resize(block.max(2 * held).min(held + left), 0);
    let mut filled = held;
    while !*eof && filled < buf.len() {
        match std::io::Read::read(file, &mut buf[filled..]) {
            Ok(0) => *eof = true,
            Ok(k) => filled += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(filled)
}

/// Bytes per parallel chunk of text.
const CHUNK: usize = 1 << 18;

/// The fast path: chunks cut at line ends, parsed in parallel; `None` when any chunk holds
/// something the fast parser does not take (the line reader then decides).
fn parse_fast(bytes: &[u8]) -> Option<Vec<DVec3>> {
    let chunks = parse_fast_with(bytes, &|points| points)?;
    let mut points = Vec::with_capacity(chunks.iter().map(|c| c.0.len()).sum());
    for (c, _, _) in chunks {
        points.extend_from_slice(&c);
    }
    Some(points)
}

/// [`parse_fast`] with `f` applied to the points of each chunk in the same parallel task
/// (so a reader can classify while it parses): per chunk, in order, `f`'s result, the
/// number of points and the number of line ends.
fn parse_fast_with<T: Send>(
    bytes: &[u8],
    f: &(impl Fn(Vec<DVec3>) -> T + Sync),
) -> Option<Vec<(T, usize, usize)>> {
    let mut cuts = vec![0];
    while let Some(&last) = cuts.last() {
        if last >= bytes.len() {
            break;
        }
        let at = (last + CHUNK).min(bytes.len());
        let end = bytes[at..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |e| at + e + 1);
        cuts.push(end);
    }
    cuts.par_windows(2)
        .map(|w| {
            let chunk = &bytes[w[0]..w[1]];
            let points = parse_chunk(chunk)?;
            let (count, lines) = (points.len(), chunk.iter().filter(|&&b| b == b'\n').count());
            Some((f(points), count, lines))
        })
        .collect()
}

/// One chunk of whole lines in a single pass ([`fast::Cursor`]): three numbers per content
/// line, read in place and correctly rounded (as `str::parse`); `None` for anything else
/// (another count, a non-number, a non-finite value, a non-ASCII byte), which the line
/// reader then explains.
fn parse_chunk(bytes: &[u8]) -> Option<Vec<DVec3>> {
    let mut c = fast::Cursor::new(bytes);
    let mut out = Vec::with_capacity(bytes.len() / 24);
    while c.next_line() {
        out.push(DVec3::new(c.coord()?, c.coord()?, c.coord()?));
        if !c.at_line_end() {
            return None;
        }
        c.end_line()?;
    }
    Some(out)
}

/// The line-by-line reader: every accepted file, every error with its line.
fn parse_lines(
    bytes: &[u8],
    path: &Path,
    lines_before: usize,
    bytes_before: usize,
) -> Result<Vec<DVec3>, MeshError> {
    let mut lines = Lines::after(bytes, path, lines_before, bytes_before)?;
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
    Ok(points)
}

/// The header of a `.npy` file: element type, order and shape.
struct NpyHeader {
    /// 4 or 8 (float32 or float64).
    size: usize,
    big_endian: bool,
    fortran: bool,
    shape: Vec<u64>,
    /// Offset of the data.
    data: usize,
}

fn npy_header(bytes: &[u8], path: &Path) -> Result<NpyHeader, MeshError> {
    let err = |m: String| MeshError::parse(path, Location::File, m);
    let rest = bytes
        .strip_prefix(b"\x93NUMPY")
        .ok_or_else(|| err("not a NumPy .npy file (no \\x93NUMPY magic)".into()))?;
    let (major, rest) = rest.split_first().ok_or_else(|| err("truncated .npy header".into()))?;
    let rest = rest.get(1..).ok_or_else(|| err("truncated .npy header".into()))?;
    let (len, start) = match major {
        1 => (rest.get(..2).map(|b| u16::from_le_bytes([b[0], b[1]]) as usize), 10),
        2 | 3 => (rest.get(..4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize), 12),
        v => return Err(err(format!(".npy format version {v} is not supported (1, 2 or 3)"))),
    };
    let len = len.ok_or_else(|| err("truncated .npy header".into()))?;
    let text = bytes.get(start..start + len).ok_or_else(|| err("truncated .npy header".into()))?;
    let text = std::str::from_utf8(text).map_err(|_| err("the .npy header is not text".into()))?;
    let field = |key: &str| -> Option<&str> {
        let at = text.find(&format!("'{key}'"))? + key.len() + 2;
        Some(text[at..].trim_start().strip_prefix(':')?.trim_start())
    };
    let descr = field("descr")
        .and_then(|d| d.strip_prefix('\'')?.split('\'').next())
        .ok_or_else(|| err(format!("the .npy header has no 'descr': {text}")))?;
    let (big_endian, size) = match descr {
        "<f8" => (false, 8),
        ">f8" => (true, 8),
        "<f4" => (false, 4),
        ">f4" => (true, 4),
        d => {
            return Err(err(format!(
                "the .npy array holds '{d}'; points must be float64 or float32 ('<f8', '<f4')"
            )));
        }
    };
    let fortran = field("fortran_order").is_some_and(|v| v.starts_with("True"));
    let shape = field("shape")
        .and_then(|s| s.strip_prefix('(')?.split(')').next())
        .ok_or_else(|| err(format!("the .npy header has no 'shape': {text}")))?;
    let shape = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.trim_end_matches('L').parse::<u64>().map_err(|_| err(format!("bad .npy shape ({shape})"))))
        .collect::<Result<Vec<u64>, _>>()?;
    Ok(NpyHeader { size, big_endian, fortran, shape, data: start + len })
}

/// Parses a `.npy` file holding an N×3 float64 or float32 array.
pub fn parse_npy(bytes: &[u8], path: &Path) -> Result<Vec<DVec3>, MeshError> {
    let err = |m: String| MeshError::parse(path, Location::File, m);
    let h = npy_header(bytes, path)?;
    let n = match h.shape[..] {
        [n, 3] => n as usize,
        _ => return Err(err(format!("the .npy array has shape {:?}; points need shape (N, 3)", h.shape))),
    };
    if n == 0 {
        return Err(err("no points in the file".into()));
    }
    let data = &bytes[h.data..];
    let need = n.checked_mul(3 * h.size).ok_or_else(|| err("the .npy shape is too large".into()))?;
    if data.len() != need {
        return Err(err(format!(
            "the .npy data holds {} bytes, but shape ({n}, 3) of {}-byte floats needs {need}",
            data.len(),
            h.size
        )));
    }
    let value = |k: usize| -> f64 {
        let b = &data[k * h.size..(k + 1) * h.size];
        match (h.size, h.big_endian) {
            (8, false) => f64::from_le_bytes(b.try_into().unwrap_or_default()),
            (8, true) => f64::from_be_bytes(b.try_into().unwrap_or_default()),
            (_, false) => f32::from_le_bytes(b.try_into().unwrap_or_default()) as f64,
            (_, true) => f32::from_be_bytes(b.try_into().unwrap_or_default()) as f64,
        }
    };
    let at = |i: usize, c: usize| if h.fortran { c * n + i } else { 3 * i + c };
    let points: Vec<DVec3> = (0..n)
        .into_par_iter()
        .with_min_len(1 << 14)
        .map(|i| DVec3::new(value(at(i, 0)), value(at(i, 1)), value(at(i, 2))))
        .collect();
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(err(format!("point {i} has a coordinate that is not finite ({})", points[i])));
    }
    Ok(points)
}

/// Writes one class per line (`1` inside, `0` outside, `2` on the boundary), in bulk.
pub fn write_classes(out: &mut impl Write, classes: &[super::classifier::Class]) -> std::io::Result<()> {
    let mut buf = Vec::with_capacity(2 * classes.len().min(1 << 20));
    for chunk in classes.chunks(1 << 20) {
        buf.clear();
        for &c in chunk {
            buf.extend_from_slice(&[b'0' + c as u8, b'\n']);
        }
        out.write_all(&buf)?;
    }
    out.flush()
}

/// The header of a version 1 `.npy` file of `descr` elements in C order (also what
/// [`crate::voxel::npy`] writes its volumes with).
pub fn write_npy_header(out: &mut impl Write, descr: &str, shape: &str) -> std::io::Result<()> {
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    // Magic (6) + version (2) + length (2) + header + newline: a multiple of 64 bytes.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    out.write_all(b"\x93NUMPY\x01\x00")?;
    out.write_all(&(header.len() as u16).to_le_bytes())?;
    out.write_all(header.as_bytes())
}

/// Writes points as a `.npy` file: an N×3 little-endian float64 array (what [`read`] takes).
pub fn write_npy(out: &mut impl Write, points: &[DVec3]) -> std::io::Result<()> {
    write_npy_header(out, "<f8", &format!("({}, 3)", points.len()))?;
    for chunk in points.chunks(1 << 16) {
        let bytes: Vec<u8> = chunk.iter().flat_map(|p| p.to_array()).flat_map(f64::to_le_bytes).collect();
        out.write_all(&bytes)?;
    }
    out.flush()
}

/// Writes the classes as a `.npy` file: a 1-D `uint8` array (0 outside, 1 inside, 2 on the
/// boundary), for NumPy users.
pub fn write_classes_npy(out: &mut impl Write, classes: &[super::classifier::Class]) -> std::io::Result<()> {
    write_npy_header(out, "|u1", &format!("({},)", classes.len()))?;
    let bytes: Vec<u8> = classes.iter().map(|&c| c as u8).collect();
    out.write_all(&bytes)?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_one_pass_reader_agrees_with_the_line_reader() {
        let p = Path::new("pts.txt");
        let text = b"1. +2 -.5e-3\n\t1\x0b2\x0c3\r\n  # c\n1e300 0 -0 #x\n7 8 9";
        assert_eq!(parse_chunk(text).unwrap(), parse_lines(text, p, 0, 0).unwrap());
        for bad in [&b"1 2 3 4\n"[..], b"1 2\n", b"1 2 inf\n", b"1 2 3x\n", b"1 2 1e999\n", b"1 2 \xc3\xa9\n"]
        {
            assert!(parse_chunk(bad).is_none(), "{:?}", String::from_utf8_lossy(bad));
            assert!(parse(bad, p).is_err(), "{:?}", String::from_utf8_lossy(bad));
        }
    }

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
        // Many chunks parse in parallel to the same points as the line reader.
        let mut text = String::new();
        let mut rng = crate::random::Rng::new(3);
        for i in 0..120_000 {
            let q = rng.point_in_box(DVec3::splat(-1e3), DVec3::splat(1e3));
            text.push_str(&format!("{} {} {}{}\n", q.x, q.y, q.z, if i % 1000 == 0 { " # c" } else { "" }));
        }
        let fast = parse_fast(text.as_bytes()).unwrap();
        assert_eq!(fast.len(), 120_000);
        assert_eq!(fast, parse_lines(text.as_bytes(), p, 0, 0).unwrap());
        // A bad line late in the file still gets its line number.
        let bad = format!("{text}1 2\n");
        let e = parse(bad.as_bytes(), p).unwrap_err().to_string();
        assert!(e.contains("pts.txt:120001") && e.contains("expected 'x y z', found 2"), "{e}");
    }

    #[test]
    fn blocks_read_the_same_points_and_place_errors() {
        let dir = std::env::temp_dir().join(format!("texgeo-points-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.txt");
        let mut text = String::from("# points\n\n");
        let mut rng = crate::random::Rng::new(5);
        for i in 0..3000 {
            let q = rng.point_in_box(DVec3::splat(-10.0), DVec3::splat(10.0));
            text.push_str(&format!("{} {} {}{}\n", q.x, q.y, q.z, if i % 7 == 0 { "   # note" } else { "" }));
        }
        text.push_str(&format!("# {}\n1 2 3", "x".repeat(5000))); // a line longer than a block, no final newline
        std::fs::write(&path, &text).unwrap();
        let whole = parse(text.as_bytes(), &path).unwrap();
        for block in [1, 100, 4096, 1 << 20] {
            let mut r = PointReader::with_block(&path, block).unwrap();
            let mut got = Vec::new();
            let mut blocks = 0;
            while let Some(b) = r.next_block().unwrap() {
                assert!(r.estimated_total() >= got.len() + b.len());
                got.extend(b);
                blocks += 1;
            }
            assert_eq!(got, whole, "block {block}");
            assert_eq!(r.estimated_total(), whole.len());
            assert!(block > 100_000 || blocks > 1);
        }
        // An error in a late block names its line of the file; non-UTF-8 bytes too.
        for (bad, line, what) in
            [("1 2\n", 3004, "expected 'x y z'"), ("1 2 \u{e9}\n", 3004, "'\u{e9}' is not a number")]
        {
            std::fs::write(&path, format!("{}{bad}", &text[..text.len() - 5])).unwrap();
            let mut r = PointReader::with_block(&path, 4096).unwrap();
            let e = loop {
                match r.next_block() {
                    Ok(Some(_)) => continue,
                    Ok(None) => panic!("no error"),
                    Err(e) => break e.to_string(),
                }
            };
            assert!(e.contains(&format!("p.txt:{line}")) && e.contains(what), "{e}");
        }
        std::fs::write(&path, b"\xff\n1 2 3\n").unwrap();
        let e = PointReader::with_block(&path, 4096).unwrap().next_block().unwrap_err().to_string();
        assert!(e.contains("p.txt:1") && e.contains("invalid UTF-8"), "{e}");
        std::fs::write(&path, "# nothing\n\n").unwrap();
        let e = PointReader::with_block(&path, 4).unwrap().next_block().unwrap_err().to_string();
        assert!(e.contains("no points"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn npy(descr: &str, fortran: bool, shape: &str, data: &[u8]) -> Vec<u8> {
        let h = format!(
            "{{'descr': '{descr}', 'fortran_order': {}, 'shape': {shape}, }}\n",
            if fortran { "True" } else { "False" }
        );
        [
            b"\x93NUMPY\x01\x00".to_vec(),
            (h.len() as u16).to_le_bytes().to_vec(),
            h.into_bytes(),
            data.to_vec(),
        ]
        .concat()
    }

    #[test]
    fn npy_points_in_every_layout_and_classes_out() {
        let p = Path::new("pts.npy");
        let pts = [[1.0, 2.0, 3.0], [4.5, -6.0, 0.25]];
        let le8: Vec<u8> = pts.iter().flatten().flat_map(|v: &f64| v.to_le_bytes()).collect();
        let be4: Vec<u8> = pts.iter().flatten().flat_map(|&v| (v as f32).to_be_bytes()).collect();
        let fo8: Vec<u8> =
            (0..3).flat_map(|c| pts.iter().map(move |q| q[c])).flat_map(|v: f64| v.to_le_bytes()).collect();
        let want: Vec<DVec3> = pts.iter().map(|&q| DVec3::from_array(q)).collect();
        assert_eq!(parse_npy(&npy("<f8", false, "(2, 3)", &le8), p).unwrap(), want);
        assert_eq!(parse_npy(&npy(">f4", false, "(2, 3)", &be4), p).unwrap(), want);
        assert_eq!(parse_npy(&npy("<f8", true, "(2, 3)", &fo8), p).unwrap(), want);
        let e = parse_npy(&npy("<f8", false, "(3, 2)", &le8), p).unwrap_err().to_string();
        assert!(e.starts_with("pts.npy: ") && e.contains("shape (N, 3)"), "{e}");
        let e = parse_npy(&npy("<i8", false, "(2, 3)", &le8), p).unwrap_err().to_string();
        assert!(e.contains("'<i8'") && e.contains("float64 or float32"), "{e}");
        let e = parse_npy(&npy("<f8", false, "(2, 3)", &le8[..40]), p).unwrap_err().to_string();
        assert!(e.contains("holds 40 bytes"), "{e}");
        let nan: Vec<u8> = [0.0, f64::NAN, 0.0].iter().flat_map(|v| v.to_le_bytes()).collect();
        let e = parse_npy(&npy("<f8", false, "(1, 3)", &nan), p).unwrap_err().to_string();
        assert!(e.contains("point 0") && e.contains("not finite"), "{e}");
        assert!(parse_npy(b"OFF\n", p).unwrap_err().to_string().contains("not a NumPy"));
        use super::super::classifier::Class;
        let mut out = Vec::new();
        write_classes_npy(&mut out, &[Class::Inside, Class::Outside, Class::OnBoundary]).unwrap();
        assert_eq!(out.len() % 64, 3);
        assert!(out.starts_with(b"\x93NUMPY\x01\x00"));
        assert!(
            String::from_utf8_lossy(&out).contains("'descr': '|u1', 'fortran_order': False, 'shape': (3,)")
        );
        assert_eq!(&out[out.len() - 3..], &[1, 0, 2]);
        let mut text = Vec::new();
        write_classes(&mut text, &[Class::Inside, Class::Outside, Class::OnBoundary]).unwrap();
        assert_eq!(text, b"1\n0\n2\n");
        let mut out = Vec::new();
        write_npy(&mut out, &want).unwrap();
        assert_eq!(parse_npy(&out, p).unwrap(), want);
    }
}
