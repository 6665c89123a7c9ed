//! The suite's results for a person (a table) and for CI systems (JUnit XML: one
//! `<testcase>` per check, `<failure>` for a failed one, `<skipped>` for one the device
//! does not support).

use std::fmt::Write;
use std::time::Duration;

use super::{Failure, Outcome, Record};

/// The results of one run on one device.
pub struct Summary<'a> {
    /// The device, as `DeviceInfo::label` prints it.
    pub device: &'a str,
    pub validation: bool,
    pub records: &'a [Record],
}

impl Summary<'_> {
    /// (passed, failed, not supported).
    pub fn counts(&self) -> (usize, usize, usize) {
        let count = |f: fn(&Outcome) -> bool| self.records.iter().filter(|r| f(&r.outcome)).count();
        (
            count(|o| matches!(o, Outcome::Pass)),
            count(|o| matches!(o, Outcome::Fail(_))),
            count(|o| matches!(o, Outcome::NotSupported(_))),
        )
    }

    fn total_time(&self) -> Duration {
        self.records.iter().map(|r| r.time).sum()
    }

    /// The table: check, result, time, and the first mismatch or the reason.
    pub fn table(&self) -> String {
        let width = self.records.iter().map(|r| r.name.len()).max().unwrap_or(5).max(5);
        let mut out = String::new();
        let _ = writeln!(out, "{:<width$}  {:<13}  {:>7}  detail", "check", "result", "time");
        for r in self.records {
            let (result, detail) = match &r.outcome {
                Outcome::Pass => ("pass", r.what.to_string()),
                Outcome::Fail(f) => {
                    ("FAIL", f.to_string().lines().map(str::trim).collect::<Vec<_>>().join(" "))
                }
                Outcome::NotSupported(why) => ("not supported", format!("needs {why}")),
            };
            let _ =
                writeln!(out, "{:<width$}  {result:<13}  {:>6.2}s  {detail}", r.name, r.time.as_secs_f64());
        }
        let (pass, fail, unsupported) = self.counts();
        let _ = write!(
            out,
            "{pass} passed, {fail} failed, {unsupported} not supported, in {:.1} s on {} (validation layer {})",
            self.total_time().as_secs_f64(),
            self.device,
            if self.validation { "on" } else { "off" }
        );
        out
    }

    /// The JUnit XML document.
    pub fn junit(&self) -> String {
        let (_, fail, unsupported) = self.counts();
        let (n, time) = (self.records.len(), self.total_time().as_secs_f64());
        let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            x,
            "<testsuites name=\"texgeo check\" tests=\"{n}\" failures=\"{fail}\" errors=\"0\" skipped=\"{unsupported}\" time=\"{time:.3}\">"
        );
        let _ = writeln!(
            x,
            "  <testsuite name=\"texgeo check\" tests=\"{n}\" failures=\"{fail}\" errors=\"0\" skipped=\"{unsupported}\" time=\"{time:.3}\">"
        );
        let _ = writeln!(x, "    <properties>");
        let _ = writeln!(x, "      <property name=\"device\" value=\"{}\"/>", escape(self.device));
        let _ = writeln!(
            x,
            "      <property name=\"validation\" value=\"{}\"/>",
            if self.validation { "on" } else { "off" }
        );
        let _ = writeln!(x, "    </properties>");
        for r in self.records {
            let group = r.name.split('-').next().unwrap_or(r.name);
            let open = format!(
                "    <testcase classname=\"texgeo.check.{}\" name=\"{}\" time=\"{:.3}\"",
                escape(group),
                escape(r.name),
                r.time.as_secs_f64()
            );
            match &r.outcome {
                Outcome::Pass => {
                    let _ = writeln!(x, "{open}/>");
                }
                Outcome::Fail(f) => {
                    let kind = match f {
                        Failure::Mismatch(_) => "mismatch",
                        Failure::Error(_) => "error",
                    };
                    let text = escape(&f.to_string());
                    let _ = writeln!(x, "{open}>");
                    let _ = writeln!(x, "      <failure type=\"{kind}\" message=\"{text}\">{text}</failure>");
                    let _ = writeln!(x, "    </testcase>");
                }
                Outcome::NotSupported(why) => {
                    let _ = writeln!(x, "{open}>");
                    let _ = writeln!(x, "      <skipped message=\"not supported: {}\"/>", escape(why));
                    let _ = writeln!(x, "    </testcase>");
                }
            }
        }
        x.push_str("  </testsuite>\n</testsuites>\n");
        x
    }
}

/// Text as XML character data or attribute value: markup characters escaped, control
/// characters XML cannot hold replaced.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\t' => out.push_str("&#9;"),
            c if (c as u32) < 0x20 => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check::Mismatch;

    #[test]
    fn junit_escapes_and_marks_each_outcome() {
        let records = [
            Record { name: "a-one", what: "x", outcome: Outcome::Pass, time: Duration::from_millis(5) },
            Record {
                name: "a-two",
                what: "x",
                outcome: Outcome::Fail(Failure::Mismatch(Mismatch {
                    item: "texel (1, 2) <\"&\">".into(),
                    expected: "1".into(),
                    got: "0".into(),
                })),
                time: Duration::ZERO,
            },
            Record {
                name: "b-three",
                what: "x",
                outcome: Outcome::NotSupported("logicOp".into()),
                time: Duration::ZERO,
            },
        ];
        let s = Summary { device: "dev <1>", validation: true, records: &records };
        let x = s.junit();
        assert_eq!(x.matches("<testcase ").count(), 3, "{x}");
        assert!(x.contains("texel (1, 2) &lt;&quot;&amp;&quot;&gt;: expected 1, got 0"), "{x}");
        assert!(x.contains("<skipped message=\"not supported: logicOp\"/>"), "{x}");
        assert!(x.contains("failures=\"1\"") && x.contains("skipped=\"1\""), "{x}");
        assert!(x.contains("value=\"dev &lt;1&gt;\""), "{x}");
        let t = s.table();
        assert!(t.contains("1 passed, 1 failed, 1 not supported"), "{t}");
    }
}
