//! `texgeo sweep MANIFEST --task T [options] -o DIR [--shard I/N] [--jobs J]`,
//! `texgeo sweep merge DIR`, and the hidden `texgeo sweep worker`.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Context as _;
use serde_json::{Map, Value};
use texgeo::sweep::manifest::typed_value;
use texgeo::sweep::pool::{self, Plan};
use texgeo::sweep::record::ResultsFile;
use texgeo::sweep::{Manifest, Outcome, Shard, SweepError, SweepInfo, TaskKind, merge, worker};

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Args {
    #[command(subcommand)]
    command: Option<Command>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(clap::Subcommand)]
enum Command {
    /// Merge every shard's results in DIR into sweep.csv, summary.md and time-vs-size.svg.
    Merge {
        /// The sweep's output folder.
        dir: PathBuf,
    },
    /// The worker process a sweep starts (JSON lines on standard input and output).
    #[command(hide = true)]
    Worker,
}

#[derive(clap::Args)]
struct RunArgs {
    /// The meshes: a file with one path (or builtin:NAME) per line, a CSV with a `mesh`
    /// column and per-mesh option columns, or a folder of mesh files.
    #[arg(required = true)]
    manifest: Option<PathBuf>,
    /// What to run on each mesh.
    #[arg(long, required = true, value_parser = parse_task)]
    task: Option<TaskKind>,
    /// Output folder: results-I-of-N.jsonl per shard, sweep.json, and the merged table.
    #[arg(short, long, value_name = "DIR", required = true)]
    output: Option<PathBuf>,
    /// Run shard I of N (0-based): every N-th mesh from the I-th.
    #[arg(long, value_name = "I/N", default_value = "0/1")]
    shard: Shard,
    /// Worker processes running meshes in parallel.
    #[arg(long, short, default_value_t = 1, value_parser = clap::value_parser!(u16).range(1..=256))]
    jobs: u16,
    /// Seconds one mesh may take before its worker is killed and the mesh recorded as a
    /// timeout (more than 0, at most 10⁷: about four months).
    #[arg(long, value_name = "SECONDS", default_value = "600", value_parser = |s: &str| crate::args::seconds(s, 1e7))]
    timeout: Duration,
    /// Address-space limit of each worker, MiB (a mesh that needs more is recorded as out of memory).
    #[arg(long, value_name = "MIB")]
    memory_limit: Option<u64>,
    /// Continue a sweep whose folder exists, skipping meshes already recorded (the default).
    #[arg(long)]
    resume: bool,
    /// Discard this shard's earlier results and run all its meshes again.
    #[arg(long, conflicts_with = "resume")]
    restart: bool,

    /// Task method (inclusion: auto (default), cpu, gpu, …; voxelize: auto (default), zoned,
    /// cpu, …; subdivide: gpu, cpu; boolean: the inclusion method of its point tests).
    #[arg(long, help_heading = "Task options")]
    method: Option<String>,
    /// inclusion: random points per mesh (default 1000).
    #[arg(long, help_heading = "Task options")]
    points: Option<u64>,
    /// inclusion: seed of the random points (default 1).
    #[arg(long, help_heading = "Task options")]
    seed: Option<u64>,
    /// inclusion: TetraGrid resolution (default 32).
    #[arg(long, help_heading = "Task options")]
    grid: Option<u64>,
    /// inclusion: tetrahedra per point-vertex of the GPU methods.
    #[arg(long, help_heading = "Task options")]
    batch: Option<u64>,
    /// inclusion, voxelize: accept meshes that are not solids (open, self-intersecting,
    /// nested, inverted); they are classified by the generalized winding number (inside iff
    /// w ≥ ½) on the CPU whatever the method, and the defect is kept in a `non_solid` column.
    #[arg(long, help_heading = "Task options")]
    allow_open: bool,
    /// voxelize: voxels per side (default 64).
    #[arg(long, help_heading = "Task options")]
    res: Option<u64>,
    /// voxelize: zone height of `zoned`.
    #[arg(long, help_heading = "Task options")]
    zone: Option<u64>,
    /// subdivide: subdivision level (default 2).
    #[arg(long, short, help_heading = "Task options")]
    level: Option<u64>,
    /// boolean: union, intersection, difference (default) or symmetric-difference.
    #[arg(long, help_heading = "Task options")]
    op: Option<String>,
    /// boolean: the second operand — `turned` (default: the mesh turned 10° about y and moved
    /// 1 % of its diagonal), `transform:STEPS` (`texgeo boolean --transform-b` steps) or
    /// `builtin:NAME`.
    #[arg(long, help_heading = "Task options")]
    with: Option<String>,
    /// What every result is compared with (inclusion: cpu; voxelize: scanline; subdivide:
    /// auto = cpu for gpu, osd for cpu; boolean: none, or cgal), or `none`.
    #[arg(long, help_heading = "Task options")]
    reference: Option<String>,
    /// Any task option by name (repeatable), e.g. --set tolerance=1e-6.
    #[arg(long = "set", value_name = "KEY=VALUE", help_heading = "Task options")]
    set: Vec<String>,
}

fn parse_task(s: &str) -> Result<TaskKind, String> {
    TaskKind::parse(s).ok_or_else(|| {
        format!("unknown task '{s}' (expected {})", TaskKind::ALL.map(|t| t.name()).join(", "))
    })
}

pub fn run(device: Option<&str>, args: Args) -> anyhow::Result<()> {
    match args.command {
        Some(Command::Worker) => Ok(worker::main()?),
        Some(Command::Merge { dir }) => run_merge(&dir),
        None => sweep(device, args.run),
    }
}

fn run_merge(dir: &std::path::Path) -> anyhow::Result<()> {
    let (merged, out) = merge::merge(dir)?;
    say!("{}", counts_line(&merged));
    say!("wrote {}, {}, {}", out.csv.display(), out.summary.display(), out.plot.display());
    Ok(())
}

fn counts_line(merged: &merge::Merged) -> String {
    let counts = merged.counts();
    let mut parts: Vec<String> =
        Outcome::ALL.iter().filter_map(|o| counts.get(o).map(|n| format!("{n} {o}"))).collect();
    if !merged.missing.is_empty() {
        parts.push(format!("{} not run yet", merged.missing.len()));
    }
    format!("{} meshes: {}", merged.info.entries.len(), parts.join(", "))
}

/// The options given on the command line, by name.
fn options(a: &RunArgs) -> anyhow::Result<Map<String, Value>> {
    let mut m = Map::new();
    let mut put = |k: &str, v: Option<Value>| {
        if let Some(v) = v {
            m.insert(k.to_string(), v);
        }
    };
    put("method", a.method.clone().map(Value::from));
    put("points", a.points.map(Value::from));
    put("seed", a.seed.map(Value::from));
    put("grid", a.grid.map(Value::from));
    put("batch", a.batch.map(Value::from));
    put("allow_open", a.allow_open.then_some(Value::Bool(true)));
    put("res", a.res.map(Value::from));
    put("zone", a.zone.map(Value::from));
    put("level", a.level.map(Value::from));
    put("reference", a.reference.clone().map(Value::from));
    put("op", a.op.clone().map(Value::from));
    put("with", a.with.clone().map(Value::from));
    for kv in &a.set {
        let (k, v) = kv.split_once('=').with_context(|| format!("--set {kv}: expected KEY=VALUE"))?;
        m.insert(k.trim().to_string(), typed_value(v.trim()));
    }
    Ok(m)
}

fn sweep(device: Option<&str>, a: RunArgs) -> anyhow::Result<()> {
    let (Some(manifest_path), Some(task), Some(dir)) = (&a.manifest, a.task, &a.output) else {
        anyhow::bail!("give MANIFEST, --task and -o DIR");
    };
    let manifest = Manifest::read(manifest_path)?;
    let options = task.options(&options(&a)?).map_err(SweepError::Options)?;
    let program = std::env::current_exe().context("finding the texgeo binary for the workers")?;
    let plan = Plan {
        task,
        options: options.clone(),
        device: device.map(str::to_string),
        timeout: a.timeout,
        jobs: usize::from(a.jobs),
        memory_limit_mib: a.memory_limit,
        program,
        args: vec!["sweep".into(), "worker".into()],
    };
    // Every entry's options are checked now, not when its turn comes.
    plan.jobs_for(&manifest.entries).map_err(|(line, message)| SweepError::Manifest {
        path: manifest_path.clone(),
        line,
        message,
    })?;

    SweepInfo::new(task.name(), options, &manifest).prepare(dir)?;
    let path = ResultsFile::path_in(dir, a.shard);
    if a.restart && path.exists() {
        std::fs::remove_file(&path).with_context(|| format!("removing {}", path.display()))?;
    }
    let (mut results, done) = ResultsFile::open(&path)?;
    let done = texgeo::sweep::record::indices(&done);
    let mine: Vec<_> = manifest.shard(a.shard).collect();
    let pending: Vec<_> = mine.iter().copied().filter(|e| !done.contains(&e.index)).collect();
    let jobs = plan.jobs_for(pending.iter().copied()).map_err(|(_, m)| SweepError::Options(m))?;
    say!(
        "sweep {task} over {}: shard {} has {} meshes, {} already recorded, {} to run on {} worker(s)",
        manifest_path.display(),
        a.shard,
        mine.len(),
        mine.len() - pending.len(),
        jobs.len(),
        plan.jobs.min(jobs.len().max(1))
    );
    let start = Instant::now();
    let total = jobs.len();
    let mut n = 0;
    pool::run(&plan, jobs, |r| {
        results.append(&r)?;
        n += 1;
        let why = if r.reason.is_empty() { String::new() } else { format!(" ({})", r.reason) };
        // One line per mesh with the time since the start: a log of a long sweep is never silent.
        say!(
            "[{n}/{total} at {:.1} s] {}: {}{why} {:.1} ms",
            start.elapsed().as_secs_f64(),
            r.mesh,
            r.outcome,
            r.total_ms().unwrap_or(0.0)
        );
        Ok(())
    })?;
    say!(
        "shard {} done in {:.1} s; results in {}",
        a.shard,
        start.elapsed().as_secs_f64(),
        results.path().display()
    );
    if a.shard.count == 1 {
        run_merge(dir)?;
    }
    Ok(())
}
