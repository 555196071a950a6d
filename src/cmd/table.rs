//! Fixed-width text tables of the commands' readable reports (`glassdb fit`, `stack`,
//! `spectral`, `registry show`): each column's gap, width and alignment are written once and
//! serve its title and every row, so a title cannot drift from the values under it.

use std::fmt::Write as _;

/// Which side of its width a column's text keeps to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Align {
    /// Text at the left, spaces after it.
    Left,
    /// Text at the right, spaces before it.
    Right,
}

/// One column: the text before it (the indent of the first column, the gap to the previous
/// one), its width in characters and its alignment. Text longer than the width is kept whole.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Column {
    /// Written before the column.
    pub gap: &'static str,
    /// The least number of characters the column takes.
    pub width: usize,
    /// Where its text stands within that width.
    pub align: Align,
}

impl Column {
    /// A column of `width` characters after `gap`, its text at the left.
    pub const fn left(gap: &'static str, width: usize) -> Column {
        Column {
            gap,
            width,
            align: Align::Left,
        }
    }

    /// A column of `width` characters after `gap`, its text at the right.
    pub const fn right(gap: &'static str, width: usize) -> Column {
        Column {
            gap,
            width,
            align: Align::Right,
        }
    }
}

/// The layout of a table of `N` columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TextTable<const N: usize> {
    /// The columns, left to right.
    pub columns: [Column; N],
}

impl<const N: usize> TextTable<N> {
    /// One line of the table (without its newline): the titles, or a row's values formatted
    /// as text.
    pub fn line<S: AsRef<str>>(&self, cells: [S; N]) -> String {
        let mut line = String::new();
        for (column, cell) in self.columns.iter().zip(&cells) {
            let (text, width) = (cell.as_ref(), column.width);
            let _ = match column.align {
                Align::Left => write!(line, "{}{text:<width$}", column.gap),
                Align::Right => write!(line, "{}{text:>width$}", column.gap),
            };
        }
        line
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Titles and values line up at the right or the left of each column's width, after its
    /// gap; a value wider than its column is written whole, moving what follows it.
    #[test]
    fn cells_are_padded_to_their_column_after_its_gap() {
        let table = TextTable {
            columns: [
                Column::left("  ", 6),
                Column::right(" ", 5),
                Column::right("   ", 3),
            ],
        };
        assert_eq!(table.line(["curve", "deg", "n"]), "  curve    deg     n");
        assert_eq!(table.line(["r", "12", "1234"]), "  r         12   1234");
        assert_eq!(
            table.line(["θ (°)".to_string(), format!("{:.2}", 0.5), "–".to_string()]),
            "  θ (°)   0.50     –"
        );
    }
}
