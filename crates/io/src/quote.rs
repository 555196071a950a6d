//! Values from an input quoted in a message, bounded: a field of a CSV, a line of a catalog, a
//! JSON string can be megabytes long, and an error line that echoes it whole is unreadable
//! (issue 32: lines of 200–400 kB). Every reader that quotes what it read goes through
//! [`quoted`].

use std::fmt;

/// The most characters of a value a message quotes; a longer value is cut there, with an
/// ellipsis and its full length.
pub const MAX_QUOTED_CHARS: usize = 80;

/// A value from an input, displayed quoted, of at most [`MAX_QUOTED_CHARS`] characters:
/// `"abc"` (escapes and all, as `{:?}` writes it), or `"abcd…" (204800 bytes)` when it is
/// longer; [`backticked`] writes `` `abc` `` instead, as is.
#[derive(Debug, Clone, Copy)]
pub struct Quoted<'a> {
    text: &'a str,
    backticks: bool,
}

/// `text` quoted for a message as `{:?}` quotes it, bounded (see [`Quoted`]).
pub fn quoted(text: &str) -> Quoted<'_> {
    Quoted {
        text,
        backticks: false,
    }
}

/// `text` between backticks for a message, as it is, bounded (see [`Quoted`]).
pub fn backticked(text: &str) -> Quoted<'_> {
    Quoted {
        text,
        backticks: true,
    }
}

/// A parser's message (which may quote its input: a TOML error shows the line, a JSON error
/// the unknown field), cut to a bounded length on each line.
pub fn bounded_message(message: &str) -> String {
    message
        .lines()
        .map(|line| match line.char_indices().nth(4 * MAX_QUOTED_CHARS) {
            None => line.to_string(),
            Some((cut, _)) => format!("{}… ({} bytes)", &line[..cut], line.len()),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// A parser's error shown bounded ([`bounded_message`]): serde_json's `invalid type: string
/// "…"` quotes the input whole. The error itself is kept, and so is its source.
#[derive(Debug)]
pub struct BoundedError<E>(pub E);

impl<E: fmt::Display> fmt::Display for BoundedError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&bounded_message(&self.0.to_string()))
    }
}

impl<E: std::error::Error> std::error::Error for BoundedError<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

impl fmt::Display for Quoted<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (head, cut) = match self.text.char_indices().nth(MAX_QUOTED_CHARS) {
            None => (self.text, false),
            Some((at, _)) => (&self.text[..at], true),
        };
        let ellipsis = if cut { "…" } else { "" };
        if self.backticks {
            write!(f, "`{head}{ellipsis}`")?;
        } else {
            let quoted = format!("{head:?}");
            let open = quoted.strip_suffix('"').unwrap_or(&quoted);
            write!(f, "{open}{ellipsis}\"")?;
        }
        if cut {
            write!(f, " ({} bytes)", self.text.len())?;
        }
        Ok(())
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
        assert_eq!(backticked("abc").to_string(), "`abc`");
        let shown = backticked(&long).to_string();
        assert!(shown.ends_with("…` (200000 bytes)"), "{shown}");
        let message = format!("line 4\n4 | x = \"{}\n  | ^\nexpected", "a".repeat(400_000));
        let bounded = bounded_message(&message);
        assert!(bounded.len() < 1000, "{bounded}");
        assert!(
            bounded.ends_with("(400009 bytes)\n  | ^\nexpected"),
            "{bounded}"
        );
    }
}
