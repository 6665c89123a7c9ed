//! Tables of saved reports regenerated into a Markdown page (`texgeo reproduce
//! --results-md PAGE`), so that a results page shows what a run measured rather than
//! numbers pasted by hand. Any CSV file serves: a `texgeo reproduce` report's, a
//! `texgeo bench` suite's, a comparison tool's. The page marks each generated table with
//! two comments:
//!
//! ```text
//! <!-- texgeo table: report/csv/claims.csv; columns: id, verdict -->
//! (the table, written by texgeo)
//! <!-- end of texgeo table -->
//! ```
//!
//! The file is named relative to the page; `columns:` (optional) picks and orders the
//! CSV's columns by name. Everything outside the markers is the page's own text and is
//! kept byte for byte. A file that is missing, empty, without rows or with rows of
//! another width than its header is refused, and the page is left as it was.

use std::fmt::Write as _;
use std::path::Path;

use super::{ReproduceError, Result};

/// The comment that opens a generated table.
pub const BEGIN: &str = "<!-- texgeo table: ";
/// The comment that closes it.
pub const END: &str = "<!-- end of texgeo table -->";

/// `page` (the text of the file at `path`) with every marked table written anew from the
/// CSV file its marker names; how many tables it holds.
pub fn regenerate(path: &Path, page: &str) -> Result<(String, usize)> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let bad = |line: usize, why: String| ReproduceError::Usage(format!("{}:{line}: {why}", path.display()));
    let mut out = String::with_capacity(page.len());
    let mut lines = page.split_inclusive('\n').enumerate();
    let mut tables = 0;
    while let Some((i, line)) = lines.next() {
        out.push_str(line);
        let Some(spec) = line.trim_end().strip_prefix(BEGIN).and_then(|s| s.strip_suffix("-->")) else {
            continue;
        };
        let (file, columns) = match spec.trim().split_once("; columns:") {
            Some((f, c)) => (f.trim(), c.split(',').map(str::trim).filter(|c| !c.is_empty()).collect()),
            None => (spec.trim(), Vec::new()),
        };
        let table = table(&dir.join(file), file, &columns).map_err(|why| bad(i + 1, why))?;
        // Skip the old table up to its end marker.
        let end = lines.by_ref().find(|(_, l)| l.trim_end() == END);
        let Some((_, end)) = end else { return Err(bad(i + 1, format!("no \"{END}\" after this marker"))) };
        out.push_str(&table);
        out.push_str(end);
        tables += 1;
    }
    Ok((out, tables))
}

/// Whether a CSV cell is a number (such columns are right-aligned).
fn numeric(cell: &str) -> bool {
    cell.parse::<f64>().is_ok()
}

/// The Markdown table of the CSV file at `path` (`name` as the page links it), its
/// `columns` in that order (all when empty), and the link to the file.
fn table(path: &Path, name: &str, columns: &[&str]) -> std::result::Result<String, String> {
    if !path.is_file() {
        return Err(format!("{name}: missing (no saved report there; tools/results makes every one)"));
    }
    if std::fs::metadata(path).map_err(|e| format!("{name}: {e}"))?.len() == 0 {
        return Err(format!("{name}: empty (a damaged report: no header, no rows)"));
    }
    let mut r = csv::Reader::from_path(path).map_err(|e| format!("{name}: {e}"))?;
    let header: Vec<String> =
        r.headers().map_err(|e| format!("{name}: {e}"))?.iter().map(String::from).collect();
    let picked: Vec<usize> = if columns.is_empty() {
        (0..header.len()).collect()
    } else {
        columns
            .iter()
            .map(|c| {
                header
                    .iter()
                    .position(|h| h == c)
                    .ok_or_else(|| format!("{name} has no column \"{c}\" (it has: {})", header.join(", ")))
            })
            .collect::<std::result::Result<_, _>>()?
    };
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| format!("{name}: {e}"))?;
        rows.push(picked.iter().map(|&i| rec.get(i).unwrap_or("").to_string()).collect::<Vec<_>>());
    }
    if rows.is_empty() {
        return Err(format!("{name}: a header and no rows (a damaged or cut-short report)"));
    }
    let cell =
        |s: &str| if s.is_empty() { "–".to_string() } else { s.replace('|', "/").replace('\n', " ") };
    let mut s = String::new();
    let names: Vec<String> = picked.iter().map(|&i| cell(&header[i])).collect();
    let _ = writeln!(s, "\n| {} |", names.join(" | "));
    s.push('|');
    for k in 0..picked.len() {
        let column = rows.iter().map(|r| r[k].as_str()).filter(|c| !c.is_empty());
        let right = column.clone().next().is_some() && column.clone().all(numeric);
        s.push_str(if right { "---:|" } else { "---|" });
    }
    s.push('\n');
    for row in &rows {
        let _ = writeln!(s, "| {} |", row.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
    }
    let _ = writeln!(s, "\nFrom [{name}]({name}).\n");
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn page_in(dir: &Path, csv: &str, page: &str) -> (std::path::PathBuf, String) {
        std::fs::create_dir_all(dir.join("r")).unwrap();
        std::fs::write(dir.join("r/t.csv"), csv).unwrap();
        (dir.join("page.md"), page.to_string())
    }

    #[test]
    fn marked_tables_are_rewritten_from_their_csv_and_the_rest_is_kept() {
        let dir = std::env::temp_dir().join(format!("texgeo-page-{}", std::process::id()));
        let (path, page) = page_in(
            &dir,
            "id,value (×),note\nA,2.5,x|y\nB,,\n",
            "# Page\n\nHand-written | kept |\n\n<!-- texgeo table: r/t.csv; columns: value (×), id -->\nold\n\
             stuff\n<!-- end of texgeo table -->\nafter\n",
        );
        let (new, n) = regenerate(&path, &page).unwrap();
        assert_eq!(n, 1);
        assert_eq!(
            new,
            "# Page\n\nHand-written | kept |\n\n<!-- texgeo table: r/t.csv; columns: value (×), id -->\n\n\
             | value (×) | id |\n|---:|---|\n| 2.5 | A |\n| – | B |\n\nFrom [r/t.csv](r/t.csv).\n\n\
             <!-- end of texgeo table -->\nafter\n"
        );
        // Regenerating the regenerated page changes nothing; a new number changes the page.
        assert_eq!(regenerate(&path, &new).unwrap().0, new);
        std::fs::write(dir.join("r/t.csv"), "id,value (×),note\nA,3.5,\nB,,\n").unwrap();
        assert!(regenerate(&path, &new).unwrap().0.contains("| 3.5 | A |"));
        // Every column, in the file's order, without a column list.
        let all = "<!-- texgeo table: r/t.csv -->\n<!-- end of texgeo table -->\n";
        assert!(regenerate(&path, all).unwrap().0.contains("| id | value (×) | note |\n|---|---:|---|\n"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_bad_marker_names_the_page_line() {
        let dir = std::env::temp_dir().join(format!("texgeo-page-bad-{}", std::process::id()));
        let (path, _) = page_in(&dir, "id\nA\n", "");
        let e = |page: &str| regenerate(&path, page).unwrap_err().to_string();
        let unclosed = "x\n<!-- texgeo table: r/t.csv -->\n| old |\n";
        assert!(e(unclosed).ends_with("page.md:2: no \"<!-- end of texgeo table -->\" after this marker"));
        let column = "<!-- texgeo table: r/t.csv; columns: nope -->\n<!-- end of texgeo table -->\n";
        assert!(
            e(column).contains("page.md:1: r/t.csv has no column \"nope\" (it has: id)"),
            "{}",
            e(column)
        );
        let missing = "<!-- texgeo table: r/none.csv -->\n<!-- end of texgeo table -->\n";
        assert!(
            e(missing).contains("page.md:1: r/none.csv: missing (no saved report there"),
            "{}",
            e(missing)
        );
        // A damaged file: a row wider than the header, nothing at all, a header alone.
        let marker = "<!-- texgeo table: r/t.csv -->\n<!-- end of texgeo table -->\n";
        for (csv, why) in [
            ("id\nA\nB,2\n", "found record with 2 fields, but the previous record has 1 fields"),
            ("", "r/t.csv: empty (a damaged report"),
            ("id,value\n", "r/t.csv: a header and no rows"),
        ] {
            std::fs::write(dir.join("r/t.csv"), csv).unwrap();
            assert!(e(marker).contains(why), "{csv:?}: {}", e(marker));
            assert!(e(marker).starts_with(&format!("{}:1: ", path.display())), "{}", e(marker));
            assert_eq!(e(marker).lines().count(), 1, "{}", e(marker));
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
