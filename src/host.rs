//! The machine texgeo runs on: what reports name and what large requests are checked
//! against, so a too-large job fails with a clear error instead of an allocation failure.

/// Memory the system reports as available (`MemAvailable`), in bytes; `None` if unknown.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `Err((need, have MiB))` when `bytes` exceed the available memory. Estimates are
/// computed with saturating arithmetic: `u64::MAX` bytes means "at least that much" and
/// prints as such ([`Mib`]).
pub fn check_available(bytes: u64) -> Result<(), (Mib, u64)> {
    match available_memory() {
        Some(have) if bytes > have => Err((Mib::of(bytes), have / (1 << 20))),
        _ => Ok(()),
    }
}

/// The estimate-and-refuse check run before anything large is allocated: `Err` saying
/// "WHAT need N MiB, but only M MiB are available" when `bytes` (a saturating
/// estimate) exceed the available memory.
pub fn check_memory(what: impl std::fmt::Display, bytes: u128) -> Result<(), String> {
    check_available(Mib::saturate(bytes))
        .map_err(|(need, have)| format!("{what} need {need} MiB, but only {have} MiB are available"))
}

/// A memory estimate for messages, in MiB (rounded up). An estimate that reached the
/// largest byte count (`u64::MAX`, where saturating arithmetic stops) prints as "more
/// than …" instead of a number that wrapped around.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Mib {
    mib: u64,
    saturated: bool,
}

impl Mib {
    /// `bytes` in MiB; `u64::MAX` means "at least".
    pub fn of(bytes: u64) -> Mib {
        Mib { mib: bytes.div_ceil(1 << 20), saturated: bytes == u64::MAX }
    }

    /// A wide estimate, saturated at `u64::MAX` bytes.
    pub fn of_wide(bytes: u128) -> Mib {
        Mib::of(Mib::saturate(bytes))
    }

    /// A wide byte count as a `u64`, `u64::MAX` when larger.
    pub fn saturate(bytes: u128) -> u64 {
        u64::try_from(bytes).unwrap_or(u64::MAX)
    }
}

impl std::fmt::Display for Mib {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.saturated { write!(f, "more than {}", self.mib - 1) } else { write!(f, "{}", self.mib) }
    }
}

/// `n` for a message, or "more than LIMIT" when an estimate reached `limit`, where
/// saturating arithmetic stopped counting.
pub fn count_text(n: u128, limit: u128) -> String {
    if n >= limit { format!("more than {}", limit - 1) } else { n.to_string() }
}

/// The CPU's model name, for reports.
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".to_string())
}

/// Resets this process' peak resident set (VmHWM) to its current size, so the next
/// [`peak_rss_kib`] measures what comes after; false where the kernel does not allow it.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// This process' peak resident set (VmHWM), KiB.
pub fn peak_rss_kib() -> Option<u64> {
    status_kib("VmHWM:")
}

/// This process' current resident set (VmRSS), KiB.
pub fn rss_kib() -> Option<u64> {
    status_kib("VmRSS:")
}

fn status_kib(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// The machine's name (`/proc/sys/kernel/hostname`).
pub fn hostname() -> String {
    read_trimmed("/proc/sys/kernel/hostname").unwrap_or_else(|| "unknown host".to_string())
}

/// The operating system and kernel: "Debian GNU/Linux 12 (bookworm), Linux 6.1.0".
pub fn os() -> String {
    let name = std::fs::read_to_string("/etc/os-release").ok().and_then(|s| {
        s.lines().find_map(|l| l.strip_prefix("PRETTY_NAME=")).map(|v| v.trim_matches('"').to_string())
    });
    let kernel = read_trimmed("/proc/sys/kernel/osrelease").map(|k| format!("Linux {k}"));
    match (name, kernel) {
        (Some(n), Some(k)) => format!("{n}, {k}"),
        (n, k) => n.or(k).unwrap_or_else(|| std::env::consts::OS.to_string()),
    }
}

/// Total memory (`MemTotal`), in bytes.
pub fn total_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

fn read_trimmed(path: &str) -> Option<String> {
    std::fs::read_to_string(path).ok().map(|s| s.trim().to_string()).filter(|s| !s.is_empty())
}

/// The load average over 1, 5 and 15 minutes (`/proc/loadavg`).
pub fn load_average() -> Option<[f64; 3]> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = s.split_whitespace().map(|v| v.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

/// CPU time counters, in clock ticks: the whole machine's (all cores, `/proc/stat`) and
/// this process' with its waited-for children (`/proc/self/stat`).
#[derive(Clone, Copy, Debug)]
pub struct CpuTicks {
    /// Every core's ticks, idle included.
    pub total: u64,
    /// Every core's ticks spent running something.
    pub busy: u64,
    /// This process' user + system ticks, its finished children's included.
    pub own: u64,
}

impl CpuTicks {
    pub fn now() -> Option<CpuTicks> {
        let stat = std::fs::read_to_string("/proc/stat").ok()?;
        let cpu: Vec<u64> =
            stat.lines().next()?.split_whitespace().skip(1).filter_map(|v| v.parse().ok()).collect();
        // user nice system idle iowait irq softirq steal (guest time is inside user).
        let total: u64 = cpu.iter().take(8).sum();
        let idle = cpu.get(3)? + cpu.get(4).copied().unwrap_or(0);
        let own_stat = std::fs::read_to_string("/proc/self/stat").ok()?;
        // Fields after the command name (which may hold spaces) start at the state (3).
        let rest = own_stat.rsplit_once(')')?.1;
        let f: Vec<u64> = rest.split_whitespace().map(|v| v.parse().unwrap_or(0)).collect();
        // utime, stime, cutime, cstime are fields 14–17: 11–14 after the state.
        let own = f.get(11)? + f.get(12)? + f.get(13)? + f.get(14)?;
        Some(CpuTicks { total, busy: total - idle.min(total), own })
    }
}
