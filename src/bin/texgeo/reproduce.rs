//! `texgeo reproduce -o DIR`: every experiment of both theses, one report (Markdown,
//! HTML, CSV, plots, pictures, claims); `--compare A B` sets two runs side by side;
//! `--results-md PAGE` writes a saved report's tables into a results page.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use texgeo::report::Progress;
use texgeo::report::reproduce::{self, Config, EXPERIMENTS, Monitor};

#[derive(clap::Args)]
pub struct Args {
    /// Built-in models and small sizes: about two minutes on two cores.
    #[arg(long)]
    quick: bool,
    /// Add N repetitions to every timed comparison: narrower intervals, fewer
    /// "inconclusive" verdicts, a longer run.
    #[arg(long, value_name = "N", default_value_t = 0)]
    repeat: usize,
    /// Where `tools/fetch-models` put the models that stand in for the thesis' ones.
    #[arg(long, default_value = "models")]
    models: PathBuf,
    /// Run only these experiments (comma-separated): inclusion, voxelize, boolean, subdivide.
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Output folder: report.md, report.html, csv/, plots/, figures/, run.json.
    #[arg(
        short,
        long = "output",
        alias = "out",
        value_name = "DIR",
        required_unless_present_any = ["compare", "results_md"]
    )]
    out: Option<PathBuf>,
    /// Compare two report folders (two devices, or two runs): every claim's verdict on
    /// both side by side, the GPU's speed-ups over the CPU on both beside the thesis',
    /// the values that moved by more than the noise their repeated runs showed, and the
    /// claims whose verdict changed.
    #[arg(long, num_args = 2, value_names = ["OLD", "NEW"], conflicts_with_all = ["quick", "only", "out"])]
    compare: Option<Vec<PathBuf>>,
    /// Rewrite the tables of a Markdown page (docs/results.md) from the saved reports' CSV
    /// files its marker comments name, relative to the page (`<!-- texgeo table: FILE;
    /// columns: … -->` … `<!-- end of texgeo table -->`): a reproduction report's, a
    /// `texgeo bench` suite's, a comparison tool's. The rest of the page is kept as it is;
    /// a missing or damaged file is refused and the page left unchanged.
    #[arg(long, value_name = "PAGE", conflicts_with_all = ["quick", "only", "out", "compare"])]
    results_md: Option<PathBuf>,
}

/// Progress bars on standard error: one per experiment and one overall (at a terminal;
/// elsewhere one line per experiment's start and end).
struct Bars {
    multi: MultiProgress,
    overall: ProgressBar,
}

struct Bar {
    bar: ProgressBar,
    started: bool,
}

impl Progress for Bar {
    fn total(&mut self, steps: u64) {
        self.bar.inc_length(steps);
    }

    fn step(&mut self, what: &str) {
        if std::mem::replace(&mut self.started, true) {
            self.bar.inc(1);
        }
        self.bar.set_message(what.to_string());
    }
}

impl Drop for Bar {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

impl Monitor for Bars {
    fn begin(&mut self, name: &str) -> Box<dyn Progress> {
        let bar = self.multi.insert_before(&self.overall, ProgressBar::new(0));
        bar.set_style(
            ProgressStyle::with_template("{prefix:>28} [{bar:30}] {pos}/{len} {elapsed:>4} {wide_msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.set_prefix(name.to_string());
        self.overall.set_message(name.to_string());
        Box::new(Bar { bar, started: false })
    }

    fn end(&mut self, name: &str, elapsed: Duration) {
        self.overall.inc(1);
        let _ = self.multi.println(format!("{name}: {:.1} s", elapsed.as_secs_f64()));
    }
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    if let Some(dirs) = &args.compare {
        let [old, new] = dirs.as_slice() else { anyhow::bail!("--compare needs two folders: OLD NEW") };
        let c = reproduce::compare(old, new)?;
        say!("{}", c.markdown.trim_end());
        if !c.damage.is_empty() {
            anyhow::bail!("damaged report(s), compared in part only: {}", c.damage.join("; "));
        }
        return Ok(());
    }
    if let Some(page) = &args.results_md {
        let text = std::fs::read_to_string(page).map_err(|e| anyhow::anyhow!("{}: {e}", page.display()))?;
        let (new, tables) = reproduce::results_page(page, &text)?;
        if tables == 0 {
            anyhow::bail!("{}: no \"{}FILE -->\" marker", page.display(), reproduce::TABLE_MARKER);
        }
        let what = if new == text { "unchanged" } else { "rewritten" };
        if new != text {
            reproduce::write_atomic(page, new.as_bytes())?;
        }
        say!("{}: {tables} table(s) from the saved reports, {what}", page.display());
        return Ok(());
    }
    let out = args.out.clone().ok_or_else(|| anyhow::anyhow!("-o DIR is required"))?;
    let config =
        Config { quick: args.quick, repeat: args.repeat, models_dir: args.models, only: args.only, out };
    // Before the device opens and minutes of measuring start.
    config.check()?;
    let ctx = crate::open_context(device)?;
    let selected =
        EXPERIMENTS.iter().filter(|e| config.only.is_empty() || config.only.iter().any(|o| o == e.key));
    if !std::io::stderr().is_terminal() {
        let outcome = reproduce::run(&ctx, &config, &mut texgeo::report::Lines::new("texgeo reproduce"))?;
        return summarize(&outcome);
    }
    let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
    let overall = multi.add(ProgressBar::new(selected.count() as u64));
    overall.set_style(
        ProgressStyle::with_template("{prefix:>28} [{bar:30}] {pos}/{len} {elapsed:>4} {wide_msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("##-"),
    );
    overall.set_prefix("texgeo reproduce");
    let mut bars = Bars { multi, overall };
    let outcome = reproduce::run(&ctx, &config, &mut bars)?;
    bars.overall.finish_and_clear();
    summarize(&outcome)
}

/// The closing lines of a run; an error when a part failed.
fn summarize(outcome: &reproduce::Outcome) -> anyhow::Result<()> {
    say!(
        "wrote {} and {} in {:.1} s: claims {} hold, {} do not hold, {} inconclusive (within noise), {} not measurable",
        outcome.report.display(),
        outcome.html.display(),
        outcome.elapsed.as_secs_f64(),
        outcome.verdicts[0],
        outcome.verdicts[1],
        outcome.verdicts[2],
        outcome.verdicts[3]
    );
    for d in &outcome.disagreements {
        note!("texgeo: warning: answers differ from the reference: {d}");
    }
    if !outcome.failures.is_empty() {
        let list: Vec<String> = outcome.failures.iter().map(|(k, e)| format!("{k}: {e}")).collect();
        anyhow::bail!("the report is written, but {} part(s) failed: {}", list.len(), list.join("; "));
    }
    Ok(())
}
