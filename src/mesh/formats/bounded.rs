//! Reading an input file whole, a block at a time, never more than it can be.
//!
//! A pipe, a FIFO or a device (`/dev/zero`, a mesh that is a link to `/dev/urandom`) has
//! no size to trust and may never end; a regular file may be larger than the memory. So
//! every mesh, point and volume file is read in blocks of [`BLOCK`] bytes, and after each
//! block the format's [`Guard`] looks at what came: a byte no token of the format can
//! start with (a control byte in a text format, a non-finite coordinate in binary STL), a
//! line longer than [`MAX_LINE`] or a header longer than [`MAX_HEADER`] ends the reading
//! there, with the file and byte offset. A file that keeps coming past what the memory
//! can hold is refused too. What was read whole then goes to the format's parser, which
//! words every other error.

use std::io::Read as _;
use std::path::Path;

use crate::mesh::error::Location;
use crate::mesh::{MeshError, Result};

/// Bytes read at a time.
pub(crate) const BLOCK: usize = 1 << 20;
/// The longest line a text format may have: 16 MiB (a polygon of about two million
/// vertices, or a comment that long).
pub const MAX_LINE: usize = 16 << 20;
/// The longest header a format with a text header may have (PLY, binvox, `.npy`): 1 MiB.
pub const MAX_HEADER: usize = 1 << 20;

/// Where reading stops: the byte offset in the file and why.
#[derive(Debug)]
pub(crate) struct Stop {
    pub at: u64,
    pub why: String,
}

/// A format's look at the bytes read so far.
pub(crate) trait Guard {
    /// `bytes` is everything read so far; `bytes[from..]` came with the last block.
    fn check(&mut self, bytes: &[u8], from: usize) -> Result<(), Stop>;
}

/// Text: no control byte but whitespace (tab, newline, vertical tab, form feed, carriage
/// return), no line longer than [`MAX_LINE`]. `what` names the format in messages.
pub(crate) struct Text {
    what: &'static str,
    /// Where the current line starts.
    line_start: usize,
}

impl Text {
    pub fn new(what: &'static str) -> Text {
        Text { what, line_start: 0 }
    }

    /// Text that starts at byte `at` (after a header).
    pub fn starting_at(what: &'static str, at: usize) -> Text {
        Text { what, line_start: at }
    }

    /// Checks `bytes[from..]`, the continuation of a text whose current line started at
    /// `self.line_start`; offsets in messages are `base` + the index into `bytes`.
    pub fn check_at(&mut self, bytes: &[u8], from: usize, base: u64) -> Result<(), Stop> {
        const ONES: u64 = 0x0101_0101_0101_0101;
        let mut i = from;
        while i < bytes.len() {
            // Eight bytes at a time while none is below 0x20 (the usual case between line
            // ends): `(w − 0x20…) & !w & 0x80…` is zero exactly then.
            if let Some(word) = bytes.get(i..i + 8).and_then(|w| <[u8; 8]>::try_from(w).ok()) {
                let w = u64::from_le_bytes(word);
                let below = w.wrapping_sub(0x20 * ONES) & !w & (0x80 * ONES);
                if below == 0 {
                    i += 8;
                    continue;
                }
                // The lowest flagged byte is the first one below 0x20 (the borrow that can
                // flag a byte by mistake only runs upward from a true one): the bytes
                // before it are plain, and a line end (the usual case) is handled here.
                let k = (below.trailing_zeros() / 8) as usize;
                if bytes[i + k] == b'\n' {
                    self.line_ends(i + k, base)?;
                    self.line_start = i + k + 1;
                    i += k + 1;
                    continue;
                }
            }
            for (k, &b) in bytes[i..bytes.len().min(i + 8)].iter().enumerate() {
                if b >= 0x20 {
                    continue;
                }
                let at = i + k;
                if b == b'\n' {
                    self.line_ends(at, base)?;
                    self.line_start = at + 1;
                } else if !matches!(b, b'\t' | 0x0b | 0x0c | b'\r') {
                    return Err(Stop {
                        at: base + at as u64,
                        why: format!("byte 0x{b:02x} cannot be part of {} text (a control byte)", self.what),
                    });
                }
            }
            i += 8;
        }
        self.line_ends(bytes.len(), base)
    }

    /// Fails when the line running up to `end` is longer than [`MAX_LINE`].
    fn line_ends(&self, end: usize, base: u64) -> Result<(), Stop> {
        if end - self.line_start > MAX_LINE {
            return Err(Stop {
                at: base + self.line_start as u64,
                why: format!("a line longer than {} MiB (the longest a line may be)", MAX_LINE >> 20),
            });
        }
        Ok(())
    }

    /// Moves the line start when the caller drops `n` bytes from the front of its buffer.
    pub fn shift(&mut self, n: usize) {
        self.line_start = self.line_start.saturating_sub(n);
    }
}

impl Guard for Text {
    fn check(&mut self, bytes: &[u8], from: usize) -> Result<(), Stop> {
        self.check_at(bytes, from, 0)
    }
}

/// A text header ending with the line `last` (e.g. `end_header`), then anything: the
/// header is [`Text`] and at most [`MAX_HEADER`] bytes. `header_end` is where the data
/// starts once the header is complete.
pub(crate) struct Header {
    text: Text,
    last: &'static [u8],
    pub header_end: Option<usize>,
}

impl Header {
    pub fn new(what: &'static str, last: &'static [u8]) -> Header {
        Header { text: Text::new(what), last, header_end: None }
    }
}

impl Guard for Header {
    fn check(&mut self, bytes: &[u8], from: usize) -> Result<(), Stop> {
        if self.header_end.is_some() {
            return Ok(());
        }
        // Only the first MAX_HEADER bytes (and one more, to know there are more) matter.
        let end = bytes.len().min(MAX_HEADER + 1);
        let from = from.min(end);
        let mut line_start = self.text.line_start;
        for i in from..end {
            if bytes[i] == b'\n' {
                if bytes[line_start..i].trim_ascii() == self.last {
                    self.text.check_at(&bytes[..i + 1], from, 0)?;
                    self.header_end = Some(i + 1);
                    return Ok(());
                }
                line_start = i + 1;
            }
        }
        self.text.check_at(&bytes[..end], from, 0)?;
        if bytes.len() > MAX_HEADER {
            return Err(Stop {
                at: 0,
                why: format!(
                    "no '{}' line within the first {} MiB (the longest a header may be)",
                    String::from_utf8_lossy(self.last),
                    MAX_HEADER >> 20
                ),
            });
        }
        Ok(())
    }
}

/// Reads `path` whole in blocks, showing each block to `guard`; stops at the guard's
/// first objection or when the memory would not hold the file.
pub(crate) fn read(path: &Path, guard: &mut dyn Guard) -> Result<Vec<u8>> {
    let io = |error| MeshError::Io { path: path.into(), error };
    let mut file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    // A regular file's size is known: check it now. Anything else is checked as it grows.
    let size = meta.is_file().then_some(meta.len());
    let mut next_check = match size {
        Some(size) => {
            memory(path, size)?;
            u64::MAX
        }
        None => 64 << 20,
    };
    let mut bytes = Vec::with_capacity(size.map_or(BLOCK, |s| s as usize + 1));
    loop {
        let from = bytes.len();
        let got = (&mut file).take(BLOCK as u64).read_to_end(&mut bytes).map_err(io)?;
        if got == 0 {
            return Ok(bytes);
        }
        guard.check(&bytes, from).map_err(|s| {
            MeshError::parse(path, Location::Byte(s.at), format!("{}; stopped reading", s.why))
        })?;
        if bytes.len() as u64 >= next_check {
            memory(path, bytes.len() as u64 * 2)?;
            next_check *= 2;
        }
    }
}

/// Fails when `bytes` of the file (and the mesh made of them) would not fit the memory.
fn memory(path: &Path, bytes: u64) -> Result<()> {
    // What is parsed takes about as much again as the file.
    crate::host::check_memory(format!("reading {} MiB", bytes >> 20), u128::from(bytes) * 2)
        .map_err(|m| MeshError::parse(path, Location::File, m))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_stops_at_control_bytes_and_long_lines() {
        let mut t = Text::new("OFF");
        assert!(t.check(b"OFF\r\n\t1 2\x0b3\x0c\n", 0).is_ok());
        let e = Text::new("OFF").check(b"OFF\n1 2\x003\n", 0).unwrap_err();
        assert_eq!((e.at, e.why.as_str()), (7, "byte 0x00 cannot be part of OFF text (a control byte)"));
        // A line split over blocks is measured whole.
        let mut t = Text::new("OBJ");
        let mut text = b"v 1 2 3\n#".to_vec();
        assert!(t.check(&text, 0).is_ok());
        text.resize(8 + MAX_LINE + 2, b'x');
        let e = t.check(&text, 9).unwrap_err();
        assert_eq!(e.at, 8);
        assert!(e.why.contains("longer than 16 MiB"), "{}", e.why);
    }

    /// The word-at-a-time scan stops where a byte-at-a-time one does, with the same line
    /// start, on random texts of plain, high, control and line-end bytes.
    #[test]
    fn the_word_scan_agrees_with_a_byte_scan() {
        let byte_scan = |bytes: &[u8]| -> (Option<u64>, usize) {
            let mut line_start = 0;
            for (at, &b) in bytes.iter().enumerate() {
                if b == b'\n' {
                    line_start = at + 1;
                } else if b < 0x20 && !matches!(b, b'\t' | 0x0b | 0x0c | b'\r') {
                    return (Some(at as u64), line_start);
                }
            }
            (None, line_start)
        };
        let mut rng = crate::random::Rng::new(3);
        let alphabet = b"ab 1.\n\n\r\t\x0b\x00\x1f\x7f\x80\xa0\xe0\xff";
        for len in 0..80 {
            for _ in 0..200 {
                let text: Vec<u8> = (0..len)
                    .map(|_| {
                        let k = rng.below(3 * alphabet.len() as u64) as usize;
                        // Mostly plain bytes, as in real files.
                        alphabet.get(k).copied().unwrap_or(b'7')
                    })
                    .collect();
                let mut t = Text::new("OFF");
                let got = t.check(&text, 0).err().map(|e| e.at);
                let (want, line_start) = byte_scan(&text);
                assert_eq!(got, want, "{text:?}");
                if want.is_none() {
                    assert_eq!(t.line_start, line_start, "{text:?}");
                }
            }
        }
    }

    #[test]
    fn a_header_ends_at_its_last_line_and_has_a_limit() {
        let mut h = Header::new("PLY", b"end_header");
        let bytes = b"ply\nformat binary_little_endian 1.0\nend_header\n\x00\x01\x02";
        assert!(h.check(&bytes[..10], 0).is_ok());
        assert!(h.check(bytes, 10).is_ok());
        assert_eq!(h.header_end, Some(bytes.len() - 3));
        let e = Header::new("PLY", b"end_header").check(b"ply\n\x1b[2J", 0).unwrap_err();
        assert_eq!(e.at, 4);
        let long = vec![b'c'; MAX_HEADER + 10];
        let e = Header::new("PLY", b"end_header").check(&long, 0).unwrap_err();
        assert!(e.why.contains("line longer") || e.why.contains("first 1 MiB"), "{}", e.why);
    }
}
