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

    /// The content lines of `bytes` (comment after `#` removed, trimmed, non-empty), or
    /// `None` as soon as a non-ASCII byte shows up.
    pub struct ContentLines<'a> {
        rest: &'a [u8],
        /// A non-ASCII byte was seen: the caller must use the slow path.
        pub failed: bool,
    }

    impl<'a> ContentLines<'a> {
        pub fn new(bytes: &'a [u8]) -> ContentLines<'a> {
            ContentLines { rest: bytes, failed: false }
        }
    }

    impl<'a> Iterator for ContentLines<'a> {
        type Item = &'a [u8];
        #[inline]
        fn next(&mut self) -> Option<&'a [u8]> {
            while !self.rest.is_empty() {
                let end = self.rest.iter().position(|&b| b == b'\n').unwrap_or(self.rest.len());
                let line = &self.rest[..end];
                self.rest = &self.rest[(end + 1).min(self.rest.len())..];
                if !line.is_ascii() {
                    self.failed = true;
                    self.rest = &[];
                    return None;
                }
                let line = match line.iter().position(|&b| b == b'#') {
                    Some(c) => &line[..c],
                    None => line,
                };
                let start = line.iter().position(|&b| !is_space(b)).unwrap_or(line.len());
                let end = line.iter().rposition(|&b| !is_space(b)).map_or(start, |e| e + 1);
                let line = &line[start..end.max(start)];
                if !line.is_empty() {
                    return Some(line);
                }
            }
            None
        }
    }

    /// The whitespace-separated tokens of an ASCII line.
    #[inline]
    pub fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
        line.split(|&b| is_space(b)).filter(|t| !t.is_empty())
    }

    /// A finite f64, parsed exactly as `str::parse` would (correctly rounded); `None` for
    /// anything else (the slow path then explains).
    #[inline]
    pub fn coord(token: &[u8]) -> Option<f64> {
        // Only the characters of decimal numbers: `str::parse` also takes "inf", "nan" and
        // friends, which are refused anyway, and leaves nothing else for fast-float to differ on.
        if !token.iter().all(|&b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+' | b'e' | b'E')) {
            return None;
        }
        let v: f64 = fast_float2::parse(token).ok()?;
        v.is_finite().then_some(v)
    }

    /// A non-negative integer (`str::parse::<u64>` grammar: an optional `+`, then digits).
    #[inline]
    pub fn index(token: &[u8]) -> Option<u64> {
        let digits = token.strip_prefix(b"+").unwrap_or(token);
        if digits.is_empty() || digits.len() > 19 {
            return None;
        }
        let mut v = 0u64;
        for &b in digits {
            if !b.is_ascii_digit() {
                return None;
            }
            v = v * 10 + (b - b'0') as u64;
        }
        Some(v)
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
                    assert_eq!(coord(&t).map(f64::to_bits), std.map(f64::to_bits), "{s}");
                    assert_eq!(index(&t), s.parse::<u64>().ok(), "{s}");
                    tried += 1;
                }
            }
            for s in ["1.5e300", "-0", "0.1", "4.9406564584124654e-324", "1e400", "123456789012345678901"] {
                let std = s.parse::<f64>().ok().filter(|v| v.is_finite());
                assert_eq!(coord(s.as_bytes()).map(f64::to_bits), std.map(f64::to_bits), "{s}");
                assert_eq!(index(s.as_bytes()), s.parse::<u64>().ok(), "{s}");
            }
            assert!(tried > 40_000);
            assert_eq!(coord(b"inf"), None);
            let lines: Vec<&[u8]> = ContentLines::new(b"  a b # c\n\n# x\r\n d\r\n").collect();
            assert_eq!(lines, vec![&b"a b"[..], &b"d"[..]]);
            let mut l = ContentLines::new("1 2\n\u{e9}\n".as_bytes());
            assert_eq!(l.next(), Some(&b"1 2"[..]));
            assert_eq!(l.next(), None);
            assert!(l.failed);
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
