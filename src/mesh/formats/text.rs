//! Line-oriented reading shared by the text formats (OFF, OBJ checks, ASCII PLY/STL).

use std::path::Path;

use crate::mesh::{MeshError, error::Location};

/// The non-empty, comment-stripped lines of a text file, with 1-based line numbers.
pub(crate) struct Lines<'a> {
    path: &'a Path,
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Line number of the last line handed out (for "file ends" errors).
    pub last_line: usize,
}

impl<'a> Lines<'a> {
    /// Fails on bytes that are not UTF-8, naming the line and byte offset.
    pub fn new(bytes: &'a [u8], path: &'a Path) -> Result<Lines<'a>, MeshError> {
        let text = utf8(bytes, path, 0, 0)?;
        Ok(Lines { path, inner: text.lines().enumerate(), last_line: 0 })
    }

    /// The next line holding something other than whitespace and a `#` comment.
    pub fn next_content(&mut self) -> Option<(usize, &'a str)> {
        for (i, line) in self.inner.by_ref() {
            self.last_line = i + 1;
            let line = line.split('#').next().unwrap_or("").trim();
            if !line.is_empty() {
                return Some((i + 1, line));
            }
        }
        None
    }

    pub fn error(&self, line: usize, message: impl Into<String>) -> MeshError {
        MeshError::parse(self.path, Location::Line(line), message)
    }
}

/// The UTF-8 byte-order mark some editors put at the start of text files.
pub(crate) const BOM: &[u8] = b"\xef\xbb\xbf";

/// `bytes` without a leading byte-order mark, and the length of what was removed.
pub(crate) fn strip_bom(bytes: &[u8]) -> (&[u8], usize) {
    match bytes.strip_prefix(BOM) {
        Some(rest) => (rest, BOM.len()),
        None => (bytes, 0),
    }
}

/// `bytes` as text, or an error naming the line and byte offset of the first invalid
/// UTF-8 sequence. `lines_before` and `bytes_before` say where `bytes` starts in the file
/// (for text that follows a header); at the start of a file a byte-order mark is skipped.
pub(crate) fn utf8<'a>(
    bytes: &'a [u8],
    path: &Path,
    lines_before: usize,
    bytes_before: usize,
) -> Result<&'a str, MeshError> {
    let (bytes, bytes_before) = if lines_before == 0 && bytes_before == 0 {
        let (rest, skipped) = strip_bom(bytes);
        (rest, skipped)
    } else {
        (bytes, bytes_before)
    };
    std::str::from_utf8(bytes).map_err(|e| {
        let at = e.valid_up_to();
        let line = lines_before + 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        MeshError::parse(
            path,
            Location::Line(line),
            format!("not a text file (invalid UTF-8 at byte {})", bytes_before + at),
        )
    })
}

/// Parses a finite f64, or explains why not.
pub(crate) fn parse_coord(token: &str) -> Result<f64, String> {
    match token.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("coordinate '{token}' is not finite")),
        Err(_) => Err(format!("'{token}' is not a number")),
    }
}

/// Parses a count or index.
pub(crate) fn parse_index(token: &str, what: &str) -> Result<u64, String> {
    token.parse::<u64>().map_err(|_| format!("{what} '{token}' is not a non-negative integer"))
}

/// The body OFF and ASCII PLY share: one `x y z` line per vertex (shortest round-trip
/// decimals, so reading back is exact), then one `n i0 … in-1` line per face.
pub(crate) fn write_vertices_and_faces(
    w: &mut impl std::io::Write,
    mesh: &crate::mesh::Mesh,
) -> std::io::Result<()> {
    for p in mesh.positions() {
        writeln!(w, "{} {} {}", p.x, p.y, p.z)?;
    }
    for f in mesh.faces() {
        write!(w, "{}", f.len())?;
        for i in f {
            write!(w, " {i}")?;
        }
        writeln!(w)?;
    }
    Ok(())
}
