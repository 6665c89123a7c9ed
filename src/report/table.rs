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

    pub fn to_csv(&self) -> String {
        let esc = |c: &str| {
            if c.contains([',', '"', '\n']) {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.to_string()
            }
        };
        let mut s = String::new();
        let _ = writeln!(s, "{}", self.columns.iter().map(|c| esc(c)).collect::<Vec<_>>().join(","));
        for r in &self.rows {
            let _ = writeln!(s, "{}", r.iter().map(|c| esc(c)).collect::<Vec<_>>().join(","));
        }
        s
    }
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
}
