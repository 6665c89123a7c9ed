//! The report as a list of blocks, written twice from the same blocks: as Markdown
//! (`report.md`, figures linked) and as one self-contained HTML page (`report.html`,
//! figures inline), so the two never disagree.
//!
//! Inline text may hold `code`, **bold** and [links](target); the HTML writer turns
//! exactly these into tags and escapes everything else.

use std::fmt::Write as _;
use std::path::Path;

use base64::Engine as _;

use super::{ReproduceError, Result, Verdict};
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
    /// What the colours of the picture above mean: (meaning, sRGB colour).
    Legend(Vec<(String, [u8; 3])>),
    /// The claims per verdict, in [`Verdict::index`] order: the report's headline.
    Verdicts([usize; 4]),
}

/// The CSS classes that colour the verdicts, in [`Verdict::index`] order.
const VERDICT_CLASSES: [&str; 4] = ["holds", "fails", "noise", "nm"];

/// (word, CSS class) of each verdict.
fn verdicts() -> impl Iterator<Item = (&'static str, &'static str)> {
    Verdict::WORDS.into_iter().zip(VERDICT_CLASSES)
}

/// The verdicts as counts read them: "3 hold", "1 does not hold" (`index` as in
/// [`Verdict::index`]).
pub fn counted(n: usize, index: usize) -> String {
    let word = match (index, n) {
        (0, 1) => "holds",
        (0, _) => "hold",
        (1, 1) => "does not hold",
        (1, _) => "do not hold",
        (i, _) => Verdict::WORDS[i.min(3)],
    };
    format!("{n} {word}")
}

/// Whether a cell holds one number (a unit sign after it allowed): such columns are
/// right-aligned.
fn numeric(cell: &str) -> bool {
    let c = cell.trim().trim_end_matches(['%', '×']).trim_end();
    !c.is_empty() && c.replace(['\u{202f}', '\u{2009}'], "").parse::<f64>().is_ok()
}

/// The columns of `table` that hold numbers only ("–" for a missing one allowed).
fn numeric_columns(table: &Table) -> Vec<bool> {
    (0..table.columns.len())
        .map(|i| {
            let cells: Vec<&str> = table.rows.iter().filter_map(|r| r.get(i)).map(|c| c.trim()).collect();
            cells.iter().any(|c| numeric(c)) && cells.iter().all(|c| numeric(c) || *c == "–" || c.is_empty())
        })
        .collect()
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
                let align: String =
                    numeric_columns(table).iter().map(|&n| if n { "---:|" } else { "---|" }).collect();
                let _ = writeln!(s, "|{align}");
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
            Block::Legend(items) => {
                let list: Vec<String> =
                    items.iter().map(|(what, [r, g, b])| format!("{what} #{r:02x}{g:02x}{b:02x}")).collect();
                let _ = writeln!(s, "Colours: {}.\n", list.join("; "));
            }
            Block::Verdicts(counts) => {
                let parts: Vec<String> =
                    counts.iter().enumerate().map(|(i, n)| format!("**{}**", counted(*n, i))).collect();
                let _ = writeln!(s, "Claims: {}.\n", parts.join(" · "));
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
td.n,th.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}\
.holds{background:#d4edda;color:#155724}.fails{background:#f8d7da;color:#721c24}\
.noise{background:#fff3cd;color:#856404}.nm{background:#e2e3e5;color:#383d41}\
.verdicts span{display:inline-block;padding:4px 10px;margin:0 6px 6px 0;border-radius:4px;font-size:110%}\
.legend span.sw{display:inline-block;width:1em;height:1em;margin:0 4px 0 10px;vertical-align:middle;\
border:1px solid #888}\
img{max-width:100%}code{background:#f2f2f2;padding:0 2px}.note{color:#555;font-size:90%}";

/// The CSS class of a cell that is a verdict word, if it is one.
fn verdict_class(cell: &str) -> Option<&'static str> {
    verdicts().find(|(word, _)| *word == cell.trim()).map(|(_, class)| class)
}

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
                let numbers = numeric_columns(table);
                let class = |i: usize| if numbers.get(i) == Some(&true) { " class=\"n\"" } else { "" };
                for (i, c) in table.columns.iter().enumerate() {
                    let _ = write!(s, "<th{}>{}</th>", class(i), inline_html(c));
                }
                s.push_str("</tr>\n");
                for row in &table.rows {
                    s.push_str("<tr>");
                    for (i, c) in row.iter().enumerate() {
                        match verdict_class(c) {
                            Some(v) => {
                                let _ = write!(s, "<td class=\"{v}\">{}</td>", inline_html(c));
                            }
                            None => {
                                let _ = write!(s, "<td{}>{}</td>", class(i), inline_html(c));
                            }
                        }
                    }
                    s.push_str("</tr>\n");
                }
                s.push_str("</table>\n");
                for n in &table.notes {
                    let _ = writeln!(s, "<p class=\"note\">{}</p>", inline_html(n));
                }
                let _ = writeln!(s, "<p class=\"note\">CSV: <a href=\"{0}\">{0}</a></p>", escape(csv));
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
            Block::Legend(items) => {
                s.push_str("<p class=\"legend\">Colours:");
                for (what, [r, g, b]) in items {
                    let _ = write!(
                        s,
                        "<span class=\"sw\" style=\"background:#{r:02x}{g:02x}{b:02x}\"></span>{}",
                        inline_html(what)
                    );
                }
                s.push_str("</p>\n");
            }
            Block::Verdicts(counts) => {
                s.push_str("<p class=\"verdicts\">Claims:");
                for (i, (n, (_, class))) in counts.iter().zip(verdicts()).enumerate() {
                    let _ = write!(s, " <span class=\"{class}\">{}</span>", counted(*n, i));
                }
                s.push_str("</p>\n");
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

    #[test]
    fn numbers_align_right_verdicts_are_coloured_and_csvs_are_links() {
        let mut t = Table::new("T", &["name", "time (s)", "verdict"]);
        t.row(vec!["a".into(), "0.01234".into(), "holds".into()]);
        t.row(vec!["b".into(), "–".into(), "does not hold".into()]);
        t.row(vec!["c".into(), "12.5 %".into(), "inconclusive (within noise)".into()]);
        assert_eq!(numeric_columns(&t), vec![false, true, false]);
        let blocks = [Block::Verdicts([3, 1, 2, 0]), Block::Table { table: t, csv: "csv/t.csv".into() }];
        let md = to_markdown(&blocks);
        assert!(md.contains("|---|---:|---|"), "{md}");
        assert!(
            md.contains("Claims: **3 hold** · **1 does not hold** · **2 inconclusive (within noise)**"),
            "{md}"
        );
        let html = to_html("t", &blocks, Path::new(".")).unwrap();
        assert!(
            html.contains("<td class=\"n\">0.01234</td>") && html.contains("<th class=\"n\">time (s)</th>")
        );
        assert!(html.contains("<td class=\"holds\">holds</td>"), "{html}");
        assert!(html.contains("<td class=\"fails\">does not hold</td>"));
        assert!(html.contains("<td class=\"noise\">inconclusive (within noise)</td>"));
        assert!(html.contains("<span class=\"holds\">3 hold</span>"), "{html}");
        assert!(html.contains("<a href=\"csv/t.csv\">csv/t.csv</a>"), "{html}");
    }

    #[test]
    fn a_legend_names_each_colour() {
        let b = [Block::Legend(vec![("operand A".into(), [214, 120, 80]), ("result".into(), [1, 2, 3])])];
        assert!(to_markdown(&b).contains("Colours: operand A #d67850; result #010203."));
        let html = to_html("t", &b, Path::new(".")).unwrap();
        assert!(html.contains("background:#d67850\"></span>operand A"), "{html}");
    }
}
