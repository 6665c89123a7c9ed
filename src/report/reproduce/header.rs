//! The top of a report: the machine, CPU, device, driver, Vulkan version and the texgeo
//! build that produced it; also written as `run.json` for `--compare`.

use std::time::Duration;

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
