//! Which git files tell that HEAD moved, for `build.rs`'s `rerun-if-changed`. Cargo
//! reruns a build script whenever a watched path does not exist, so only existing paths
//! are watched: HEAD, and the branch it names as a loose ref file, or else the packed
//! refs that hold it. (Also compiled by `tests/build_script.rs`.)

use std::path::{Path, PathBuf};

/// The files to watch: `dir`/HEAD (the checkout's git folder), and for the branch
/// `branch` (`refs/heads/…`, `None` when HEAD is detached) its loose ref in the common
/// folder `common`, or `common`/packed-refs when the branch has no loose ref file. The
/// packed refs are watched too when they exist, as `git pack-refs` moves a loose ref
/// there; a path that does not exist is never returned.
pub fn watched(dir: Option<&Path>, common: Option<&Path>, branch: Option<&str>) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Some(dir) = dir {
        out.push(dir.join("HEAD"));
    }
    if let (Some(common), Some(branch)) = (common, branch) {
        out.push(common.join(branch));
        out.push(common.join("packed-refs"));
    }
    out.retain(|p| p.is_file());
    out
}
