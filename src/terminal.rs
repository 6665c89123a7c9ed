//! What texgeo prints for a person at a terminal.
//!
//! - Text that comes from files (a token of a mesh, a binvox header, a comment) or from
//!   names (paths) may hold control and escape bytes a terminal would act on (move the
//!   cursor, change colours, rewrite the title). [`escape`] writes them visibly (`\x1b`,
//!   `\u{9b}`); every line texgeo prints goes through it: [`say!`](crate::say),
//!   [`note!`](crate::note) and the command's error line.
//! - Printing is a courtesy: a closed standard output or error (`texgeo … 2>&1 | head
//!   -c0`) loses the lines, never the run nor its output files.

use std::borrow::Cow;
use std::fmt::Write as _;
use std::io::Write as _;

/// Whether `c` must not reach a terminal as is: control characters other than newline
/// and tab (ESC, CR, backspace, C1 controls such as CSI) and the bidirectional overrides
/// that reorder what is shown.
fn unsafe_char(c: char) -> bool {
    (c.is_control() && c != '\n' && c != '\t')
        || matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with every character a terminal would act on written as an escape: `\x1b` for
/// ASCII controls, `\u{9b}` for the others; newlines and tabs stay.
pub fn escape(text: &str) -> Cow<'_, str> {
    if !text.chars().any(unsafe_char) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if !unsafe_char(c) {
            out.push(c);
        } else if c.is_ascii() {
            let _ = write!(out, "\\x{:02x}", c as u32);
        } else {
            let _ = write!(out, "\\u{{{:x}}}", c as u32);
        }
    }
    Cow::Owned(out)
}

/// Set while a command prints JSON ([`crate::json::text_to_stderr`]): its text lines go
/// to standard error.
pub(crate) static TEXT_TO_STDERR: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Writes one line, escaped, to standard output or standard error; a closed or full
/// stream loses it. What [`say!`](crate::say) and [`note!`](crate::note) call.
pub fn print_line(to_stderr: bool, args: std::fmt::Arguments<'_>) {
    let to_stderr = to_stderr || TEXT_TO_STDERR.load(std::sync::atomic::Ordering::Relaxed);
    let text = args.to_string();
    let text = escape(&text);
    let _ = if to_stderr {
        writeln!(std::io::stderr().lock(), "{text}")
    } else {
        writeln!(std::io::stdout().lock(), "{text}")
    };
}

/// `println!` for messages: escaped ([`escape`]), and a closed standard output loses the
/// line, not the run.
#[macro_export]
macro_rules! say {
    () => {
        $crate::terminal::print_line(false, format_args!(""))
    };
    ($($arg:tt)*) => {
        $crate::terminal::print_line(false, format_args!($($arg)*))
    };
}

/// `eprintln!` for notes, warnings and errors: escaped ([`escape`]), and a closed
/// standard error loses the line, not the run.
#[macro_export]
macro_rules! note {
    ($($arg:tt)*) => {
        $crate::terminal::print_line(true, format_args!($($arg)*))
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_and_escape_characters_are_written_visibly() {
        assert!(matches!(escape("plain 'text' é ∞\ttab\nline"), Cow::Borrowed(_)));
        assert_eq!(escape("#binvox \x1b[2J\x07x"), "#binvox \\x1b[2J\\x07x");
        assert_eq!(escape("a\rb\x7f\u{9b}31m\u{202e}"), "a\\x0db\\x7f\\u{9b}31m\\u{202e}");
    }
}
