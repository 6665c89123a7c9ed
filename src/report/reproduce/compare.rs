//! `texgeo reproduce --compare OLD NEW`: what moved between two runs by more than the
//! measured noise. Each run keeps every measured value with the range of its repeated
//! runs (`csv/measurements.csv`); a value moved when the two ranges do not overlap —
//! the noise is what the runs themselves showed, not a constant. Counts and sizes (a
//! single exact value) moved when they differ at all. Claims whose verdict changed are
//! listed too.

use std::fmt::Write as _;
use std::path::Path;

use super::facts::{Facts, Stat};
use super::header::Header;
use super::{ReproduceError, Result};

const COLUMNS: [&str; 8] = ["experiment", "model", "quantity", "unit", "value", "min", "max", "runs"];

/// Every today fact as CSV; missing values have an empty value and the reason in `max`'s
/// place is not kept — they are simply absent.
pub fn measurements_csv(facts: &Facts) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record(COLUMNS);
    for f in &facts.facts {
        if let Ok(s) = &f.value {
            let _ = w.write_record([
                f.experiment,
                &f.model,
                &f.key,
                f.unit,
                &format!("{:e}", s.value),
                &format!("{:e}", s.min),
                &format!("{:e}", s.max),
                &s.runs.to_string(),
            ]);
        }
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// (experiment, model, quantity) → value.
type Measurements = Vec<((String, String, String), Stat)>;

fn read_measurements(dir: &Path) -> Result<Measurements> {
    let path = dir.join("csv").join("measurements.csv");
    let bad = |why: String| ReproduceError::Usage(format!("{}: {why}", path.display()));
    let mut r =
        csv::Reader::from_path(&path).map_err(|e| bad(format!("{e} (not a texgeo reproduce folder?)")))?;
    let header: Vec<String> =
        r.headers().map_err(|e| bad(e.to_string()))?.iter().map(str::to_string).collect();
    if header != COLUMNS {
        return Err(bad(format!("unexpected columns {}", header.join(","))));
    }
    let mut out = Vec::new();
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| bad(e.to_string()))?;
        let num = |i: usize| -> Result<f64> {
            rec.get(i)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| bad(format!("line {}: bad number in column {}", line + 2, COLUMNS[i])))
        };
        let stat = Stat { value: num(4)?, min: num(5)?, max: num(6)?, runs: num(7)? as usize };
        out.push(((rec[0].to_string(), rec[1].to_string(), rec[2].to_string()), stat));
    }
    Ok(out)
}

/// id → verdict, from `csv/claims.csv`.
fn read_verdicts(dir: &Path) -> Vec<(String, String)> {
    let Ok(mut r) = csv::Reader::from_path(dir.join("csv").join("claims.csv")) else { return Vec::new() };
    r.records().flatten().filter_map(|rec| Some((rec.get(0)?.to_string(), rec.get(6)?.to_string()))).collect()
}

fn read_header(dir: &Path) -> Option<Header> {
    serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).ok()?).ok()
}

fn num(v: f64) -> String {
    super::experiments::num(v)
}

/// The comparison of two report folders, as Markdown.
pub fn compare(old: &Path, new: &Path) -> Result<String> {
    let (a, b) = (read_measurements(old)?, read_measurements(new)?);
    let mut s = String::from("# texgeo reproduce --compare\n\n");
    for (label, dir) in [("old", old), ("new", new)] {
        match read_header(dir) {
            Some(h) => {
                let _ = writeln!(
                    s,
                    "- {label}: `{}` — {} on {} ({}), {} {}, texgeo {} ({}), {}, {}",
                    dir.display(),
                    h.device,
                    h.machine,
                    h.cpu,
                    h.driver,
                    h.vulkan,
                    h.texgeo,
                    h.commit,
                    h.date,
                    h.mode
                );
            }
            None => {
                let _ = writeln!(s, "- {label}: `{}`", dir.display());
            }
        }
    }
    let mut moved = Vec::new();
    let mut changed = Vec::new();
    let mut within = 0usize;
    let mut unmatched = 0usize;
    for (key, x) in &a {
        let Some((_, y)) = b.iter().find(|(k, _)| k == key) else {
            unmatched += 1;
            continue;
        };
        let ratio = if x.value != 0.0 { y.value / x.value } else { f64::INFINITY };
        if x.runs < 2 || y.runs < 2 {
            if x.value != y.value {
                changed.push((key, *x, *y, ratio));
            }
        } else if x.overlaps(y) {
            within += 1;
        } else {
            moved.push((key, *x, *y, ratio));
        }
    }
    moved.sort_by(|p, q| (q.3.ln().abs()).total_cmp(&p.3.ln().abs()));
    let _ = writeln!(
        s,
        "\n## Measurements that moved beyond the noise of their runs ({} of {})\n",
        moved.len(),
        moved.len() + within
    );
    if moved.is_empty() {
        s.push_str("None: every repeated measurement's runs overlap between the two reports.\n");
    } else {
        s.push_str("| experiment | model | quantity | old | new | new / old | old runs (min–max) | new runs (min–max) |\n|---|---|---|---|---|---|---|---|\n");
        for ((e, m, q), x, y, r) in &moved {
            let _ = writeln!(
                s,
                "| {e} | {m} | {q} | {} | {} | {}× | {}–{} | {}–{} |",
                num(x.value),
                num(y.value),
                num(*r),
                num(x.min),
                num(x.max),
                num(y.min),
                num(y.max)
            );
        }
    }
    let _ = writeln!(s, "\n## Single measurements and counts that differ ({})\n", changed.len());
    if changed.is_empty() {
        s.push_str("None.\n");
    } else {
        s.push_str("| experiment | model | quantity | old | new | new / old |\n|---|---|---|---|---|---|\n");
        for ((e, m, q), x, y, r) in &changed {
            let _ = writeln!(s, "| {e} | {m} | {q} | {} | {} | {}× |", num(x.value), num(y.value), num(*r));
        }
        s.push_str("\nThese were measured once per run (index builds, memory, counts): no noise estimate.\n");
    }
    let (va, vb) = (read_verdicts(old), read_verdicts(new));
    let flips: Vec<String> = va
        .iter()
        .filter_map(|(id, v)| {
            let w = vb.iter().find(|(j, _)| j == id)?;
            (w.1 != *v).then(|| format!("{id}: {v} → {}", w.1))
        })
        .collect();
    let _ = writeln!(s, "\n## Claims whose verdict changed ({})\n", flips.len());
    for f in &flips {
        let _ = writeln!(s, "- {f}");
    }
    if flips.is_empty() {
        s.push_str("None.\n");
    }
    if unmatched > 0 {
        let _ =
            writeln!(s, "\n{unmatched} measurement(s) of the old report have no counterpart in the new one.");
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::reproduce::facts::Source;

    fn run_dir(name: &str, value: f64, spread: f64) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("texgeo-compare-{name}-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("csv")).unwrap();
        let mut f = Facts::new(Source::Today);
        f.add(
            "voxelize",
            "knot",
            "time:cpu@64",
            "s",
            Stat { value, min: value - spread, max: value + spread, runs: 3 },
        );
        f.add("voxelize", "knot", "time:zoned@64", "s", Stat { value: 1.0, min: 0.9, max: 1.1, runs: 3 });
        f.add("inclusion", "knot", "memory:octants", "KiB", Stat::exact(value));
        std::fs::write(dir.join("csv/measurements.csv"), measurements_csv(&f)).unwrap();
        dir
    }

    #[test]
    fn only_values_whose_runs_do_not_overlap_have_moved() {
        let (a, b, c) = (run_dir("a", 1.0, 0.1), run_dir("b", 1.15, 0.1), run_dir("c", 2.0, 0.1));
        let ab = compare(&a, &b).unwrap();
        assert!(ab.contains("(0 of 2)"), "{ab}");
        let ac = compare(&a, &c).unwrap();
        assert!(ac.contains("(1 of 2)") && ac.contains("time:cpu@64") && ac.contains("2.000×"), "{ac}");
        assert!(ac.contains("memory:octants"), "an exact value that changed is listed: {ac}");
        for d in [a, b, c] {
            std::fs::remove_dir_all(d).unwrap();
        }
    }

    #[test]
    fn a_folder_without_measurements_is_refused() {
        let dir = std::env::temp_dir().join(format!("texgeo-compare-empty-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert!(
            matches!(compare(&dir, &dir), Err(ReproduceError::Usage(m)) if m.contains("measurements.csv"))
        );
        std::fs::remove_dir_all(dir).unwrap();
    }
}
