//! The binvox format (Patrick Min's), so other tools read texgeo's volumes: a text
//! header — `#binvox 1`, `dim N N N`, `translate` (the cube's minimum corner), `scale`
//! (the cube's side), `data` — then run-length pairs (value byte, count byte 1..=255) in
//! binvox order: index = x·N² + z·N + y (y fastest). Writing streams the runs, found 64
//! voxels at a time from transposed bit blocks (a 1024³ volume encodes in well under a
//! second), into an atomically replaced file.

use std::io::Write;
use std::path::Path;

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::{Grid, MAX_RES};
use super::scanline;
use super::solid::Solid;
use super::volume::Volume;
use crate::mesh::MeshError;
use crate::mesh::formats::bounded;

/// Encodes `volume` on `grid` as a binvox file.
pub fn to_bytes(grid: &Grid, volume: &Volume) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    write_to(&mut out, grid, volume).map_err(|e| match e.downcast::<VoxelError>() {
        Ok(v) => v,
        Err(e) => VoxelError::Usage(format!("encoding binvox: {e}")),
    })?;
    Ok(out)
}

/// Writes `volume` as a binvox file, atomically ([`crate::output`]).
pub fn write(path: impl AsRef<Path>, grid: &Grid, volume: &Volume) -> Result<()> {
    let path = path.as_ref();
    if grid.n != volume.n() {
        return Err(VoxelError::Usage(format!("a {}³ grid with a {}³ volume", grid.n, volume.n())));
    }
    Ok(crate::output::write_with(path, |w| write_to(w, grid, volume))?)
}

/// Streams the binvox encoding of `volume` to `out`.
///
/// binvox runs go along y (index x·N² + z·N + y) while the volume stores rows along x, so
/// the encoder works on groups of 64-x-value blocks: for each z it gathers the rows'
/// words of the group and transposes each 64×64 bit block, which gives 64 y-columns at
/// once; the runs of each column are then found a word at a time (trailing zeros), not a
/// voxel at a time. Groups are encoded in parallel (rayon's global pool) into lists of
/// runs, which are joined in x order, so the bytes do not depend on the number of threads.
pub fn write_to(out: &mut impl Write, grid: &Grid, volume: &Volume) -> std::io::Result<()> {
    let n = volume.n();
    if grid.n != n {
        return Err(std::io::Error::other(VoxelError::Usage(format!(
            "a {}³ grid with a {n}³ volume",
            grid.n
        ))));
    }
    header(out, grid)?;
    let mut runs = Runs::new(out);
    let wpr = volume.words_per_row();
    // Words of a row read together: a cache line's worth (8) reads the volume once, but a
    // group holds the columns of all its x values (8·64·N² bits, 64 MiB at 1024³), so with
    // more threads each group gets fewer words and at most 8 groups are in memory at once:
    // the encoder never needs more than half the volume's size besides the volume.
    // Small volumes are split too, so that every thread gets a group.
    let threads = rayon::current_num_threads().clamp(1, 8);
    let g = (8 / threads).min(wpr.div_ceil(threads)).max(1);
    let groups: Vec<usize> = (0..wpr).step_by(g).collect();
    for batch in groups.chunks(threads) {
        use rayon::prelude::*;
        let lists: Vec<RunList> = batch
            .par_iter()
            .map(|&w0| {
                let mut list = RunList::default();
                encode_group(volume, w0, g.min(wpr - w0), &mut list);
                list
            })
            .collect();
        for list in &lists {
            runs.add_list(list)?;
        }
    }
    runs.finish()
}

fn header(out: &mut impl Write, grid: &Grid) -> std::io::Result<()> {
    let (n, (m, side)) = (grid.n, grid.cube_out());
    write!(out, "#binvox 1\ndim {n} {n} {n}\ntranslate {} {} {}\nscale {}\ndata\n", m.x, m.y, m.z, side)
}

/// How [`write_scanline`] produced its file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Streamed {
    /// Occupied voxels.
    pub occupied: u64,
    /// The planes could not be finished (a row met the surface an odd number of times),
    /// so the whole volume was computed by [`scanline::voxelize`] and written instead.
    pub whole_volume: bool,
}

/// The scanline volume of `solid` on `grid`, written as a binvox file (atomically)
/// while it is computed, x plane by x plane ([`scanline::x_planes`]), so memory holds a
/// few planes instead of the N³ bits. The bytes are those [`write`] gives for
/// [`scanline::voxelize`]'s volume.
pub fn write_scanline(path: impl AsRef<Path>, grid: &Grid, solid: &Solid) -> Result<Streamed> {
    use rayon::prelude::*;
    let path = path.as_ref();
    let mut occupied = 0;
    let streamed = crate::output::write_with(path, |out| {
        header(out, grid)?;
        let mut runs = Runs::new(out);
        occupied = scanline::x_planes(solid, grid, |planes| {
            let n = planes.n();
            // Planes are encoded in parallel, their runs joined in order.
            let lists: Vec<RunList> = (0..planes.len())
                .into_par_iter()
                .map(|p| {
                    let mut list = RunList::default();
                    for k in 0..n {
                        list.column(planes.row(p, k), n);
                    }
                    list
                })
                .collect();
            for list in &lists {
                runs.add_list(list)?;
            }
            Ok(())
        })?;
        runs.finish()
    });
    match streamed {
        Ok(()) => Ok(Streamed { occupied, whole_volume: false }),
        Err(e) if e.error.get_ref().is_some_and(|inner| inner.is::<scanline::OddRow>()) => {
            let volume = scanline::voxelize(solid, grid)?;
            write(path, grid, &volume)?;
            Ok(Streamed { occupied: volume.count(), whole_volume: true })
        }
        Err(e) => Err(e.into()),
    }
}

/// The runs of the voxels with x in 64·w0 .. 64·(w0 + gw), in binvox order.
fn encode_group(volume: &Volume, w0: usize, gw: usize, runs: &mut RunList) {
    let n = volume.n();
    let ybs = n.div_ceil(64);
    let (words, wpr) = (volume.words(), volume.words_per_row());
    // Rows of consecutive z are adjacent in memory: Z_CHUNK of them are gathered together.
    const Z_CHUNK: usize = 16;
    // columns[((g·64 + xl)·N + z)·ybs + yb]: bit r = voxel (64·(w0 + g) + xl, 64·yb + r, z).
    let mut columns = vec![0u64; gw * 64 * n * ybs];
    let mut stage = vec![[0u64; 64]; gw * Z_CHUNK * ybs];
    let xs = |g: usize| (n - 64 * (w0 + g)).min(64);
    for z0 in (0..n).step_by(Z_CHUNK) {
        let zs = (n - z0).min(Z_CHUNK);
        let slot = |g: usize, dz: usize, yb: usize| (g * Z_CHUNK + dz) * ybs + yb;
        for y in 0..ybs * 64 {
            let (yb, r) = (y / 64, y % 64);
            for dz in 0..zs {
                let row = (y * n + z0 + dz) * wpr + w0;
                for g in 0..gw {
                    stage[slot(g, dz, yb)][r] = if y < n { words[row + g] } else { 0 };
                }
            }
        }
        for g in 0..gw {
            for dz in 0..zs {
                for yb in 0..ybs {
                    transpose64(&mut stage[slot(g, dz, yb)]);
                }
            }
            // xl outermost, so each column's ybs words are written together.
            #[allow(clippy::needless_range_loop)]
            for xl in 0..xs(g) {
                for dz in 0..zs {
                    let at = ((g * 64 + xl) * n + z0 + dz) * ybs;
                    for (yb, c) in columns[at..at + ybs].iter_mut().enumerate() {
                        *c = stage[slot(g, dz, yb)][xl];
                    }
                }
            }
        }
    }
    for g in 0..gw {
        for xl in 0..xs(g) {
            for z in 0..n {
                let at = ((g * 64 + xl) * n + z) * ybs;
                runs.column(&columns[at..at + ybs], n);
            }
        }
    }
}

/// Maximal runs (value, length) of a stretch of voxels, in order.
#[derive(Default)]
struct RunList {
    runs: Vec<(u8, u64)>,
}

impl RunList {
    fn add(&mut self, value: u8, count: u64) {
        match self.runs.last_mut() {
            Some((v, c)) if *v == value => *c += count,
            _ if count > 0 => self.runs.push((value, count)),
            _ => {}
        }
    }

    /// Appends the N voxels of a column along y held in `words` (64 per word, bit 0 first).
    fn column(&mut self, words: &[u64], n: usize) {
        for (w, &bits) in words.iter().enumerate() {
            self.bits(bits, (n - 64 * w).min(64));
        }
    }

    /// Appends the first `len` bits of `bits` (bit 0 first).
    fn bits(&mut self, bits: u64, len: usize) {
        // Most words of a solid are all empty or all full.
        let full = if len == 64 { u64::MAX } else { (1u64 << len) - 1 };
        if bits & full == 0 {
            return self.add(0, len as u64);
        }
        if bits & full == full {
            return self.add(1, len as u64);
        }
        let mut i = 0;
        while i < len {
            let v = (bits >> i & 1) as u8;
            // The run of v starting at bit i: up to the first bit that differs.
            let differ = if v == 1 { !bits } else { bits } >> i;
            let run = (differ.trailing_zeros() as usize).min(len - i);
            self.add(v, run as u64);
            i += run;
        }
    }
}

/// Run-length pairs (value, count ≤ 255), buffered.
struct Runs<'a, W: Write> {
    out: &'a mut W,
    buf: Vec<u8>,
    value: u8,
    count: usize,
}

impl<'a, W: Write> Runs<'a, W> {
    fn new(out: &'a mut W) -> Self {
        Runs { out, buf: Vec::with_capacity(1 << 16), value: 0, count: 0 }
    }

    /// Appends `count` voxels of `value`.
    fn add(&mut self, value: u8, count: usize) -> std::io::Result<()> {
        if value != self.value {
            self.flush_run()?;
            self.value = value;
        }
        self.count += count;
        Ok(())
    }

    /// Appends a list of runs.
    fn add_list(&mut self, list: &RunList) -> std::io::Result<()> {
        for &(value, count) in &list.runs {
            self.add(value, count as usize)?;
        }
        Ok(())
    }

    fn flush_run(&mut self) -> std::io::Result<()> {
        while self.count > 0 {
            let c = self.count.min(255);
            self.buf.extend_from_slice(&[self.value, c as u8]);
            self.count -= c;
        }
        if self.buf.len() >= 1 << 16 {
            self.out.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    fn finish(mut self) -> std::io::Result<()> {
        self.flush_run()?;
        self.out.write_all(&self.buf)
    }
}

/// Transposes a 64×64 bit matrix in place: bit c of word r becomes bit r of word c
/// (recursive block swaps, Hacker's Delight §7-3).
fn transpose64(a: &mut [u64; 64]) {
    let mut j = 32;
    let mut m: u64 = 0x0000_0000_ffff_ffff;
    while j != 0 {
        let mut k = 0;
        while k < 64 {
            let t = (a[k] >> j ^ a[k + j]) & m;
            a[k + j] ^= t;
            a[k] ^= t << j;
            k = (k + j + 1) & !j;
        }
        j >>= 1;
        m ^= m << j;
    }
}

/// Reads a binvox file (cubic, N ≤ [`MAX_RES`]), in bounded blocks that stop at the
/// first byte a binvox file cannot hold ([`bounded`]).
pub fn read(path: impl AsRef<Path>) -> Result<(Grid, Volume)> {
    let path = path.as_ref();
    let bytes = bounded::read(path, &mut Guard::default()).map_err(|e| match e {
        MeshError::Io { path, error } => VoxelError::io(path, error),
        other => VoxelError::Binvox { path: path.to_path_buf(), message: other.to_string() },
    })?;
    from_bytes(&bytes, path)
}

/// What [`bounded`] lets through of a binvox file: a text header starting with `#binvox`
/// and ending with the line `data`, then (value, count) runs with value 0 or 1 and count
/// at least 1 that cover no more than the dim³ voxels.
struct Guard {
    header: bounded::Header,
    /// Voxels of the volume (from the `dim` line) and voxels covered by the runs so far.
    voxels: u64,
    covered: u64,
    /// The next run to check starts here.
    run: usize,
}

impl Default for Guard {
    fn default() -> Guard {
        Guard { header: bounded::Header::new("a binvox header's", b"data"), voxels: 0, covered: 0, run: 0 }
    }
}

impl bounded::Guard for Guard {
    fn check(&mut self, bytes: &[u8], from: usize) -> std::result::Result<(), bounded::Stop> {
        let stop = |at: usize, why: String| bounded::Stop { at: at as u64, why };
        if self.header.header_end.is_none() {
            if !b"#binvox".starts_with(&bytes[..bytes.len().min(7)]) {
                return Err(stop(0, "not a binvox file (it must start with '#binvox')".into()));
            }
            self.header.check(bytes, from)?;
            let Some(end) = self.header.header_end else { return Ok(()) };
            let dim = bytes[..end].split(|&b| b == b'\n').find_map(|l| {
                let l = std::str::from_utf8(l).ok()?.trim();
                l.strip_prefix("dim")?.split_whitespace().next()?.parse::<u64>().ok()
            });
            self.voxels = dim.filter(|&d| d <= MAX_RES as u64).map_or(0, |d| d * d * d);
            self.run = end;
        }
        while let Some(&[value, count]) = bytes.get(self.run..self.run + 2) {
            if value > 1 || count == 0 {
                return Err(stop(
                    self.run,
                    format!(
                        "a run of value {value} and count {count} (runs are a value 0 or 1 and a count ≥ 1)"
                    ),
                ));
            }
            self.covered += u64::from(count);
            if self.covered > self.voxels {
                return Err(stop(
                    self.run,
                    format!("the runs cover more than the {} voxels of its dim", self.voxels),
                ));
            }
            self.run += 2;
        }
        Ok(())
    }
}

/// Decodes a binvox file held in memory; `path` only names it in errors.
pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<(Grid, Volume)> {
    let err = |message: String| VoxelError::Binvox { path: path.to_path_buf(), message };
    // The header is text up to and including the line "data".
    let mut pos = 0;
    let mut line_no = 0;
    let mut next_line = |pos: &mut usize| -> Result<String> {
        line_no += 1;
        let rest = &bytes[*pos..];
        let end =
            rest.iter().take(256).position(|&b| b == b'\n').ok_or_else(|| {
                err(format!("line {line_no}: header line missing or longer than 255 bytes"))
            })?;
        *pos += end + 1;
        std::str::from_utf8(&rest[..end])
            .map(|s| s.trim().to_string())
            .map_err(|_| err(format!("line {line_no}: header is not text")))
    };
    let first = next_line(&mut pos)?;
    if !first.starts_with("#binvox") {
        return Err(err("not a binvox file (no '#binvox' on the first line)".into()));
    }
    let (mut dim, mut translate, mut scale) = (None, None, None);
    let numbers = |line: &str, count: usize| -> Option<Vec<f64>> {
        let v: Vec<f64> = line.split_whitespace().skip(1).map(|t| t.parse().ok()).collect::<Option<_>>()?;
        (v.len() == count && v.iter().all(|x| x.is_finite())).then_some(v)
    };
    loop {
        let line = next_line(&mut pos)?;
        let key = line.split_whitespace().next().unwrap_or("");
        match key {
            "data" => break,
            "dim" => {
                let d: Vec<usize> = line
                    .split_whitespace()
                    .skip(1)
                    .map(|t| t.parse().ok())
                    .collect::<Option<_>>()
                    .filter(|d: &Vec<usize>| d.len() == 3)
                    .ok_or_else(|| err(format!("bad dim line '{line}'")))?;
                if d[0] != d[1] || d[1] != d[2] {
                    return Err(err(format!(
                        "dim {} {} {}: only cubic volumes are supported",
                        d[0], d[1], d[2]
                    )));
                }
                if d[0] == 0 || d[0] > MAX_RES {
                    return Err(err(format!("dim {}: outside 1..={MAX_RES}", d[0])));
                }
                dim = Some(d[0]);
            }
            "translate" => {
                let v = numbers(&line, 3).ok_or_else(|| err(format!("bad translate line '{line}'")))?;
                translate = Some(DVec3::new(v[0], v[1], v[2]));
            }
            "scale" => {
                scale = Some(numbers(&line, 1).ok_or_else(|| err(format!("bad scale line '{line}'")))?[0]);
            }
            "" => {}
            other => return Err(err(format!("unknown header line '{other}'"))),
        }
    }
    let n = dim.ok_or_else(|| err("no dim line".into()))?;
    let grid = Grid::new(n, translate.unwrap_or(DVec3::ZERO), scale.unwrap_or(1.0))
        .map_err(|e| err(format!("bad grid: {e}")))?;
    let mut volume = Volume::new(n)?;
    let total = (n as u64).pow(3);
    let mut index = 0u64;
    let data = &bytes[pos..];
    if data.len() % 2 != 0 {
        return Err(err(format!("{} bytes of run-length data: not whole (value, count) pairs", data.len())));
    }
    for (p, pair) in data.chunks_exact(2).enumerate() {
        let (value, count) = (pair[0], pair[1] as u64);
        if value > 1 || count == 0 {
            return Err(err(format!("run {p} at byte {}: value {value}, count {count}", pos + 2 * p)));
        }
        if index + count > total {
            return Err(err(format!("runs cover more than the {total} voxels of dim {n}")));
        }
        if value == 1 {
            for idx in index..index + count {
                let idx = idx as usize;
                let (x, z, y) = (idx / (n * n), idx / n % n, idx % n);
                volume.set(x, y, z, true);
            }
        }
        index += count;
    }
    if index != total {
        return Err(err(format!("runs cover {index} of the {total} voxels of dim {n}")));
    }
    Ok((grid, volume))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::Rng;

    /// The plain encoder: every voxel in binvox order, one at a time.
    fn reference(volume: &Volume) -> Vec<u8> {
        let n = volume.n();
        let mut out = Vec::new();
        let (mut value, mut count) = (false, 0u8);
        for x in 0..n {
            for z in 0..n {
                for y in 0..n {
                    let v = volume.get(x, y, z);
                    if count > 0 && (v != value || count == 255) {
                        out.extend_from_slice(&[value as u8, count]);
                        count = 0;
                    }
                    value = v;
                    count += 1;
                }
            }
        }
        out.extend_from_slice(&[value as u8, count]);
        out
    }

    #[test]
    fn bulk_encoding_equals_the_voxel_by_voxel_one() {
        let mut rng = Rng::new(9);
        let mut t = [0u64; 64];
        for w in t.iter_mut() {
            *w = rng.next_u64();
        }
        let mut tt = t;
        transpose64(&mut tt);
        for (r, c) in (0..64).flat_map(|r| (0..64).map(move |c| (r, c))) {
            assert_eq!(t[r] >> c & 1, tt[c] >> r & 1, "({r}, {c})");
        }
        for n in [1, 5, 37, 64, 65, 130, 300] {
            for density in [0.0, 0.02, 0.5, 0.98, 1.0] {
                let mut v = Volume::new(n).unwrap();
                // Blobs along y (long runs) and noise (short ones).
                for k in 0..n {
                    for j in 0..n {
                        for i in 0..n {
                            let blob = (i / 7 + j / 300 + k / 5) % 3 == 0;
                            if rng.next_f64() < density || (density > 0.0 && density < 1.0 && blob) {
                                v.set(i, j, k, true);
                            }
                        }
                    }
                }
                let grid = Grid::new(n, glam::DVec3::new(-1.0, 2.0, 0.5), 3.0).unwrap();
                let bytes = to_bytes(&grid, &v).unwrap();
                let data = bytes.split_at(bytes.windows(5).position(|w| w == b"data\n").unwrap() + 5).1;
                assert_eq!(data, &reference(&v)[..], "n {n}, density {density}");
                let (g2, v2) = from_bytes(&bytes, Path::new("mem")).unwrap();
                assert_eq!((g2, v2), (grid, v));
            }
        }
    }
}
