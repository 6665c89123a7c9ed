//! The report as a list of blocks, written twice from the same blocks: as Markdown
//! (`report.md`, figures linked) and as one self-contained HTML page (`report.html`,
//! figures inline), so the two never disagree.
//!
//! Inline text may hold `code`, **bold** and [links](target); the HTML writer turns
//! exactly these into tags and escapes everything else.

use std::fmt::Write as _;
use std::path::Path;

use base64::Engine as _;

use super::{ReproduceError, Result};
use crate::report::Table;

#[derive(Clone, Debug)]
pub enum Block {
    /// A heading of level 1–4 and its anchor.
    Heading(u8, String),
    Para(String),
    List(Vec<String>),
    /// A table and the CSV file (relative to the report) that holds the same cells.
    Table {
        table: Table,
        csv: String,
    },
    /// A PNG (or SVG) picture relative to the report, `width`×`height` pixels.
    Image {
        path: String,
        caption: String,
        width: u32,
        height: u32,
    },
    /// A plot: SVG and PNG of the same chart.
    Plot {
        svg: String,
        png: String,
        caption: String,
    },
}

/// The anchor of a heading: lower case, alphanumerics and dashes (GitHub's rule, close
/// enough for the headings texgeo writes).
pub fn anchor(text: &str) -> String {
    let mut s = String::new();
    for c in text.chars() {
        if c.is_alphanumeric() {
            s.extend(c.to_lowercase());
        } else if (c == ' ' || c == '-') && !s.ends_with('-') {
            s.push('-');
        }
    }
    s.trim_matches('-').to_string()
}

/// A table cell as Markdown can hold it (no pipes, no line breaks).
fn cell(s: &str) -> String {
    s.replace('|', "/").replace('\n', " ")
}

pub fn to_markdown(blocks: &[Block]) -> String {
    let mut s = String::new();
    for b in blocks {
        match b {
            Block::Heading(level, text) => {
                let _ = writeln!(s, "{} {text}\n", "#".repeat(usize::from((*level).clamp(1, 6))));
            }
            Block::Para(text) => {
                let _ = writeln!(s, "{text}\n");
            }
            Block::List(items) => {
                for i in items {
                    let _ = writeln!(s, "- {i}");
                }
                s.push('\n');
            }
            Block::Table { table, csv } => {
                let _ = writeln!(s, "**{}**\n", table.title);
                let _ = writeln!(
                    s,
                    "| {} |",
                    table.columns.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | ")
                );
                let _ = writeln!(s, "|{}", "---|".repeat(table.columns.len()));
                for row in &table.rows {
                    let _ =
                        writeln!(s, "| {} |", row.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
                }
                s.push('\n');
                for n in &table.notes {
                    let _ = writeln!(s, "{n}\n");
                }
                let _ = writeln!(s, "CSV: [{csv}]({csv})\n");
            }
            Block::Image { path, caption, width, height } => {
                let _ = writeln!(s, "![{caption}]({path})\n\n*{caption}* ({width}×{height}, `{path}`)\n");
            }
            Block::Plot { svg, png, caption } => {
                let _ = writeln!(s, "![{caption}]({svg})\n\n*{caption}* ([SVG]({svg}), [PNG]({png}))\n");
            }
        }
    }
    s
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Inline Markdown (`code`, **bold**, [text](link)) to HTML, everything else escaped.
pub fn inline_html(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while !rest.is_empty() {
        if let Some(after) = rest.strip_prefix('`')
            && let Some(end) = after.find('`')
        {
            let _ = write!(out, "<code>{}</code>", escape(&after[..end]));
            rest = &after[end + 1..];
        } else if let Some(after) = rest.strip_prefix("**")
            && let Some(end) = after.find("**")
        {
            let _ = write!(out, "<strong>{}</strong>", inline_html(&after[..end]));
            rest = &after[end + 2..];
        } else if let Some(after) = rest.strip_prefix('[')
            && let Some(mid) = after.find("](")
            && let Some(end) = after[mid + 2..].find(')')
        {
            let (label, target) = (&after[..mid], &after[mid + 2..mid + 2 + end]);
            let _ = write!(out, "<a href=\"{}\">{}</a>", escape(target), inline_html(label));
            rest = &after[mid + 3 + end..];
        } else {
            let c = rest.chars().next().unwrap_or(' ');
            out.push_str(&escape(&c.to_string()));
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

fn data_uri(root: &Path, relative: &str) -> Result<String> {
    let path = root.join(relative);
    let bytes = std::fs::read(&path).map_err(|source| ReproduceError::Io { path: path.clone(), source })?;
    let mime = if relative.ends_with(".svg") { "image/svg+xml" } else { "image/png" };
    Ok(format!("data:{mime};base64,{}", base64::engine::general_purpose::STANDARD.encode(bytes)))
}

const STYLE: &str = "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}\
table{border-collapse:collapse;margin:.5em 0 1em;font-size:90%}td,th{border:1px solid #bbb;padding:2px 6px;\
text-align:left}th{background:#eee}tr:nth-child(even){background:#f8f8f8}figure{margin:1em 0}\
img{max-width:100%}code{background:#f2f2f2;padding:0 2px}.note{color:#555;font-size:90%}";

/// One HTML page; pictures and plots (read from under `root`) are embedded as data URIs.
pub fn to_html(title: &str, blocks: &[Block], root: &Path) -> Result<String> {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style>\
         </head><body>\n",
        escape(title)
    );
    let mut list_open = false;
    for b in blocks {
        if list_open && !matches!(b, Block::List(_)) {
            list_open = false;
        }
        match b {
            Block::Heading(level, text) => {
                let l = (*level).clamp(1, 6);
                let _ = writeln!(s, "<h{l} id=\"{}\">{}</h{l}>", anchor(text), inline_html(text));
            }
            Block::Para(text) => {
                let _ = writeln!(s, "<p>{}</p>", inline_html(text));
            }
            Block::List(items) => {
                s.push_str("<ul>");
                for i in items {
                    let _ = write!(s, "<li>{}</li>", inline_html(i));
                }
                s.push_str("</ul>\n");
            }
            Block::Table { table, csv } => {
                let _ = write!(s, "<p><strong>{}</strong></p>\n<table><tr>", inline_html(&table.title));
                for c in &table.columns {
                    let _ = write!(s, "<th>{}</th>", inline_html(c));
                }
                s.push_str("</tr>\n");
                for row in &table.rows {
                    s.push_str("<tr>");
                    for c in row {
                        let _ = write!(s, "<td>{}</td>", inline_html(c));
                    }
                    s.push_str("</tr>\n");
                }
                s.push_str("</table>\n");
                for n in &table.notes {
                    let _ = writeln!(s, "<p class=\"note\">{}</p>", inline_html(n));
                }
                let _ = writeln!(s, "<p class=\"note\">CSV: <code>{}</code></p>", escape(csv));
            }
            Block::Image { path, caption, width, height } => {
                let _ = writeln!(
                    s,
                    "<figure><img src=\"{}\" width=\"{width}\" height=\"{height}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                    data_uri(root, path)?,
                    escape(caption),
                    inline_html(caption)
                );
            }
            Block::Plot { svg, caption, .. } => {
                let _ = writeln!(
                    s,
                    "<figure><img src=\"{}\" alt=\"{}\"><figcaption>{}</figcaption></figure>",
                    data_uri(root, svg)?,
                    escape(caption),
                    inline_html(caption)
                );
            }
        }
    }
    s.push_str("</body></html>\n");
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inline_markup_becomes_tags_and_the_rest_is_escaped() {
        assert_eq!(
            inline_html("a `x<y` **b** [c](d.csv) & e"),
            "a <code>x&lt;y</code> <strong>b</strong> <a href=\"d.csv\">c</a> &amp; e"
        );
        assert_eq!(inline_html("unclosed `tick and **star"), "unclosed `tick and **star");
    }

    #[test]
    fn anchors_follow_the_heading_text() {
        assert_eq!(anchor("1. Point in solid — Tables 4-4 … 4-9"), "1-point-in-solid-tables-4-4-4-9");
    }

    #[test]
    fn tables_carry_their_csv_link_and_no_stray_pipes() {
        let mut t = Table::new("T", &["a", "b"]);
        t.row(vec!["1|2".into(), "3".into()]);
        let md = to_markdown(&[Block::Table { table: t, csv: "csv/t.csv".into() }]);
        assert!(md.contains("| 1/2 | 3 |"), "{md}");
        assert!(md.contains("CSV: [csv/t.csv](csv/t.csv)"));
    }
}
