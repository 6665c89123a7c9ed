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

use super::facts::{Facts, Stat, geomean, loglog_slope, spearman};

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
    /// The deciding value and whether the rule holds for it, or why it cannot be computed.
    pub measure: fn(&Facts) -> Measure,
}

/// What a claim's function finds: the value shown and whether the rule holds.
pub type Measure = Result<(String, bool), String>;

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Verdict {
    Holds,
    DoesNotHold,
    NotMeasurable(String),
}

impl Verdict {
    pub fn of(m: &Measure) -> Verdict {
        match m {
            Ok((_, true)) => Verdict::Holds,
            Ok((_, false)) => Verdict::DoesNotHold,
            Err(why) => Verdict::NotMeasurable(why.clone()),
        }
    }

    /// "holds", "does not hold", "not measurable".
    pub fn word(&self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::DoesNotHold => "does not hold",
            Verdict::NotMeasurable(_) => "not measurable",
        }
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

fn pct(v: f64) -> String {
    format!("{:.1} %", 100.0 * v)
}

/// `a / b` for every model that has both: (model, size, ratio).
fn ratios(f: &Facts, exp: &str, a: &str, b: &str) -> Result<Vec<(String, f64, f64)>, String> {
    Ok(f.pairs(exp, a, b)?.into_iter().map(|(m, s, x, y)| (m, s, x.value / y.value)).collect())
}

/// The smallest ratio over all models, which must reach `at_least`.
fn min_ratio(f: &Facts, exp: &str, a: &str, b: &str, at_least: f64) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let (lo, hi) = r.iter().fold((f64::INFINITY, 0f64), |acc, p| (acc.0.min(p.2), acc.1.max(p.2)));
    let shown = if r.len() == 1 {
        format!("{} ({})", x(lo), r[0].0)
    } else {
        format!("{} … {} over {} models", x(lo), x(hi), r.len())
    };
    Ok((shown, lo >= at_least))
}

/// Slope of `key` against model size, which must be within `range`.
fn slope(f: &Facts, exp: &str, key: &str, range: (f64, f64)) -> Measure {
    let s = f.series(exp, key)?;
    let pts: Vec<(f64, f64)> = s.iter().map(|p| (p.1, p.2.value)).collect();
    let k = loglog_slope(&pts).ok_or_else(|| {
        format!("needs models whose sizes span a factor of 2 or more ({} model(s) here)", s.len())
    })?;
    Ok((format!("slope {k:.2} over {} models", s.len()), (range.0..=range.1).contains(&k)))
}

/// Rank correlation of model size and `a / b`, which must be positive.
fn grows_with_size(f: &Facts, exp: &str, a: &str, b: &str) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let sizes: Vec<f64> = r.iter().map(|p| p.1).collect();
    let vals: Vec<f64> = r.iter().map(|p| p.2).collect();
    let rho = spearman(&sizes, &vals)
        .ok_or_else(|| format!("needs three or more models of different sizes ({} here)", r.len()))?;
    Ok((
        format!(
            "rank correlation {rho:+.2} over {} models ({} … {})",
            r.len(),
            x(vals[0]),
            x(vals[vals.len() - 1])
        ),
        rho > 0.0,
    ))
}

fn on_largest(f: &Facts, exp: &str, a: &str, b: &str, at_least: f64) -> Measure {
    let r = ratios(f, exp, a, b)?;
    let (model, _, v) = r.last().ok_or("no model")?;
    Ok((format!("{} ({model})", x(*v)), *v >= at_least))
}

// ---------------------------------------------------------------- point in solid (Ch. 4)

fn tetragrid_speedup(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:cpu", "time:tetragrid-32", 10.0)
}

fn tetragrid_beyond_64(f: &Facts) -> Measure {
    let _ = f;
    Err("TetraGrid resolutions stop at 64³ in texgeo, as in the thesis' tables".into())
}

fn tetragrid_discards(f: &Facts) -> Measure {
    let s = f.series("inclusion", "tested:tetragrid-32").map_err(|e| {
        if e.starts_with("no model") { "the thesis gives no count of tests".to_string() } else { e }
    })?;
    let worst = s.iter().map(|p| p.2.value).fold(0f64, f64::max);
    Ok((format!("at least {} discarded (worst of {} models)", pct(1.0 - worst), s.len()), 1.0 - worst >= 0.9))
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
        return Err(f.why_not_run("inclusion").unwrap_or("no TetraGrid memory measured").to_string());
    }
    Ok((format!("grows on {grows} of {total} models"), grows == total))
}

fn tetragrid_build_order(f: &Facts) -> Measure {
    let mut worst: Option<(f64, String)> = None;
    for (m, _) in f.models_of("inclusion") {
        let pts: Vec<(f64, f64)> = [16.0, 32.0, 64.0]
            .iter()
            .filter_map(|&n| {
                f.get("inclusion", &m, &format!("build:tetragrid-{n}")).ok().map(|s| (n, s.value.max(1e-9)))
            })
            .collect();
        if let Some(k) = loglog_slope(&pts)
            && worst.as_ref().is_none_or(|w| k > w.0)
        {
            worst = Some((k, m));
        }
    }
    let (k, m) = worst.ok_or_else(|| {
        f.why_not_run("inclusion").unwrap_or("no TetraGrid build times at 16³–64³").to_string()
    })?;
    Ok((format!("steepest slope {k:.2} in n ({m})"), k <= 3.0))
}

fn gpu_faster(f: &Facts) -> Measure {
    on_largest(f, "inclusion", "time:cpu", "time:gpu", 2.0)
}

fn gpu_gain_grows(f: &Facts) -> Measure {
    grows_with_size(f, "inclusion", "time:cpu", "time:gpu")
}

fn gpu_factor_10(f: &Facts) -> Measure {
    let r = ratios(f, "inclusion", "time:cpu", "time:gpu")?;
    let best = r.iter().max_by(|a, b| a.2.total_cmp(&b.2)).ok_or("no model")?;
    Ok((format!("best {} ({})", x(best.2), best.0), best.2 >= 10.0))
}

fn cpu_wins_small(f: &Facts) -> Measure {
    let r = f.pairs("inclusion", "time:cpu", "time:gpu")?;
    let (m, _, cpu, gpu) = r.first().ok_or("no model")?;
    Ok((
        format!("cpu {:.3} ms vs gpu {:.3} ms ({m})", cpu.value * 1e3, gpu.value * 1e3),
        cpu.value < gpu.value,
    ))
}

fn feito_beats_jordan(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:jordan", "time:cpu", 1.0 + f64::EPSILON)
}

fn feito_linear(f: &Facts) -> Measure {
    slope(f, "inclusion", "time:cpu", (0.8, 1.2))
}

fn gpu_linear(f: &Facts) -> Measure {
    slope(f, "inclusion", "time:gpu", (0.8, 1.2))
}

/// Whether `index` has the smallest `what` (build or memory) of all indexes on every model.
fn cheapest(f: &Facts, index: &str, others: &[&str]) -> Measure {
    let mut checked = 0;
    let mut fails = Vec::new();
    for what in ["build", "memory"] {
        let mine = f.series("inclusion", &format!("{what}:{index}"))?;
        for (m, _, v) in mine {
            let rivals: Vec<Stat> =
                others.iter().filter_map(|o| f.get("inclusion", &m, &format!("{what}:{o}")).ok()).collect();
            if rivals.is_empty() {
                continue;
            }
            checked += 1;
            if rivals.iter().any(|r| r.value <= v.value) {
                fails.push(format!("{what} on {m}"));
            }
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
    Ok((shown, fails.is_empty()))
}

fn octants_cheapest(f: &Facts) -> Measure {
    cheapest(f, "octants", &["tetragrid", "bvh", "bsp", "jordan-octree"])
}

fn bsp_costliest(f: &Facts) -> Measure {
    let s = f.series("inclusion", "build:bsp").map_err(|e| {
        if e.starts_with("no model") { "texgeo has no BSP method (a BVH stands in)".to_string() } else { e }
    })?;
    let mut fails = Vec::new();
    for (m, _, v) in &s {
        for o in ["octants", "tetragrid", "jordan-octree"] {
            if f.get("inclusion", m, &format!("build:{o}")).is_ok_and(|r| r.value >= v.value) {
                fails.push(format!("{o} on {m}"));
            }
        }
    }
    let shown = if fails.is_empty() { format!("costliest on {} models", s.len()) } else { fails.join(", ") };
    Ok((shown, fails.is_empty()))
}

fn octree_helps_jordan(f: &Facts) -> Measure {
    min_ratio(f, "inclusion", "time:jordan", "time:jordan-octree", 10.0)
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
        rule: "rank correlation of triangles and cpu / gpu > 0 (three or more models)",
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
        rule: "cpu time < gpu time on the smallest model",
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

/// (model, N, method) → time, for every voxelization fact.
fn voxel_times(f: &Facts) -> Result<Vec<(String, f64, usize, String, Stat)>, String> {
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
                out.push((fact.model.clone(), size, n, method.to_string(), *s));
            }
            Err(w) => why = why.or(Some(w.clone())),
        }
    }
    if out.is_empty() {
        return Err(why.unwrap_or_else(|| "no voxelization measured".into()));
    }
    Ok(out)
}

fn voxel_get<'a>(
    t: &'a [(String, f64, usize, String, Stat)],
    model: &str,
    n: usize,
    method: &str,
) -> Option<&'a Stat> {
    t.iter().find(|e| e.0 == model && e.2 == n && e.3 == method).map(|e| &e.4)
}

/// The (model, N) cells where every method of `methods` was measured.
fn voxel_cells(t: &[(String, f64, usize, String, Stat)], methods: &[&str]) -> Vec<(String, usize)> {
    let mut cells: Vec<(String, usize)> = t.iter().map(|e| (e.0.clone(), e.2)).collect();
    cells.sort();
    cells.dedup();
    cells.retain(|(m, n)| methods.iter().all(|k| voxel_get(t, m, *n, k).is_some()));
    cells
}

const SLICERS: [&str; 5] = ["cpu", "fgpu", "pgpu", "zoned", "fang"];

fn missing_cells(t: &[(String, f64, usize, String, Stat)], methods: &[&str], f: &Facts) -> String {
    let _ = t;
    let why = f.facts.iter().filter(|x| x.experiment == "voxelize").find_map(|x| match &x.value {
        Err(w) if methods.iter().any(|m| x.key.starts_with(&format!("time:{m}@"))) => Some(w.clone()),
        _ => None,
    });
    why.unwrap_or_else(|| format!("no model and resolution has all of {}", methods.join(", ")))
}

fn voxel_grows_with_n(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let (mut grows, mut total) = (0, 0);
    let mut series: Vec<(String, String)> = t.iter().map(|e| (e.0.clone(), e.3.clone())).collect();
    series.sort();
    series.dedup();
    for (model, method) in series.iter().filter(|s| SLICERS.contains(&s.1.as_str())) {
        let mut pts: Vec<(usize, f64)> =
            t.iter().filter(|e| &e.0 == model && &e.3 == method).map(|e| (e.2, e.4.value)).collect();
        pts.sort_by_key(|p| p.0);
        if pts.len() >= 2 {
            total += 1;
            grows += usize::from(pts.windows(2).all(|w| w[1].1 > w[0].1));
        }
    }
    if total == 0 {
        return Err("needs two or more resolutions".into());
    }
    Ok((format!("time grows with N in {grows} of {total} (model, method) series"), grows == total))
}

fn voxel_grows_with_size(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let (mut grows, mut total) = (0, 0);
    let mut series: Vec<(usize, String)> = t.iter().map(|e| (e.2, e.3.clone())).collect();
    series.sort();
    series.dedup();
    for (n, method) in series.iter().filter(|s| SLICERS.contains(&s.1.as_str())) {
        let mut pts: Vec<(f64, f64)> =
            t.iter().filter(|e| e.2 == *n && &e.3 == method).map(|e| (e.1, e.4.value)).collect();
        pts.sort_by(|a, b| a.0.total_cmp(&b.0));
        if pts.len() >= 2 && pts.windows(2).all(|w| w[1].0 > w[0].0) {
            total += 1;
            grows += usize::from(pts.windows(2).all(|w| w[1].1 > w[0].1));
        }
    }
    if total == 0 {
        return Err("needs two or more models of different sizes at one resolution".into());
    }
    Ok((format!("time grows with triangles in {grows} of {total} (N, method) series"), grows == total))
}

fn mp_never_slower(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, &["pgpu", "zoned"]);
    if cells.is_empty() {
        return Err(missing_cells(&t, &["pgpu", "zoned"], f));
    }
    let mut slower = Vec::new();
    let mut ratios = Vec::new();
    for (m, n) in &cells {
        let (p, z) = (voxel_get(&t, m, *n, "pgpu").copied(), voxel_get(&t, m, *n, "zoned").copied());
        let (Some(p), Some(z)) = (p, z) else { continue };
        ratios.push(p.value / z.value);
        // Repeated runs: the ranges overlap. Single numbers (the thesis'): within 5 %.
        let equal = if p.runs > 1 && z.runs > 1 { z.overlaps(&p) } else { z.value <= p.value * 1.05 };
        if z.value > p.value && !equal {
            slower.push(format!("{m} {n}³"));
        }
    }
    let shown = format!(
        "pgpu / zoned {} … {} over {} cells{}",
        x(ratios.iter().copied().fold(f64::INFINITY, f64::min)),
        x(ratios.iter().copied().fold(0.0, f64::max)),
        cells.len(),
        if slower.is_empty() { String::new() } else { format!("; zoned slower at {}", slower.join(", ")) }
    );
    Ok((shown, slower.is_empty()))
}

/// Geometric mean of a / b over the cells where both were measured.
fn voxel_geomean(f: &Facts, a: &str, b: &str) -> Result<(f64, usize), String> {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, &[a, b]);
    let r: Vec<f64> = cells
        .iter()
        .filter_map(|(m, n)| Some(voxel_get(&t, m, *n, a)?.value / voxel_get(&t, m, *n, b)?.value))
        .collect();
    let g = geomean(&r).ok_or_else(|| missing_cells(&t, &[a, b], f))?;
    Ok((g, r.len()))
}

fn fang_near_pgpu(f: &Facts) -> Measure {
    let (g, n) = voxel_geomean(f, "fang", "pgpu")?;
    Ok((format!("fang / pgpu {} (geometric mean of {n} cells)", x(g)), (0.5..=2.0).contains(&g)))
}

fn mp_beats_fang(f: &Facts) -> Measure {
    let (g, n) = voxel_geomean(f, "fang", "zoned")?;
    Ok((format!("fang / zoned {} (geometric mean of {n} cells)", x(g)), g > 1.0))
}

/// The methods of `methods` by geometric-mean time over the cells where all were measured.
fn voxel_ranking(f: &Facts, methods: &[&str]) -> Result<Vec<(String, f64)>, String> {
    let t = voxel_times(f)?;
    let cells = voxel_cells(&t, methods);
    if cells.is_empty() {
        return Err(missing_cells(&t, methods, f));
    }
    let mut rank: Vec<(String, f64)> = methods
        .iter()
        .map(|k| {
            let v: Vec<f64> =
                cells.iter().filter_map(|(m, n)| voxel_get(&t, m, *n, k)).map(|s| s.value).collect();
            (k.to_string(), geomean(&v).unwrap_or(f64::INFINITY))
        })
        .collect();
    rank.sort_by(|a, b| a.1.total_cmp(&b.1));
    Ok(rank)
}

fn fastest_two(f: &Facts) -> Measure {
    let rank = voxel_ranking(f, &SLICERS)?;
    let order: Vec<&str> = rank.iter().map(|r| r.0.as_str()).collect();
    let top: Vec<&str> = order.iter().take(2).copied().collect();
    Ok((format!("fastest first: {}", order.join(" < ")), top.contains(&"zoned") && top.contains(&"fang")))
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
    let (c, z) = (voxel_get(&t, m, *n, "cpu"), voxel_get(&t, m, *n, "zoned"));
    let (Some(c), Some(z)) = (c, z) else { return Err("no cpu and zoned pair".into()) };
    let r = c.value / z.value;
    Ok((format!("cpu / zoned {} ({m} {n}³)", x(r)), r >= 2.0))
}

fn mp_best_gpu(f: &Facts) -> Measure {
    let rank = voxel_ranking(f, &["fgpu", "pgpu", "zoned"])?;
    let order: Vec<&str> = rank.iter().map(|r| r.0.as_str()).collect();
    Ok((format!("fastest first: {}", order.join(" < ")), order.first() == Some(&"zoned")))
}

fn gpu_linear_in_faces(f: &Facts) -> Measure {
    let t = voxel_times(f)?;
    let mut slopes = Vec::new();
    let mut ns: Vec<usize> = t.iter().map(|e| e.2).collect();
    ns.sort();
    ns.dedup();
    for method in ["pgpu", "zoned"] {
        for &n in &ns {
            let pts: Vec<(f64, f64)> =
                t.iter().filter(|e| e.2 == n && e.3 == method).map(|e| (e.1, e.4.value)).collect();
            if let Some(k) = loglog_slope(&pts) {
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
    let lo = slopes.iter().map(|s| s.2).fold(f64::INFINITY, f64::min);
    let hi = slopes.iter().map(|s| s.2).fold(f64::NEG_INFINITY, f64::max);
    Ok((
        format!("slopes {lo:.2} … {hi:.2} (pgpu, zoned; {} resolutions)", slopes.len() / 2.max(1)),
        lo >= 0.8 && hi <= 1.2,
    ))
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
    Ok((format!("sramek / cpu at 512³: at least {} ({} models)", x(lo), r.len()), lo >= 2.0))
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
        rule: "zoned ≤ pgpu at every model and N, or equal: their runs overlap (single numbers: within 5 %)",
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
    let shown = format!("{} … {} saved ({} pairs)", pct(lo), pct(hi), inside.len());
    Ok((shown, if best { hi >= at_least } else { lo >= at_least }))
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
    grows_with_size(f, "boolean", "time:phase2-cpu", "time:phase2-gpu")
}

fn boolean_linear(f: &Facts) -> Measure {
    slope(f, "boolean", "time:total", (0.8, 1.2))
}

pub const BOOLEAN: &[Claim] = &[
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
        rule: "rank correlation of triangles and phase-2 cpu / gpu > 0",
        measure: boolean_gpu_grows,
    },
    Claim {
        id: "B5",
        source: "2006 §6.6",
        quote: "el algoritmo presenta una complejidad lineal que depende del número de polígonos",
        claim: "the Boolean operation's time is linear in the number of polygons",
        rule: "log–log slope of total time against triangles within 0.8–1.2",
        measure: boolean_linear,
    },
];

// ---------------------------------------------------------------- subdivision (2010)

fn gpu_beats_cpu_l5(f: &Facts) -> Measure {
    min_ratio(f, "subdivide", "time:tcpu2", "time:gpu-path", 2.0)
}

fn gpu_beats_osd_l5(f: &Facts) -> Measure {
    match f.series("subdivide", "time:osd") {
        Err(e) if e.starts_with("no model") => Err("the thesis compared with CGAL only".into()),
        Err(e) => Err(e),
        Ok(_) => min_ratio(f, "subdivide", "time:osd", "time:gpu-path", 1.0 + f64::EPSILON),
    }
}

/// The lowest level from which the GPU path beats `rival` at every measured level.
fn crossover(f: &Facts, rival: &str) -> Measure {
    if f.source == super::facts::Source::Thesis {
        // Table 5 is level 5 only: the GPU path ahead there on every model means k ≤ 5.
        let r = ratios(f, "subdivide", "time:tcpu2", "time:gpu-path")?;
        let ahead = r.iter().filter(|p| p.2 > 1.0).count();
        return Ok((
            format!("ahead at level 5 on {ahead} of {} models (level 5 only)", r.len()),
            ahead == r.len(),
        ));
    }
    let sweep = f.models_of("subdivide");
    let (model, _) = sweep
        .iter()
        .find(|(m, _)| f.find("subdivide", m, "level:5:gpu-path").is_some())
        .ok_or_else(|| f.why_not_run("subdivide").unwrap_or("no level sweep was measured").to_string())?;
    let mut from = None;
    let mut lines = Vec::new();
    for level in 1..=5u32 {
        let gpu = f.get("subdivide", model, &format!("level:{level}:gpu-path"));
        let other = f.get("subdivide", model, &format!("level:{level}:{rival}"));
        let gpu_levels =
            f.get("subdivide", model, &format!("level:{level}:gpu-levels")).map_or(0.0, |s| s.value);
        let (Ok(g), Ok(o)) = (gpu, other) else { continue };
        if gpu_levels < 1.0 {
            continue; // the CPU did the whole level: nothing to compare
        }
        let ahead = g.value < o.value;
        lines.push(format!("L{level} {}", x(o.value / g.value)));
        if ahead {
            from = from.or(Some(level));
        } else {
            from = None;
        }
    }
    let shown = match from {
        Some(k) => format!("from level {k} ({model}: {})", lines.join(", ")),
        None => format!("at no level up to 5 ({model}: {})", lines.join(", ")),
    };
    Ok((shown, from.is_some()))
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
    let p = f.pairs("subdivide", "passes", "gpu-levels").map_err(|e| {
        if e.starts_with("no model") { "the thesis gives no pass counts".to_string() } else { e }
    })?;
    let ok = p.iter().filter(|q| q.2.value == q.3.value).count();
    Ok((format!("one pass per GPU level on {ok} of {} models", p.len()), ok == p.len()))
}

fn real_time_cube(f: &Facts) -> Measure {
    let cube = f
        .models_of("subdivide")
        .into_iter()
        .find(|(m, _)| m.contains("cube"))
        .ok_or_else(|| f.why_not_run("subdivide").unwrap_or("no cube among the models").to_string())?;
    let t = f.get("subdivide", &cube.0, "time:tgpu")?;
    Ok((format!("{:.2} ms ({})", t.value * 1e3, cube.0), t.value <= 1.0 / 30.0))
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
        rule: "OpenSubdiv / GPU path > 1 on every model",
        measure: gpu_beats_osd_l5,
    },
    Claim {
        id: "S3",
        source: "2010 §3.4, Table 5",
        quote: "los modelos fueron subdivididos hasta obtener una superficie límite de nivel 5",
        claim: "the GPU subdivision beats the CPU from some level k ≤ 5 on",
        rule: "a level k ≤ 5 from which the GPU path is faster than the CPU reference at every level",
        measure: crossover_cpu,
    },
    Claim {
        id: "S4",
        source: "2010 §3.4",
        quote: "una de las implementaciones más rápidas […] en la CPU",
        claim: "the GPU subdivision beats OpenSubdiv from some level k ≤ 5 on",
        rule: "a level k ≤ 5 from which the GPU path is faster than OpenSubdiv at every level",
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
