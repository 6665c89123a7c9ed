//! Result tables: Markdown for people, CSV for plotting.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::Environment;

/// `v` with `digits` significant digits, in plain notation (no exponent; integers
/// keep all their digits): 0.01234, 1.234, 1234, 123456.
pub fn sig(v: f64, digits: usize) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let decimals = (digits as i32 - 1 - v.abs().log10().floor() as i32).clamp(0, 12) as usize;
    format!("{v:.decimals$}")
}

#[derive(Clone, Debug, Default)]
pub struct Table {
    pub title: String,
    pub columns: Vec<String>,
    pub rows: Vec<Vec<String>>,
    /// Lines printed under the table (what was measured, how, caveats).
    pub notes: Vec<String>,
    /// File stem of the table's CSV (`REPORT-STEM.csv`); empty = numbered.
    pub stem: String,
    /// The unit of each column's numbers where the title rather than the column's name
    /// says it (empty: none); the CSV's header names it.
    pub units: Vec<String>,
}

impl Table {
    pub fn new(title: impl Into<String>, columns: &[&str]) -> Table {
        Table {
            title: title.into(),
            columns: columns.iter().map(|c| c.to_string()).collect(),
            ..Default::default()
        }
    }

    /// Names the table's CSV file.
    pub fn named(mut self, stem: &str) -> Table {
        self.stem = stem.to_string();
        self
    }

    /// Names `unit` as the unit of `columns` (the CSV header says it: "phase 1 (ms)").
    pub fn unit(mut self, unit: &str, columns: impl IntoIterator<Item = usize>) -> Table {
        self.units.resize(self.columns.len(), String::new());
        for c in columns {
            if let Some(u) = self.units.get_mut(c) {
                *u = unit.to_string();
            }
        }
        self
    }

    pub fn row(&mut self, cells: Vec<String>) {
        self.rows.push(cells);
    }

    pub fn note(&mut self, note: impl Into<String>) {
        self.notes.push(note.into());
    }

    pub fn to_markdown(&self) -> String {
        let mut s = format!("### {}\n\n| {} |\n|", self.title, self.columns.join(" | "));
        for _ in &self.columns {
            s.push_str("---|");
        }
        s.push('\n');
        for r in &self.rows {
            let _ = writeln!(s, "| {} |", r.join(" | "));
        }
        for n in &self.notes {
            let _ = write!(s, "\n{n}\n");
        }
        s
    }

    /// The table as CSV for a program to read: numbers only, units in the header. A
    /// ratio "2.31×" or share "12.5 %" is written 2.31 or 12.5 with "(×)" or "(%)" in its
    /// column's name, a missing value ("–") is an empty cell, ∞ is `inf`, and Markdown
    /// markup (`code`, [links](…)) is dropped.
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let cells: Vec<Vec<(String, Option<&str>)>> =
            self.rows.iter().map(|r| r.iter().map(|c| csv_cell(c)).collect()).collect();
        let header: Vec<String> = self
            .columns
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let name = plain(name);
                let suffix = cells.iter().find_map(|r| r.get(i).and_then(|c| c.1));
                let unit = self.units.get(i).filter(|u| !u.is_empty()).map(String::as_str).or(suffix);
                match unit {
                    Some(u) if !name.contains(u) => format!("{name} ({u})"),
                    _ => name,
                }
            })
            .collect();
        let _ = w.write_record(&header);
        for r in cells {
            let _ = w.write_record(r.iter().map(|c| c.0.as_str()));
        }
        String::from_utf8(w.into_inner().unwrap_or_default()).unwrap_or_default()
    }
}

/// Text without Markdown's inline markup: `code` → code, [label](target) → label.
fn plain(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(c) = rest.chars().next() {
        if let Some(after) = rest.strip_prefix('[')
            && let Some(mid) = after.find("](")
            && let Some(end) = after[mid + 2..].find(')')
        {
            out.push_str(&after[..mid]);
            rest = &after[mid + 3 + end..];
        } else {
            if c != '`' {
                out.push(c);
            }
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// A Markdown cell as a CSV cell, and the unit sign taken off it (× or %) when it was a
/// number followed by one.
fn csv_cell(cell: &str) -> (String, Option<&'static str>) {
    let c = cell.trim();
    if c == "–" || c == "-" {
        return (String::new(), None);
    }
    if c == "∞" {
        return ("inf".into(), None);
    }
    let number = |s: &str| {
        let s: String = s.trim().chars().filter(|c| !matches!(c, '\u{202f}' | '\u{2009}')).collect();
        s.parse::<f64>().is_ok().then_some(s)
    };
    for unit in ["×", "%"] {
        if let Some(n) = c.strip_suffix(unit).and_then(number) {
            return (n, Some(unit));
        }
    }
    if let Some(n) = number(c) {
        return (n, None);
    }
    (plain(c), None)
}

/// A set of tables from one run, with the environment that produced them.
pub struct Report {
    pub name: String,
    pub environment: Environment,
    pub tables: Vec<Table>,
}

impl Report {
    pub fn to_markdown(&self) -> String {
        let mut s = format!("# texgeo bench {}\n\n{}\n\n", self.name, self.environment.describe());
        for t in &self.tables {
            s.push_str(&t.to_markdown());
            s.push('\n');
        }
        s
    }

    /// Writes `NAME.md` and one `NAME-<k>.csv` per table (or `NAME.csv` for one table)
    /// into `dir`; returns the files written.
    /// Every file is written atomically ([`crate::output`]).
    pub fn write(&self, dir: &Path) -> crate::output::Result<Vec<PathBuf>> {
        crate::output::check_dir(dir)?;
        let mut written = Vec::new();
        let md = dir.join(format!("{}.md", self.name));
        crate::output::write_bytes(&md, self.to_markdown().as_bytes())?;
        written.push(md);
        for (k, t) in self.tables.iter().enumerate() {
            let name = if !t.stem.is_empty() {
                format!("{}-{}.csv", self.name, t.stem)
            } else if self.tables.len() == 1 {
                format!("{}.csv", self.name)
            } else {
                let slug: String = t
                    .title
                    .chars()
                    .map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' })
                    .collect();
                let slug = slug.split('-').filter(|p| !p.is_empty()).take(4).collect::<Vec<_>>().join("-");
                format!("{}-{}-{slug}.csv", self.name, k + 1)
            };
            let path = dir.join(name);
            crate::output::write_bytes(&path, t.to_csv().as_bytes())?;
            written.push(path);
        }
        Ok(written)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn significant_digits_are_the_same_at_every_magnitude() {
        assert_eq!(super::sig(0.000123456, 4), "0.0001235");
        assert_eq!(super::sig(1.23456, 4), "1.235");
        assert_eq!(super::sig(1234.56, 4), "1235");
        assert_eq!(super::sig(123456.0, 4), "123456");
        assert_eq!(super::sig(-2.5, 2), "-2.5");
        assert_eq!(super::sig(0.0, 3), "0");
    }

    #[test]
    fn csv_cells_are_numbers_with_their_units_in_the_header() {
        let mut t = super::Table::new("T (ms)", &["[model](#m)", "speed-up", "saved", "time", "note"])
            .unit("ms", [3]);
        t.row(vec!["`a`".into(), "2.31×".into(), "99.4 %".into(), "1\u{202f}234.5".into(), "x, y".into()]);
        t.row(vec!["b".into(), "–".into(), "∞".into(), "0.5".into(), "–".into()]);
        assert_eq!(
            t.to_csv(),
            "model,speed-up (×),saved (%),time (ms),note\na,2.31,99.4,1234.5,\"x, y\"\nb,,inf,0.5,\n"
        );
        // A unit the column's name already says is not said twice.
        let mut t = super::Table::new("T", &["today / thesis (×)", "spread (± %)"]);
        t.row(vec!["0.5×".into(), "12 %".into()]);
        assert_eq!(t.to_csv(), "today / thesis (×),spread (± %)\n0.5,12\n");
    }
}
