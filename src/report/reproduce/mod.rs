//! `texgeo reproduce`: every experiment of both theses in one run, and one report a
//! reader can open, diff against another machine's and paste from (SPEC §7).
//!
//! The experiments are a list of entries ([`EXPERIMENTS`]): a name, the thesis tables it
//! reproduces, the function that runs it (the `texgeo bench …` suites' own measuring
//! code), the thesis' claims about it (`claims.rs`) and its pictures. An experiment
//! whose command does not exist yet is an entry without a runner: its section says so
//! and its claims are "not measurable". Adding one is adding an entry.
//!
//! A run writes into its folder: `report.md` and `report.html` (the same blocks, the HTML
//! with every figure inline), `csv/` (every table, plus `measurements.csv` — each
//! measured value with the range of its repeated runs, which `--compare` uses as its
//! noise — and `claims.csv`), `plots/` (SVG + PNG), `figures/` (PNG pictures rendered by
//! texgeo's own Vulkan pipeline, described in `figures.json`) and `run.json` (machine,
//! device, version). Every file is written atomically. A saved report's tables are
//! written into a Markdown page between marker comments by [`results_page`].

mod claims;
mod compare;
mod doc;
mod experiments;
mod facts;
mod figures;
mod files;
mod header;
mod page;
mod thesis;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use claims::{Claim, Decision, Found, Value, Verdict};
pub use compare::compare;
pub use experiments::{EXPERIMENTS, Experiment, Figure};
pub use facts::{Facts, NotRun, Stat};
pub use figures::{FigureRecord, valence_model};
pub use files::{check_writable, write_atomic};
pub use page::{BEGIN as TABLE_MARKER, regenerate as results_page};

use crate::gpu::Context;
use crate::report::{Progress, Table};
use doc::Block;
use files::Layout;

pub type Result<T, E = ReproduceError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum ReproduceError {
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{0}")]
    Usage(String),
    #[error("{0}")]
    Plot(String),
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    #[error(transparent)]
    Inclusion(#[from] crate::inclusion::InclusionError),
    #[error(transparent)]
    Voxel(#[from] crate::voxel::VoxelError),
    #[error(transparent)]
    Subdiv(#[from] crate::subdiv::SubdivError),
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
    #[error(transparent)]
    Boolean(#[from] crate::boolean::BooleanError),
}

impl ReproduceError {
    /// The device feature missing, when that is why the error happened: such an
    /// experiment is not measurable on this device rather than failed.
    pub fn unsupported(&self) -> Option<&str> {
        use crate::gpu::GpuError::Unsupported;
        let gpu = match self {
            ReproduceError::Gpu(g) => g,
            ReproduceError::Inclusion(crate::inclusion::InclusionError::Gpu(g)) => g,
            ReproduceError::Voxel(crate::voxel::VoxelError::Gpu(g)) => g,
            ReproduceError::Subdiv(crate::subdiv::SubdivError::Gpu(g)) => g,
            ReproduceError::Render(crate::render::RenderError::Gpu(g)) => g,
            ReproduceError::Boolean(crate::boolean::BooleanError::Inclusion {
                source: crate::inclusion::InclusionError::Gpu(g),
                ..
            }) => g,
            _ => return None,
        };
        match gpu {
            Unsupported(m) => Some(m),
            _ => None,
        }
    }
}

/// What to run.
#[derive(Clone, Debug)]
pub struct Config {
    /// Built-in models and small sizes (about two minutes on two cores).
    pub quick: bool,
    /// Repetitions added to every timed comparison (narrower intervals, fewer
    /// inconclusive verdicts, a longer run).
    pub repeat: usize,
    /// Where `tools/fetch-models` put the thesis stand-ins.
    pub models_dir: PathBuf,
    /// Experiment names to run (empty: all).
    pub only: Vec<String>,
    pub out: PathBuf,
}

impl Config {
    /// Checks `--only` names and the output folder before anything runs.
    pub fn check(&self) -> Result<()> {
        for name in &self.only {
            if !EXPERIMENTS.iter().any(|e| e.key == name) {
                return Err(ReproduceError::Usage(format!(
                    "--only: unknown experiment '{name}' (known: {})",
                    EXPERIMENTS.iter().map(|e| e.key).collect::<Vec<_>>().join(", ")
                )));
            }
        }
        check_writable(&self.out)
    }

    fn selected(&self, key: &str) -> bool {
        self.only.is_empty() || self.only.iter().any(|o| o == key)
    }
}

/// Shows a run's progress: one progress per experiment.
pub trait Monitor {
    /// `name` starts; its steps go to the returned progress.
    fn begin(&mut self, name: &str) -> Box<dyn Progress>;
    /// `name` ended, after `elapsed`.
    fn end(&mut self, name: &str, elapsed: Duration);
}

/// A monitor that shows nothing.
pub struct Quiet;

struct NoProgress;

impl Progress for NoProgress {
    fn step(&mut self, _what: &str) {}
}

impl Monitor for Quiet {
    fn begin(&mut self, _name: &str) -> Box<dyn Progress> {
        Box::new(NoProgress)
    }
    fn end(&mut self, _name: &str, _elapsed: Duration) {}
}

impl Monitor for crate::report::Lines {
    fn begin(&mut self, name: &str) -> Box<dyn Progress> {
        self.started(name);
        Box::new(NoProgress)
    }
    fn end(&mut self, name: &str, elapsed: Duration) {
        self.ended(name, elapsed);
    }
}

/// What a run produced.
#[derive(Debug)]
pub struct Outcome {
    pub report: PathBuf,
    pub html: PathBuf,
    /// Experiments that failed, with the error (their sections say so too).
    pub failures: Vec<(String, String)>,
    /// Methods whose answers differed from the reference, per experiment.
    pub disagreements: Vec<String>,
    /// Claims per verdict: holds, does not hold, inconclusive (within noise), not measurable.
    pub verdicts: [usize; 4],
    pub elapsed: Duration,
}

/// The state an experiment runs with: the device, the settings, where its tables,
/// plots and pictures go, and the facts it adds for the claims.
pub struct Run<'a> {
    pub ctx: &'a Context,
    pub quick: bool,
    /// Repetitions to add to every timed comparison.
    pub repeat: usize,
    pub models_dir: &'a Path,
    pub progress: &'a mut dyn Progress,
    pub facts: &'a mut Facts,
    pub thesis: &'a Facts,
    layout: &'a Layout,
    names: &'a mut HashSet<String>,
    figures: &'a mut Vec<FigureRecord>,
    disagreements: &'a mut Vec<String>,
}

impl Run<'_> {
    fn unique(&mut self, stem: &str) -> Result<()> {
        if !self.names.insert(stem.to_string()) {
            return Err(ReproduceError::Usage(format!("two outputs are named {stem}")));
        }
        Ok(())
    }

    /// `table` as a block, its cells written to `csv/STEM.csv`. An empty cell (a number
    /// a thesis table does not have) shows as "–".
    pub fn table(&mut self, mut table: Table, stem: &str) -> Result<Block> {
        self.unique(&format!("csv/{stem}"))?;
        for cell in table.rows.iter_mut().flatten().filter(|c| c.trim().is_empty()) {
            *cell = "–".to_string();
        }
        let csv = format!("{}/{stem}.csv", Layout::CSV);
        self.layout.write(&csv, table.to_csv().as_bytes())?;
        Ok(Block::Table { table, csv })
    }

    /// `chart` as `plots/STEM.svg` and `.png`; a chart with more curves than a reader
    /// can tell apart as several (`STEM.svg`, `STEM-2.svg`, …, [`Chart::split`]).
    ///
    /// [`Chart::split`]: crate::report::plot::Chart::split
    pub fn plot(&mut self, chart: &crate::report::plot::Chart, stem: &str) -> Result<Vec<Block>> {
        let mut blocks = Vec::new();
        for (i, part) in chart.split().iter().enumerate() {
            let stem = if i == 0 { stem.to_string() } else { format!("{stem}-{}", i + 1) };
            self.unique(&format!("plots/{stem}"))?;
            let (svg, png) =
                (format!("{}/{stem}.svg", Layout::PLOTS), format!("{}/{stem}.png", Layout::PLOTS));
            self.layout.write(&svg, part.svg().map_err(ReproduceError::Plot)?.as_bytes())?;
            self.layout.write(&png, &part.png().map_err(ReproduceError::Plot)?)?;
            blocks.push(Block::Plot { svg, png, caption: part.title.clone() });
        }
        Ok(blocks)
    }

    /// A rendered picture as `figures/STEM.png`, described in `figures.json`.
    pub fn picture(
        &mut self,
        picture: &crate::render::Picture,
        stem: &str,
        caption: &str,
        mut record: FigureRecord,
    ) -> Result<Block> {
        self.unique(&format!("figures/{stem}"))?;
        let path = format!("{}/{stem}.png", Layout::FIGURES);
        picture.save_png(self.layout.root.join(&path))?;
        record.file = path.clone();
        record.width = picture.width;
        record.height = picture.height;
        self.figures.push(record);
        Ok(Block::Image { path, caption: caption.to_string(), width: picture.width, height: picture.height })
    }

    /// Records that `what` gave answers different from the reference.
    pub fn disagreement(&mut self, what: String) {
        self.disagreements.push(what);
    }
}

/// How an experiment's run ended, as its row of the summary says.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    Ran,
    /// It did not run, or ran into an error: why.
    Skipped(NotRun),
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Status::Ran => f.write_str("ran"),
            Status::Skipped(NotRun::LeftOut) => f.write_str("not run: left out by --only"),
            Status::Skipped(NotRun::NoCommand(why)) => write!(f, "not run: {why}"),
            Status::Skipped(NotRun::Unsupported(why)) => write!(f, "not measurable on this device: {why}"),
            Status::Skipped(NotRun::Failed(err)) => write!(f, "FAILED: {err}"),
        }
    }
}

/// One experiment's part of the report: its blocks, how it ended and how long it took.
struct Section {
    experiment: &'static Experiment,
    blocks: Vec<Block>,
    status: Status,
    elapsed: Duration,
}

/// What every experiment of a run adds to: the facts, the output names, the pictures,
/// the disagreements and the failures.
struct Collected {
    today: Facts,
    names: HashSet<String>,
    figures: Vec<FigureRecord>,
    disagreements: Vec<String>,
    failures: Vec<(String, String)>,
}

/// Runs the selected experiments and writes the report into `config.out`: each
/// experiment in turn ([`run_experiment`]), the claims from the facts ([`claims_table`]),
/// then the report around them ([`assemble`]) and its files ([`write_report`]).
pub fn run(ctx: &Context, config: &Config, monitor: &mut dyn Monitor) -> Result<Outcome> {
    config.check()?;
    let start = Instant::now();
    let watch = header::Watch::start();
    let layout = Layout::create(&config.out)?;
    let mut header = header::Header::new(ctx, config);
    let thesis = thesis::facts();
    let mut c = Collected {
        today: Facts::new(facts::Source::Today),
        names: HashSet::new(),
        figures: Vec::new(),
        disagreements: Vec::new(),
        failures: Vec::new(),
    };
    let mut sections = Vec::new();
    for e in EXPERIMENTS {
        if !config.selected(e.key) {
            c.today.skipped(e.key, NotRun::LeftOut);
            continue;
        }
        let t = Instant::now();
        let mut progress = monitor.begin(e.title);
        let (blocks, status) = run_experiment(ctx, config, e, progress.as_mut(), &thesis, &layout, &mut c);
        let elapsed = t.elapsed();
        monitor.end(e.title, elapsed);
        sections.push(Section { experiment: e, blocks, status, elapsed });
    }
    let (claims, claim_numbers, verdicts) = claims_table(&thesis, &c.today);
    let elapsed = start.elapsed();
    header.state = Some(watch.finish());
    let claims = (claims, claim_numbers);
    let blocks = assemble(&header, &layout, sections, claims, verdicts, &c.disagreements, elapsed)?;
    let (report, html) = write_report(&layout, &header, &c, blocks)?;
    Ok(Outcome { report, html, failures: c.failures, disagreements: c.disagreements, verdicts, elapsed })
}

/// Runs one experiment and draws its figures: its blocks and how it ended. A device
/// that lacks a feature makes it (or a figure) not measurable; any other error is a
/// failure, recorded and said in its section.
fn run_experiment(
    ctx: &Context,
    config: &Config,
    e: &'static Experiment,
    progress: &mut dyn Progress,
    thesis: &Facts,
    layout: &Layout,
    c: &mut Collected,
) -> (Vec<Block>, Status) {
    let runner = match e.runner {
        Err(why) => return skip(c, e, NotRun::NoCommand(why.to_string())),
        Ok(runner) => runner,
    };
    let mut r = Run {
        ctx,
        quick: config.quick,
        repeat: config.repeat,
        models_dir: &config.models_dir,
        progress,
        facts: &mut c.today,
        thesis,
        layout,
        names: &mut c.names,
        figures: &mut c.figures,
        disagreements: &mut c.disagreements,
    };
    match runner(&mut r) {
        Ok(mut blocks) => {
            draw_figures(&mut r, e, &mut blocks, &mut c.failures);
            (blocks, Status::Ran)
        }
        Err(err) => {
            let why = match err.unsupported() {
                Some(why) => NotRun::Unsupported(why.to_string()),
                None => {
                    c.failures.push((e.key.to_string(), err.to_string()));
                    NotRun::Failed(err.to_string())
                }
            };
            skip(c, e, why)
        }
    }
}

/// Records why `e` has no facts; its section says so in one paragraph.
fn skip(c: &mut Collected, e: &'static Experiment, why: NotRun) -> (Vec<Block>, Status) {
    let para = match &why {
        NotRun::LeftOut => "**Not run:** left out by --only.".to_string(),
        NotRun::NoCommand(why) => format!("**Not run:** {why}."),
        NotRun::Unsupported(why) => format!("**Not measurable on this device:** {why}."),
        NotRun::Failed(err) => format!("**Failed:** {err}"),
    };
    c.today.skipped(e.key, why.clone());
    (vec![Block::Para(para)], Status::Skipped(why))
}

/// Draws the figures of `e` after its tables; a figure the device cannot draw says so,
/// one that fails is recorded as a failure.
fn draw_figures(r: &mut Run, e: &Experiment, blocks: &mut Vec<Block>, failures: &mut Vec<(String, String)>) {
    r.progress.total(e.figures.len() as u64);
    for f in e.figures {
        r.progress.step(f.title);
        blocks.push(Block::Heading(4, format!("Figure: {} ({})", f.title, f.thesis)));
        let draw = match f.draw {
            Err(why) => {
                blocks.push(Block::Para(format!("Not drawn: {why}.")));
                continue;
            }
            Ok(draw) => draw,
        };
        match draw(r) {
            Ok(pictures) => blocks.extend(pictures),
            Err(err) => match err.unsupported() {
                Some(why) => blocks.push(Block::Para(format!("**Not drawn on this device:** {why}."))),
                None => {
                    failures.push((format!("{}: figure {}", e.key, f.key), err.to_string()));
                    blocks.push(Block::Para(format!("**Figure failed:** {err}")));
                }
            },
        }
    }
}

/// How the claims table reads its verdicts, under the table.
const CLAIMS_NOTE: &str = "Verdicts are computed from the numbers by the rule in \"decided by\"; the same rule applied \
     to the thesis' own tables gives \"thesis' own numbers\". Words of degree are read the same way everywhere: faster \
     or better — a ratio above 1; much, considerably, greatly — at least 2×; drastically, enormously, the vast \
     majority — at least 10× (90 %); linear — a log–log slope within 0.8–1.2; close — within a factor of 2; equal or \
     better — not slower beyond the range of the repeated runs (within 5 % for single numbers, such as the thesis'). \
     Each compared pair was measured in turn, repetition by repetition (A, B, A, B, …), so that load from other work \
     hits both sides alike. A value in parentheses after a measured one is its interval: for a ratio, the range of \
     the per-repetition ratios; for a slope or a rank correlation, the range of the values fitted to each repetition \
     on its own (the number of models says how few points a fit has); for a geometric mean, the geometric means of \
     the cells' interval ends. A claim holds or does not hold only when the whole interval lies on one side of the \
     rule's threshold; otherwise it is \"inconclusive (within noise)\" (more repetitions with `--repeat N` narrow the \
     intervals). Counts, bytes and single builds carry no interval. \"not measurable\" says why in \"measured here\".";

/// The columns of the claims table; `csv/claims.csv` has them and [`CLAIM_NUMBERS`]
/// after them, and `--compare` reads them back.
pub const CLAIM_COLUMNS: [&str; 7] = [
    "id",
    "source",
    "claim (the thesis' words)",
    "decided by",
    "thesis' own numbers",
    "measured here",
    "verdict",
];

/// The numbers `csv/claims.csv` adds to [`CLAIM_COLUMNS`]: the value the rule decided on
/// from the thesis' tables and from today's measurements, today's interval, and their
/// unit (empty where the rule counts models rather than deciding on one number).
pub const CLAIM_NUMBERS: [&str; 5] =
    ["thesis value", "measured value", "measured interval low", "measured interval high", "unit"];

/// Every claim of every experiment, computed from the thesis' numbers and from
/// `today`'s: the report's table, the same rows with the deciding numbers for
/// `csv/claims.csv`, and how many claims have each verdict ([`Verdict::index`]).
fn claims_table(thesis: &Facts, today: &Facts) -> (Table, Table, [usize; 4]) {
    let mut table = Table::new("Claims of the theses, checked against today's measurements", &CLAIM_COLUMNS);
    let mut numbers = Table::new(&table.title, &[&CLAIM_COLUMNS[..], &CLAIM_NUMBERS].concat());
    let mut verdicts = [0usize; 4];
    for c in EXPERIMENTS.iter().flat_map(|e| e.claims) {
        let (then, now) = ((c.measure)(thesis), (c.measure)(today));
        let verdict = Verdict::of(&now);
        verdicts[verdict.index()] += 1;
        let thesis_cell = match &then {
            Ok(found) => format!("{} ({})", found.shown, Verdict::of(&then).word()),
            Err(why) => format!("– ({why})"),
        };
        let measured = match &now {
            Ok(found) => found.shown.clone(),
            Err(why) => why.clone(),
        };
        let value = |m: &claims::Measure| m.as_ref().ok().and_then(|f| f.value);
        let number = |v: Option<f64>| v.map(|v| v.to_string()).unwrap_or_default();
        let (t, n) = (value(&then), value(&now));
        let row = vec![
            c.id.to_string(),
            c.source.to_string(),
            format!("{} («{}»)", c.claim, c.quote),
            c.rule.to_string(),
            thesis_cell,
            measured,
            verdict.word().to_string(),
        ];
        let mut with_numbers = row.clone();
        with_numbers.extend([
            number(t.map(|v| v.value)),
            number(n.map(|v| v.value)),
            number(n.map(|v| v.lo)),
            number(n.map(|v| v.hi)),
            n.or(t).map(|v| v.unit.to_string()).unwrap_or_default(),
        ]);
        table.row(row);
        numbers.row(with_numbers);
    }
    table.note(CLAIMS_NOTE);
    (table, numbers, verdicts)
}

/// The report's blocks: the verdict counts, the machine, the summary, the claims (shown
/// as the first table, written to `csv/claims.csv` as the second, which adds the
/// numbers), each experiment's section and the list of files.
fn assemble(
    header: &header::Header,
    layout: &Layout,
    sections: Vec<Section>,
    (claims, claim_numbers): (Table, Table),
    verdicts: [usize; 4],
    disagreements: &[String],
    elapsed: Duration,
) -> Result<Vec<Block>> {
    let write_table = |t: Table, stem: &str| -> Result<Block> {
        let csv = format!("{}/{stem}.csv", Layout::CSV);
        layout.write(&csv, t.to_csv().as_bytes())?;
        Ok(Block::Table { table: t, csv })
    };
    let longest = sections.iter().max_by_key(|s| s.elapsed).map(|s| (s.experiment.title, s.elapsed));
    let mut blocks = vec![
        Block::Para("This report reproduces the experiments of two theses:".into()),
        Block::List(thesis::CITATIONS.iter().map(|c| c.to_string()).collect()),
        Block::Verdicts(verdicts),
    ];
    blocks.extend(header.state.as_ref().and_then(|s| s.warning()));
    blocks.push(write_table(header.table(elapsed, longest), "run")?);
    blocks.push(header::Header::note());
    let mut summary =
        Table::new("Experiments", &["experiment", "thesis tables", "command", "status", "time (s)"]);
    for s in &sections {
        let e = s.experiment;
        summary.row(vec![
            format!("[{}](#{})", e.title, doc::anchor(e.title)),
            e.tables.to_string(),
            format!("`{}`", e.command),
            s.status.to_string(),
            format!("{:.1}", s.elapsed.as_secs_f64()),
        ]);
    }
    blocks.push(Block::Heading(2, "Summary".into()));
    blocks.push(write_table(summary, "experiments")?);
    blocks.push(Block::Para(format!(
        "Claims: **{}** hold, **{}** do not hold, **{}** are inconclusive (within noise), **{}** are not measurable \
         here (details in [Claims](#claims)). {}",
        verdicts[0],
        verdicts[1],
        verdicts[2],
        verdicts[3],
        if disagreements.is_empty() {
            "Every method gave the reference's answer on every point, voxel and vertex checked.".to_string()
        } else {
            format!("**Answers that differ from the reference:** {}.", disagreements.join("; "))
        }
    )));
    blocks.push(Block::Heading(2, "Claims".into()));
    let csv = format!("{}/claims.csv", Layout::CSV);
    layout.write(&csv, claim_numbers.to_csv().as_bytes())?;
    blocks.push(Block::Table { table: claims, csv });
    for s in sections {
        let e = s.experiment;
        blocks.push(Block::Heading(2, e.title.to_string()));
        blocks.push(Block::Para(format!("Reproduces {}; the same code as `{}`.", e.tables, e.command)));
        blocks.extend(s.blocks);
    }
    blocks.push(Block::Heading(2, "Files".into()));
    blocks.push(Block::List(vec![
        "`report.md`, `report.html` (the same report, figures inline)".into(),
        "`csv/` every table above as CSV; `csv/measurements.csv` every measured value with the range of its runs; \
         `csv/claims.csv` the claims; `csv/models.csv` each model's size and the thesis model it stands for"
            .into(),
        "`plots/` SVG and PNG of every plot; `figures/` the pictures, described in `figures.json`".into(),
        "`run.json` machine, device and version; `texgeo reproduce --compare A B` compares two runs (two devices \
         side by side)"
            .into(),
    ]));
    Ok(blocks)
}

/// Writes the report's files besides the tables' CSVs: measurements, models, run.json,
/// figures.json, report.md and report.html; returns the paths of the last two.
fn write_report(
    layout: &Layout,
    header: &header::Header,
    c: &Collected,
    blocks: Vec<Block>,
) -> Result<(PathBuf, PathBuf)> {
    layout.write("csv/measurements.csv", compare::measurements_csv(&c.today).as_bytes())?;
    layout.write("csv/models.csv", compare::models_csv(&c.today).as_bytes())?;
    layout.write("run.json", header.json().as_bytes())?;
    let figures_json = serde_json::to_string_pretty(&c.figures)
        .map_err(|e| ReproduceError::Usage(format!("figures.json: {e}")))?;
    layout.write("figures.json", figures_json.as_bytes())?;
    let markdown = format!("# texgeo reproduction report\n\n{}", doc::to_markdown(&blocks));
    let report = layout.write("report.md", markdown.as_bytes())?;
    let mut html_blocks = vec![Block::Heading(1, "texgeo reproduction report".into())];
    html_blocks.extend(blocks);
    let html = doc::to_html("texgeo reproduction report", &html_blocks, &layout.root)?;
    let html = layout.write("report.html", html.as_bytes())?;
    Ok((report, html))
}
