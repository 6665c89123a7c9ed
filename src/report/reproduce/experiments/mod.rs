//! The list of experiments a reproduction runs, and what their runners share: the
//! models (built-in ones for `--quick`, the thesis' stand-ins otherwise), today-beside-
//! thesis tables and curves.

mod boolean;
mod inclusion;
mod subdivide;
mod voxelize;

use std::path::Path;

use super::claims::{self, Claim};
use super::doc::Block;
use super::facts::{Facts, Stat};
use super::figures;
use super::{Result, Run};
use crate::mesh::spec::MeshSpec;
use crate::mesh::{Mesh, procedural};
use crate::report::Table;
use crate::report::plot::{Chart, Series};

/// Runs an experiment: measures, adds facts, returns the section's blocks.
pub type Runner = fn(&mut Run) -> Result<Vec<Block>>;

/// Draws a figure: returns its picture blocks.
pub type Draw = fn(&mut Run) -> Result<Vec<Block>>;

/// A picture of an experiment, rendered by texgeo's own Vulkan pipeline.
pub struct Figure {
    pub key: &'static str,
    pub title: &'static str,
    /// The thesis figure it stands for.
    pub thesis: &'static str,
    /// Err: why it cannot be drawn yet.
    pub draw: std::result::Result<Draw, &'static str>,
}

/// One experiment of the reproduction (see the module docs of `reproduce`).
pub struct Experiment {
    /// Its `--only` name.
    pub key: &'static str,
    pub title: &'static str,
    /// The thesis tables it reproduces.
    pub tables: &'static str,
    /// The command that runs it alone.
    pub command: &'static str,
    /// Err: why it cannot run yet (the section says so, its claims are not measurable).
    pub runner: std::result::Result<Runner, &'static str>,
    pub claims: &'static [Claim],
    pub figures: &'static [Figure],
}

pub const EXPERIMENTS: &[Experiment] = &[
    Experiment {
        key: "inclusion",
        title: "Point in solid",
        tables: "2006 thesis, Ch. 4, Tables 4-4 … 4-9",
        command: "texgeo bench inclusion",
        runner: Ok(inclusion::run),
        claims: claims::INCLUSION,
        figures: &[Figure {
            key: "inclusion-slice",
            title: "an inclusion slice",
            thesis: "query points on a plane, coloured by the GPU test's answer",
            draw: Ok(figures::inclusion_slice),
        }],
    },
    Experiment {
        key: "voxelize",
        title: "Solid voxelization",
        tables: "2006 thesis, Ch. 5, Table 5-2",
        command: "texgeo bench voxelize",
        runner: Ok(voxelize::run),
        claims: claims::VOXELIZE,
        figures: &[Figure {
            key: "voxel-aspect",
            title: "voxelized models with the Perlin aspect",
            thesis: "2006 Fig. 5-9",
            draw: Ok(figures::voxel_aspect),
        }],
    },
    Experiment {
        key: "boolean",
        title: "Boolean operations",
        tables: "2006 thesis, Ch. 6, Table 6-1",
        command: "texgeo bench boolean",
        runner: Ok(boolean::run),
        claims: claims::BOOLEAN,
        figures: &[Figure {
            key: "boolean-results",
            title: "Boolean results",
            thesis: "2006 Figs. 6-9 … 6-12",
            draw: Ok(figures::boolean_results),
        }],
    },
    Experiment {
        key: "subdivide",
        title: "Catmull-Clark subdivision with fragment meshes",
        tables: "2010 thesis, §3.4, Table 5 (with OpenSubdiv beside it)",
        command: "texgeo bench subdivide",
        runner: Ok(subdivide::run),
        claims: claims::SUBDIVIDE,
        figures: &[
            Figure {
                key: "valence-levels",
                title: "subdivision levels 0–3, vertices coloured by valence",
                thesis: "2010 Figs. 27–30",
                draw: Ok(figures::valence_levels),
            },
            Figure {
                key: "crease-sharpness",
                title: "creases of every sharpness",
                thesis: "sharp features, as OpenSubdiv refines them",
                draw: Ok(figures::crease_sharpness),
            },
            Figure {
                key: "fragment-layout",
                title: "the fragment-mesh layout of one face",
                thesis: "2010 §3.3.1, SPEC §5.2",
                draw: Ok(figures::fragment_layout),
            },
        ],
    },
];

/// A model of an experiment and the thesis model it stands for ("–": none).
pub struct Model {
    pub thesis: &'static str,
    pub name: String,
    pub mesh: Mesh,
}

/// The built-in models `--quick` uses: the thesis' 1200-triangle Torusknot and finer
/// tubes around the same knot, so sizes span a factor of eight.
pub fn quick_models() -> Vec<Model> {
    vec![
        Model { thesis: "Torusknot", name: "builtin:knot".into(), mesh: procedural::torus_knot() },
        Model { thesis: "–", name: "knot tube 150×12".into(), mesh: procedural::torus_knot_tube(150, 12) },
        Model { thesis: "–", name: "knot tube 300×16".into(), mesh: procedural::torus_knot_tube(300, 16) },
    ]
}

/// The stand-ins found: `builtin:NAME` or a file under `dir`. Missing files are named in
/// the returned notes (run `tools/fetch-models`).
pub fn stand_ins(dir: &Path, list: &[(&'static str, &'static str)]) -> Result<(Vec<Model>, Vec<String>)> {
    let mut models = Vec::new();
    let mut notes = Vec::new();
    for &(thesis, name) in list {
        let spec = MeshSpec::parse(name).in_folder(dir);
        match spec.file() {
            Some(path) if !path.is_file() => notes.push(format!(
                "{} not found (run tools/fetch-models): no stand-in for {thesis}",
                path.display()
            )),
            _ => models.push(Model { thesis, name: name.to_string(), mesh: spec.load()? }),
        }
    }
    Ok((models, notes))
}

/// The models table: which texgeo model stands in for which thesis model.
pub fn models_table(experiment: &'static str, run: &Run, models: &[(String, &str, usize)]) -> Table {
    let mut t = Table::new(
        "Models: texgeo's stand-ins for the thesis' models",
        &["thesis model", "thesis triangles", "texgeo model", "texgeo triangles"],
    );
    for (name, thesis, size) in models {
        let thesis_size =
            run.thesis.size(experiment, thesis).map_or("–".to_string(), |s| format!("{s:.0}"));
        t.row(vec![thesis.to_string(), thesis_size, name.clone(), size.to_string()]);
    }
    t
}

/// A number with four significant digits (no exponent).
pub fn num(v: f64) -> String {
    crate::report::sig(v, 4)
}

/// The spread of a value's runs beside it: half their range as a share of the value, in
/// per cent ("–" for a single number or a count).
pub fn spread(s: &Stat) -> String {
    if s.runs < 2 || s.value == 0.0 {
        return "–".into();
    }
    crate::report::sig(50.0 * (s.max - s.min) / s.value.abs(), 2)
}

/// One quantity of a comparison table: its label, today's key and the thesis' key.
pub struct Quantity {
    pub label: String,
    pub today: String,
    pub thesis: String,
}

impl Quantity {
    pub fn new(label: impl Into<String>, today: impl Into<String>, thesis: impl Into<String>) -> Quantity {
        Quantity { label: label.into(), today: today.into(), thesis: thesis.into() }
    }

    pub fn same(label: impl Into<String>, key: impl Into<String>) -> Quantity {
        let key = key.into();
        Quantity::new(label, key.clone(), key)
    }
}

/// The thesis' value, today's and their ratio for every model and quantity: one row
/// each. Cells that cannot be filled say why ("–": the thesis has no such number).
pub fn comparison(
    run: &Run,
    experiment: &'static str,
    title: &str,
    unit: &str,
    quantities: &[Quantity],
) -> Table {
    let mut t = Table::new(
        title,
        &[
            "thesis model",
            "texgeo model",
            "quantity",
            &format!("thesis ({unit})"),
            &format!("today ({unit})"),
            "spread of today's runs (± %)",
            "today / thesis (×)",
        ],
    );
    t.note(
        "today: the mean (inclusion) or median (other experiments) of the runs; spread: half the range of the runs \
         as a share of that value (\"–\": one build, a count or bytes).",
    );
    for (model, _) in run.facts.models_of(experiment) {
        let thesis_model = run.facts.thesis_name(experiment, &model);
        for q in quantities {
            let today = run.facts.get(experiment, &model, &q.today);
            let then = run.thesis.get(experiment, &thesis_model, &q.thesis);
            if today.is_err() && run.facts.find(experiment, &model, &q.today).is_none() {
                continue; // not part of this run (e.g. a resolution not measured)
            }
            let ratio = match (&today, &then) {
                (Ok(a), Ok(b)) if b.value > 0.0 => crate::report::sig(a.value / b.value, 3),
                _ => "–".to_string(),
            };
            t.row(vec![
                thesis_model.clone(),
                model.clone(),
                q.label.clone(),
                then.map_or_else(|_| "–".to_string(), |s| num(s.value)),
                today.as_ref().map_or_else(|why| format!("not measurable: {why}"), |s| num(s.value)),
                today.as_ref().map_or_else(|_| "–".to_string(), spread),
                ratio,
            ]);
        }
    }
    t
}

/// (size, value) of `key` over the models of `facts`.
pub fn curve(facts: &Facts, experiment: &str, key: &str) -> Vec<(f64, f64)> {
    facts
        .series(experiment, key)
        .map(|s| s.into_iter().map(|p| (p.1, p.2.value)).collect())
        .unwrap_or_default()
}

/// (size, a / b) over the models with both.
pub fn ratio_curve(facts: &Facts, experiment: &str, a: &str, b: &str) -> Vec<(f64, f64)> {
    facts
        .pairs(experiment, a, b)
        .map(|s| s.into_iter().map(|p| (p.1, p.2.value / p.3.value)).collect())
        .unwrap_or_default()
}

/// One curve of a speed-up chart: its label, its colour, today's ratio of two keys and
/// the thesis' (when the thesis has both quantities).
pub type Speedup<'a> = (String, usize, [&'a str; 2], Option<[&'a str; 2]>);

/// A log-log chart of speed-ups against size (`x`), today's beside the thesis'.
pub fn speedup_plot(
    r: &mut Run,
    experiment: &str,
    curves: &[Speedup],
    title: impl Into<String>,
    x: &str,
    stem: &str,
) -> Result<Vec<Block>> {
    let series = curves
        .iter()
        .flat_map(|(label, colour, [a, b], thesis)| {
            let thesis = thesis.map_or_else(Vec::new, |[ta, tb]| ratio_curve(r.thesis, experiment, ta, tb));
            both(label, *colour, ratio_curve(r.facts, experiment, a, b), thesis)
        })
        .collect();
    r.plot(&Chart::loglog(title, x, "speed-up (×)", series), stem)
}

/// Today's curve and, when the thesis has points, the thesis' in the same colour.
pub fn both(label: &str, colour: usize, today: Vec<(f64, f64)>, thesis: Vec<(f64, f64)>) -> Vec<Series> {
    let today = today_or_thesis(format!("{label} (today)"), today, false, colour);
    today.into_iter().chain(today_or_thesis(format!("{label} (thesis)"), thesis, true, colour)).collect()
}

/// A curve of today's numbers or (`thesis`) the thesis', when it has points.
pub fn today_or_thesis(
    label: String,
    points: Vec<(f64, f64)>,
    thesis: bool,
    colour: usize,
) -> Option<Series> {
    (!points.is_empty()).then_some(Series { label, points, thesis, colour })
}

/// The tables of `texgeo bench EXPERIMENT`'s own report under a heading, each as
/// `csv/EXPERIMENT-bench-STEM.csv` (numbered where the table has no stem).
pub fn details(r: &mut Run, experiment: &str, tables: Vec<Table>) -> Result<Vec<Block>> {
    let mut blocks = vec![Block::Heading(3, format!("Details (as `texgeo bench {experiment}` prints them)"))];
    for (k, t) in tables.into_iter().enumerate() {
        let stem = if t.stem.is_empty() { (k + 1).to_string() } else { t.stem.clone() };
        blocks.push(r.table(Table { stem: String::new(), ..t }, &format!("{experiment}-bench-{stem}"))?);
    }
    Ok(blocks)
}
