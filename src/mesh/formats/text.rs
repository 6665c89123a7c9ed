//! Line-oriented reading shared by the text formats (OFF, OBJ checks, ASCII PLY/STL).

use std::path::Path;

use crate::mesh::{MeshError, error::Location};

/// The non-empty, comment-stripped lines of a text file, with 1-based line numbers.
pub(crate) struct Lines<'a> {
    path: &'a Path,
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Lines of the file before `inner`'s first.
    before: usize,
    /// Line number of the last line handed out (for "file ends" errors).
    pub last_line: usize,
}

impl<'a> Lines<'a> {
    /// Fails on bytes that are not UTF-8, naming the line and byte offset.
    pub fn new(bytes: &'a [u8], path: &'a Path) -> Result<Lines<'a>, MeshError> {
        Lines::after(bytes, path, 0, 0)
    }

    /// The lines of `bytes`, a part of a file that starts after `lines_before` lines and
    /// `bytes_before` bytes (for the line numbers and offsets of errors).
    pub fn after(
        bytes: &'a [u8],
        path: &'a Path,
        lines_before: usize,
        bytes_before: usize,
    ) -> Result<Lines<'a>, MeshError> {
        let text = utf8(bytes, path, lines_before, bytes_before)?;
        Ok(Lines { path, inner: text.lines().enumerate(), before: lines_before, last_line: lines_before })
    }

    /// The next line holding something other than whitespace and a `#` comment.
    pub fn next_content(&mut self) -> Option<(usize, &'a str)> {
        for (i, line) in self.inner.by_ref() {
            self.last_line = self.before + i + 1;
            let line = line.split('#').next().unwrap_or("").trim();
            if !line.is_empty() {
                return Some((self.last_line, line));
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
    write_vertices(w, mesh, "")?;
    write_faces(w, mesh, |f, out| {
        out.extend_from_slice(itoa::Buffer::new().format(f.len()).as_bytes());
        0
    })
}

/// One `PREFIXx y z` line per vertex, shortest round-trip decimals.
pub(crate) fn write_vertices(
    w: &mut impl std::io::Write,
    mesh: &crate::mesh::Mesh,
    prefix: &str,
) -> std::io::Result<()> {
    let p = mesh.positions();
    write_in_chunks(w, p.len(), |i, out| {
        out.extend_from_slice(prefix.as_bytes());
        push_f64(out, p[i].x);
        out.push(b' ');
        push_f64(out, p[i].y);
        out.push(b' ');
        push_f64(out, p[i].z);
        out.push(b'\n');
    })
}

/// Appends `x` as `format!("{x}")` does — the shortest decimal that reads back to the
/// same f64, never in exponent form — but through `ryu`, several times faster. The one
/// difference: when two shortest decimals are equally close to `x`, ryu takes the even
/// last digit where `format!` rounds up; both read back to `x`.
pub(crate) fn push_f64(out: &mut Vec<u8>, x: f64) {
    if !x.is_finite() {
        out.extend_from_slice(format!("{x}").as_bytes());
        return;
    }
    let mut buf = ryu::Buffer::new();
    let text = buf.format_finite(x);
    let (sign, text) = match text.strip_prefix('-') {
        Some(t) => ("-", t),
        None => ("", text),
    };
    out.extend_from_slice(sign.as_bytes());
    let Some((mantissa, exp)) = text.split_once('e') else {
        out.extend_from_slice(text.strip_suffix(".0").unwrap_or(text).as_bytes());
        return;
    };
    let exp: i64 = exp.parse().unwrap_or(0);
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits: Vec<u8> = int.bytes().chain(frac.bytes()).collect();
    // Where the decimal point falls among the digits.
    let point = int.len() as i64 + exp;
    if point <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', (-point) as usize));
        out.extend_from_slice(&digits);
    } else if point as usize >= digits.len() {
        out.extend_from_slice(&digits);
        out.extend(std::iter::repeat_n(b'0', point as usize - digits.len()));
    } else {
        out.extend_from_slice(&digits[..point as usize]);
        out.push(b'.');
        out.extend_from_slice(&digits[point as usize..]);
    }
}

/// One line per face: what `start` writes (it returns the index base, 0 or 1), then
/// ` i` per vertex index.
pub(crate) fn write_faces(
    w: &mut impl std::io::Write,
    mesh: &crate::mesh::Mesh,
    start: impl Fn(&[u32], &mut Vec<u8>) -> u64 + Sync,
) -> std::io::Result<()> {
    write_in_chunks(w, mesh.num_faces(), |f, out| {
        let face = mesh.face(f);
        let base = start(face, out);
        let mut digits = itoa::Buffer::new();
        for &i in face {
            out.push(b' ');
            out.extend_from_slice(digits.format(u64::from(i) + base).as_bytes());
        }
        out.push(b'\n');
    })
}

/// Writes the lines of `count` items, formatted in parallel (rayon's global pool) in
/// chunks and written in item order: the same bytes as formatting them one by one, for
/// any number of threads. A few chunks per thread are held at a time.
pub(crate) fn write_in_chunks(
    w: &mut impl std::io::Write,
    count: usize,
    line: impl Fn(usize, &mut Vec<u8>) + Sync,
) -> std::io::Result<()> {
    use rayon::prelude::*;
    const CHUNK: usize = 1 << 14;
    let batch = CHUNK * 4 * rayon::current_num_threads().max(1);
    for first in (0..count).step_by(batch) {
        let end = (first + batch).min(count);
        let chunks: Vec<Vec<u8>> = (first..end)
            .step_by(CHUNK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|c| {
                let mut out = Vec::with_capacity(64 * CHUNK);
                for i in c..(c + CHUNK).min(end) {
                    line(i, &mut out);
                }
                out
            })
            .collect();
        for chunk in chunks {
            w.write_all(&chunk)?;
        }
    }
    Ok(())
}

/// The fast path of the text readers: the same grammar as [`Lines`] + [`parse_coord`] /
/// [`parse_index`] on plain ASCII, a byte at a time, without allocating. Anything it is not
/// sure of (a non-ASCII byte, a token it cannot parse) makes it give up (`None`), and the
/// reader runs its line-by-line path, which accepts the same files and words the errors.
pub(crate) mod fast {
    /// ASCII whitespace as `str::split_whitespace` and `str::trim` see it.
    #[inline]
    fn is_space(b: u8) -> bool {
        b == b' ' || (9..=13).contains(&b)
    }

    /// Spaces inside a line: [`is_space`] but the newline.
    #[inline]
    fn is_inline_space(b: u8) -> bool {
        b != b'\n' && is_space(b)
    }

    /// Reads whitespace-separated numbers from ASCII text in one pass, line by line, in
    /// place: no per-line or per-token allocation and no second look at a byte. Every
    /// reader returns `None` for anything the line-by-line readers might word differently
    /// (a non-ASCII byte, a malformed or non-finite number), which then decide.
    pub struct Cursor<'a> {
        bytes: &'a [u8],
        at: usize,
    }

    impl<'a> Cursor<'a> {
        pub fn new(bytes: &'a [u8]) -> Cursor<'a> {
            Cursor { bytes, at: 0 }
        }

        /// Moves to the first token of the next content line (skipping blank lines and
        /// `#` comments); false at the end of the text.
        pub fn next_line(&mut self) -> bool {
            loop {
                while self.at < self.bytes.len() && is_space(self.bytes[self.at]) {
                    self.at += 1;
                }
                match self.bytes.get(self.at) {
                    None => return false,
                    Some(b'#') => {
                        if self.end_line().is_none() {
                            return false;
                        }
                    }
                    Some(_) => return true,
                }
            }
        }

        /// Skips the rest of the line (extra values, a comment), which must be ASCII.
        pub fn end_line(&mut self) -> Option<()> {
            let rest = &self.bytes[self.at..];
            let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
            if !rest[..len].is_ascii() {
                return None;
            }
            self.at += (len + 1).min(rest.len());
            Some(())
        }

        /// True at the end of the line's tokens (its end, or a comment).
        pub fn at_line_end(&mut self) -> bool {
            self.skip_inline_spaces();
            matches!(self.bytes.get(self.at), None | Some(b'\n' | b'#'))
        }

        #[inline]
        fn skip_inline_spaces(&mut self) {
            while self.at < self.bytes.len() && is_inline_space(self.bytes[self.at]) {
                self.at += 1;
            }
        }

        /// The next token ends here: a space, a comment, the line's or the text's end.
        #[inline]
        fn delimited(&self) -> bool {
            self.bytes.get(self.at).is_none_or(|&b| is_space(b) || b == b'#')
        }

        /// The next token of the line, whatever it holds.
        pub fn word(&mut self) -> Option<&'a [u8]> {
            self.skip_inline_spaces();
            let start = self.at;
            while !self.delimited() {
                self.at += 1;
            }
            (self.at > start).then(|| &self.bytes[start..self.at])
        }

        /// The next token of the line as a finite f64, correctly rounded like [`coord`].
        #[inline]
        pub fn coord(&mut self) -> Option<f64> {
            self.skip_inline_spaces();
            // Only the characters that start decimal numbers ("inf", "nan": slow path).
            let &first = self.bytes.get(self.at)?;
            if !(first.is_ascii_digit() || matches!(first, b'.' | b'-' | b'+')) {
                return None;
            }
            let (v, used): (f64, usize) = fast_float2::parse_partial(&self.bytes[self.at..]).ok()?;
            self.at += used;
            (used > 0 && v.is_finite() && self.delimited()).then_some(v)
        }

        /// The next token of the line as a non-negative integer, like [`index`].
        #[inline]
        pub fn index(&mut self) -> Option<u64> {
            self.skip_inline_spaces();
            if self.bytes.get(self.at) == Some(&b'+') {
                self.at += 1;
            }
            let start = self.at;
            let mut v = 0u64;
            while let Some(&b) = self.bytes.get(self.at).filter(|b| b.is_ascii_digit()) {
                v = v.wrapping_mul(10).wrapping_add((b - b'0') as u64);
                self.at += 1;
            }
            let digits = self.at - start;
            (digits > 0 && digits <= 19 && self.delimited()).then_some(v)
        }
    }

    #[cfg(test)]
    mod tests {
        use super::*;
        use crate::random::Rng;

        #[test]
        fn numbers_parse_like_the_standard_library() {
            let mut rng = Rng::new(11);
            let alphabet = b"0123456789.-+eE";
            let mut tried = 0;
            for len in 1..12 {
                for _ in 0..4000 {
                    let t: Vec<u8> =
                        (0..len).map(|_| alphabet[rng.below(alphabet.len() as u64) as usize]).collect();
                    let s = std::str::from_utf8(&t).unwrap();
                    let std = s.parse::<f64>().ok().filter(|v| v.is_finite());
                    // The cursor, with the token ending at a space or at the end of the text.
                    for text in [t.clone(), [&t[..], b" 7"].concat()] {
                        let got = Cursor::new(&text).coord();
                        assert_eq!(got.map(f64::to_bits), std.map(f64::to_bits), "{s}");
                        assert_eq!(Cursor::new(&text).index(), s.parse::<u64>().ok(), "{s}");
                    }
                    tried += 1;
                }
            }
            for s in ["1.5e300", "-0", "0.1", "4.9406564584124654e-324", "1e400", "123456789012345678901"] {
                let std = s.parse::<f64>().ok().filter(|v| v.is_finite());
                assert_eq!(Cursor::new(s.as_bytes()).coord().map(f64::to_bits), std.map(f64::to_bits), "{s}");
                // 21 digits: not a u64 for either.
                assert_eq!(Cursor::new(s.as_bytes()).index(), s.parse::<u64>().ok(), "{s}");
            }
            assert!(tried > 40_000);
            assert_eq!(Cursor::new(b"inf").coord(), None);
            let mut c = Cursor::new(b"  a b # c\n\n# x\r\n d\r\n");
            assert!(c.next_line());
            assert_eq!((c.word(), c.word(), c.word()), (Some(&b"a"[..]), Some(&b"b"[..]), None));
            assert!(c.at_line_end() && c.end_line().is_some() && c.next_line());
            assert_eq!(c.word(), Some(&b"d"[..]));
            assert!(c.end_line().is_some() && !c.next_line());
            let mut c = Cursor::new("1 2\n\u{e9}\n".as_bytes());
            assert!(c.next_line());
            assert_eq!((c.index(), c.coord()), (Some(1), Some(2.0)));
            assert!(c.end_line().is_some() && c.next_line());
            assert_eq!(c.end_line(), None);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    #[test]
    fn fast_decimals_are_the_shortest_that_read_back() {
        let mut rng = Rng::new(13);
        let mut values =
            vec![0.0, -0.0, 1.0, -1.0, 0.1, 1e-7, 1e16, 1e22, 123456.0, 5e-324, f64::MAX, f64::MIN_POSITIVE];
        values.extend((-330..310).map(|e| 10f64.powi(e)));
        for _ in 0..200_000 {
            let bits = rng.next_u64();
            values.push(f64::from_bits(bits));
            values.push(f64::from(f32::from_bits(bits as u32)));
            values.push((rng.next_f64() - 0.5) * 10f64.powi((bits % 40) as i32 - 20));
        }
        let mut out = Vec::new();
        let mut ties = 0;
        for x in values.into_iter().filter(|x| x.is_finite()) {
            out.clear();
            push_f64(&mut out, x);
            let text = std::str::from_utf8(&out).unwrap();
            let display = format!("{x}");
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{text} for {x:e}");
            assert_eq!(text.len(), display.len(), "{text} vs {display}");
            // Equal but for the last digit, and only in a tie (rare).
            if text != display {
                assert_eq!(text[..text.len() - 1], display[..display.len() - 1], "{text} vs {display}");
                ties += 1;
            }
        }
        // About 0.2 % of these samples are ties.
        assert!(ties < 2_000, "{ties} ties");
    }
}
