//! The theses' quantitative claims about the experiments texgeo reproduces, each with
//! the rule that decides it and a function that computes the deciding value from facts
//! (`facts.rs`): run on the thesis' own tables it gives the thesis' value, run on today's
//! measurements it gives today's value and the verdict. No verdict is written by hand.
//!
//! Words of degree are read the same way everywhere: "faster", "better" — a ratio above
//! 1; "much", "considerably", "greatly" — at least 2×; "drastically", "enormously", "the
//! vast majority" — at least 10× (90 %); "linear" — a log–log slope between 0.8 and 1.2;
//! "close" — within a factor of 2; "equal or better" — not slower beyond the range of the
//! repeated runs (within 5 % for single numbers, such as the thesis').

use super::facts::{Facts, Missing, Ratio, Stat, geomean, loglog_slope, spearman};

/// A claim of a thesis.
pub struct Claim {
    pub id: &'static str,
    /// Where it is written: "2006 §4.4.3.2".
    pub source: &'static str,
    /// The thesis' words, shortened (Spanish).
    pub quote: &'static str,
    /// The claim in English, as tested.
    pub claim: &'static str,
    /// How the verdict is decided.
    pub rule: &'static str,
    /// The deciding value and where the rule puts it, or why it cannot be computed.
    pub measure: fn(&Facts) -> Measure,
}

/// Where a rule puts a deciding value and its interval: wholly on the side where the
/// claim holds, wholly on the other side, or across the threshold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Decision {
    Holds,
    DoesNotHold,
    /// The interval straddles the threshold: the noise of the repetitions decides.
    Inconclusive,
}

impl From<bool> for Decision {
    fn from(holds: bool) -> Decision {
        if holds { Decision::Holds } else { Decision::DoesNotHold }
    }
}

impl Decision {
    /// Holds when every part holds, does not hold when any part does not, else inconclusive.
    fn all(parts: impl IntoIterator<Item = Decision>) -> Decision {
        Decision::unless(Decision::DoesNotHold, Decision::Holds, parts)
    }

    /// Holds when any part holds, does not hold when every part does not, else inconclusive.
    fn any(parts: impl IntoIterator<Item = Decision>) -> Decision {
        Decision::unless(Decision::Holds, Decision::DoesNotHold, parts)
    }

    /// `decisive` as soon as a part is; else `otherwise` when every part is, or
    /// inconclusive.
    fn unless(
        decisive: Decision,
        otherwise: Decision,
        parts: impl IntoIterator<Item = Decision>,
    ) -> Decision {
        let mut out = otherwise;
        for d in parts {
            if d == decisive {
                return decisive;
            }
            if d == Decision::Inconclusive {
                out = Decision::Inconclusive;
            }
        }
        out
    }
}

/// What is missing, in words; `why` when no model has the quantity at all (its source
/// never measured it).
fn unless_measured(why: &'static str) -> impl Fn(Missing) -> String {
    move |e| if matches!(e, Missing::NoModel(_)) { why.to_string() } else { e.into() }
}

/// The interval [lo, hi] against "at least t".
fn at_least(lo: f64, hi: f64, t: f64) -> Decision {
    if lo >= t {
        Decision::Holds
    } else if hi < t {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    }
}

/// The interval [lo, hi] against "above t".
fn above(lo: f64, hi: f64, t: f64) -> Decision {
    if lo > t {
        Decision::Holds
    } else if hi <= t {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    }
}

/// The interval [lo, hi] against "at most t".
fn at_most(lo: f64, hi: f64, t: f64) -> Decision {
    if hi <= t {
        Decision::Holds
    } else if lo > t {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    }
}

/// The interval [lo, hi] against "within a–b".
fn within(lo: f64, hi: f64, a: f64, b: f64) -> Decision {
    if lo >= a && hi <= b {
        Decision::Holds
    } else if hi < a || lo > b {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    }
}

/// The number a rule decided on and its interval, for programs (`claims.csv`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Value {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
    /// "ratio", "slope", "rank correlation", "share" or "s".
    pub unit: &'static str,
}

impl Value {
    fn ratio(r: &Ratio) -> Value {
        Value { value: r.value, lo: r.lo, hi: r.hi, unit: "ratio" }
    }
}

/// What a claim's function finds: the value shown (with its interval), where the rule
/// puts it, and the deciding number when the rule has one (not for counts of models).
#[derive(Clone, Debug)]
pub struct Found {
    pub shown: String,
    pub decision: Decision,
    pub value: Option<Value>,
}

impl From<(String, Decision)> for Found {
    fn from((shown, decision): (String, Decision)) -> Found {
        Found { shown, decision, value: None }
    }
}

impl Found {
    fn with(mut self, value: Value) -> Found {
        self.value = Some(value);
        self
    }
}

pub type Measure = Result<Found, String>;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    Holds,
    DoesNotHold,
    Inconclusive,
    NotMeasurable(String),
}

impl Verdict {
    pub fn of(m: &Measure) -> Verdict {
        match m {
            Ok(Found { decision: Decision::Holds, .. }) => Verdict::Holds,
            Ok(Found { decision: Decision::DoesNotHold, .. }) => Verdict::DoesNotHold,
            Ok(Found { decision: Decision::Inconclusive, .. }) => Verdict::Inconclusive,
            Err(why) => Verdict::NotMeasurable(why.clone()),
        }
    }

    /// The words of the four verdicts, in [`Verdict::index`] order.
    pub const WORDS: [&'static str; 4] =
        ["holds", "does not hold", "inconclusive (within noise)", "not measurable"];

    /// 0 holds, 1 does not hold, 2 inconclusive, 3 not measurable: where the verdict
    /// is counted.
    pub fn index(&self) -> usize {
        match self {
            Verdict::Holds => 0,
            Verdict::DoesNotHold => 1,
            Verdict::Inconclusive => 2,
            Verdict::NotMeasurable(_) => 3,
        }
    }

    /// "holds", "does not hold", "inconclusive (within noise)", "not measurable".
    pub fn word(&self) -> &'static str {
        Verdict::WORDS[self.index()]
    }
}

fn x(v: f64) -> String {
    if v >= 100.0 {
        format!("{v:.0}×")
    } else if v >= 10.0 {
        format!("{v:.1}×")
    } else {
        format!("{v:.2}×")
    }
}

/// A ratio and, when it has one, its interval: "2.31× (2.10–2.52×)".
fn xr(r: &Ratio) -> String {
    if x(r.lo) == x(r.hi) {
        x(r.value)
    } else {
        format!("{} ({}–{})", x(r.value), x(r.lo).trim_end_matches('×'), x(r.hi))
    }
}

/// A slope or correlation and its interval: "0.95 (0.81–1.10)".
fn fr(v: f64, lo: f64, hi: f64, sign: bool) -> String {
    let f = |v: f64| if sign { format!("{v:+.2}") } else { format!("{v:.2}") };
    if f(lo) == f(hi) { f(v) } else { format!("{} ({}–{})", f(v), f(lo), f(hi)) }
}

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// `a / b` with its interval for every model that has both: (model, size, ratio).
fn ratios(f: &Facts, exp: &str, a: &str, b: &str) -> Result<Vec<(String, f64, Ratio)>, String> {
    Ok(f.ratios(exp, a, b)?)
}

/// The ratio on every model, which must reach `t` (`strict`: exceed it).
fn min_ratio(f: &Facts, exp: &str, a: &str, b: &str, t: f64, strict: bool) -> Measure {
    min_ratio_above(f, exp, a, b, t, strict, 0.0)
}

/// Below this time (s) a measured run is mostly fixed cost and scheduling: on the quick
/// set's pyramid OpenSubdiv and the GPU path both take about a millisecond, and a busy
/// core moved their ratio from 0.1× to over 1×.
const DECIDING_TIME: f64 = 5e-3;

/// [`min_ratio`], except that a model where today both sides took less than `floor`
/// seconds decides nothing (it stays inconclusive): the claim is about the algorithms'
/// cost, which such times do not show.
fn min_ratio_above(f: &Facts, exp: &str, a: &str, b: &str, t: f64, strict: bool, floor: f64) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let too_short = |m: &str| {
        let time = |key: &str| f.get(exp, m, key).map_or(f64::INFINITY, |s| s.value);
        f.source == super::facts::Source::Today && time(a) < floor && time(b) < floor
    };
    let short: Vec<&str> = r.iter().filter(|p| too_short(&p.0)).map(|p| p.0.as_str()).collect();
    let rule = |m: &str, q: &Ratio| {
        if short.contains(&m) {
            Decision::Inconclusive
        } else if strict {
            above(q.lo, q.hi, t)
        } else {
            at_least(q.lo, q.hi, t)
        }
    };
    let decision = Decision::all(r.iter().map(|p| rule(&p.0, &p.2)));
    let low = r.iter().min_by(|p, q| p.2.value.total_cmp(&q.2.value)).ok_or("no model")?;
    let high = r.iter().map(|p| p.2.value).fold(0f64, f64::max);
    let mut shown = if r.len() == 1 {
        format!("{} ({})", xr(&low.2), low.0)
    } else {
        format!("lowest {} ({}), highest {} over {} models", xr(&low.2), low.0, x(high), r.len())
    };
    if !short.is_empty() {
        let ms = floor * 1e3;
        shown += &format!("; both sides under {ms:.0} ms, not deciding: {}", short.join(", "));
    }
    Ok(Found::from((shown, decision)).with(Value::ratio(&low.2)))
}

/// The log–log slope of `points` (size, value) and its interval: the range of the slopes
/// fitted to each repetition's values, when every point has the same number of them.
fn slope_interval(points: &[(f64, f64, &[f64])]) -> Option<(f64, f64, f64, usize)> {
    let k = loglog_slope(&points.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>())?;
    let reps = points.first().map_or(0, |p| p.2.len());
    if reps < 2 || points.iter().any(|p| p.2.len() != reps) {
        return Some((k, k, k, 0));
    }
    let (mut lo, mut hi) = (k, k);
    for j in 0..reps {
        if let Some(kj) = loglog_slope(&points.iter().map(|p| (p.0, p.2[j])).collect::<Vec<_>>()) {
            lo = lo.min(kj);
            hi = hi.max(kj);
        }
    }
    Some((k, lo, hi, reps))
}

/// "over 3 models, fitted to each of 4 repetitions".
fn fitted(models: usize, reps: usize) -> String {
    if reps == 0 {
        format!("over {models} models")
    } else {
        format!("over {models} models; interval: each of {reps} repetitions fitted")
    }
}

/// Slope of `key` against model size, which must be within `range`.
fn slope(f: &Facts, exp: &str, key: &str, range: (f64, f64)) -> Measure {
    let s = f.series(exp, key)?;
    let pts: Vec<(f64, f64, &[f64])> = s.iter().map(|p| (p.1, p.2.value, f.runs(exp, &p.0, key))).collect();
    let (k, lo, hi, reps) = slope_interval(&pts).ok_or_else(|| {
        format!("needs models whose sizes span a factor of 2 or more ({} model(s) here)", s.len())
    })?;
    Ok(Found::from((
        format!("slope {} {}", fr(k, lo, hi, false), fitted(s.len(), reps)),
        within(lo, hi, range.0, range.1),
    ))
    .with(Value { value: k, lo, hi, unit: "slope" }))
}

/// Rank correlation of model size and `a / b`, which must be positive, with `a / b`
/// above 1 on the largest model: a gap that shrinks while `b` stays slower is no
/// advantage of `b` that grows.
fn advantage_grows(f: &Facts, exp: &str, a: &str, b: &str) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let sizes: Vec<f64> = r.iter().map(|p| p.1).collect();
    let vals: Vec<f64> = r.iter().map(|p| p.2.value).collect();
    let rho = spearman(&sizes, &vals)
        .ok_or_else(|| format!("needs three or more models of different sizes ({} here)", r.len()))?;
    let reps = r.first().map_or(0, |p| p.2.runs.len());
    let (mut lo, mut hi) = (rho, rho);
    if reps >= 2 && r.iter().all(|p| p.2.runs.len() == reps) {
        for j in 0..reps {
            let v: Vec<f64> = r.iter().map(|p| p.2.runs[j]).collect();
            if let Some(q) = spearman(&sizes, &v) {
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
    }
    let largest = &r[r.len() - 1];
    let decision = Decision::all([above(lo, hi, 0.0), above(largest.2.lo, largest.2.hi, 1.0)]);
    Ok(Found::from((
        format!(
            "rank correlation {} over {} models; {} on the smallest, {} on the largest",
            fr(rho, lo, hi, true),
            r.len(),
            xr(&r[0].2),
            xr(&largest.2)
        ),
        decision,
    ))
    .with(Value { value: rho, lo, hi, unit: "rank correlation" }))
}

/// The ratio on the largest model, which must reach `t`.
fn on_largest(f: &Facts, exp: &str, a: &str, b: &str, t: f64) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let (model, _, q) = r.last().ok_or("no model")?;
    Ok(Found::from((format!("{} ({model})", xr(q)), at_least(q.lo, q.hi, t))).with(Value::ratio(q)))
}

// ---------------------------------------------------------------- point in solid (Ch. 4)

fn tetragrid_speedup(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:cpu", "time:tetragrid-32", 10.0, false)
}

fn tetragrid_beyond_64(f: &Facts) -> Measure {
    let _ = f;
    Err("TetraGrid resolutions stop at 64³ in texgeo, as in the thesis' tables".into())
}

fn tetragrid_discards(f: &Facts) -> Measure {
    let s = f
        .series("inclusion", "tested:tetragrid-32")
        .map_err(unless_measured("the thesis gives no count of tests"))?;
    let worst = s.iter().map(|p| p.2.value).fold(0f64, f64::max);
    Ok(Found::from((
        format!("at least {} discarded (worst of {} models; counted, no noise)", pct(1.0 - worst), s.len()),
        (1.0 - worst >= 0.9).into(),
    ))
    .with(Value { value: 1.0 - worst, lo: 1.0 - worst, hi: 1.0 - worst, unit: "share" }))
}

fn tetragrid_memory_grows(f: &Facts) -> Measure {
    let models = f.models_of("inclusion");
    let (mut grows, mut total) = (0, 0);
    for (m, _) in &models {
        let mem: Vec<f64> = [2, 4, 8, 16, 32, 64]
            .iter()
            .filter_map(|n| f.get("inclusion", m, &format!("memory:tetragrid-{n}")).ok())
            .map(|s| s.value)
            .collect();
        if mem.len() >= 2 {
            total += 1;
            grows += usize::from(mem.windows(2).all(|w| w[1] > w[0]));
        }
    }
    if total == 0 {
        return Err(f.not_run_or("inclusion", "no TetraGrid memory measured"));
    }
    Ok((format!("grows on {grows} of {total} models (counted bytes, no noise)"), (grows == total).into())
        .into())
}

fn tetragrid_build_order(f: &Facts) -> Measure {
    let mut worst: Option<((f64, f64, f64, usize), String)> = None;
    let mut decisions = Vec::new();
    for (m, _) in f.models_of("inclusion") {
        let keys: Vec<(f64, String)> =
            [16, 32, 64].iter().map(|n| (*n as f64, format!("build:tetragrid-{n}"))).collect();
        let pts: Vec<(f64, f64, &[f64])> = keys
            .iter()
            .filter_map(|(n, k)| {
                f.get("inclusion", &m, k).ok().map(|s| (*n, s.value.max(1e-9), f.runs("inclusion", &m, k)))
            })
            .collect();
        if let Some(k) = slope_interval(&pts) {
            decisions.push(at_most(k.1, k.2, 3.0));
            if worst.as_ref().is_none_or(|w| k.0 > w.0.0) {
                worst = Some((k, m));
            }
        }
    }
    let ((k, lo, hi, reps), m) =
        worst.ok_or_else(|| f.not_run_or("inclusion", "no TetraGrid build times at 16³–64³"))?;
    let how = if reps > 0 { format!("; interval: each of {reps} builds fitted") } else { String::new() };
    Ok(Found::from((
        format!("steepest slope {} in n ({m}{how})", fr(k, lo, hi, false)),
        Decision::all(decisions),
    ))
    .with(Value { value: k, lo, hi, unit: "slope" }))
}

fn gpu_faster(f: &Facts) -> Measure {
    on_largest(f, "inclusion", "time:cpu", "time:gpu", 2.0)
}

fn gpu_gain_grows(f: &Facts) -> Measure {
    advantage_grows(f, "inclusion", "time:cpu", "time:gpu")
}

fn gpu_factor_10(f: &Facts) -> Measure {
    let r = ratios(f, "inclusion", "time:cpu", "time:gpu")?;
    let best = r.iter().max_by(|a, b| a.2.value.total_cmp(&b.2.value)).ok_or("no model")?;
    let decision = Decision::any(r.iter().map(|p| at_least(p.2.lo, p.2.hi, 10.0)));
    Ok(Found::from((format!("best {} ({})", xr(&best.2), best.0), decision)).with(Value::ratio(&best.2)))
}

fn cpu_wins_small(f: &Facts) -> Measure {
    let r = ratios(f, "inclusion", "time:gpu", "time:cpu")?;
    let (m, _, q) = r.first().ok_or("no model")?;
    Ok(Found::from((format!("gpu / cpu {} ({m})", xr(q)), above(q.lo, q.hi, 1.0))).with(Value::ratio(q)))
}

fn feito_beats_jordan(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:jordan", "time:cpu", 1.0, true)
}

fn feito_linear(f: &Facts) -> Measure {
    slope(f, "inclusion", "time:cpu", (0.8, 1.2))
}

fn gpu_linear(f: &Facts) -> Measure {
    slope(f, "inclusion", "time:gpu", (0.8, 1.2))
}

/// Whether `mine` is below `rival` beyond the range of their runs.
fn below(mine: &Stat, rival: &Stat) -> Decision {
    if mine.max < rival.min {
        Decision::Holds
    } else if mine.min >= rival.max {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    }
}

/// Whether `index` has the smallest `what` (build or memory) of all indexes on every model.
fn cheapest(f: &Facts, index: &str, others: &[&str]) -> Measure {
    let mut checked = 0;
    let mut fails = Vec::new();
    let mut decisions = Vec::new();
    for what in ["build", "memory"] {
        let mine = f.series("inclusion", &format!("{what}:{index}"))?;
        for (m, _, v) in mine {
            let rivals: Vec<Stat> =
                others.iter().filter_map(|o| f.get("inclusion", &m, &format!("{what}:{o}")).ok()).collect();
            if rivals.is_empty() {
                continue;
            }
            checked += 1;
            let d = Decision::all(rivals.iter().map(|r| below(&v, r)));
            if d != Decision::Holds {
                fails.push(format!(
                    "{what} on {m}{}",
                    if d == Decision::Inconclusive { " (within noise)" } else { "" }
                ));
            }
            decisions.push(d);
        }
    }
    if checked == 0 {
        return Err("no other index measured beside it".into());
    }
    let shown = if fails.is_empty() {
        format!("cheapest in {checked} of {checked} comparisons")
    } else {
        format!("not the cheapest: {}", fails.join(", "))
    };
    Ok((
        format!("{shown} (build times: medians of their runs, compared beyond their range)"),
        Decision::all(decisions),
    )
        .into())
}

fn octants_cheapest(f: &Facts) -> Measure {
    cheapest(f, "octants", &["tetragrid", "bvh", "bsp", "jordan-octree"])
}

fn bsp_costliest(f: &Facts) -> Measure {
    let s = f
        .series("inclusion", "build:bsp")
        .map_err(unless_measured("texgeo has no BSP method (a BVH stands in)"))?;
    let mut fails = Vec::new();
    for (m, _, v) in &s {
        for o in ["octants", "tetragrid", "jordan-octree"] {
            if f.get("inclusion", m, &format!("build:{o}")).is_ok_and(|r| r.value >= v.value) {
                fails.push(format!("{o} on {m}"));
            }
        }
    }
    let shown = if fails.is_empty() { format!("costliest on {} models", s.len()) } else { fails.join(", ") };
    Ok((shown, fails.is_empty().into()).into())
}

fn octree_helps_jordan(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:jordan", "time:jordan-octree", 10.0, false)
}

pub const INCLUSION: &[Claim] = &[
    Claim {
        id: "I1",
        source: "2006 §4.4.3.1, §4.4.4, Table 4-5",
        quote: "con el uso de esta estructura el rendimiento aumenta de forma drástica",
        claim: "TetraGrid (32³) makes Feito-Torres drastically faster than without optimizer",
        rule: "time without optimizer / time with TetraGrid 32³ ≥ 10× on every model",
        measure: tetragrid_speedup,
    },
    Claim {
        id: "I2",
        source: "2006 §4.4.3.1",
        quote: "a partir de 64³ el beneficio en el rendimiento es inapreciable",
        claim: "TetraGrid resolutions beyond 64³ bring no noticeable gain",
        rule: "needs resolutions above 64³",
        measure: tetragrid_beyond_64,
    },
    Claim {
        id: "I3",
        source: "2006 §4.3.2.4",
        quote: "permite descartar la gran mayoría de tetraedros del sólido",
        claim: "a point is tested only against its cell's tetrahedra: the vast majority are discarded",
        rule: "share of tetrahedra not listed in a query point's 32³ cell ≥ 90 % on every model",
        measure: tetragrid_discards,
    },
    Claim {
        id: "I4",
        source: "2006 §4.4.3.1, Table 4-4",
        quote: "a mayor resolución, mayor espacio en memoria",
        claim: "TetraGrid memory grows with the resolution",
        rule: "memory increases from each resolution to the next (2³ … 64³) on every model",
        measure: tetragrid_memory_grows,
    },
    Claim {
        id: "I5",
        source: "2006 §4.4.3.1, Table 4-4",
        quote: "el orden de complejidad de la construcción del grid de tetraedros está en O(n³)",
        claim: "building the TetraGrid costs at most O(n³)",
        rule: "log–log slope of build time against n (16³, 32³, 64³) ≤ 3 on every model",
        measure: tetragrid_build_order,
    },
    Claim {
        id: "I6",
        source: "2006 §4.4.3.1 (Fig. 4-7)",
        quote: "los resultados en GPU son mucho más eficientes que en CPU",
        claim: "the GPU test is much faster than the CPU test",
        rule: "cpu / gpu ≥ 2× on the largest model",
        measure: gpu_faster,
    },
    Claim {
        id: "I7",
        source: "2006 §4.4.3.1, §4.4.3.2",
        quote: "esta diferencia aumenta con la complejidad del sólido",
        claim: "the GPU's advantage grows with the size of the solid",
        rule: "rank correlation of triangles and cpu / gpu > 0 (three or more models), and cpu / gpu > 1 on the \
               largest: a gap that narrows while the GPU stays slower is no advantage",
        measure: gpu_gain_grows,
    },
    Claim {
        id: "I8",
        source: "2006 §4.4.3.2",
        quote: "llegando en ocasiones a un factor de 10 en el rendimiento",
        claim: "the GPU test reaches 10× the speed of the CPU test",
        rule: "largest cpu / gpu over the models ≥ 10×",
        measure: gpu_factor_10,
    },
    Claim {
        id: "I9",
        source: "2006 §4.4.3.2",
        quote: "para mallas poco complejas, la CPU tiene cierta ventaja",
        claim: "on simple meshes the CPU test beats the GPU test",
        rule: "gpu / cpu > 1 on the smallest model",
        measure: cpu_wins_small,
    },
    Claim {
        id: "I10",
        source: "2006 §4.4.3.2, Table 4-9",
        quote: "los tiempos de los tests son mejores comparados con los óptimos de Jordan",
        claim: "Feito-Torres (no preprocessing) is faster than Jordan's ray crossings",
        rule: "jordan / cpu > 1 on every model",
        measure: feito_beats_jordan,
    },
    Claim {
        id: "I11",
        source: "2006 §4.4.3.2",
        quote: "mantiene una relación lineal directa con el número de polígonos",
        claim: "Feito-Torres' time is linear in the number of polygons",
        rule: "log–log slope of cpu time against triangles within 0.8–1.2",
        measure: feito_linear,
    },
    Claim {
        id: "I12",
        source: "2006 §4.3.3",
        quote: "el algoritmo implementado en GPU presenta un coste lineal respecto al número de triángulos",
        claim: "the GPU test's time is linear in the number of triangles",
        rule: "log–log slope of gpu time against triangles within 0.8–1.2",
        measure: gpu_linear,
    },
    Claim {
        id: "I13",
        source: "2006 §4.4.3.2, Tables 4-7, 4-8",
        quote: "el optimizador de octantes de Feito-Torres es el menos costoso",
        claim: "the octant index is the cheapest to build and to keep",
        rule: "octants' build time and memory below every other index's on every model",
        measure: octants_cheapest,
    },
    Claim {
        id: "I14",
        source: "2006 §4.4.3.2, Table 4-8",
        quote: "el algoritmo basado en BSP es el más costoso en preprocesamiento",
        claim: "BSP is the most expensive to preprocess",
        rule: "BSP build time above every other index's on every model",
        measure: bsp_costliest,
    },
    Claim {
        id: "I15",
        source: "2006 §4.4.3.2, Table 4-9",
        quote: "la versión optimizada con octree mejora enormemente el rendimiento",
        claim: "the octree improves Jordan's test enormously",
        rule: "jordan / jordan-octree ≥ 10× on every model",
        measure: octree_helps_jordan,
    },
];

// ---------------------------------------------------------------- voxelization (Ch. 5)

/// One voxelization time: (model, model size, N, method, time, every repetition).
type VoxelTime = (String, f64, usize, String, Stat, Vec<f64>);

/// (model, N, method) → time, for every voxelization fact.
fn voxel_times(f: &Facts) -> Result<Vec<VoxelTime>, String> {
    if let Some(why) = f.why_not_run("voxelize") {
        return Err(why.to_string());
    }
    let mut out = Vec::new();
    let mut why = None;
    for fact in f.facts.iter().filter(|x| x.experiment == "voxelize") {
        let Some(rest) = fact.key.strip_prefix("time:") else { continue };
        let Some((method, n)) = rest.split_once('@') else { continue };
        let Ok(n) = n.parse::<usize>() else { continue };
        match &fact.value {
            Ok(s) => {
                let size = f.size("voxelize", &fact.model).unwrap_or(0.0);
                out.push((fact.model.clone(), size, n, method.to_string(), *s, fact.runs.clone()));
            }
            Err(w) => why = why.or(Some(w.clone())),
        }
    }
    if out.is_empty() {
        return Err(why.unwrap_or_else(|| "no voxelization measured".into()));
    }
    Ok(out)
}

fn voxel_get<'a>(t: &'a [VoxelTime], model: &str, n: usize, method: &str) -> Option<&'a Stat> {
    t.iter().find(|e| e.0 == model && e.2 == n && e.3 == method).map(|e| &e.4)
}

/// `a / b` with its interval at one (model, N).
fn voxel_ratio(f: &Facts, model: &str, n: usize, a: &str, b: &str) -> Option<Ratio> {
    let fact = |k: &str| f.find("voxelize", model, &format!("time:{k}@{n}"));
    Ratio::of(fact(a)?, fact(b)?)
}

/// Whether `next` is slower than `prev` beyond the range of their runs (runs measured
/// at different times: their ranges, not paired ratios).
fn grows(prev: &Stat, next: &Stat) -> Decision {
    if next.min > prev.max {
        Decision::Holds
    } else if next.max < prev.min {
        Decision::DoesNotHold
    } else if prev.runs > 1 || next.runs > 1 {
        Decision::Inconclusive
    } else {
        (next.value > prev.value).into()
    }
}

/// The (model, N) cells where every method of `methods` was measured.
fn voxel_cells(t: &[VoxelTime], methods: &[&str]) -> Vec<(String, usize)> {
    let mut cells: Vec<(String, usize)> = t.iter().map(|e| (e.0.clone(), e.2)).collect();
    cells.sort();
    cells.dedup();
    cells.retain(|(m, n)| methods.iter().all(|k| voxel_get(t, m, *n, k).is_some()));
    cells
}

const SLICERS: [&str; 5] = ["cpu", "fgpu", "pgpu", "zoned", "fang"];

fn missing_cells(t: &[VoxelTime], methods: &[&str], f: &Facts) -> String {
    let _ = t;
    let why = f.facts.iter().filter(|x| x.experiment == "voxelize").find_map(|x| match &x.value {
        Err(w) if methods.iter().any(|m| x.key.starts_with(&format!("time:{m}@"))) => Some(w.clone()),
        _ => None,
    });
    why.unwrap_or_else(|| format!("no model and resolution has all of {}", methods.join(", ")))
}

fn voxel_grows_with_n(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let mut series: Vec<(String, String)> = t.iter().map(|e| (e.0.clone(), e.3.clone())).collect();
    series.sort();
    series.dedup();
    let curves = series.iter().filter(|s| SLICERS.contains(&s.1.as_str())).map(|(model, method)| {
        let mut pts: Vec<(usize, Stat)> =
            t.iter().filter(|e| &e.0 == model && &e.3 == method).map(|e| (e.2, e.4)).collect();
        pts.sort_by_key(|p| p.0);
        (pts.len() >= 2).then(|| pts.into_iter().map(|p| p.1).collect::<Vec<Stat>>())
    });
    let (grows_n, total, decisions) = growth(curves);
    if total == 0 {
        return Err("needs two or more resolutions".into());
    }
    Ok((
        format!(
            "time grows with N beyond the runs' range in {grows_n} of {total} (model, method) series; the rest \
             within it or shrinking"
        ),
        Decision::all(decisions),
    )
        .into())
}

fn voxel_grows_with_size(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let mut series: Vec<(usize, String)> = t.iter().map(|e| (e.2, e.3.clone())).collect();
    series.sort();
    series.dedup();
    let curves = series.iter().filter(|s| SLICERS.contains(&s.1.as_str())).map(|(n, method)| {
        let mut pts: Vec<(f64, Stat)> =
            t.iter().filter(|e| e.2 == *n && &e.3 == method).map(|e| (e.1, e.4)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        (pts.len() >= 2 && pts.windows(2).all(|w| w[1].0 > w[0].0))
            .then(|| pts.into_iter().map(|p| p.1).collect::<Vec<Stat>>())
    });
    let (grows_n, total, decisions) = growth(curves);
    if total == 0 {
        return Err("needs two or more models of different sizes at one resolution".into());
    }
    Ok((
        format!(
            "time grows with triangles beyond the runs' range in {grows_n} of {total} (N, method) series; the \
             rest within it or shrinking"
        ),
        Decision::all(decisions),
    )
        .into())
}

/// Of `curves` (each the times along a growing quantity; `None`: too few points), how
/// many grow beyond their runs' range at every step, how many there are, and each one's
/// decision.
fn growth(curves: impl Iterator<Item = Option<Vec<Stat>>>) -> (usize, usize, Vec<Decision>) {
    let decisions: Vec<Decision> =
        curves.flatten().map(|c| Decision::all(c.windows(2).map(|w| grows(&w[0], &w[1])))).collect();
    let grows_n = decisions.iter().filter(|&&d| d == Decision::Holds).count();
    (grows_n, decisions.len(), decisions)
}

/// "Equal or better": zoned is slower only where the whole interval of pgpu / zoned lies
/// below 1 (the per-repetition ratios, measured in turn); a single number (the thesis')
/// counts as equal within 5 %.
fn mp_never_slower(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, &["pgpu", "zoned"]);
    let ratios: Vec<(String, Ratio)> = cells
        .iter()
        .filter_map(|(m, n)| voxel_ratio(f, m, *n, "pgpu", "zoned").map(|r| (format!("{m} {n}³"), r)))
        .collect();
    if ratios.is_empty() {
        return Err(missing_cells(&t, &["pgpu", "zoned"], f));
    }
    let single = |r: &Ratio| r.lo == r.hi;
    let slower: Vec<&str> = ratios
        .iter()
        .filter(|(_, r)| if single(r) { r.value < 1.0 / 1.05 } else { r.hi < 1.0 })
        .map(|(cell, _)| cell.as_str())
        .collect();
    let (low_cell, low) = ratios.iter().min_by(|a, b| a.1.value.total_cmp(&b.1.value)).ok_or("no cell")?;
    let high = ratios.iter().map(|(_, r)| r.value).fold(0f64, f64::max);
    let shown = format!(
        "pgpu / zoned lowest {} ({low_cell}), highest {} over {} cells{}",
        xr(low),
        x(high),
        ratios.len(),
        if slower.is_empty() { String::new() } else { format!("; zoned slower at {}", slower.join(", ")) }
    );
    Ok(Found::from((shown, slower.is_empty().into())).with(Value::ratio(low)))
}

/// Geometric mean of a / b over the cells where both were measured, with the geometric
/// means of the cells' interval ends as its interval.
fn voxel_geomean(f: &Facts, a: &str, b: &str) -> Result<(Ratio, usize), String> {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, &[a, b]);
    let r: Vec<Ratio> = cells.iter().filter_map(|(m, n)| voxel_ratio(f, m, *n, a, b)).collect();
    let g = |k: fn(&Ratio) -> f64| geomean(&r.iter().map(k).collect::<Vec<_>>());
    let (Some(value), Some(lo), Some(hi)) = (g(|q| q.value), g(|q| q.lo), g(|q| q.hi)) else {
        return Err(missing_cells(&t, &[a, b], f));
    };
    Ok((Ratio { value, lo, hi, runs: Vec::new() }, r.len()))
}

fn fang_near_pgpu(f: &Facts) -> Measure {
    let (g, n) = voxel_geomean(f, "fang", "pgpu")?;
    Ok(Found::from((
        format!("fang / pgpu {} (geometric mean of {n} cells)", xr(&g)),
        within(g.lo, g.hi, 0.5, 2.0),
    ))
    .with(Value::ratio(&g)))
}

fn mp_beats_fang(f: &Facts) -> Measure {
    let (g, n) = voxel_geomean(f, "fang", "zoned")?;
    Ok(Found::from((
        format!("fang / zoned {} (geometric mean of {n} cells)", xr(&g)),
        above(g.lo, g.hi, 1.0),
    ))
    .with(Value::ratio(&g)))
}

/// The methods of `methods`, fastest first by geometric-mean time over the cells where
/// all were measured: from the medians, then from each repetition (all methods of a
/// cell ran in turn in each), when every cell has the same number of repetitions.
fn voxel_rankings(f: &Facts, methods: &[&str]) -> Result<(Vec<String>, Vec<Vec<String>>), String> {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, methods);
    if cells.is_empty() {
        return Err(missing_cells(&t, methods, f));
    }
    let rank = |time: &dyn Fn(&VoxelTime) -> Option<f64>| -> Vec<String> {
        let mut r: Vec<(String, f64)> = methods
            .iter()
            .map(|k| {
                let v: Option<Vec<f64>> = cells
                    .iter()
                    .map(|(m, n)| t.iter().find(|e| &e.0 == m && e.2 == *n && e.3 == *k).and_then(time))
                    .collect();
                (k.to_string(), v.and_then(|v| geomean(&v)).unwrap_or(f64::INFINITY))
            })
            .collect();
        r.sort_by(|a, b| a.1.total_cmp(&b.1));
        r.into_iter().map(|p| p.0).collect()
    };
    let medians = rank(&|e| Some(e.4.value));
    let reps = t.first().map_or(0, |e| e.5.len());
    let per_rep = if reps >= 2 && t.iter().all(|e| e.5.len() == reps) {
        (0..reps).map(|j| rank(&|e| e.5.get(j).copied())).collect()
    } else {
        Vec::new()
    };
    Ok((medians, per_rep))
}

/// A ranking condition decided on the medians and on every repetition's ranking.
fn ranked(f: &Facts, methods: &[&str], holds: fn(&[String]) -> bool) -> Measure {
    let (medians, per_rep) = voxel_rankings(f, methods)?;
    let order = medians.join(" < ");
    if per_rep.is_empty() {
        return Ok((format!("fastest first: {order}"), holds(&medians).into()).into());
    }
    let agree = per_rep.iter().filter(|r| holds(r)).count();
    let decision = if agree == per_rep.len() && holds(&medians) {
        Decision::Holds
    } else if agree == 0 && !holds(&medians) {
        Decision::DoesNotHold
    } else {
        Decision::Inconclusive
    };
    Ok((
        format!("fastest first: {order}; the rule holds in {agree} of {} repetitions", per_rep.len()),
        decision,
    )
        .into())
}

fn fastest_two(f: &Facts) -> Measure {
    ranked(f, &SLICERS, |o| o.iter().take(2).any(|m| m == "zoned") && o.iter().take(2).any(|m| m == "fang"))
}

fn gpu_gain_voxel(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, &["cpu", "zoned"]);
    let (m, n) = cells
        .iter()
        .max_by(|a, b| {
            let size = |m: &str| f.size("voxelize", m).unwrap_or(0.0);
            (a.1, size(&a.0)).partial_cmp(&(b.1, size(&b.0))).unwrap_or(std::cmp::Ordering::Equal)
        })
        .ok_or_else(|| missing_cells(&t, &["cpu", "zoned"], f))?;
    let r = voxel_ratio(f, m, *n, "cpu", "zoned").ok_or("no cpu and zoned pair")?;
    Ok(Found::from((format!("cpu / zoned {} ({m} {n}³)", xr(&r)), at_least(r.lo, r.hi, 2.0)))
        .with(Value::ratio(&r)))
}

fn mp_best_gpu(f: &Facts) -> Measure {
    ranked(f, &["fgpu", "pgpu", "zoned"], |o| o.first().is_some_and(|m| m == "zoned"))
}

fn gpu_linear_in_faces(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let mut slopes = Vec::new();
    let mut ns: Vec<usize> = t.iter().map(|e| e.2).collect();
    ns.sort();
    ns.dedup();
    let mut models = 0;
    for method in ["pgpu", "zoned"] {
        for &n in &ns {
            let pts: Vec<(f64, f64, &[f64])> = t
                .iter()
                .filter(|e| e.2 == n && e.3 == method)
                .map(|e| (e.1, e.4.value, e.5.as_slice()))
                .collect();
            if let Some(k) = slope_interval(&pts) {
                models = models.max(pts.len());
                slopes.push((method, n, k));
            }
        }
    }
    if slopes.is_empty() {
        if voxel_cells(&t, &["pgpu"]).is_empty() || voxel_cells(&t, &["zoned"]).is_empty() {
            return Err(missing_cells(&t, &["pgpu", "zoned"], f));
        }
        return Err("needs models whose sizes span a factor of 2 or more at one resolution".into());
    }
    let lo = slopes.iter().map(|s| s.2.1).fold(f64::INFINITY, f64::min);
    let hi = slopes.iter().map(|s| s.2.2).fold(f64::NEG_INFINITY, f64::max);
    let k_lo = slopes.iter().map(|s| s.2.0).fold(f64::INFINITY, f64::min);
    let k_hi = slopes.iter().map(|s| s.2.0).fold(f64::NEG_INFINITY, f64::max);
    let reps = slopes.iter().map(|s| s.2.3).min().unwrap_or(0);
    Ok((
        format!(
            "slopes {k_lo:.2} … {k_hi:.2}, interval {lo:.2}–{hi:.2} (pgpu, zoned; {} resolutions; {})",
            slopes.len() / 2,
            fitted(models, reps)
        ),
        Decision::all(slopes.iter().map(|s| within(s.2.1, s.2.2, 0.8, 1.2))),
    )
        .into())
}

fn sramek(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let cells: Vec<(String, usize)> =
        voxel_cells(&t, &["cpu", "sramek"]).into_iter().filter(|c| c.1 >= 512).collect();
    if cells.is_empty() {
        return Err(
            "Sramek's method is not reproduced (the exact scanline is texgeo's §5.2.1 baseline)".into()
        );
    }
    let r: Vec<f64> = cells
        .iter()
        .filter_map(|(m, n)| Some(voxel_get(&t, m, *n, "sramek")?.value / voxel_get(&t, m, *n, "cpu")?.value))
        .collect();
    let lo = r.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(Found::from((
        format!("sramek / cpu at 512³: at least {} ({} models)", x(lo), r.len()),
        (lo >= 2.0).into(),
    ))
    .with(Value { value: lo, lo, hi: lo, unit: "ratio" }))
}

pub const VOXELIZE: &[Claim] = &[
    Claim {
        id: "V1",
        source: "2006 §5.4.2, Table 5-2",
        quote: "el rendimiento de todos los métodos está en función de […] la resolución del espacio de voxels",
        claim: "every method's time grows with the resolution",
        rule: "time increases with N for every (model, method)",
        measure: voxel_grows_with_n,
    },
    Claim {
        id: "V2",
        source: "2006 §5.4.2, Table 5-2",
        quote: "el rendimiento de todos los métodos está en función de la complejidad poligonal del sólido",
        claim: "every method's time grows with the number of polygons",
        rule: "time increases with triangles for every (N, method)",
        measure: voxel_grows_with_size,
    },
    Claim {
        id: "V3",
        source: "2006 §5.4.2",
        quote: "el rendimiento obtenido siempre es igual o mejor que utilizando una sola pasada",
        claim: "the multi-pass GPU version (PGPU-MP, `zoned`) is never slower than the single-pass one (PGPU)",
        rule: "pgpu / zoned ≥ 1 at every model and N, or equal: its per-repetition interval reaches 1 (single \
               numbers: within 5 %)",
        measure: mp_never_slower,
    },
    Claim {
        id: "V4",
        source: "2006 §5.4.2",
        quote: "el algoritmo de Fang […] presenta tiempos cercanos a los del algoritmo de Segura en GPU programable de simple pasada",
        claim: "Fang's times are close to PGPU's",
        rule: "geometric mean of fang / pgpu within 0.5–2",
        measure: fang_near_pgpu,
    },
    Claim {
        id: "V5",
        source: "2006 §5.4.2",
        quote: "el algoritmo de Fang no sea tan eficiente como el de Segura en GPU programable de múltiples pasadas",
        claim: "Fang is slower than PGPU-MP",
        rule: "geometric mean of fang / zoned > 1",
        measure: mp_beats_fang,
    },
    Claim {
        id: "V6",
        source: "2006 §5.4.3",
        quote: "las opciones que presentan mayor rendimiento son […] GPU programable de múltiple pasada y el algoritmo de Fang",
        claim: "PGPU-MP and Fang are the two fastest methods",
        rule: "zoned and fang have the two lowest geometric-mean times of cpu, fgpu, pgpu, zoned, fang",
        measure: fastest_two,
    },
    Claim {
        id: "V7",
        source: "2006 §5.4.3",
        quote: "el rendimiento aumenta de forma considerable mediante el uso de la GPU",
        claim: "the GPU makes voxelization considerably faster than the CPU slicer",
        rule: "cpu / zoned ≥ 2× on the largest model at the largest N",
        measure: gpu_gain_voxel,
    },
    Claim {
        id: "V8",
        source: "2006 §5.4.3",
        quote: "en especial la versión de GPU programable de múltiples pasadas",
        claim: "PGPU-MP is the fastest GPU slicer",
        rule: "zoned has the lowest geometric-mean time of fgpu, pgpu, zoned",
        measure: mp_best_gpu,
    },
    Claim {
        id: "V9",
        source: "2006 §5.4.2",
        quote: "las versiones GPU […] presentan un rendimiento lineal en función del número de caras",
        claim: "the GPU versions' time is linear in the number of faces",
        rule: "log–log slope of pgpu and zoned time against triangles within 0.8–1.2 at every N",
        measure: gpu_linear_in_faces,
    },
    Claim {
        id: "V10",
        source: "2006 §5.4.2",
        quote: "con resoluciones altas (a partir de 512³) el algoritmo de Segura en versión software presenta un rendimiento mucho mejor",
        claim: "at 512³ the CPU slicer is much faster than Sramek's method",
        rule: "sramek / cpu ≥ 2× at 512³ on every model",
        measure: sramek,
    },
];

// ---------------------------------------------------------------- Booleans (Ch. 6)

/// The share of point tests grouping saves on models within `sizes`, which must reach
/// `at_least` (on the largest such model when `best`).
fn reduction(f: &Facts, sizes: std::ops::Range<f64>, at_least: f64, best: bool) -> Measure {
    let s = f.series("boolean", "reduction")?;
    let inside: Vec<&(String, f64, Stat)> = s.iter().filter(|p| sizes.contains(&p.1)).collect();
    if inside.is_empty() {
        return Err(format!("no pair of meshes with {:.0}–{:.0} triangles", sizes.start, sizes.end));
    }
    let lo = inside.iter().map(|p| p.2.value).fold(f64::INFINITY, f64::min);
    let hi = inside.iter().map(|p| p.2.value).fold(0.0, f64::max);
    let shown = format!("{} … {} saved ({} pairs; counted, no noise)", pct(lo), pct(hi), inside.len());
    let decided = if best { hi } else { lo };
    Ok(Found::from((shown, (decided >= at_least).into())).with(Value {
        value: decided,
        lo: decided,
        hi: decided,
        unit: "share",
    }))
}

fn grouping_small(f: &Facts) -> Measure {
    reduction(f, 0.0..15_001.0, 0.55, false)
}

fn grouping_large(f: &Facts) -> Measure {
    reduction(f, 50_000.0..f64::INFINITY, 0.85, false)
}

fn grouping_huge(f: &Facts) -> Measure {
    reduction(f, 150_000.0..f64::INFINITY, 0.95, true)
}

fn boolean_gpu_grows(f: &Facts) -> Measure {
    advantage_grows(f, "boolean", "time:phase2-cpu", "time:phase2-gpu")
}

fn boolean_linear(f: &Facts) -> Measure {
    slope(f, "boolean", "time:total", (0.8, 1.2))
}

fn grouping_halves_phase2(f: &Facts) -> Measure {
    min_ratio(f, "boolean", "time:phase2-plain", "time:phase2-grouped", 2.0, false)
}

/// All three operations from one refinement against the dearest single one: the largest
/// ratio over the pairs, which must stay within 1.25.
fn all_ops_as_one(f: &Facts) -> Measure {
    if f.source == super::facts::Source::Thesis {
        return Err("the thesis timed each operation on its own".into());
    }
    let r = ratios(f, "boolean", "time:all-ops", "time:one-op")?;
    let (model, _, worst) =
        r.iter().max_by(|a, b| a.2.value.total_cmp(&b.2.value)).ok_or_else(|| "no pair".to_string())?;
    Ok(Found::from((
        format!("all three / one at most {} ({model}; {} pairs)", xr(worst), r.len()),
        Decision::all(r.iter().map(|p| at_most(p.2.lo, p.2.hi, 1.25))),
    ))
    .with(Value::ratio(worst)))
}

fn boolean_gpu_better(f: &Facts) -> Measure {
    on_largest(f, "boolean", "time:phase2-cpu", "time:phase2-gpu", 2.0)
}

pub const BOOLEAN: &[Claim] = &[
    Claim {
        id: "B0",
        source: "2006 §6.6, Table 6-1",
        quote: "Esta optimización reduce en gran medida el número de tests de inclusión punto-en-sólido",
        claim: "grouped classification greatly cuts phase 2 (far fewer point tests)",
        rule: "phase-2 time plain / grouped ≥ 2× on every pair (today both with CPU point tests)",
        measure: grouping_halves_phase2,
    },
    Claim {
        id: "B1",
        source: "2006 §6.6",
        quote: "con mallas de complejidad baja (hasta ~15000 triángulos) la reducción está entre el 55% y el 65%",
        claim: "grouping saves 55–65 % of the point tests up to ~15 000 triangles",
        rule: "share of point tests saved ≥ 55 % on every pair up to 15 000 triangles",
        measure: grouping_small,
    },
    Claim {
        id: "B2",
        source: "2006 §6.6",
        quote: "a partir de 50000 triángulos la reducción está entre el 85% y el 90%",
        claim: "grouping saves 85–90 % of the point tests from 50 000 triangles",
        rule: "share saved ≥ 85 % on every pair from 50 000 triangles",
        measure: grouping_large,
    },
    Claim {
        id: "B3",
        source: "2006 §6.6",
        quote: "a partir de 150000 triángulos […] la reducción llega hasta el 95%",
        claim: "from 150 000 triangles grouping saves up to 95 % of the point tests",
        rule: "largest share saved ≥ 95 % among pairs from 150 000 triangles",
        measure: grouping_huge,
    },
    Claim {
        id: "B4",
        source: "2006 §6.6, Table 6-1",
        quote: "a mayor número de polígonos, mayor es la ventaja de utilizar la GPU en la versión optimizada",
        claim: "the GPU classification's advantage grows with the number of polygons",
        rule: "rank correlation of triangles and phase-2 cpu / gpu > 0, and cpu / gpu > 1 on the largest pair: a \
               gap that narrows while the GPU stays slower is no advantage",
        measure: boolean_gpu_grows,
    },
    Claim {
        id: "B5",
        source: "2006 §6.6",
        quote: "el algoritmo presenta una complejidad lineal que depende del número de polígonos",
        claim: "the Boolean operation's time is linear in the number of polygons",
        rule: "log–log slope of the grouped A − B total (today with CPU point tests) against triangles within 0.8–1.2",
        measure: boolean_linear,
    },
    Claim {
        id: "B6",
        source: "2006 §6.5.3",
        quote: "el coste de realizar todas las operaciones booleanas simples […] es casi el mismo que el de una sola de ellas",
        claim: "all simple Boolean operations cost about the same as one of them (one refinement and classification)",
        rule: "phase 1 + phase 2 + ∪, ∩, − assembled ≤ 1.25 × the same with only the dearest one, on every pair",
        measure: all_ops_as_one,
    },
    Claim {
        id: "B7",
        source: "2006 §6.6",
        quote: "El rendimiento del algoritmo de inclusión de puntos basado en GPU es bastante mejor que la versión software",
        claim: "the GPU point test makes the Boolean operation considerably faster than the software one",
        rule: "phase-2 time with CPU / with GPU point tests ≥ 2× on the largest pair",
        measure: boolean_gpu_better,
    },
];

// ---------------------------------------------------------------- subdivision (2010)

fn gpu_beats_cpu_l5(f: &Facts) -> Measure {
    min_ratio(f, "subdivide", "time:tcpu2", "time:gpu-path", 2.0, false)
}

fn gpu_beats_osd_l5(f: &Facts) -> Measure {
    f.series("subdivide", "time:osd").map_err(unless_measured("the thesis compared with CGAL only"))?;
    min_ratio_above(f, "subdivide", "time:osd", "time:gpu-path", 1.0, true, DECIDING_TIME)
}

/// The lowest level from which the GPU path beats `rival` at every measured level.
fn crossover(f: &Facts, rival: &str) -> Measure {
    if f.source == super::facts::Source::Thesis {
        // Table 5 is level 5 only: the GPU path ahead there on every model means k ≤ 5.
        let r = ratios(f, "subdivide", "time:tcpu2", "time:gpu-path")?;
        let ahead = r.iter().filter(|p| p.2.value > 1.0).count();
        return Ok((
            format!("ahead at level 5 on {ahead} of {} models (level 5 only)", r.len()),
            (ahead == r.len()).into(),
        )
            .into());
    }
    let sweep = f.models_of("subdivide");
    let (model, _) = sweep
        .iter()
        .find(|(m, _)| f.find("subdivide", m, "level:5:gpu-path").is_some())
        .ok_or_else(|| f.not_run_or("subdivide", "no level sweep was measured"))?;
    // "Beats" is faster in every repetition: equal speed (a ratio of 1.00×, or an
    // interval across 1) beats nothing.
    let mut from = None;
    let mut lines = Vec::new();
    let mut last = Decision::DoesNotHold;
    let mut last_ratio = None;
    for level in 1..=5u32 {
        let fact = |k: &str| f.find("subdivide", model, &format!("level:{level}:{k}"));
        let gpu_levels =
            f.get("subdivide", model, &format!("level:{level}:gpu-levels")).map_or(0.0, |s| s.value);
        let Some(q) = fact(rival).zip(fact("gpu-path")).and_then(|(o, g)| Ratio::of(o, g)) else { continue };
        if gpu_levels < 1.0 {
            continue; // the CPU did the whole level: nothing to compare
        }
        last = above(q.lo, q.hi, 1.0);
        last_ratio = Some(Value::ratio(&q));
        lines.push(format!("L{level} {}", xr(&q)));
        if last == Decision::Holds {
            from = from.or(Some(level));
        } else {
            from = None;
        }
    }
    let shown = match from {
        Some(k) => format!("from level {k} ({model}: {})", lines.join(", ")),
        None => format!("at no level up to 5 ({model}: {})", lines.join(", ")),
    };
    // From some level k ≤ 5 on: it comes down to level 5.
    let found = Found::from((shown, last));
    Ok(match last_ratio {
        Some(v) => found.with(v),
        None => found,
    })
}

fn crossover_cpu(f: &Facts) -> Measure {
    crossover(f, "cpu")
}

fn crossover_osd(f: &Facts) -> Measure {
    if f.source == super::facts::Source::Thesis {
        return Err("the thesis compared with CGAL only".into());
    }
    crossover(f, "osd")
}

fn one_pass_per_level(f: &Facts) -> Measure {
    let p = f
        .pairs("subdivide", "passes", "gpu-levels")
        .map_err(unless_measured("the thesis gives no pass counts"))?;
    let ok = p.iter().filter(|q| q.2.value == q.3.value).count();
    Ok((format!("one pass per GPU level on {ok} of {} models", p.len()), (ok == p.len()).into()).into())
}

fn real_time_cube(f: &Facts) -> Measure {
    let cube = f
        .models_of("subdivide")
        .into_iter()
        .find(|(m, _)| m.contains("cube"))
        .ok_or_else(|| f.not_run_or("subdivide", "no cube among the models"))?;
    let t = f.get("subdivide", &cube.0, "time:tgpu")?;
    let ms = |v: f64| format!("{:.2}", v * 1e3);
    let shown = if t.runs > 1 && ms(t.min) != ms(t.max) {
        format!("{} ms ({}–{} ms over {} runs; {})", ms(t.value), ms(t.min), ms(t.max), t.runs, cube.0)
    } else {
        format!("{} ms ({})", ms(t.value), cube.0)
    };
    Ok(Found::from((shown, at_most(t.min, t.max, 1.0 / 30.0))).with(Value {
        value: t.value,
        lo: t.min,
        hi: t.max,
        unit: "s",
    }))
}

pub const SUBDIVIDE: &[Claim] = &[
    Claim {
        id: "S1",
        source: "2010 §3.4, Table 5 (and §2: «la subdivisión en la GPU es mucho más rápida»)",
        quote: "la solución propuesta fue comparada con una de las implementaciones más rápidas […] en la CPU",
        claim: "at level 5 the GPU path is much faster than a CPU implementation",
        rule: "CPU time (TCPU²) / GPU path (TCPU¹ + TGPU and the rest) ≥ 2× on every model",
        measure: gpu_beats_cpu_l5,
    },
    Claim {
        id: "S2",
        source: "2010 §3.4, Table 5",
        quote: "una de las implementaciones más rápidas con las que se cuenta actualmente en la CPU",
        claim: "at level 5 the GPU path beats today's reference CPU library (OpenSubdiv)",
        rule: "OpenSubdiv / GPU path > 1 on every model (a model where both take under 5 ms does not decide)",
        measure: gpu_beats_osd_l5,
    },
    Claim {
        id: "S3",
        source: "2010 §3.4, Table 5",
        quote: "los modelos fueron subdivididos hasta obtener una superficie límite de nivel 5",
        claim: "the GPU subdivision beats the CPU from some level k ≤ 5 on",
        rule: "a level k ≤ 5 from which the GPU path is faster than the CPU reference at every level, in every \
               repetition",
        measure: crossover_cpu,
    },
    Claim {
        id: "S4",
        source: "2010 §3.4",
        quote: "una de las implementaciones más rápidas […] en la CPU",
        claim: "the GPU subdivision beats OpenSubdiv from some level k ≤ 5 on",
        rule: "a level k ≤ 5 from which the GPU path is faster than OpenSubdiv at every level, in every repetition: \
               equal speed (1.00×) does not beat it",
        measure: crossover_osd,
    },
    Claim {
        id: "S5",
        source: "2010 Conclusiones",
        quote: "se obtiene el próximo nivel de subdivisión en solo una pasada de render",
        claim: "each subdivision level is one render pass",
        rule: "fragment passes = GPU levels on every model",
        measure: one_pass_per_level,
    },
    Claim {
        id: "S6",
        source: "2010 Conclusiones, Table 5",
        quote: "lográndose resultados de subdivisión en tiempo real",
        claim: "subdivision runs in real time (the thesis' cube at level 5)",
        rule: "TGPU of the cube at level 5 ≤ 1/30 s",
        measure: real_time_cube,
    },
];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::Samples;
    use crate::report::reproduce::facts::Source;
    use std::time::Duration;

    fn samples(ms: &[f64]) -> Samples {
        Samples(ms.iter().map(|v| Duration::from_secs_f64(v / 1e3)).collect())
    }

    /// A model of a test: name, size, (key, per-repetition ms).
    type TestModel<'a> = (&'a str, f64, &'a [(&'a str, &'a [f64])]);

    /// Today's facts of `exp`.
    fn today(exp: &'static str, models: &[TestModel]) -> Facts {
        let mut f = Facts::new(Source::Today);
        for (name, size, keys) in models {
            f.model(exp, name, *size, "–");
            for (key, ms) in *keys {
                let s = samples(ms);
                f.add_runs(exp, name, key, Stat::median_of(&s), &s);
            }
        }
        f
    }

    fn decision(m: Measure) -> Decision {
        m.expect("measurable").decision
    }

    #[test]
    fn a_verdict_needs_the_whole_interval_on_one_side() {
        assert_eq!(at_least(2.1, 3.0, 2.0), Decision::Holds);
        assert_eq!(at_least(1.5, 1.9, 2.0), Decision::DoesNotHold);
        assert_eq!(at_least(1.9, 2.1, 2.0), Decision::Inconclusive);
        assert_eq!(within(0.9, 1.1, 0.8, 1.2), Decision::Holds);
        assert_eq!(within(0.7, 0.9, 0.8, 1.2), Decision::Inconclusive);
        assert_eq!(within(1.3, 1.5, 0.8, 1.2), Decision::DoesNotHold);
        // Per-repetition ratios 1.2, 0.9, 1.1: OpenSubdiv / GPU path straddles 1.
        let f = today(
            "subdivide",
            &[("cube", 100.0, &[("time:osd", &[12.0, 9.0, 11.0]), ("time:gpu-path", &[10.0, 10.0, 10.0])])],
        );
        let Found { shown, decision: d, .. } = gpu_beats_osd_l5(&f).unwrap();
        assert_eq!(d, Decision::Inconclusive, "{shown}");
        assert!(shown.contains("(0.90–1.20×)"), "the interval is shown: {shown}");
        // Every repetition ahead: decided.
        let f = today(
            "subdivide",
            &[("cube", 100.0, &[("time:osd", &[12.0, 13.0, 11.0]), ("time:gpu-path", &[10.0, 10.0, 10.0])])],
        );
        assert_eq!(decision(gpu_beats_osd_l5(&f)), Decision::Holds);
    }

    #[test]
    fn times_of_a_millisecond_do_not_decide_which_library_is_faster() {
        // Every repetition has OpenSubdiv behind on the pyramid, but both take about a
        // millisecond: that model decides nothing; the knot, timed in tenths of a second,
        // decides alone.
        let pyramid: TestModel =
            ("pyramid", 10.0, &[("time:osd", &[0.9, 0.95, 0.92]), ("time:gpu-path", &[1.2, 1.1, 1.3])]);
        let knot: TestModel = (
            "knot",
            1000.0,
            &[("time:osd", &[300.0, 310.0, 290.0]), ("time:gpu-path", &[130.0, 120.0, 140.0])],
        );
        let Found { shown, decision: d, .. } = gpu_beats_osd_l5(&today("subdivide", &[pyramid])).unwrap();
        assert_eq!(d, Decision::Inconclusive, "{shown}");
        assert!(shown.contains("not deciding: pyramid"), "{shown}");
        assert_eq!(decision(gpu_beats_osd_l5(&today("subdivide", &[pyramid, knot]))), Decision::Inconclusive);
        // The knot behind: does not hold, whatever the pyramid shows.
        let slow: TestModel = (
            "knot",
            1000.0,
            &[("time:osd", &[100.0, 110.0, 90.0]), ("time:gpu-path", &[130.0, 120.0, 140.0])],
        );
        assert_eq!(decision(gpu_beats_osd_l5(&today("subdivide", &[pyramid, slow]))), Decision::DoesNotHold);
        // The other ratio claims keep no floor: the same times decide there.
        let f = today("subdivide", &[pyramid]);
        assert_eq!(
            decision(min_ratio(&f, "subdivide", "time:gpu-path", "time:osd", 1.0, true)),
            Decision::Holds
        );
    }

    #[test]
    fn ratios_are_taken_per_repetition() {
        // Load doubled both sides of repetition 2: per repetition the ratio stays 4×,
        // while the sides' own ranges would allow 2×–8×.
        let f = today(
            "subdivide",
            &[(
                "cube",
                100.0,
                &[("time:tcpu2", &[40.0, 80.0, 40.0]), ("time:gpu-path", &[10.0, 20.0, 10.0])],
            )],
        );
        let Found { shown, decision: d, .. } = gpu_beats_cpu_l5(&f).unwrap();
        assert_eq!(d, Decision::Holds, "{shown}");
        assert!(shown.starts_with("4.00× (cube)"), "{shown}");
    }

    #[test]
    fn a_narrowing_gap_while_the_gpu_is_slower_is_no_growing_advantage() {
        // cpu / gpu rises with size (0.04 → 0.14) but the GPU is 7–25× slower throughout.
        let sa: [(&str, &[f64]); 2] = [("time:phase2-cpu", &[1.0; 3]), ("time:phase2-gpu", &[25.0; 3])];
        let sb: [(&str, &[f64]); 2] = [("time:phase2-cpu", &[2.0; 3]), ("time:phase2-gpu", &[20.0; 3])];
        let sc: [(&str, &[f64]); 2] = [("time:phase2-cpu", &[1.0; 3]), ("time:phase2-gpu", &[7.0; 3])];
        let f = today("boolean", &[("small", 1e3, &sa), ("mid", 1e4, &sb), ("large", 1e5, &sc)]);
        let Found { shown, decision: d, .. } = boolean_gpu_grows(&f).unwrap();
        assert_eq!(d, Decision::DoesNotHold, "{shown}");
    }

    #[test]
    fn the_multi_pass_version_is_slower_only_beyond_its_interval() {
        let cell = |zoned: &'static [f64]| -> [(&'static str, &'static [f64]); 2] {
            [("time:pgpu@64", &[10.0, 10.0, 10.0]), ("time:zoned@64", zoned)]
        };
        // Per repetition 1.05, 0.95, 1.0: equal within its noise, so never slower.
        let (a, b) = (cell(&[9.5, 10.5, 10.0]), cell(&[12.0, 12.5, 11.0]));
        let Found { shown, decision: d, .. } =
            mp_never_slower(&today("voxelize", &[("knot", 1e3, &a)])).unwrap();
        assert_eq!(d, Decision::Holds, "{shown}");
        assert!(shown.contains("(0.95–1.05×)"), "the interval is shown: {shown}");
        // Slower in every repetition on one model: does not hold, and the cell is named.
        let Found { shown, decision: d, .. } =
            mp_never_slower(&today("voxelize", &[("knot", 1e3, &a), ("tube", 1e4, &b)])).unwrap();
        assert_eq!(d, Decision::DoesNotHold, "{shown}");
        assert!(shown.contains("zoned slower at tube 64³"), "{shown}");
    }

    #[test]
    fn real_time_shows_the_range_of_its_runs() {
        let keys: [(&str, &[f64]); 1] = [("time:tgpu", &[20.0, 40.0, 30.0])];
        let Found { shown, decision: d, .. } =
            real_time_cube(&today("subdivide", &[("cube", 6.0, &keys)])).unwrap();
        assert!(shown.starts_with("30.00 ms (20.00–40.00 ms over 3 runs"), "{shown}");
        assert_eq!(d, Decision::Inconclusive, "1/30 s lies inside the runs: {shown}");
    }

    #[test]
    fn equal_speed_beats_nothing() {
        // The GPU path and OpenSubdiv take about the same time at every level (the median
        // ratio 1.005× shows as 1.00×): S4 must not hold.
        let mut keys: Vec<(String, Vec<f64>)> = Vec::new();
        for level in 1..=5 {
            keys.push((format!("level:{level}:gpu-path"), vec![10.0; 3]));
            keys.push((format!("level:{level}:osd"), vec![10.05, 9.9, 10.1]));
        }
        let mut f = Facts::new(Source::Today);
        f.model("subdivide", "builtin:knot", 1e4, "–");
        for (k, ms) in &keys {
            let s = samples(ms);
            f.add_runs("subdivide", "builtin:knot", k, Stat::median_of(&s), &s);
        }
        for level in 1..=5 {
            f.add("subdivide", "builtin:knot", &format!("level:{level}:gpu-levels"), "", Stat::exact(1.0));
        }
        let Found { shown, decision: d, .. } = crossover_osd(&f).unwrap();
        assert_eq!(d, Decision::Inconclusive, "{shown}");
        assert!(shown.contains("L5 1.00× (0.99–1.01×)"), "{shown}");
    }
}
