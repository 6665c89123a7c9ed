//! Numbers the claims are judged on: one store for the thesis' tables and one for
//! today's measurements, with the same experiments, quantities and units, so one claim
//! function computes both the thesis' value and today's.
//!
//! A fact is (experiment, model, quantity) → a value with the range of its repeated
//! runs, or the reason it is missing (the device lacks a feature, the experiment was not
//! run). Times are in seconds. Quantities used so far:
//!
//! - `inclusion`: `time:METHOD` (s per set of points; methods as `texgeo inclusion
//!   --method`, plus `gpu-batch-1`, `tetragrid-N`, `bsp`), `build:INDEX` (s) and
//!   `memory:INDEX` (KiB) for `octants`, `tetragrid`, `bvh`, `bsp`, `jordan-octree`,
//!   `tetragrid-N`; `tested:tetragrid-N` (share of all tetrahedra a point is tested against).
//! - `voxelize`: `time:METHOD@N` (s) for `cpu`, `fgpu`, `pgpu`, `zoned`, `fang`, `scanline`.
//! - `subdivide`: `time:tcpu1`, `time:tgpu`, `time:gpu-path`, `time:tcpu2`, `time:osd` (s,
//!   level 5), `faces`, `fragments`, `passes`, `gpu-levels`; per level L of the level sweep
//!   `level:L:gpu-path`, `level:L:cpu`, `level:L:osd`, `level:L:gpu-levels`.
//! - `boolean` (for `texgeo bench boolean` when it exists): `reduction` (share of point
//!   tests saved by grouping, 0–1), `time:phase1`, `time:phase2-cpu`, `time:phase2-gpu`,
//!   `time:total`.
//!
//! Every model has a size (`size`: triangles of its covering, or faces for subdivision).

use crate::report::Samples;

/// A measured value and the range of the runs behind it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stat {
    /// The figure the tables show (a mean or a median).
    pub value: f64,
    pub min: f64,
    pub max: f64,
    /// Repeated runs behind it (1: a single measurement or a count).
    pub runs: usize,
}

impl Stat {
    pub fn exact(value: f64) -> Stat {
        Stat { value, min: value, max: value, runs: 1 }
    }

    /// Mean of the samples, in seconds, with their range.
    pub fn mean_of(s: &Samples) -> Stat {
        Stat::with_range(s.mean().as_secs_f64(), s)
    }

    /// Median of the samples, in seconds, with their range.
    pub fn median_of(s: &Samples) -> Stat {
        Stat::with_range(s.median().as_secs_f64(), s)
    }

    fn with_range(value: f64, s: &Samples) -> Stat {
        Stat { value, min: s.min().as_secs_f64(), max: s.max().as_secs_f64(), runs: s.0.len().max(1) }
    }

    /// Whether the runs of `self` and `other` overlap: the difference is within the
    /// measured noise.
    pub fn overlaps(&self, other: &Stat) -> bool {
        self.min <= other.max && other.min <= self.max
    }
}

#[derive(Clone, Debug)]
pub struct Fact {
    pub experiment: &'static str,
    pub model: String,
    pub key: String,
    pub unit: &'static str,
    pub value: Result<Stat, String>,
    /// Every repetition's value in the order they ran (empty: a single number). The
    /// sides of a comparison are measured in turn, so repetition k of two facts of one
    /// model ran back to back.
    pub runs: Vec<f64>,
}

/// Why an experiment has no facts at all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum NotRun {
    /// `--only` left it out.
    LeftOut,
    /// Its command does not exist yet: why.
    NoCommand(String),
    /// The device lacks a feature it needs: which.
    Unsupported(String),
    /// It failed: the error.
    Failed(String),
}

impl std::fmt::Display for NotRun {
    /// The words a claim that needs the experiment shows.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NotRun::LeftOut => f.write_str("not run: left out by --only"),
            NotRun::NoCommand(why) => f.write_str(why),
            NotRun::Unsupported(why) => write!(f, "not measurable on this device: {why}"),
            NotRun::Failed(err) => write!(f, "the experiment failed: {err}"),
        }
    }
}

/// Why a number is missing, said in words a reader of the report understands (never
/// the store's keys).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Missing {
    /// The experiment did not run.
    NotRun(NotRun),
    /// This device could not measure the number: the reason.
    Why(String),
    /// No model of the source has the quantity (key).
    NoModel(String),
    /// One model lacks the quantity.
    NotFor { key: String, model: String },
    /// No model has both quantities.
    NoPair(String, String),
}

impl std::fmt::Display for Missing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Missing::NotRun(why) => why.fmt(f),
            Missing::Why(why) => f.write_str(why),
            Missing::NoModel(key) => write!(f, "no model has {}", describe(key)),
            Missing::NotFor { key, model } => write!(f, "{} was not measured on {model}", describe(key)),
            Missing::NoPair(a, b) => write!(f, "no model has both {} and {}", describe(a), describe(b)),
        }
    }
}

impl From<Missing> for String {
    fn from(m: Missing) -> String {
        m.to_string()
    }
}

/// A method or part of a key in words.
fn method_words(m: &str) -> String {
    let words = match m {
        "cpu" => "the CPU test",
        "gpu" => "the GPU test",
        "jordan" => "Jordan's test",
        "jordan-octree" => "Jordan's test with an octree",
        "gpu-path" => "the GPU path",
        "tcpu1" => "the CPU base level (TCPU¹)",
        "tgpu" => "the fragment passes (TGPU)",
        "tcpu2" => "the CPU reference (TCPU²)",
        "osd" => "OpenSubdiv",
        "phase1" => "phase 1",
        "phase2-cpu" | "phase2-grouped" => "phase 2 with CPU point tests",
        "phase2-gpu" => "phase 2 with GPU point tests",
        "phase2-plain" => "phase 2 with plain classification",
        "total" => "the whole grouped operation",
        "all-ops" => "all three operations",
        "one-op" => "a single operation",
        other => return other.replace("tetragrid-", "TetraGrid ").replace('-', " "),
    };
    words.to_string()
}

/// A quantity of the store in words: "time:phase2-cpu" → "the time of phase 2 with CPU
/// point tests".
pub fn describe(key: &str) -> String {
    let parts: Vec<&str> = key.split(':').collect();
    match parts.as_slice() {
        ["time", m] => match m.split_once('@') {
            Some((m, n)) => format!("the time of {} at {n}³", method_words(m)),
            None => format!("the time of {}", method_words(m)),
        },
        ["build", m] => format!("the build time of {}", method_words(m)),
        ["memory", m] => format!("the memory of {}", method_words(m)),
        ["tested", m] => format!("the share of tetrahedra tested by {}", method_words(m)),
        ["level", l, "gpu-levels"] => format!("the GPU levels at level {l}"),
        ["level", l, m] => format!("the time of {} at level {l}", method_words(m)),
        ["reduction"] => "the share of point tests saved".into(),
        ["passes"] => "a count of fragment passes".into(),
        ["gpu-levels"] => "a count of GPU levels".into(),
        _ => key.replace([':', '-'], " "),
    }
}

/// Where the numbers come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    Thesis,
    Today,
}

#[derive(Clone, Debug)]
pub struct Facts {
    pub source: Source,
    pub facts: Vec<Fact>,
    /// (experiment, model, size, thesis model it stands for or "–").
    pub models: Vec<(&'static str, String, f64, String)>,
    /// Experiments that did not run, and why.
    pub not_run: Vec<(&'static str, NotRun)>,
}

impl Facts {
    pub fn new(source: Source) -> Facts {
        Facts { source, facts: Vec::new(), models: Vec::new(), not_run: Vec::new() }
    }

    /// Declares a model of `experiment` with its size and the thesis model it stands for.
    pub fn model(&mut self, experiment: &'static str, model: &str, size: f64, thesis: &str) {
        if !self.models.iter().any(|m| m.0 == experiment && m.1 == model) {
            self.models.push((experiment, model.to_string(), size, thesis.to_string()));
        }
    }

    pub fn add(&mut self, experiment: &'static str, model: &str, key: &str, unit: &'static str, stat: Stat) {
        self.push(experiment, model, key, unit, Ok(stat));
    }

    /// A timed value (seconds) with every repetition behind it.
    pub fn add_runs(&mut self, experiment: &'static str, model: &str, key: &str, stat: Stat, runs: &Samples) {
        self.push(experiment, model, key, "s", Ok(stat));
        if let Some(f) = self.facts.last_mut() {
            f.runs = runs.0.iter().map(|d| d.as_secs_f64()).collect();
        }
    }

    pub fn missing(
        &mut self,
        experiment: &'static str,
        model: &str,
        key: &str,
        unit: &'static str,
        why: &str,
    ) {
        self.push(experiment, model, key, unit, Err(why.to_string()));
    }

    fn push(
        &mut self,
        experiment: &'static str,
        model: &str,
        key: &str,
        unit: &'static str,
        value: Result<Stat, String>,
    ) {
        self.facts.push(Fact {
            experiment,
            model: model.to_string(),
            key: key.to_string(),
            unit,
            value,
            runs: Vec::new(),
        });
    }

    pub fn skipped(&mut self, experiment: &'static str, why: NotRun) {
        self.not_run.push((experiment, why));
    }

    /// Why nothing of `experiment` can be found, if it did not run.
    pub fn why_not_run(&self, experiment: &str) -> Option<&NotRun> {
        self.not_run.iter().find(|n| n.0 == experiment).map(|n| &n.1)
    }

    /// [`Facts::why_not_run`] in words, else `otherwise`: why a claim on `experiment`
    /// has no number.
    pub fn not_run_or(&self, experiment: &str, otherwise: &str) -> String {
        self.why_not_run(experiment).map_or_else(|| otherwise.to_string(), NotRun::to_string)
    }

    /// The models of `experiment`, smallest first: (name, size).
    pub fn models_of(&self, experiment: &str) -> Vec<(String, f64)> {
        let mut v: Vec<(String, f64)> =
            self.models.iter().filter(|m| m.0 == experiment).map(|m| (m.1.clone(), m.2)).collect();
        v.sort_by(|a, b| a.1.total_cmp(&b.1));
        v
    }

    /// The thesis model `model` stands for ("–" if none).
    pub fn thesis_name(&self, experiment: &str, model: &str) -> String {
        self.models
            .iter()
            .find(|m| m.0 == experiment && m.1 == model)
            .map_or_else(|| "–".to_string(), |m| m.3.clone())
    }

    pub fn size(&self, experiment: &str, model: &str) -> Option<f64> {
        self.models.iter().find(|m| m.0 == experiment && m.1 == model).map(|m| m.2)
    }

    pub fn find(&self, experiment: &str, model: &str, key: &str) -> Option<&Fact> {
        self.facts.iter().find(|f| f.experiment == experiment && f.model == model && f.key == key)
    }

    /// The value, or why there is none.
    pub fn get(&self, experiment: &str, model: &str, key: &str) -> Result<Stat, Missing> {
        if let Some(why) = self.why_not_run(experiment) {
            return Err(Missing::NotRun(why.clone()));
        }
        match self.find(experiment, model, key) {
            Some(f) => f.value.clone().map_err(Missing::Why),
            None => Err(Missing::NotFor { key: key.to_string(), model: model.to_string() }),
        }
    }

    /// `key` on every model that has it, smallest model first: (model, size, value).
    /// Err: the reason, when no model has it.
    pub fn series(&self, experiment: &str, key: &str) -> Result<Vec<(String, f64, Stat)>, Missing> {
        if let Some(why) = self.why_not_run(experiment) {
            return Err(Missing::NotRun(why.clone()));
        }
        let mut out = Vec::new();
        let mut why = None;
        for (model, size) in self.models_of(experiment) {
            match self.find(experiment, &model, key).map(|f| &f.value) {
                Some(Ok(s)) => out.push((model, size, *s)),
                Some(Err(w)) => why = why.or(Some(w.clone())),
                None => {}
            }
        }
        if out.is_empty() {
            return Err(why.map_or_else(|| Missing::NoModel(key.to_string()), Missing::Why));
        }
        Ok(out)
    }

    /// `a / b` with its interval on every model that has both, smallest model first:
    /// (model, size, ratio).
    pub fn ratios(&self, experiment: &str, a: &str, b: &str) -> Result<Vec<(String, f64, Ratio)>, Missing> {
        let pairs = self.pairs(experiment, a, b)?;
        Ok(pairs
            .into_iter()
            .filter_map(|(m, size, _, _)| {
                let r = Ratio::of(self.find(experiment, &m, a)?, self.find(experiment, &m, b)?)?;
                Some((m, size, r))
            })
            .collect())
    }

    /// Every repetition of `key` on `model` (empty: a single number or none).
    pub fn runs(&self, experiment: &str, model: &str, key: &str) -> &[f64] {
        self.find(experiment, model, key).map_or(&[], |f| f.runs.as_slice())
    }

    /// `a` and `b` on every model that has both: (model, size, a, b).
    pub fn pairs(
        &self,
        experiment: &str,
        a: &str,
        b: &str,
    ) -> Result<Vec<(String, f64, Stat, Stat)>, Missing> {
        let first = self.series(experiment, a)?;
        let mut out = Vec::new();
        let mut why = None;
        for (model, size, x) in first {
            match self.get(experiment, &model, b) {
                Ok(y) => out.push((model, size, x, y)),
                Err(w) => why = why.or(Some(w)),
            }
        }
        if out.is_empty() {
            return Err(why.unwrap_or_else(|| Missing::NoPair(a.to_string(), b.to_string())));
        }
        Ok(out)
    }
}

/// A ratio of two measured values with its interval: the range of the per-repetition
/// ratios when both sides were measured in turn the same number of times, else the
/// widest ratio their ranges allow (a point for single numbers).
#[derive(Clone, Debug, PartialEq)]
pub struct Ratio {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
    /// Per-repetition ratios (empty when the sides were not paired).
    pub runs: Vec<f64>,
}

impl Ratio {
    pub fn of(a: &Fact, b: &Fact) -> Option<Ratio> {
        let (x, y) = (a.value.as_ref().ok()?, b.value.as_ref().ok()?);
        if a.runs.len() >= 2 && a.runs.len() == b.runs.len() && b.runs.iter().all(|v| *v > 0.0) {
            let runs: Vec<f64> = a.runs.iter().zip(&b.runs).map(|(p, q)| p / q).collect();
            let lo = runs.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = runs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            return Some(Ratio { value: median(&runs), lo, hi, runs });
        }
        let value = x.value / y.value;
        let (lo, hi) = if x.runs > 1 || y.runs > 1 { (x.min / y.max, x.max / y.min) } else { (value, value) };
        Some(Ratio { value, lo: lo.min(value), hi: hi.max(value), runs: Vec::new() })
    }
}

/// Median of a non-empty list (0 for an empty one).
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => 0.0,
        n if n % 2 == 1 => s[n / 2],
        n => (s[n / 2 - 1] + s[n / 2]) / 2.0,
    }
}

/// Least-squares slope of log(y) against log(x); `None` unless the sizes span at least
/// a factor of two.
pub fn loglog_slope(points: &[(f64, f64)]) -> Option<f64> {
    let pts: Vec<(f64, f64)> =
        points.iter().filter(|p| p.0 > 0.0 && p.1 > 0.0).map(|p| (p.0.ln(), p.1.ln())).collect();
    let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| (a.0.min(p.0), a.1.max(p.0)));
    if pts.len() < 2 || hi - lo < 2f64.ln() {
        return None;
    }
    let n = pts.len() as f64;
    let (mx, my) = (pts.iter().map(|p| p.0).sum::<f64>() / n, pts.iter().map(|p| p.1).sum::<f64>() / n);
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    Some(sxy / sxx)
}

/// Spearman's rank correlation of two equally long lists (ties get their mean rank);
/// `None` for fewer than three items.
pub fn spearman(x: &[f64], y: &[f64]) -> Option<f64> {
    if x.len() < 3 || x.len() != y.len() {
        return None;
    }
    let ranks = |v: &[f64]| {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
        let mut r = vec![0.0; v.len()];
        let mut i = 0;
        while i < idx.len() {
            let mut j = i;
            while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
                j += 1;
            }
            for &k in &idx[i..=j] {
                r[k] = (i + j) as f64 / 2.0;
            }
            i = j + 1;
        }
        r
    };
    let (rx, ry) = (ranks(x), ranks(y));
    let n = x.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let (vx, vy): (f64, f64) =
        (rx.iter().map(|a| (a - mx).powi(2)).sum(), ry.iter().map(|b| (b - my).powi(2)).sum());
    if vx == 0.0 || vy == 0.0 {
        return None;
    }
    Some(cov / (vx * vy).sqrt())
}

/// Geometric mean of positive values.
pub fn geomean(v: &[f64]) -> Option<f64> {
    let logs: Vec<f64> = v.iter().filter(|x| **x > 0.0).map(|x| x.ln()).collect();
    (!logs.is_empty() && logs.len() == v.len()).then(|| (logs.iter().sum::<f64>() / logs.len() as f64).exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slopes_and_ranks() {
        let pts: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0].iter().map(|&x| (x, 3.0 * x * x)).collect();
        assert!((loglog_slope(&pts).unwrap() - 2.0).abs() < 1e-12);
        assert_eq!(loglog_slope(&[(1.0, 1.0), (1.5, 2.0)]), None, "sizes within a factor of two");
        assert!((spearman(&[1.0, 2.0, 3.0], &[10.0, 20.0, 30.0]).unwrap() - 1.0).abs() < 1e-12);
        assert!((spearman(&[1.0, 2.0, 3.0], &[3.0, 2.0, 1.0]).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(spearman(&[1.0, 2.0], &[1.0, 2.0]), None);
        assert!((geomean(&[1.0, 100.0]).unwrap() - 10.0).abs() < 1e-9);
    }

    #[test]
    fn missing_facts_carry_their_reason() {
        let mut f = Facts::new(Source::Today);
        f.model("voxelize", "knot", 1200.0, "Torusknot");
        f.missing("voxelize", "knot", "time:zoned@64", "s", "device lacks logic_op");
        f.add("voxelize", "knot", "time:cpu@64", "s", Stat::exact(0.1));
        let why = |s: &str| Missing::Why(s.to_string());
        assert_eq!(f.get("voxelize", "knot", "time:zoned@64"), Err(why("device lacks logic_op")));
        assert_eq!(f.series("voxelize", "time:zoned@64").unwrap_err(), why("device lacks logic_op"));
        assert_eq!(f.series("voxelize", "time:cpu@64").unwrap().len(), 1);
        // A quantity no model has is said in words, not by its key.
        let none = f.series("voxelize", "time:fang@64").unwrap_err();
        assert_eq!(none, Missing::NoModel("time:fang@64".into()));
        assert_eq!(none.to_string(), "no model has the time of fang at 64³");
        f.skipped("boolean", NotRun::NoCommand("not run".into()));
        let not_run = f.series("boolean", "reduction").unwrap_err();
        assert_eq!(not_run, Missing::NotRun(NotRun::NoCommand("not run".into())));
        assert_eq!(not_run.to_string(), "not run");
        f.skipped("voxelize2", NotRun::Unsupported("logic_op".into()));
        assert_eq!(f.not_run_or("voxelize2", "–"), "not measurable on this device: logic_op");
        assert_eq!(f.not_run_or("voxelize3", "nothing measured"), "nothing measured");
        f.model("boolean2", "torus", 10.0, "–");
        let e = f.pairs("boolean2", "time:phase2-cpu", "time:phase2-gpu").unwrap_err().to_string();
        assert_eq!(e, "no model has the time of phase 2 with CPU point tests");
        assert!(!e.contains(':'), "{e}");
    }
}
