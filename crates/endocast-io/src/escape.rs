//! Text a file supplies (header values, names) is escaped before it reaches a message, so that
//! a header cannot write control sequences to the user's terminal.

use std::fmt::Write;

/// `text` with every control character (newlines, escape sequences, NUL) and every invisible
/// reordering or zero-width character written as a `\u{...}` escape; printable text, accented
/// and mathematical characters included, is kept as it is.
pub fn escape(text: &str) -> String {
    if !text.chars().any(needs_escape) {
        return text.to_owned();
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if needs_escape(c) {
            // Writing to a String cannot fail.
            let _ = write!(out, "\\u{{{:x}}}", u32::from(c));
        } else {
            out.push(c);
        }
    }
    out
}

fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(
            c,
            '\u{200B}'..='\u{200F}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}' | '\u{FEFF}'
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_and_invisible_characters_are_escaped() {
        assert_eq!(escape("64 × 64 – ok…"), "64 × 64 – ok…");
        assert_eq!(escape("a\u{1b}[31mred\n\0"), "a\\u{1b}[31mred\\u{a}\\u{0}");
        assert_eq!(escape("x\u{202e}gpj.exe"), "x\\u{202e}gpj.exe");
    }
}
