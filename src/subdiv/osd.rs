//! OpenSubdiv as the independent reference: runs the helper `tools/osd-refine.cpp`
//! (built by `tools/setup` into `target/tools/osd-refine`) on a surface written to a
//! temporary OBJ file — its sharp features and options as tags (`tags`) — and reads its
//! output back.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::mesh::{Mesh, formats};
use crate::scratch::ScratchDir;

use super::{Result, SubdivError, Surface, tags};

/// Environment variable naming the helper binary, overriding the default location.
pub const HELPER_ENV: &str = "TEXGEO_OSD_REFINE";

/// The helper binary: `$TEXGEO_OSD_REFINE`, else `target/tools/osd-refine` of this
/// checkout, else `tools/osd-refine` next to the running executable's `target` folder.
/// Fails with [`SubdivError::HelperMissing`] (saying to run `tools/setup`) when absent.
pub fn helper_path() -> Result<PathBuf> {
    crate::scratch::helper(HELPER_ENV, "osd-refine").map_err(|path| SubdivError::HelperMissing { path })
}

/// How to run the helper.
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Time topology creation + refinement + interpolation this many times (minimum kept).
    pub repeat: Option<u32>,
    /// Skip full topology in the last level (OpenSubdiv's faster drawing-only setting).
    pub sparse: bool,
    /// Do not write (nor read back) the refined mesh: for timing only.
    pub no_output: bool,
}

/// What the helper produced.
#[derive(Clone, Debug)]
pub struct Run {
    /// The last level, in OpenSubdiv's vertex order (absent with `no_output`).
    pub mesh: Option<Mesh>,
    /// Minimum and median time of refine + interpolate over the repeats, in seconds.
    pub min_seconds: Option<f64>,
    pub median_seconds: Option<f64>,
}

/// OpenSubdiv's Catmull-Clark refinement of `mesh` (smooth, default options) to `level`.
pub fn refine(mesh: &Mesh, level: u32) -> Result<Mesh> {
    refine_surface(&Surface::smooth(mesh.clone()), level)
}

/// OpenSubdiv's refinement of `surface` (sharp features and options) to `level`; faces
/// under holes are left out.
pub fn refine_surface(surface: &Surface, level: u32) -> Result<Mesh> {
    let run = run(surface, level, &Options::default())?;
    run.mesh.ok_or_else(|| helper_error(Path::new("osd-refine"), "no mesh was produced"))
}

/// Seconds OpenSubdiv takes to refine `surface` to `level` (minimum of `repeat` runs).
pub fn time(surface: &Surface, level: u32, repeat: u32) -> Result<f64> {
    let options = Options { repeat: Some(repeat.max(1)), no_output: true, ..Options::default() };
    let run = run(surface, level, &options)?;
    run.min_seconds.ok_or_else(|| helper_error(Path::new("osd-refine"), "no timing was printed"))
}

/// Median seconds of refine + interpolate of `surface` to `level` over `repeat` runs.
pub fn time_median(surface: &Surface, level: u32, repeat: u32) -> Result<f64> {
    let options = Options { repeat: Some(repeat.max(1)), no_output: true, ..Options::default() };
    let run = run(surface, level, &options)?;
    run.median_seconds.ok_or_else(|| helper_error(Path::new("osd-refine"), "no timing was printed"))
}

/// Runs the helper on `surface` with `options`.
pub fn run(surface: &Surface, level: u32, options: &Options) -> Result<Run> {
    let helper = helper_path()?;
    let dir = ScratchDir::new("osd")?;
    let input = dir.join("in.obj");
    let output = dir.join("out.off");
    let mut text = Vec::new();
    tags::write_obj(&mut text, surface).map_err(|error| SubdivError::Io { path: input.clone(), error })?;
    std::fs::write(&input, text).map_err(|error| SubdivError::Io { path: input.clone(), error })?;

    let mut command = Command::new(&helper);
    command.arg(&input).arg(level.to_string());
    if !options.no_output {
        command.arg(&output);
    }
    if let Some(n) = options.repeat {
        command.arg("--repeat").arg(n.to_string());
    }
    if options.sparse {
        command.arg("--sparse");
    }
    let result = command.output().map_err(|error| SubdivError::Io { path: helper.clone(), error })?;
    if !result.status.success() {
        let stderr = String::from_utf8_lossy(&result.stderr);
        return Err(helper_error(&helper, format!("{}: {}", result.status, stderr.trim())));
    }
    let stdout = String::from_utf8_lossy(&result.stdout);
    let (min_seconds, median_seconds) = match options.repeat {
        Some(_) => (
            Some(parse_seconds(&stdout, "min_seconds=").ok_or_else(|| {
                helper_error(&helper, "expected 'min_seconds=S' on stdout (run tools/setup)".to_string())
            })?),
            Some(parse_seconds(&stdout, "median_seconds=").ok_or_else(|| {
                helper_error(
                    &helper,
                    "expected 'median_seconds=S' on stdout (an old helper: run tools/setup)".to_string(),
                )
            })?),
        ),
        None => (None, None),
    };
    let mesh = if options.no_output { None } else { Some(formats::read(&output)?) };
    Ok(Run { mesh, min_seconds, median_seconds })
}

fn helper_error(path: &Path, message: impl Into<String>) -> SubdivError {
    SubdivError::Helper { path: path.to_path_buf(), message: message.into() }
}

/// The value of `key` (`min_seconds=` or `median_seconds=`) in the helper's timing line.
fn parse_seconds(stdout: &str, key: &str) -> Option<f64> {
    stdout.split_whitespace().find_map(|t| t.strip_prefix(key))?.parse().ok()
}

#[cfg(test)]
mod tests {
    #[test]
    fn parses_the_timing_line() {
        let line =
            "osd-refine: level=5 vertices=10 faces=8 repeat=3 min_seconds=1.250000 median_seconds=1.5\n";
        assert_eq!(super::parse_seconds(line, "min_seconds="), Some(1.25));
        assert_eq!(super::parse_seconds(line, "median_seconds="), Some(1.5));
        assert_eq!(super::parse_seconds("nothing", "min_seconds="), None);
    }
}
