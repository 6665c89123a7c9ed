//! Sweeps: one task run over a whole mesh collection, each mesh in isolation, results
//! kept line by line so that nothing finished is ever lost.
//!
//! - [`folder`]: `DIR/sweep.json`, what the sweep is (task, options, meshes); a folder
//!   holding another sweep is refused.
//! - [`manifest`]: the meshes (a list of paths, a CSV with per-mesh options, or a folder)
//!   and the shard `I/N` a process takes of them (every N-th entry from the I-th).
//! - [`task`]: what runs on one mesh. A task is one [`task::Task`] implementation (its
//!   options, the sizes, checks, hashes and times it records, its refusals) plus one arm of
//!   [`task::TaskKind`]; [`tasks`] holds `inclusion`, `voxelize` and `subdivide`.
//! - [`worker`]: the process that runs meshes: it opens one Vulkan device and keeps its
//!   pipelines for all the meshes it is given, and answers one JSON line per mesh.
//! - [`pool`]: the sweeping process: J workers, per-mesh time limits, a worker that dies
//!   (panic, abort, segfault, out of memory) or overruns is recorded for its current mesh
//!   and replaced.
//! - [`record`]: one mesh's result, and the results file `results-I-of-N.jsonl`, appended
//!   one whole line per `write` (O_APPEND, then fsync); a torn last line left by a kill is
//!   dropped when the sweep resumes.
//! - [`merge`]: every shard's results into one CSV, a Markdown summary and an SVG plot of
//!   time against size, identical whatever the number of shards (rows in manifest order).

pub mod folder;
pub mod manifest;
pub mod merge;
pub mod plot;
pub mod pool;
pub mod record;
pub mod task;
pub mod tasks;
pub mod worker;

use std::path::{Path, PathBuf};

pub use folder::SweepInfo;
pub use manifest::{Entry, Manifest, Shard};
pub use record::{Outcome, Record};
pub use task::{Failure, Task, TaskKind};

pub type Result<T, E = SweepError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// A manifest line that cannot be used: `manifest.txt:3: message`.
    #[error("{}{}: {message}", path.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Manifest { path: PathBuf, line: Option<usize>, message: String },
    /// A results file with a damaged line that is not the last one.
    #[error("{}:{line}: {message}", path.display())]
    Results { path: PathBuf, line: usize, message: String },
    /// Options that do not fit the task.
    #[error("{0}")]
    Options(String),
    /// A sweep folder that holds another sweep, or results that do not go together.
    #[error("{0}")]
    Mismatch(String),
    /// A worker process could not be started or did not say it was ready.
    #[error("sweep worker: {0}")]
    Worker(String),
    /// The time-vs-size plot could not be drawn.
    #[error("plot: {0}")]
    Plot(String),
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
}

impl SweepError {
    pub(crate) fn io(path: impl AsRef<Path>, source: std::io::Error) -> SweepError {
        SweepError::Io { path: path.as_ref().to_path_buf(), source }
    }
}

/// Writes `bytes` to `path` whole or not at all, synced to the disk
/// ([`crate::output::write_bytes_durable`]).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::output::write_bytes_durable(path, bytes)
        .map_err(|e| SweepError::Io { path: e.path, source: e.error })
}
