//! One mesh's result and the results file of a shard.
//!
//! `results-I-of-N.jsonl` holds one JSON object per line, one line per mesh. A line is
//! written with a single `write` on a file opened with O_APPEND and synced before the next
//! mesh is recorded, so a kill leaves at most a torn last line, which [`ResultsFile::open`]
//! drops (a damaged line before the last one is an error: the file was edited or the disk
//! failed). An exclusive `flock` keeps two processes from appending to the same shard.

use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io::{Read as _, Write as _};
use std::os::fd::AsRawFd as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{Result, SweepError};

/// How a mesh's run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// The task ran and every check passed.
    Ok,
    /// The task declined the mesh with a clear error (unreadable, not closed, too large, …).
    Refused,
    /// The task ran and a check failed, or it hit an unexpected error.
    Failed,
    /// The worker died on this mesh (panic, abort, segfault, out of memory).
    Crashed,
    /// No result within the time limit; the worker was killed.
    Timeout,
}

impl Outcome {
    pub const ALL: [Outcome; 5] =
        [Outcome::Ok, Outcome::Refused, Outcome::Failed, Outcome::Crashed, Outcome::Timeout];

    pub fn name(self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::Refused => "refused",
            Outcome::Failed => "failed",
            Outcome::Crashed => "crashed",
            Outcome::Timeout => "timeout",
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One mesh's line in the results. Everything but `times_ms` and `peak_rss_kib` is the
/// same on every run of the same sweep on the same device.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// Position in the manifest (0-based); the merged table is sorted by it.
    pub index: usize,
    /// The mesh as the manifest names it.
    pub mesh: String,
    pub task: String,
    pub outcome: Outcome,
    /// A short slug for refusals and failures (`not-closed`, `unreadable`, `panic`, …).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub reason: String,
    /// The full message.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub error: String,
    /// Counts: vertices, faces, and what the task produced.
    #[serde(default)]
    pub sizes: BTreeMap<String, u64>,
    /// Properties and comparisons (closed, manifold, differences from the reference, …).
    #[serde(default)]
    pub checks: BTreeMap<String, Value>,
    /// FNV-1a 64 of each output, as 16 hex digits.
    #[serde(default)]
    pub hashes: BTreeMap<String, String>,
    /// Milliseconds per phase; `total` is the whole mesh, reading included.
    #[serde(default)]
    pub times_ms: BTreeMap<String, f64>,
    /// Peak resident memory of the worker while it ran this mesh (KiB), when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_rss_kib: Option<u64>,
}

impl Record {
    pub fn new(index: usize, mesh: &str, task: &str) -> Record {
        Record {
            index,
            mesh: mesh.to_string(),
            task: task.to_string(),
            outcome: Outcome::Ok,
            reason: String::new(),
            error: String::new(),
            sizes: BTreeMap::new(),
            checks: BTreeMap::new(),
            hashes: BTreeMap::new(),
            times_ms: BTreeMap::new(),
            peak_rss_kib: None,
        }
    }

    pub fn size(&mut self, key: &str, value: impl TryInto<u64>) {
        self.sizes.insert(key.to_string(), value.try_into().unwrap_or(u64::MAX));
    }

    pub fn check(&mut self, key: &str, value: impl Into<Value>) {
        self.checks.insert(key.to_string(), value.into());
    }

    pub fn hash(&mut self, key: &str, hash: &Fnv) {
        self.hashes.insert(key.to_string(), format!("{:016x}", hash.finish()));
    }

    pub fn time(&mut self, key: &str, d: Duration) {
        // Microsecond resolution keeps the lines short.
        let ms = (d.as_secs_f64() * 1e6).round() / 1e3;
        self.times_ms.insert(key.to_string(), ms);
    }

    /// Total milliseconds, if recorded.
    pub fn total_ms(&self) -> Option<f64> {
        self.times_ms.get("total").copied()
    }
}

/// FNV-1a, 64 bits: a stable hash of outputs (std's hasher may change between releases).
#[derive(Clone, Copy, Debug)]
pub struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    pub fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    pub fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }

    pub fn finish(&self) -> u64 {
        self.0
    }
}

/// A shard's results file, open for appending and locked against a second writer.
pub struct ResultsFile {
    path: PathBuf,
    file: File,
}

impl ResultsFile {
    /// `DIR/results-I-of-N.jsonl`.
    pub fn path_in(dir: &Path, shard: super::Shard) -> PathBuf {
        dir.join(format!("results-{}-of-{}.jsonl", shard.index, shard.count))
    }

    /// Opens (creating) the file, reads the records already there and cuts off a torn
    /// last line.
    pub fn open(path: &Path) -> Result<(ResultsFile, Vec<Record>)> {
        let io = |e| SweepError::io(path, e);
        let mut file =
            std::fs::OpenOptions::new().read(true).append(true).create(true).open(path).map_err(io)?;
        lock(&file, path)?;
        let mut text = Vec::new();
        file.read_to_end(&mut text).map_err(io)?;
        let (records, good) = parse(path, &text)?;
        if good < text.len() {
            // O_APPEND writes go to the end whatever the length, so cutting is enough.
            file.set_len(good as u64).map_err(io)?;
            file.sync_all().map_err(io)?;
        }
        Ok((ResultsFile { path: path.to_path_buf(), file }, records))
    }

    /// Appends one record as one line: a single write, then fsync.
    pub fn append(&mut self, record: &Record) -> Result<()> {
        let mut line = serde_json::to_vec(record).map_err(|e| SweepError::io(&self.path, e.into()))?;
        line.push(b'\n');
        let io = |e| SweepError::io(&self.path, e);
        let written = self.file.write(&line).map_err(io)?;
        if written != line.len() {
            return Err(io(std::io::Error::other(format!(
                "short write ({written} of {} bytes)",
                line.len()
            ))));
        }
        self.file.sync_data().map_err(io)
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

/// An exclusive advisory lock for the lifetime of `file` (file systems without locks are
/// accepted as they are).
fn lock(file: &File, path: &Path) -> Result<()> {
    // SAFETY: flock on a file descriptor we own; no memory is involved.
    let rc = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
    if rc == 0 {
        return Ok(());
    }
    let e = std::io::Error::last_os_error();
    match e.raw_os_error() {
        Some(libc::EWOULDBLOCK) => Err(SweepError::Mismatch(format!(
            "{} is being written by another sweep process (same shard started twice?)",
            path.display()
        ))),
        Some(libc::ENOLCK) | Some(libc::EOPNOTSUPP) => Ok(()),
        _ => Err(SweepError::io(path, e)),
    }
}

/// Parses the complete lines of a results file: the records, and the byte length of the
/// part that is whole (a last line without its newline is torn and not counted).
pub fn parse(path: &Path, text: &[u8]) -> Result<(Vec<Record>, usize)> {
    let good = text.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let mut records = Vec::new();
    for (n, line) in text[..good].split(|&b| b == b'\n').enumerate() {
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let record: Record = serde_json::from_slice(line).map_err(|e| SweepError::Results {
            path: path.to_path_buf(),
            line: n + 1,
            message: format!("not a sweep result ({e})"),
        })?;
        records.push(record);
    }
    Ok((records, good))
}

/// Reads a results file without changing it (a torn last line is ignored).
pub fn read(path: &Path) -> Result<Vec<Record>> {
    let text = std::fs::read(path).map_err(|e| SweepError::io(path, e))?;
    Ok(parse(path, &text)?.0)
}

/// The manifest indices a set of records covers.
pub fn indices(records: &[Record]) -> BTreeSet<usize> {
    records.iter().map(|r| r.index).collect()
}

/// FNV-1a of a mesh: faces, then positions as f64 bits (an output's identity in results).
pub fn mesh_hash(mesh: &crate::mesh::Mesh) -> Fnv {
    let mut h = Fnv::default();
    for f in mesh.faces() {
        h.u64(f.len() as u64);
        for &v in f {
            h.u64(u64::from(v));
        }
    }
    for p in mesh.positions() {
        for c in p.to_array() {
            h.u64(c.to_bits());
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torn_last_line_is_dropped_and_damage_elsewhere_is_an_error() {
        let a = serde_json::to_string(&Record::new(0, "a.off", "voxelize")).unwrap();
        let b = serde_json::to_string(&Record::new(1, "b.off", "voxelize")).unwrap();
        let text = format!("{a}\n{b}\n{}", &a[..10]);
        let (records, good) = parse(Path::new("r.jsonl"), text.as_bytes()).unwrap();
        assert_eq!(records.len(), 2);
        assert_eq!(good, a.len() + b.len() + 2);
        let damaged = format!("{a}\n{}\n{b}\n", &a[..10]);
        let e = parse(Path::new("r.jsonl"), damaged.as_bytes()).unwrap_err();
        assert!(e.to_string().starts_with("r.jsonl:2: not a sweep result"), "{e}");
    }

    #[test]
    fn fnv_matches_the_published_vectors() {
        let mut h = Fnv::default();
        assert_eq!(h.finish(), 0xcbf29ce484222325);
        h.bytes(b"a");
        assert_eq!(h.finish(), 0xaf63dc4c8601ec8c);
        let mut h = Fnv::default();
        h.bytes(b"foobar");
        assert_eq!(h.finish(), 0x85944171f73967e8);
    }
}
