//! Values from an input quoted in a message, bounded: a field of a CSV, a line of a catalog, a
//! JSON string can be megabytes long, and an error line that echoes it whole is unreadable
//! (issue 32: lines of 200–400 kB). Every reader that quotes what it read goes through
//! [`quoted`].

use std::fmt;

/// The most characters of a value a message quotes; a longer value is cut there, with an
/// ellipsis and its full length.
pub const MAX_QUOTED_CHARS: usize = 80;

/// A value from an input, displayed as a quoted string (as `{:?}` writes it, escapes and all)
/// of at most [`MAX_QUOTED_CHARS`] characters: `"abc"`, or `"abcd…" (204800 bytes)` when
/// it is longer.
#[derive(Debug, Clone, Copy)]
pub struct Quoted<'a>(&'a str);

/// `text` quoted for a message, bounded (see [`Quoted`]).
pub fn quoted(text: &str) -> Quoted<'_> {
    Quoted(text)
}

impl fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.char_indices().nth(MAX_QUOTED_CHARS) {
            None => write!(f, "{:?}", self.0),
            Some((cut, _)) => {
                let head = format!("{:?}", &self.0[..cut]);
                let open = head.strip_suffix('"').unwrap_or(&head);
                write!(f, "{open}…\" ({} bytes)", self.0.len())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_values_are_quoted_as_debug_does() {
        for text in ["", "abc", "a \"b\"\n", "é, ü"] {
            assert_eq!(quoted(text).to_string(), format!("{text:?}"));
        }
        let exact = "x".repeat(MAX_QUOTED_CHARS);
        assert_eq!(quoted(&exact).to_string(), format!("{exact:?}"));
    }

    #[test]
    fn long_values_are_cut_with_an_ellipsis_and_their_length() {
        let long = "é".repeat(100_000);
        let shown = quoted(&long).to_string();
        assert_eq!(
            shown,
            format!("\"{}…\" (200000 bytes)", "é".repeat(MAX_QUOTED_CHARS))
        );
        let escaped = "\n".repeat(1000);
        let shown = quoted(&escaped).to_string();
        assert!(shown.starts_with("\"\\n\\n"), "{shown}");
        assert!(shown.ends_with("…\" (1000 bytes)"), "{shown}");
        assert!(shown.len() < 2 * MAX_QUOTED_CHARS + 20, "{shown}");
    }
}
