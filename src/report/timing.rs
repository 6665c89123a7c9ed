//! Repeated timing with medians: single runs on a shared 2-core machine are noisy.

use std::time::{Duration, Instant};

/// Durations of repeated runs of one measurement.
#[derive(Clone, Debug, Default)]
pub struct Samples(pub Vec<Duration>);

impl Samples {
    pub fn push(&mut self, d: Duration) {
        self.0.push(d);
    }

    pub fn median(&self) -> Duration {
        let mut v = self.0.clone();
        v.sort();
        match v.len() {
            0 => Duration::ZERO,
            n if n % 2 == 1 => v[n / 2],
            n => (v[n / 2 - 1] + v[n / 2]) / 2,
        }
    }

    pub fn min(&self) -> Duration {
        self.0.iter().copied().min().unwrap_or_default()
    }

    pub fn max(&self) -> Duration {
        self.0.iter().copied().max().unwrap_or_default()
    }

    pub fn mean(&self) -> Duration {
        match self.0.len() {
            0 => Duration::ZERO,
            n => self.0.iter().sum::<Duration>() / n as u32,
        }
    }

    /// Half the range of the runs as a share of `centre` (their mean or median), in per
    /// cent: the spread shown beside a value ("–" in a table for fewer than two runs).
    pub fn spread_percent(&self, centre: Duration) -> Option<f64> {
        (self.0.len() >= 2 && !centre.is_zero())
            .then(|| 50.0 * (self.max() - self.min()).as_secs_f64() / centre.as_secs_f64())
    }

    /// [`Samples::spread_percent`] about the median, as a table cell.
    pub fn spread_cell(&self) -> String {
        self.spread_percent(self.median()).map_or_else(|| "–".to_string(), |p| super::sig(p, 2))
    }

    /// Run by run sums of the same runs of several parts (the runs of a whole made of
    /// them, so its median and spread can be taken).
    pub fn sum(parts: &[&Samples]) -> Samples {
        let n = parts.iter().map(|s| s.0.len()).min().unwrap_or(0);
        Samples((0..n).map(|i| parts.iter().map(|s| s.0[i]).sum::<Duration>()).collect())
    }

    pub fn median_ms(&self) -> f64 {
        self.median().as_secs_f64() * 1e3
    }
}

/// Runs `f` `runs` times (after one warm-up run) and returns the durations it reports.
/// `f` measures itself, so set-up outside its timed section is not counted.
pub fn time_runs<E>(runs: usize, mut f: impl FnMut() -> Result<Duration, E>) -> Result<Samples, E> {
    f()?;
    let mut s = Samples::default();
    for _ in 0..runs.max(1) {
        s.push(f()?);
    }
    Ok(s)
}

/// One side of an interleaved comparison: runs once and says how long its timed part took.
pub type Side<'a, E> = dyn FnMut() -> Result<Duration, E> + 'a;

/// Runs every side once untimed (warm-up), then `runs` rounds of A, B, … in turn, and
/// returns each side's durations. Load that comes and goes hits every side of a
/// comparison alike, and sample k of every side comes from round k, so the ratio of two
/// sides can be taken round by round.
pub fn interleave<E>(runs: usize, sides: &mut [&mut Side<'_, E>]) -> Result<Vec<Samples>, E> {
    for side in sides.iter_mut() {
        side()?;
    }
    let mut out = vec![Samples::default(); sides.len()];
    for _ in 0..runs.max(1) {
        for (side, samples) in sides.iter_mut().zip(&mut out) {
            samples.push(side()?);
        }
    }
    Ok(out)
}

/// Times a closure.
pub fn timed<T>(f: impl FnOnce() -> T) -> (T, Duration) {
    let t = Instant::now();
    let v = f();
    (v, t.elapsed())
}
