//! The top of a report: the machine, CPU, device, driver, Vulkan version and the texgeo
//! build that produced it; also written as `run.json` for `--compare`.

use std::time::{Duration, Instant};

use super::Config;
use super::doc::Block;
use crate::gpu::Context;
use crate::report::Table;

/// The commit texgeo was built from (`build.rs`; "unknown" without git).
pub const COMMIT: &str = env!("TEXGEO_GIT_COMMIT");

#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Header {
    pub machine: String,
    pub os: String,
    pub cpu: String,
    pub cores: usize,
    pub memory_gib: f64,
    pub device: String,
    pub device_kind: String,
    pub driver: String,
    pub vulkan: String,
    pub masked: Vec<String>,
    pub validation: bool,
    pub texgeo: String,
    pub commit: String,
    pub date: String,
    pub mode: String,
    pub models: String,
    /// How busy the machine was during the run (absent in reports of older texgeo).
    #[serde(default)]
    pub state: Option<MachineState>,
}

/// Other processes' share of the machine's CPU time above which a report warns that
/// the machine was busy.
const BUSY_SHARE: f64 = 0.2;

/// The machine's state over a run: load averages before and after, the run's CPU time
/// against its wall time, and the share of all cores' time other processes took.
#[derive(Clone, Debug, Default, serde::Serialize, serde::Deserialize)]
pub struct MachineState {
    pub load_before: Option<[f64; 3]>,
    pub load_after: Option<[f64; 3]>,
    pub wall_s: f64,
    /// texgeo's CPU time (its threads and helper processes), seconds.
    pub cpu_s: Option<f64>,
    /// Share of all cores' time other processes ran during the run (0–1).
    pub others_share: Option<f64>,
}

/// Watches the machine from the start of a run to its end.
pub struct Watch {
    start: Instant,
    load: Option<[f64; 3]>,
    ticks: Option<crate::host::CpuTicks>,
}

impl Watch {
    pub fn start() -> Watch {
        Watch {
            start: Instant::now(),
            load: crate::host::load_average(),
            ticks: crate::host::CpuTicks::now(),
        }
    }

    pub fn finish(&self) -> MachineState {
        let wall_s = self.start.elapsed().as_secs_f64();
        let end = crate::host::CpuTicks::now();
        // /proc/stat and /proc/self/stat count in the same clock ticks (USER_HZ, 100 on Linux).
        let (cpu_s, others_share) = match (self.ticks, end) {
            (Some(a), Some(b)) if b.total > a.total => {
                let own = b.own.saturating_sub(a.own);
                let busy = b.busy.saturating_sub(a.busy);
                let others = busy.saturating_sub(own) as f64 / (b.total - a.total) as f64;
                (Some(own as f64 / 100.0), Some(others.clamp(0.0, 1.0)))
            }
            _ => (None, None),
        };
        MachineState {
            load_before: self.load,
            load_after: crate::host::load_average(),
            wall_s,
            cpu_s,
            others_share,
        }
    }
}

impl MachineState {
    /// Whether other work took a noticeable share of the machine.
    pub fn busy(&self) -> bool {
        self.others_share.is_some_and(|s| s >= BUSY_SHARE)
    }

    /// The warning at the top of a report made on a busy machine.
    pub fn warning(&self) -> Option<Block> {
        let share = self.others_share.filter(|_| self.busy())?;
        Some(Block::Para(format!(
            "**Warning: the machine was busy.** Other processes took {:.0} % of all cores' time during this run. \
             Timings are slower and noisier than on a quiet machine; each pair of methods was measured in turn so \
             that load hits both alike, and a verdict whose interval crosses its threshold is reported as \
             \"inconclusive (within noise)\". Rerun on a quiet machine, or with `--repeat N`, to decide more claims.",
            100.0 * share
        )))
    }
}

impl Header {
    pub fn new(ctx: &Context, config: &Config) -> Header {
        let info = ctx.info();
        let env = crate::report::Environment::new(info.label());
        Header {
            machine: crate::host::hostname(),
            os: crate::host::os(),
            cpu: env.cpu,
            cores: env.cores,
            memory_gib: crate::host::total_memory().unwrap_or(0) as f64 / f64::from(1u32 << 30),
            device: info.name.clone(),
            device_kind: info.kind.clone(),
            driver: format!("{} {}", info.driver, info.driver_info),
            vulkan: info.api_version.clone(),
            masked: info.masked.clone(),
            validation: ctx.validating(),
            texgeo: env.version.to_string(),
            commit: COMMIT.to_string(),
            date: env.date,
            mode: if config.quick { "quick (built-in models, small sizes)".into() } else { "full".into() },
            models: config.models_dir.display().to_string(),
            state: None,
        }
    }

    pub fn json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// The header table, with the run's time and its longest experiment.
    pub fn table(&self, elapsed: Duration, longest: Option<(&str, Duration)>) -> Table {
        let mut t = Table::new("Where this ran", &["what", "value"]);
        let mut row = |k: &str, v: String| t.row(vec![k.to_string(), v]);
        row("machine", format!("{} ({})", self.machine, self.os));
        row("CPU", format!("{} ({} cores), {:.1} GiB", self.cpu, self.cores, self.memory_gib));
        row("device", format!("{} ({})", self.device, self.device_kind));
        row("driver", self.driver.clone());
        row("Vulkan", self.vulkan.clone());
        if !self.masked.is_empty() {
            row("masked features", format!("{} (TEXGEO_MASK_FEATURES)", self.masked.join(", ")));
        }
        row("validation layer", if self.validation { "on (slower)".into() } else { "off".into() });
        row("texgeo", format!("{} (commit {})", self.texgeo, self.commit));
        row("date", self.date.clone());
        row("mode", self.mode.clone());
        row("run time", format!("{:.1} s", elapsed.as_secs_f64()));
        if let Some((name, d)) = longest {
            row("longest experiment", format!("{name}: {:.1} s", d.as_secs_f64()));
        }
        if let Some(s) = &self.state {
            let load = |l: Option<[f64; 3]>| {
                l.map_or("unknown".to_string(), |l| format!("{:.2}, {:.2}, {:.2}", l[0], l[1], l[2]))
            };
            row(
                "load average (1, 5, 15 min)",
                format!("before {}; after {}", load(s.load_before), load(s.load_after)),
            );
            row(
                "CPU time",
                match s.cpu_s {
                    Some(c) => format!(
                        "texgeo {c:.1} s of CPU in {:.1} s of wall time ({:.2} cores busy on average)",
                        s.wall_s,
                        c / s.wall_s.max(1e-9)
                    ),
                    None => "unknown (no /proc)".into(),
                },
            );
            row(
                "other processes",
                match s.others_share {
                    Some(o) => format!(
                        "{:.0} % of all cores' time{}",
                        100.0 * o,
                        if s.busy() {
                            " (busy: times are slower and noisier than on a quiet machine)"
                        } else {
                            ""
                        }
                    ),
                    None => "unknown (no /proc)".into(),
                },
            );
        }
        t
    }

    /// What the times mean.
    pub fn note() -> Block {
        Block::Para(
            "Times are wall-clock on this machine, which may have been shared with other work; the thesis' numbers \
             come from its own hardware (2006: Pentium 4E 3.4 GHz + GeForce 7800 GTX; 2010: Pentium 4 3.0 GHz + \
             GeForce 9800 GT). Ratios are today / thesis unless named otherwise."
                .into(),
        )
    }
}
