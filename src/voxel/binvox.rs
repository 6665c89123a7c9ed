//! The binvox format (Patrick Min's), so other tools read texgeo's volumes: a text
//! header — `#binvox 1`, `dim N N N`, `translate` (the cube's minimum corner), `scale`
//! (the cube's side), `data` — then run-length pairs (value byte, count byte 1..=255) in
//! binvox order: index = x·N² + z·N + y (y fastest).

use std::io::Write as _;
use std::path::Path;

use glam::DVec3;

use super::error::{Result, VoxelError};
use super::grid::{Grid, MAX_RES};
use super::volume::Volume;

/// Encodes `volume` on `grid` as a binvox file.
pub fn to_bytes(grid: &Grid, volume: &Volume) -> Result<Vec<u8>> {
    let n = volume.n();
    if grid.n != n {
        return Err(VoxelError::Usage(format!("a {}³ grid with a {n}³ volume", grid.n)));
    }
    let mut out = Vec::new();
    let m = grid.min;
    let _ = write!(
        out,
        "#binvox 1\ndim {n} {n} {n}\ntranslate {} {} {}\nscale {}\ndata\n",
        m.x, m.y, m.z, grid.side
    );
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
    if count > 0 {
        out.extend_from_slice(&[value as u8, count]);
    }
    Ok(out)
}

/// Writes `volume` as a binvox file.
pub fn write(path: impl AsRef<Path>, grid: &Grid, volume: &Volume) -> Result<()> {
    let path = path.as_ref();
    std::fs::write(path, to_bytes(grid, volume)?).map_err(|e| VoxelError::io(path, e))
}

/// Reads a binvox file (cubic, N ≤ [`MAX_RES`]).
pub fn read(path: impl AsRef<Path>) -> Result<(Grid, Volume)> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| VoxelError::io(path, e))?;
    from_bytes(&bytes, path)
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
