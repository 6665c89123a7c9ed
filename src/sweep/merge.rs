//! `texgeo sweep merge DIR`: every shard's results into `sweep.csv`, `summary.md` and
//! `time-vs-size.svg`.
//!
//! Rows are in manifest order and columns in name order, so the outputs depend only on
//! the results, never on how many shards produced them or in which order they finished.
//! Measurements that vary from run to run (times, peak memory) are the CSV's last columns
//! (`peak_rss_kib`, `time_*_ms`) and the summary's last sections (after "Slowest meshes").

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::Value;

use super::folder::SweepInfo;
use super::record::{self, Outcome, Record};
use super::{Result, SweepError, plot, write_atomic};

pub const CSV: &str = "sweep.csv";
pub const SUMMARY: &str = "summary.md";
pub const PLOT: &str = "time-vs-size.svg";

/// A sweep's results gathered from its shards.
#[derive(Clone, Debug)]
pub struct Merged {
    pub info: SweepInfo,
    /// One per mesh that has a result, in manifest order.
    pub records: Vec<Record>,
    /// Manifest indices without a result yet.
    pub missing: Vec<usize>,
}

impl Merged {
    /// Meshes per outcome.
    pub fn counts(&self) -> BTreeMap<Outcome, usize> {
        let mut c = BTreeMap::new();
        for r in &self.records {
            *c.entry(r.outcome).or_default() += 1;
        }
        c
    }

    /// (outcome, reason) → meshes, for everything that is not `ok`.
    pub fn reasons(&self) -> BTreeMap<(Outcome, String), Vec<&str>> {
        let mut m: BTreeMap<(Outcome, String), Vec<&str>> = BTreeMap::new();
        for r in self.records.iter().filter(|r| r.outcome != Outcome::Ok) {
            m.entry((r.outcome, r.reason.clone())).or_default().push(&r.mesh);
        }
        m
    }
}

/// The files [`write`] produced.
#[derive(Clone, Debug)]
pub struct Outputs {
    pub csv: PathBuf,
    pub summary: PathBuf,
    pub plot: PathBuf,
}

/// `results-I-of-N.jsonl` → (I, N).
fn shard_of(name: &str) -> Option<(usize, usize)> {
    let (i, n) = name.strip_prefix("results-")?.strip_suffix(".jsonl")?.split_once("-of-")?;
    Some((i.parse().ok()?, n.parse().ok()?))
}

/// Reads `sweep.json` and every results file of `dir`.
pub fn collect(dir: &Path) -> Result<Merged> {
    let info = SweepInfo::read(dir)?;
    let mut files = Vec::new();
    for item in std::fs::read_dir(dir).map_err(|e| SweepError::io(dir, e))? {
        let path = item.map_err(|e| SweepError::io(dir, e))?.path();
        if let Some(shard) = path.file_name().and_then(|n| n.to_str()).and_then(shard_of) {
            files.push((shard, path));
        }
    }
    files.sort();
    let counts: BTreeSet<usize> = files.iter().map(|((_, n), _)| *n).collect();
    if counts.len() > 1 {
        return Err(SweepError::Mismatch(format!(
            "{} holds results of sweeps split into different numbers of shards ({}); merge one kind",
            dir.display(),
            counts.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ")
        )));
    }
    let mut by_index: BTreeMap<usize, Record> = BTreeMap::new();
    for ((i, n), path) in &files {
        for r in record::read(path)? {
            let belongs = info.entries.get(r.index).is_some_and(|e| e.mesh == r.mesh);
            if !belongs || r.index % n != *i || r.task != info.task {
                return Err(SweepError::Mismatch(format!(
                    "{}: result for '{}' (entry {}) does not belong to shard {i}/{n} of this sweep",
                    path.display(),
                    r.mesh,
                    r.index
                )));
            }
            // A mesh recorded twice in one shard (a re-run by hand): the last line wins.
            by_index.insert(r.index, r);
        }
    }
    let missing = (0..info.entries.len()).filter(|i| !by_index.contains_key(i)).collect();
    Ok(Merged { info, records: by_index.into_values().collect(), missing })
}

/// Collects and writes the three outputs into `dir`.
pub fn merge(dir: &Path) -> Result<(Merged, Outputs)> {
    let merged = collect(dir)?;
    let outputs = write(dir, &merged)?;
    Ok((merged, outputs))
}

/// Writes `sweep.csv`, `summary.md` and `time-vs-size.svg` (each replaced whole).
pub fn write(dir: &Path, merged: &Merged) -> Result<Outputs> {
    let outputs = Outputs { csv: dir.join(CSV), summary: dir.join(SUMMARY), plot: dir.join(PLOT) };
    write_atomic(&outputs.csv, &csv(merged)?)?;
    write_atomic(&outputs.summary, summary(merged).as_bytes())?;
    write_atomic(&outputs.plot, plot::time_vs_size(merged)?.as_bytes())?;
    Ok(outputs)
}

fn keys<'a, V: 'a>(maps: impl Iterator<Item = &'a BTreeMap<String, V>>) -> Vec<String> {
    maps.flat_map(|m| m.keys().cloned()).collect::<BTreeSet<_>>().into_iter().collect()
}

fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Null => String::new(),
        v => v.to_string(),
    }
}

/// The table: identity columns, sizes, checks, hashes, error; then measurements.
pub fn csv(merged: &Merged) -> Result<Vec<u8>> {
    let rs = &merged.records;
    let sizes = keys(rs.iter().map(|r| &r.sizes));
    let checks = keys(rs.iter().map(|r| &r.checks));
    let hashes = keys(rs.iter().map(|r| &r.hashes));
    let mut times = keys(rs.iter().map(|r| &r.times_ms));
    // Total first among the times.
    times.sort_by_key(|k| (k != "total", k.clone()));

    let mut header: Vec<String> = ["index", "mesh", "outcome", "reason"].map(String::from).to_vec();
    header.extend(sizes.iter().map(|k| format!("size_{k}")));
    header.extend(checks.iter().map(|k| format!("check_{k}")));
    header.extend(hashes.iter().map(|k| format!("hash_{k}")));
    header.push("error".into());
    header.push("peak_rss_kib".into());
    header.extend(times.iter().map(|k| format!("time_{k}_ms")));

    let mut rows: Vec<(usize, Vec<String>)> = rs
        .iter()
        .map(|r| {
            let mut row = vec![r.index.to_string(), r.mesh.clone(), r.outcome.to_string(), r.reason.clone()];
            row.extend(sizes.iter().map(|k| r.sizes.get(k).map(u64::to_string).unwrap_or_default()));
            row.extend(checks.iter().map(|k| r.checks.get(k).map(cell).unwrap_or_default()));
            row.extend(hashes.iter().map(|k| r.hashes.get(k).cloned().unwrap_or_default()));
            row.push(r.error.clone());
            row.push(r.peak_rss_kib.map(|p| p.to_string()).unwrap_or_default());
            row.extend(
                times.iter().map(|k| r.times_ms.get(k).map(|t| format!("{t:.3}")).unwrap_or_default()),
            );
            (r.index, row)
        })
        .collect();
    for &i in &merged.missing {
        let mut row = vec![String::new(); header.len()];
        row[0] = i.to_string();
        row[1] = merged.info.entries[i].mesh.clone();
        row[2] = "missing".into();
        rows.push((i, row));
    }
    rows.sort_by_key(|(i, _)| *i);

    let mut w = csv::Writer::from_writer(Vec::new());
    let err = |e: csv::Error| SweepError::io(CSV, std::io::Error::other(e));
    w.write_record(&header).map_err(err)?;
    for (_, row) in rows {
        w.write_record(&row).map_err(err)?;
    }
    w.into_inner().map_err(|e| SweepError::io(CSV, std::io::Error::other(e.to_string())))
}

fn md(s: &str) -> String {
    s.replace('|', "\\|").replace('\n', " ")
}

fn list(meshes: &[&str], max: usize) -> String {
    let mut s = meshes.iter().take(max).map(|m| format!("`{}`", md(m))).collect::<Vec<_>>().join(", ");
    if meshes.len() > max {
        let _ = write!(s, ", … ({} more)", meshes.len() - max);
    }
    s
}

/// Heading line of the sections after which everything depends on timing.
pub const TIMED_SECTIONS: &str = "## Slowest meshes";

/// The Markdown summary.
pub fn summary(merged: &Merged) -> String {
    let info = &merged.info;
    let mut s = String::new();
    let _ = writeln!(s, "# Sweep: {}\n", info.task);
    let options: Vec<String> =
        info.options.iter().filter(|(_, v)| !v.is_null()).map(|(k, v)| format!("{k}={}", cell(v))).collect();
    let _ = writeln!(s, "Options: {}.", if options.is_empty() { "none".into() } else { options.join(", ") });
    let _ = writeln!(
        s,
        "Meshes: {} in the manifest, {} with a result{}.\n",
        info.entries.len(),
        merged.records.len(),
        if merged.missing.is_empty() {
            String::new()
        } else {
            format!(", {} not run yet", merged.missing.len())
        }
    );

    let _ = writeln!(s, "## Outcomes\n\n| outcome | meshes |\n|---|---|");
    let counts = merged.counts();
    for o in Outcome::ALL {
        let _ = writeln!(s, "| {o} | {} |", counts.get(&o).copied().unwrap_or(0));
    }
    if !merged.missing.is_empty() {
        let _ = writeln!(s, "| not run yet | {} |", merged.missing.len());
    }

    let reasons = merged.reasons();
    let _ = writeln!(s, "\n## Refusals and failures by reason\n");
    if reasons.is_empty() {
        let _ = writeln!(s, "None: every mesh passed.");
    } else {
        let _ = writeln!(s, "| outcome | reason | meshes | which |\n|---|---|---|---|");
        let mut rows: Vec<_> = reasons.iter().collect();
        rows.sort_by(|a, b| a.0.0.cmp(&b.0.0).then(b.1.len().cmp(&a.1.len())).then(a.0.1.cmp(&b.0.1)));
        for ((o, reason), meshes) in rows {
            let _ = writeln!(s, "| {o} | {} | {} | {} |", md(reason), meshes.len(), list(meshes, 8));
        }
    }

    let bad: Vec<&Record> =
        merged.records.iter().filter(|r| !matches!(r.outcome, Outcome::Ok | Outcome::Refused)).collect();
    if !bad.is_empty() {
        let _ = writeln!(
            s,
            "\n## Failures, crashes and timeouts\n\n| mesh | outcome | reason | error |\n|---|---|---|---|"
        );
        for r in bad {
            let error: String = r.error.chars().take(300).collect();
            let _ = writeln!(s, "| `{}` | {} | {} | {} |", md(&r.mesh), r.outcome, md(&r.reason), md(&error));
        }
    }

    let _ = writeln!(s, "\n{TIMED_SECTIONS}\n");
    let _ = writeln!(s, "Wall time per mesh in the worker (reading included); varies from run to run.\n");
    let mut timed: Vec<&Record> = merged.records.iter().filter(|r| r.total_ms().is_some()).collect();
    timed.sort_by(|a, b| b.total_ms().partial_cmp(&a.total_ms()).unwrap_or(std::cmp::Ordering::Equal));
    let _ = writeln!(s, "| mesh | faces | outcome | total ms | peak RSS MiB |\n|---|---|---|---|---|");
    for r in timed.iter().take(10) {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {:.1} | {} |",
            md(&r.mesh),
            r.sizes.get("faces").map(u64::to_string).unwrap_or_default(),
            r.outcome,
            r.total_ms().unwrap_or(0.0),
            r.peak_rss_kib.map(|k| format!("{:.0}", k as f64 / 1024.0)).unwrap_or_default()
        );
    }
    let total: f64 = timed.iter().filter_map(|r| r.total_ms()).sum();
    let _ = writeln!(s, "\nSum over all meshes: {:.1} s.", total / 1e3);
    let _ = writeln!(s, "\n## Time against size\n\n![total time per mesh against its faces]({PLOT})");
    s
}
