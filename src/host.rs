//! The machine texgeo runs on: what reports name and what large requests are checked
//! against, so a too-large job fails with a clear error instead of an allocation failure.

/// Memory the system reports as available (`MemAvailable`), in bytes; `None` if unknown.
pub fn available_memory() -> Option<u64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `Err((need MiB, have MiB))` when `bytes` exceed the available memory.
pub fn check_available(bytes: u64) -> Result<(), (u64, u64)> {
    match available_memory() {
        Some(have) if bytes > have => Err((bytes.div_ceil(1 << 20), have / (1 << 20))),
        _ => Ok(()),
    }
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
