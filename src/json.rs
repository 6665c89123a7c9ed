//! The commands' `--json` output: one JSON object on standard output, numbers as numbers,
//! durations in milliseconds. The shapes are the stats structs' own (`Serialize`); while
//! a command prints JSON its text lines go to standard error ([`crate::terminal`]).

use std::io::Write as _;
use std::time::Duration;

use serde::Serialize;

/// A duration as milliseconds (a float), for `#[serde(serialize_with = "…")]`.
pub fn ms<S: serde::Serializer>(d: &Duration, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(d.as_secs_f64() * 1e3)
}

/// Durations as milliseconds.
pub fn ms_list<S: serde::Serializer>(ds: &[Duration], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(ds.iter().map(|d| d.as_secs_f64() * 1e3))
}

/// Prints `value` as one line of JSON on standard output (a closed stdout loses it, as
/// it does text lines). Non-finite numbers become `null`.
pub fn print(value: &impl Serialize) {
    if let Ok(text) = serde_json::to_string(value) {
        let _ = writeln!(std::io::stdout().lock(), "{text}");
    }
}

/// From now on, text lines ([`say!`](crate::say)) go to standard error, so that standard
/// output holds only the JSON object.
pub fn text_to_stderr() {
    crate::terminal::TEXT_TO_STDERR.store(true, std::sync::atomic::Ordering::Relaxed);
}
