//! `texgeo reproduce --compare OLD NEW`: what moved between two runs by more than the
//! measured noise. Each run keeps every measured value with the range of its repeated
//! runs (`csv/measurements.csv`); a value moved when the two ranges do not overlap —
//! the noise is what the runs themselves showed, not a constant. Counts and sizes (a
//! single exact value) moved when they differ at all. Claims whose verdict changed are
//! listed too, and so is everything that keeps the two reports from being compared whole:
//! a missing or unreadable file (`run.json`, `csv/measurements.csv`, `csv/claims.csv`,
//! `report.md`), measurements and claims found in one report only. A report with a
//! missing or unreadable file is damaged ([`Comparison::damage`]): the command prints the
//! comparison and exits with status 2.

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

/// Reads `csv/measurements.csv`; a missing file is `Ok(None)` (the caller lists it).
fn read_measurements(dir: &Path) -> Result<Option<Measurements>> {
    let path = dir.join("csv").join("measurements.csv");
    let bad = |why: String| ReproduceError::Usage(format!("{}: {why}", path.display()));
    if !path.exists() {
        return Ok(None);
    }
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
    Ok(Some(out))
}

/// id → verdict, from `csv/claims.csv`; `Err` says what is wrong with the file.
fn read_verdicts(dir: &Path) -> std::result::Result<Vec<(String, String)>, String> {
    let path = dir.join("csv").join("claims.csv");
    let mut r = csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        match (rec.get(0), rec.get(6)) {
            (Some(id), Some(verdict)) if !id.is_empty() => out.push((id.to_string(), verdict.to_string())),
            _ => return Err(format!("{}: line {}: no claim id and verdict", path.display(), line + 2)),
        }
    }
    Ok(out)
}

fn read_header(dir: &Path) -> std::result::Result<Header, String> {
    let path = dir.join("run.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// What `--compare` found: the comparison as Markdown, and what is missing or unreadable
/// in either report (empty: both are whole).
#[derive(Clone, Debug)]
pub struct Comparison {
    pub markdown: String,
    pub damage: Vec<String>,
}

/// At most this many keys are listed per "in one report only" list.
const LISTED: usize = 20;

/// A Markdown list of `keys` (at most [`LISTED`], then how many more).
fn key_list(s: &mut String, keys: &[String]) {
    for k in keys.iter().take(LISTED) {
        let _ = writeln!(s, "- {k}");
    }
    if keys.len() > LISTED {
        let _ = writeln!(s, "- … and {} more", keys.len() - LISTED);
    }
}

fn num(v: f64) -> String {
    super::experiments::num(v)
}

/// The comparison of two report folders. Fails when either has no readable
/// measurements (nothing to compare), listing every problem of both.
pub fn compare(old: &Path, new: &Path) -> Result<Comparison> {
    let mut damage = Vec::new();
    let mut measured = Vec::new();
    for dir in [old, new] {
        match read_measurements(dir) {
            Ok(Some(m)) => measured.push(m),
            Ok(None) => damage.push(format!("{}: missing", dir.join("csv/measurements.csv").display())),
            Err(e) => damage.push(e.to_string()),
        }
        for file in ["report.md", "csv/claims.csv", "run.json"] {
            if !dir.join(file).is_file() {
                damage.push(format!("{}: missing", dir.join(file).display()));
            }
        }
    }
    let [a, b]: [Measurements; 2] = measured
        .try_into()
        .map_err(|_| ReproduceError::Usage(format!("cannot compare the reports: {}", damage.join("; "))))?;
    let mut s = String::from("# texgeo reproduce --compare\n\n");
    for (label, dir) in [("old", old), ("new", new)] {
        match read_header(dir) {
            Ok(h) => {
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
            Err(e) => {
                if dir.join("run.json").is_file() {
                    damage.push(e);
                }
                let _ = writeln!(s, "- {label}: `{}`", dir.display());
            }
        }
    }
    let mut moved = Vec::new();
    let mut changed = Vec::new();
    let mut within = 0usize;
    let name = |(e, m, q): &(String, String, String)| format!("{e} / {m} / {q}");
    let only_old: Vec<String> =
        a.iter().filter(|(k, _)| !b.iter().any(|(j, _)| j == k)).map(|(k, _)| name(k)).collect();
    let only_new: Vec<String> =
        b.iter().filter(|(k, _)| !a.iter().any(|(j, _)| j == k)).map(|(k, _)| name(k)).collect();
    for (key, x) in &a {
        let Some((_, y)) = b.iter().find(|(k, _)| k == key) else { continue };
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
    let mut verdicts = Vec::new();
    for dir in [old, new] {
        match read_verdicts(dir) {
            Ok(v) => verdicts.push(v),
            Err(e) => {
                if dir.join("csv/claims.csv").is_file() {
                    damage.push(e);
                }
                verdicts.push(Vec::new());
            }
        }
    }
    let (va, vb) = (&verdicts[0], &verdicts[1]);
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
    let claims_only = |x: &[(String, String)], y: &[(String, String)]| -> Vec<String> {
        x.iter().filter(|(id, _)| !y.iter().any(|(j, _)| j == id)).map(|(id, _)| id.clone()).collect()
    };
    let lists = [
        ("Measurements of the old report missing from the new one", only_old),
        ("Measurements of the new report missing from the old one", only_new),
        ("Claims of the old report missing from the new one", claims_only(va, vb)),
        ("Claims of the new report missing from the old one", claims_only(vb, va)),
    ];
    for (title, keys) in &lists {
        if !keys.is_empty() {
            let _ = writeln!(s, "\n## {title} ({})\n", keys.len());
            key_list(&mut s, keys);
        }
    }
    if !damage.is_empty() {
        let _ = writeln!(s, "\n## Damaged reports: missing or unreadable files ({})\n", damage.len());
        for d in &damage {
            let _ = writeln!(s, "- {d}");
        }
    }
    Ok(Comparison { markdown: s, damage })
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
        let ab = compare(&a, &b).unwrap().markdown;
        assert!(ab.contains("(0 of 2)"), "{ab}");
        let ac = compare(&a, &c).unwrap().markdown;
        assert!(ac.contains("(1 of 2)") && ac.contains("time:cpu@64") && ac.contains("2.000×"), "{ac}");
        assert!(ac.contains("memory:octants"), "an exact value that changed is listed: {ac}");
        for d in [a, b, c] {
            std::fs::remove_dir_all(d).unwrap();
        }
    }

    #[test]
    fn a_damaged_report_is_named_with_what_is_missing() {
        let a = run_dir("whole", 1.0, 0.1);
        let b = run_dir("damaged", 1.0, 0.1);
        for dir in [&a, &b] {
            std::fs::write(dir.join("report.md"), "# report\n").unwrap();
            std::fs::write(dir.join("run.json"), "{}").unwrap();
            std::fs::write(
                dir.join("csv/claims.csv"),
                "id,source,claim,decided by,thesis,measured,verdict\nV1,s,c,d,t,m,holds\nV2,s,c,d,t,m,holds\n",
            )
            .unwrap();
        }
        // Whole but for run.json's contents: damaged, and said so.
        let c = compare(&a, &b).unwrap();
        assert_eq!(c.damage.len(), 2, "{:?}", c.damage);
        assert!(c.damage.iter().all(|d| d.contains("run.json")), "{:?}", c.damage);
        // Measurements cut to the first row, claims deleted.
        let m = std::fs::read_to_string(b.join("csv/measurements.csv")).unwrap();
        let cut: Vec<&str> = m.lines().take(2).collect();
        std::fs::write(b.join("csv/measurements.csv"), cut.join("\n") + "\n").unwrap();
        std::fs::remove_file(b.join("csv/claims.csv")).unwrap();
        let c = compare(&a, &b).unwrap();
        assert!(c.damage.iter().any(|d| d.ends_with("claims.csv: missing")), "{:?}", c.damage);
        let md = &c.markdown;
        assert!(md.contains("Measurements of the old report missing from the new one (2)"), "{md}");
        assert!(
            md.contains("voxelize / knot / time:zoned@64")
                && md.contains("inclusion / knot / memory:octants")
        );
        assert!(
            md.contains("Claims of the old report missing from the new one (2)") && md.contains("- V2"),
            "{md}"
        );
        assert!(md.contains("## Damaged reports"), "{md}");
        for d in [a, b] {
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
