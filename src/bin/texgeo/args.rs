//! Value checks shared by the commands' options: numbers that must be finite and
//! positive are refused at parse time (status 2, clap's one-line message).

/// A finite number > 0.
pub fn positive_f32(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("'{s}' is not a number"))?;
    if !v.is_finite() || v <= 0.0 {
        return Err(format!("{s} must be a finite number greater than 0"));
    }
    Ok(v)
}

/// An integer ≥ 1.
pub fn positive_usize(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("'{s}' is not a whole number ≥ 1")),
    }
}

/// An integer ≥ 1.
pub fn positive_u32(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(v) => Ok(v),
        Err(_) => Err(format!("'{s}' is not a whole number ≥ 1 (up to {})", u32::MAX)),
    }
}

/// The most worker threads `--threads` (and `bench scale --thread-counts`) take: starting
/// a pool costs more than linear time in its size, and beyond a few threads per core
/// nothing is gained.
pub const MAX_THREADS: usize = 1024;

/// A thread count: 1 ..= [`MAX_THREADS`].
pub fn threads(s: &str) -> Result<usize, String> {
    match s.parse::<u128>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(v) if v > MAX_THREADS as u128 => {
            Err(format!("{s} is more than the {MAX_THREADS} threads texgeo starts"))
        }
        Ok(v) => Ok(v as usize),
        Err(_) => Err(format!("'{s}' is not a whole number of threads (1 to {MAX_THREADS})")),
    }
}

/// Seconds as a duration: a finite number in `0 < s ≤ max` (so it always converts).
pub fn seconds(s: &str, max: f64) -> Result<std::time::Duration, String> {
    let v: f64 = s.parse().map_err(|_| format!("'{s}' is not a number of seconds"))?;
    if !(v > 0.0 && v <= max) {
        return Err(format!("{s} is outside 0 < seconds ≤ {max}"));
    }
    Ok(std::time::Duration::from_secs_f64(v))
}

/// `--threads N`: the size of the global pool every parallel step runs in (default: every
/// core). Results never depend on it.
pub fn use_threads(threads: Option<usize>) -> anyhow::Result<()> {
    if let Some(n) = threads {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .map_err(|e| anyhow::anyhow!("--threads {n}: {e}"))?;
    }
    Ok(())
}
