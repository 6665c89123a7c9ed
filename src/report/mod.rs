//! Benchmarks and reproduction reports: timing with medians, tables written as Markdown
//! and CSV, and the description of the machine and device that produced them.

pub mod bench;
pub mod plot;
pub mod reproduce;
mod table;
mod timing;

pub use table::{Report, Table, sig};
pub use timing::{Samples, Side, interleave, time_runs, timed};

/// Where a long measurement says what it is doing: `texgeo bench` prints a line per
/// step, `texgeo reproduce` advances a progress bar.
pub trait Progress: Send {
    /// How many more steps follow (called before them; a run of several parts calls it
    /// once per part).
    fn total(&mut self, _steps: u64) {}
    /// A step starts.
    fn step(&mut self, what: &str);
}

/// Prints every step on standard error after a prefix (`bench inclusion: …`).
pub struct Log(pub &'static str);

impl Progress for Log {
    fn step(&mut self, what: &str) {
        crate::note!("{}: {what}", self.0);
    }
}

/// One line on standard error when each part of a long run starts and one when it ends,
/// with the time it took and the time since the run began: progress for a log file or
/// CI, where bars do not show.
pub struct Lines {
    prefix: &'static str,
    start: std::time::Instant,
}

impl Lines {
    pub fn new(prefix: &'static str) -> Lines {
        Lines { prefix, start: std::time::Instant::now() }
    }

    pub fn started(&self, what: &str) {
        crate::note!("{}: {what}: started at {:.1} s", self.prefix, self.start.elapsed().as_secs_f64());
    }

    pub fn ended(&self, what: &str, took: std::time::Duration) {
        crate::note!(
            "{}: {what}: done in {:.1} s (at {:.1} s)",
            self.prefix,
            took.as_secs_f64(),
            self.start.elapsed().as_secs_f64()
        );
    }
}

/// Where and on what a measurement was made; printed at the top of every report.
#[derive(Clone, Debug)]
pub struct Environment {
    pub device: String,
    pub cpu: String,
    pub cores: usize,
    pub date: String,
    pub version: &'static str,
}

impl Environment {
    pub fn new(device: String) -> Environment {
        let cpu = crate::host::cpu_model();
        let date = std::process::Command::new("date")
            .arg("-u")
            .arg("+%Y-%m-%d %H:%M UTC")
            .output()
            .ok()
            .and_then(|o| String::from_utf8(o.stdout).ok())
            .map(|s| s.trim().to_string())
            .unwrap_or_default();
        Environment {
            device,
            cpu,
            cores: std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
            date,
            version: env!("CARGO_PKG_VERSION"),
        }
    }

    pub fn describe(&self) -> String {
        format!(
            "texgeo {} on {}; CPU: {} ({} cores); {}",
            self.version, self.device, self.cpu, self.cores, self.date
        )
    }
}
