//! The sweep folder: `sweep.json` (what is swept: task, options, meshes), one results
//! file per shard, and the merged outputs. Every shard of a sweep writes the same
//! `sweep.json`; a folder that holds another sweep is refused, so results of different
//! questions are never mixed.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use super::manifest::Manifest;
use super::{Result, SweepError, write_atomic};

/// The description of a sweep, `DIR/sweep.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepInfo {
    pub task: String,
    /// Sweep-level options, defaults filled in.
    pub options: Map<String, Value>,
    /// The manifest as given (informative; not compared on resume).
    pub manifest: String,
    /// The meshes in manifest order, with their per-mesh option overrides.
    pub entries: Vec<InfoEntry>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InfoEntry {
    pub mesh: String,
    #[serde(default, skip_serializing_if = "Map::is_empty")]
    pub options: Map<String, Value>,
}

impl SweepInfo {
    pub fn new(task: &str, options: Map<String, Value>, manifest: &Manifest) -> SweepInfo {
        SweepInfo {
            task: task.to_string(),
            options,
            manifest: manifest.source.to_string_lossy().into_owned(),
            entries: manifest
                .entries
                .iter()
                .map(|e| InfoEntry { mesh: e.mesh.clone(), options: e.options.clone() })
                .collect(),
        }
    }

    fn same_sweep(&self, other: &SweepInfo) -> bool {
        self.task == other.task && self.options == other.options && self.entries == other.entries
    }

    pub fn path(dir: &Path) -> PathBuf {
        dir.join("sweep.json")
    }

    pub fn read(dir: &Path) -> Result<SweepInfo> {
        let path = SweepInfo::path(dir);
        let text = std::fs::read(&path).map_err(|e| SweepError::io(&path, e))?;
        serde_json::from_slice(&text)
            .map_err(|e| SweepError::Mismatch(format!("{}: not a sweep description ({e})", path.display())))
    }

    /// Creates `dir` and its `sweep.json`, or checks that the one there describes this
    /// same sweep (resuming it, or another shard of it).
    pub fn prepare(&self, dir: &Path) -> Result<()> {
        std::fs::create_dir_all(dir).map_err(|e| SweepError::io(dir, e))?;
        let path = SweepInfo::path(dir);
        if path.exists() {
            let there = SweepInfo::read(dir)?;
            if !there.same_sweep(self) {
                let what = if there.task != self.task {
                    format!("task {}", there.task)
                } else if there.options != self.options {
                    format!("other options ({})", Value::Object(there.options.clone()))
                } else {
                    "another list of meshes".to_string()
                };
                return Err(SweepError::Mismatch(format!(
                    "{} holds a sweep with {what}; give another output folder (or remove it)",
                    dir.display()
                )));
            }
            return Ok(());
        }
        let mut text = serde_json::to_vec_pretty(self).map_err(|e| SweepError::io(&path, e.into()))?;
        text.push(b'\n');
        write_atomic(&path, &text)
    }
}
