//! `texgeo reproduce --compare OLD NEW`: two runs side by side — each claim's verdict on
//! both (two devices, or one device on two days) and the GPU's speed-ups over the CPU
//! beside the thesis' — and what moved between them by more than the measured noise. Each run keeps every measured value with the range of its repeated
//! runs (`csv/measurements.csv`); a value moved when the two ranges do not overlap —
//! the noise is what the runs themselves showed, not a constant. Counts and sizes (a
//! single exact value) moved when they differ at all. Claims whose verdict changed are
//! listed too, and so is everything that keeps the two reports from being compared whole:
//! a missing or unreadable file (`run.json`, `csv/measurements.csv`, `csv/claims.csv`),
//! measurements and claims found in one report only. Those three files are all a comparison
//! reads, so a saved report (its `csv/` and `run.json`, as `docs/report/` keeps) compares
//! whole without its `report.md`, plots and figures. A report with a
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

const MODEL_COLUMNS: [&str; 4] = ["experiment", "model", "size", "thesis model"];

/// Every model of `facts` with its size and the thesis model it stands for ("–": none).
pub fn models_csv(facts: &Facts) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record(MODEL_COLUMNS);
    for (experiment, model, size, thesis) in &facts.models {
        let _ = w.write_record([experiment, model.as_str(), &size.to_string(), thesis.as_str()]);
    }
    String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
}

/// (experiment, model) → thesis model, from `csv/models.csv` (empty when the report has
/// none: its ratios are shown without the thesis').
fn read_models(dir: &Path) -> Vec<((String, String), String)> {
    let Ok(mut r) = csv::Reader::from_path(dir.join("csv").join("models.csv")) else { return Vec::new() };
    r.records()
        .filter_map(|rec| rec.ok())
        .filter_map(|rec| Some(((rec.get(0)?.to_string(), rec.get(1)?.to_string()), rec.get(3)?.to_string())))
        .collect()
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

/// A claim as `csv/claims.csv` keeps it.
#[derive(Clone, Debug, Default)]
struct ClaimRow {
    id: String,
    claim: String,
    thesis: String,
    measured: String,
    verdict: String,
}

/// The claims of `csv/claims.csv`; `Err` says what is wrong with the file.
fn read_claims(dir: &Path) -> std::result::Result<Vec<ClaimRow>, String> {
    let path = dir.join("csv").join("claims.csv");
    let mut r = csv::Reader::from_path(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (line, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| format!("{}: {e}", path.display()))?;
        let cell = |i: usize| rec.get(i).unwrap_or("").to_string();
        match (rec.get(0), rec.get(6)) {
            (Some(id), Some(_)) if !id.is_empty() => out.push(ClaimRow {
                id: id.to_string(),
                claim: cell(2),
                thesis: cell(4),
                measured: cell(5),
                verdict: cell(6),
            }),
            _ => return Err(format!("{}: line {}: no claim id and verdict", path.display(), line + 2)),
        }
    }
    Ok(out)
}

/// The claim without its quote: "The GPU test is faster («…»)" → "The GPU test is faster".
fn claim_words(claim: &str) -> &str {
    claim.split(" («").next().unwrap_or(claim)
}

/// A Markdown table cell: no pipes, no line breaks.
fn cell(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

/// Every claim of either report, its verdict on both side by side with the value that
/// decided it, and the thesis' own.
fn claims_side_by_side(s: &mut String, a: &[ClaimRow], b: &[ClaimRow]) {
    let mut ids: Vec<&str> = a.iter().map(|c| c.id.as_str()).collect();
    ids.extend(b.iter().map(|c| c.id.as_str()).filter(|id| !a.iter().any(|c| c.id == *id)));
    let _ = writeln!(s, "\n## Claims on both ({})\n", ids.len());
    if ids.is_empty() {
        s.push_str("No claims in either report.\n");
        return;
    }
    s.push_str(
        "| id | claim | thesis' own numbers | old: measured | old: verdict | new: measured | new: verdict |\n\
         |---|---|---|---|---|---|---|\n",
    );
    let absent =
        ClaimRow { measured: "–".into(), verdict: "not in this report".into(), ..ClaimRow::default() };
    for id in ids {
        let x = a.iter().find(|c| c.id == id).unwrap_or(&absent);
        let y = b.iter().find(|c| c.id == id).unwrap_or(&absent);
        let known = if x.claim.is_empty() { y } else { x };
        let _ = writeln!(
            s,
            "| {id} | {} | {} | {} | {} | {} | {} |",
            cell(claim_words(&known.claim)),
            cell(&known.thesis),
            cell(&x.measured),
            cell(&x.verdict),
            cell(&y.measured),
            cell(&y.verdict)
        );
    }
    let counts = |rows: &[ClaimRow]| {
        let count = |v: &str| rows.iter().filter(|c| c.verdict == v).count();
        let words = super::Verdict::WORDS.iter().enumerate();
        words.map(|(i, v)| super::doc::counted(count(v), i)).collect::<Vec<_>>().join(", ")
    };
    let _ = writeln!(s, "\nold: {}; new: {}.", counts(a), counts(b));
}

/// The speed-ups of the GPU methods over the CPU ones a reader compares across devices:
/// (experiment, label, CPU quantity, GPU quantity); `@N` stands for every resolution.
const SPEEDUPS: [(&str, &str, &str, &str); 7] = [
    ("inclusion", "Feito-Torres: CPU / GPU", "time:cpu", "time:gpu"),
    ("inclusion", "Feito-Torres: CPU / GPU + TetraGrid 32³", "time:cpu", "time:gpu+tetragrid"),
    ("voxelize", "slicing: cpu / pgpu", "time:cpu@N", "time:pgpu@N"),
    ("voxelize", "slicing: cpu / zoned", "time:cpu@N", "time:zoned@N"),
    ("boolean", "phase 2 grouped: CPU / GPU point tests", "time:phase2-cpu", "time:phase2-gpu"),
    ("subdivide", "level 5: CPU reference / GPU path", "time:tcpu2", "time:gpu-path"),
    ("subdivide", "level 5: OpenSubdiv / GPU path", "time:osd", "time:gpu-path"),
];

/// A speed-up a report can show: (experiment, label, model, CPU quantity, GPU quantity).
type SpeedUp = (&'static str, String, String, String, String);

/// The speed-ups either report has, in the order of [`SPEEDUPS`], each model as the
/// first report to have it lists it; `@N` is read as every resolution measured.
fn speedups_of(runs: [&Measurements; 2]) -> Vec<SpeedUp> {
    let mut rows: Vec<SpeedUp> = Vec::new();
    for (e, label, cpu, gpu) in SPEEDUPS {
        for ((_, model, q), _) in runs.iter().flat_map(|m| m.iter()).filter(|((x, _, _), _)| x == e) {
            let (cpu_key, gpu_key, label) = match (cpu.strip_suffix("@N"), gpu.strip_suffix("@N")) {
                (Some(c), Some(g)) => {
                    let Some(n) = q.strip_prefix(&format!("{c}@")) else { continue };
                    (q.clone(), format!("{g}@{n}"), format!("{label} at {n}³"))
                }
                _ if q == cpu => (cpu.to_string(), gpu.to_string(), label.to_string()),
                _ => continue,
            };
            if !rows.iter().any(|r| r.0 == e && r.1 == label && &r.2 == model) {
                rows.push((e, label, model.clone(), cpu_key, gpu_key));
            }
        }
    }
    rows
}

/// The CPU / GPU time ratios of both reports per model, beside the thesis' for the
/// thesis model each stands for (from `csv/models.csv`).
fn speedups_side_by_side(s: &mut String, dirs: [&Path; 2], runs: [&Measurements; 2]) {
    let thesis = super::thesis::facts();
    let models = dirs.map(read_models);
    let ratio = |m: &Measurements, e: &str, model: &str, c: &str, g: &str| -> Option<f64> {
        let value =
            |q: &str| m.iter().find(|((x, y, z), _)| x == e && y == model && z == q).map(|p| p.1.value);
        let (c, g) = (value(c)?, value(g)?);
        (g > 0.0).then(|| c / g)
    };
    let shown = |v: Option<f64>| v.map_or_else(|| "–".to_string(), |v| crate::report::sig(v, 3));
    let rows: Vec<String> = speedups_of(runs)
        .iter()
        .filter_map(|(e, label, model, c, g)| {
            let (x, y) = (ratio(runs[0], e, model, c, g), ratio(runs[1], e, model, c, g));
            if x.is_none() && y.is_none() {
                return None;
            }
            let stands_for = models
                .iter()
                .flatten()
                .find(|((xe, xm), t)| xe == e && xm == model && t != "–")
                .map(|(_, t)| t.as_str());
            let then = stands_for.and_then(|t| {
                let get = |k: &str| thesis.get(e, t, k).ok().map(|st| st.value);
                let (c, g) = (get(c)?, get(g)?);
                (g > 0.0).then(|| c / g)
            });
            Some(format!(
                "| {e} | {} | {} | {} | {} | {} | {} |",
                cell(label),
                cell(model),
                stands_for.unwrap_or("–"),
                shown(then),
                shown(x),
                shown(y)
            ))
        })
        .collect();
    let _ =
        writeln!(s, "\n## The GPU against the CPU: speed-ups on both, beside the thesis' ({})\n", rows.len());
    if rows.is_empty() {
        s.push_str("Neither report has a GPU and a CPU time of the same model.\n");
        return;
    }
    s.push_str(
        "| experiment | CPU time / GPU time | texgeo model | thesis model | thesis (×) | old (×) | new (×) |\n\
         |---|---|---|---|---:|---:|---:|\n",
    );
    for r in &rows {
        let _ = writeln!(s, "{r}");
    }
    s.push_str(
        "\nAbove 1 the GPU method is faster. Ratios of the runs' central values (means for point in solid, medians \
         otherwise); the thesis' from its tables for the model the texgeo model stands for (\"–\": none, or the \
         thesis has no such number).\n",
    );
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
    let [a, b] = read_measurements_of_both(old, new, &mut damage)?;
    let mut s = String::from("# texgeo reproduce --compare\n\n");
    for (label, dir) in [("old", old), ("new", new)] {
        header_line(&mut s, label, dir, &mut damage);
    }
    let [va, vb] = [old, new].map(|dir| {
        read_claims(dir).unwrap_or_else(|e| {
            if dir.join("csv/claims.csv").is_file() {
                damage.push(e);
            }
            Vec::new()
        })
    });
    claims_side_by_side(&mut s, &va, &vb);
    speedups_side_by_side(&mut s, [old, new], [&a, &b]);
    moved_sections(&mut s, &a, &b);
    flipped_section(&mut s, &va, &vb);
    let name = |(e, m, q): &(String, String, String)| format!("{e} / {m} / {q}");
    let only = |x: &Measurements, y: &Measurements| -> Vec<String> {
        x.iter().filter(|(k, _)| !y.iter().any(|(j, _)| j == k)).map(|(k, _)| name(k)).collect()
    };
    let claims_only = |x: &[ClaimRow], y: &[ClaimRow]| -> Vec<String> {
        x.iter().filter(|c| !y.iter().any(|d| d.id == c.id)).map(|c| c.id.clone()).collect()
    };
    let lists = [
        ("Measurements of the old report missing from the new one", only(&a, &b)),
        ("Measurements of the new report missing from the old one", only(&b, &a)),
        ("Claims of the old report missing from the new one", claims_only(&va, &vb)),
        ("Claims of the new report missing from the old one", claims_only(&vb, &va)),
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

/// Both reports' measurements; a missing file of either report goes to `damage`, and
/// without measurements in both there is nothing to compare.
fn read_measurements_of_both(old: &Path, new: &Path, damage: &mut Vec<String>) -> Result<[Measurements; 2]> {
    let mut measured = Vec::new();
    for dir in [old, new] {
        match read_measurements(dir) {
            Ok(Some(m)) => measured.push(m),
            Ok(None) => damage.push(format!("{}: missing", dir.join("csv/measurements.csv").display())),
            Err(e) => damage.push(e.to_string()),
        }
        for file in ["csv/claims.csv", "run.json"] {
            if !dir.join(file).is_file() {
                damage.push(format!("{}: missing", dir.join(file).display()));
            }
        }
    }
    measured
        .try_into()
        .map_err(|_| ReproduceError::Usage(format!("cannot compare the reports: {}", damage.join("; "))))
}

/// "- old: `DIR` — device on machine (CPU), driver, …" from the report's `run.json`.
fn header_line(s: &mut String, label: &str, dir: &Path, damage: &mut Vec<String>) {
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

/// The repeated measurements whose runs do not overlap between the reports, largest
/// change first, and the single numbers and counts that differ at all.
fn moved_sections(s: &mut String, a: &Measurements, b: &Measurements) {
    let mut moved = Vec::new();
    let mut changed = Vec::new();
    let mut within = 0usize;
    for (key, x) in a {
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
}

/// The claims whose verdict differs between the reports.
fn flipped_section(s: &mut String, a: &[ClaimRow], b: &[ClaimRow]) {
    let flips: Vec<String> = a
        .iter()
        .filter_map(|x| {
            let y = b.iter().find(|y| y.id == x.id)?;
            (y.verdict != x.verdict).then(|| format!("{}: {} → {}", x.id, x.verdict, y.verdict))
        })
        .collect();
    let _ = writeln!(s, "\n## Claims whose verdict changed ({})\n", flips.len());
    for f in &flips {
        let _ = writeln!(s, "- {f}");
    }
    if flips.is_empty() {
        s.push_str("None.\n");
    }
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

    /// A report folder made by the report's own writers from `speedup`: the GPU test
    /// `speedup` times faster than the CPU test on two models (every repetition alike).
    fn device_report(name: &str, speedup: f64) -> (std::path::PathBuf, Facts) {
        use crate::report::Samples;
        use std::time::Duration;
        let dir = std::env::temp_dir().join(format!("texgeo-compare-{name}-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("csv")).unwrap();
        let mut f = Facts::new(Source::Today);
        for (model, thesis, size, cpu) in
            [("builtin:knot", "Torusknot", 1200.0, 0.01), ("big", "–", 9600.0, 0.08)]
        {
            f.model("inclusion", model, size, thesis);
            for (key, t) in [("time:cpu", cpu), ("time:gpu", cpu / speedup)] {
                let runs =
                    Samples((0..4).map(|k| Duration::from_secs_f64(t * (1.0 + 0.01 * k as f64))).collect());
                f.add_runs("inclusion", model, key, Stat::mean_of(&runs), &runs);
            }
        }
        let (_, claims, _) = super::super::claims_table(&super::super::thesis::facts(), &f);
        std::fs::write(dir.join("csv/claims.csv"), claims.to_csv()).unwrap();
        std::fs::write(dir.join("csv/measurements.csv"), measurements_csv(&f)).unwrap();
        std::fs::write(dir.join("csv/models.csv"), models_csv(&f)).unwrap();
        std::fs::write(dir.join("report.md"), "# report\n").unwrap();
        (dir, f)
    }

    #[test]
    fn two_devices_show_every_claim_and_speed_up_side_by_side() {
        let ((fast, f), (slow, g)) = (device_report("gpu", 5.0), device_report("cpu", 1.0 / 3.0));
        let md = compare(&fast, &slow).unwrap().markdown;
        let claims: Vec<super::ClaimRow> = super::read_claims(&fast).unwrap();
        assert!(md.contains(&format!("## Claims on both ({})", claims.len())), "{md}");
        // The claim that the GPU test is at least 2× faster on the largest model (I6):
        // decided by the same rule on both, one verdict per device.
        let row = |id: &str| md.lines().find(|l| l.starts_with(&format!("| {id} |"))).unwrap().to_string();
        let i6 = row("I6");
        let verdicts: Vec<&str> = i6.trim_end_matches(" |").split(" | ").collect();
        assert_eq!((verdicts[4], verdicts[6]), ("holds", "does not hold"), "{i6}");
        assert!(i6.contains("(holds)"), "the thesis' own verdict beside them: {i6}");
        // Every claim is a row, with its verdict from each report.
        for c in &claims {
            assert!(row(&c.id).contains(&c.verdict), "{}", c.id);
        }
        // The speed-ups: measured on both, the thesis' for the model the knot stands for.
        let ratio = |f: &Facts, m: &str| {
            let v = |k| f.get("inclusion", m, k).unwrap().value;
            crate::report::sig(v("time:cpu") / v("time:gpu"), 3)
        };
        let thesis = super::super::thesis::facts();
        let t = |k| thesis.get("inclusion", "Torusknot", k).unwrap().value;
        let then = crate::report::sig(t("time:cpu") / t("time:gpu"), 3);
        let knot = md.lines().find(|l| l.contains("| Feito-Torres: CPU / GPU | builtin:knot |")).unwrap();
        assert!(
            knot.ends_with(&format!(
                "| Torusknot | {then} | {} | {} |",
                ratio(&f, "builtin:knot"),
                ratio(&g, "builtin:knot")
            )),
            "{knot}"
        );
        let big = md.lines().find(|l| l.contains("| Feito-Torres: CPU / GPU | big |")).unwrap();
        assert!(big.ends_with(&format!("| – | – | {} | {} |", ratio(&f, "big"), ratio(&g, "big"))), "{big}");
        for d in [fast, slow] {
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
