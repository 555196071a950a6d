//! The `.cube` reader, in its phases: each keyword line updates what the header declares
//! ([`CubeHeader::keyword`]), each table row goes to the 1D or the 3D table
//! ([`CubeRows::push`]), and at the end the tables are checked against the header and built
//! with their domains ([`CubeHeader::build`]).

use std::path::Path;

use super::{CubeError, CubeLut, Domain, DomainTable, MAX_CUBE_1D_SIZE, MAX_CUBE_3D_SIZE};

/// One non-empty, non-comment line of the file, trimmed, with its 1-based number.
struct Line<'a> {
    number: usize,
    text: &'a str,
}

impl Line<'_> {
    /// The error of this line: `problem`, naming the file, the line and its text.
    fn error(&self, path: &Path, problem: String) -> CubeError {
        CubeError::Syntax {
            path: path.to_path_buf(),
            line: self.number,
            text: self.text.chars().take(80).collect(),
            problem,
        }
    }
}

/// What the keyword lines declared.
#[derive(Default)]
struct CubeHeader {
    title: Option<String>,
    size1: Option<usize>,
    size3: Option<usize>,
    range1: Option<(f32, f32)>,
    range3: Option<(f32, f32)>,
    domain_min: Option<[f32; 3]>,
    domain_max: Option<[f32; 3]>,
}

/// The table rows read so far: the 1D table's, then the 3D table's (red fastest).
#[derive(Default)]
struct CubeRows {
    rows1: Vec<f32>,
    rows3: Vec<f32>,
    started: bool,
}

/// Parses the text of a `.cube` file (module docs); `path` names it in errors.
pub(super) fn parse_cube(text: &str, path: &Path) -> Result<CubeLut, CubeError> {
    let mut header = CubeHeader::default();
    let mut rows = CubeRows::default();
    let mut last_line = 0;
    for (k, raw) in text.lines().enumerate() {
        last_line = k + 1;
        let line = Line {
            number: k + 1,
            text: raw.trim(),
        };
        if line.text.is_empty() || line.text.starts_with('#') {
            continue;
        }
        let first = line.text.split_whitespace().next().unwrap_or("");
        let starts_number = first
            .chars()
            .next()
            .is_some_and(|c| c.is_ascii_digit() || matches!(c, '-' | '+' | '.'));
        if starts_number {
            rows.push(&line, &header, path)?;
        } else if rows.started {
            let keyword = first.to_ascii_uppercase();
            return Err(line.error(
                path,
                format!("{keyword} after the table's first row: keywords come first"),
            ));
        } else {
            header.keyword(&line, path)?;
        }
    }
    header.build(rows, last_line, path)
}

impl CubeHeader {
    /// Reads one keyword line into the header.
    fn keyword(&mut self, line: &Line<'_>, path: &Path) -> Result<(), CubeError> {
        let mut words = line.text.split_whitespace();
        let first = words.next().unwrap_or("");
        let keyword = first.to_ascii_uppercase();
        let args: Vec<&str> = words.collect();
        let error = |problem: String| line.error(path, problem);
        let numbers = |n: usize| -> Result<Vec<f32>, CubeError> {
            let parsed: Option<Vec<f32>> = args
                .iter()
                .map(|a| a.parse::<f32>().ok().filter(|v| v.is_finite()))
                .collect();
            match parsed {
                Some(v) if v.len() == n => Ok(v),
                _ => Err(error(format!("{keyword} takes {n} finite number(s)"))),
            }
        };
        let size = |max: usize| -> Result<usize, CubeError> {
            match args.as_slice() {
                [n] => match n.parse::<usize>() {
                    Ok(n) if (2..=max).contains(&n) => Ok(n),
                    _ => Err(error(format!(
                        "{keyword} must be a whole number from 2 to {max}"
                    ))),
                },
                _ => Err(error(format!("{keyword} takes one whole number"))),
            }
        };
        let twice = || error(format!("{keyword} given twice"));
        match keyword.as_str() {
            "TITLE" => {
                if self.title.is_some() {
                    return Err(twice());
                }
                let rest = line.text[first.len()..].trim();
                self.title = Some(rest.trim_matches('"').to_string());
            }
            "LUT_1D_SIZE" => set_once(&mut self.size1, size(MAX_CUBE_1D_SIZE)?, twice)?,
            "LUT_3D_SIZE" => set_once(&mut self.size3, size(MAX_CUBE_3D_SIZE)?, twice)?,
            "LUT_1D_INPUT_RANGE" | "LUT_3D_INPUT_RANGE" => {
                let v = numbers(2)?;
                if v[1] <= v[0] {
                    return Err(error(format!(
                        "{keyword}: the maximum must exceed the minimum"
                    )));
                }
                let slot = if keyword == "LUT_1D_INPUT_RANGE" {
                    &mut self.range1
                } else {
                    &mut self.range3
                };
                set_once(slot, (v[0], v[1]), twice)?;
            }
            "DOMAIN_MIN" | "DOMAIN_MAX" => {
                let v = numbers(3)?;
                let slot = if keyword == "DOMAIN_MIN" {
                    &mut self.domain_min
                } else {
                    &mut self.domain_max
                };
                set_once(slot, [v[0], v[1], v[2]], twice)?;
            }
            "LUT_2D_SIZE" => return Err(error("2D tables are not supported".to_string())),
            _ => {
                return Err(error(format!(
                    "unknown keyword {keyword} (known: TITLE, LUT_1D_SIZE, LUT_3D_SIZE, LUT_1D_INPUT_RANGE, LUT_3D_INPUT_RANGE, DOMAIN_MIN, DOMAIN_MAX)"
                )));
            }
        }
        Ok(())
    }

    /// Entries (three values each) the 1D and the 3D table declare.
    fn wanted(&self) -> (usize, usize) {
        (
            self.size1.unwrap_or(0) * 3,
            self.size3.map_or(0, |n| n * n * n * 3),
        )
    }

    /// Checks the rows against the sizes and the domain keywords against each other, and
    /// builds the tables.
    fn build(self, rows: CubeRows, last_line: usize, path: &Path) -> Result<CubeLut, CubeError> {
        let invalid = |problem: String| CubeError::Invalid {
            path: path.to_path_buf(),
            problem,
        };
        let (want1, want3) = self.wanted();
        if self.size1.is_none() && self.size3.is_none() {
            return Err(invalid(
                "no LUT_1D_SIZE or LUT_3D_SIZE: not a .cube file".to_string(),
            ));
        }
        if rows.rows1.len() < want1 || rows.rows3.len() < want3 {
            return Err(invalid(format!(
                "ends at line {last_line} after {} rows, but the header declares {}",
                (rows.rows1.len() + rows.rows3.len()) / 3,
                declared(self.size1, self.size3)
            )));
        }
        let domain_tags = self.domain_min.is_some() || self.domain_max.is_some();
        if domain_tags && self.size1.is_some() && self.size3.is_some() {
            return Err(invalid("DOMAIN_MIN/DOMAIN_MAX with both a 1D and a 3D table: give each table's domain with LUT_1D_INPUT_RANGE and LUT_3D_INPUT_RANGE".to_string()));
        }
        if domain_tags && (self.range1.is_some() || self.range3.is_some()) {
            return Err(invalid(
                "both DOMAIN_MIN/DOMAIN_MAX and LUT_*_INPUT_RANGE: give the domain once"
                    .to_string(),
            ));
        }
        let domain_from = |range: Option<(f32, f32)>| -> Result<Domain, CubeError> {
            if domain_tags {
                let d = Domain {
                    min: self.domain_min.unwrap_or(Domain::UNIT.min),
                    max: self.domain_max.unwrap_or(Domain::UNIT.max),
                };
                if (0..3).any(|c| d.max[c] <= d.min[c]) {
                    return Err(invalid(
                        "DOMAIN_MAX must exceed DOMAIN_MIN in every channel".to_string(),
                    ));
                }
                Ok(d)
            } else {
                Ok(range.map_or(Domain::UNIT, |(lo, hi)| Domain {
                    min: [lo; 3],
                    max: [hi; 3],
                }))
            }
        };
        let shaper = match self.size1 {
            Some(_) => {
                let len = rows.rows1.len() / 3;
                Some(DomainTable::new(len, domain_from(self.range1)?, rows.rows1))
            }
            None => None,
        };
        let cube = match self.size3 {
            Some(n) => Some(DomainTable::new(n, domain_from(self.range3)?, rows.rows3)),
            None => None,
        };
        Ok(CubeLut {
            path: path.to_path_buf(),
            title: self.title,
            shaper,
            cube,
        })
    }
}

impl CubeRows {
    /// Reads one table row (three finite numbers) into the 1D table, or once it is full the
    /// 3D table.
    fn push(&mut self, line: &Line<'_>, header: &CubeHeader, path: &Path) -> Result<(), CubeError> {
        let (want1, want3) = header.wanted();
        if !self.started {
            self.started = true;
            if header.size1.is_none() && header.size3.is_none() {
                return Err(line.error(
                    path,
                    "table rows before LUT_1D_SIZE or LUT_3D_SIZE".to_string(),
                ));
            }
            // Sizes are bounded above, so these reservations are too.
            self.rows1.reserve_exact(want1);
            self.rows3.reserve_exact(want3);
        }
        let values: Option<Vec<f32>> = line
            .text
            .split_whitespace()
            .map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite()))
            .collect();
        let Some(values) = values.filter(|v| v.len() == 3) else {
            return Err(line.error(
                path,
                "a table row is three finite numbers (R G B)".to_string(),
            ));
        };
        if self.rows1.len() < want1 {
            self.rows1.extend_from_slice(&values);
        } else if self.rows3.len() < want3 {
            self.rows3.extend_from_slice(&values);
        } else {
            return Err(line.error(
                path,
                format!(
                    "more rows than the header declares ({})",
                    declared(header.size1, header.size3)
                ),
            ));
        }
        Ok(())
    }
}

/// Stores `value` in an empty `slot`; a keyword given twice is refused.
fn set_once<T>(
    slot: &mut Option<T>,
    value: T,
    twice: impl FnOnce() -> CubeError,
) -> Result<(), CubeError> {
    if slot.is_some() {
        return Err(twice());
    }
    *slot = Some(value);
    Ok(())
}

/// What the header declares, for messages.
fn declared(size1: Option<usize>, size3: Option<usize>) -> String {
    match (size1, size3) {
        (Some(a), Some(n)) => format!("{a} 1D rows then {n}³ = {} 3D rows", n * n * n),
        (Some(a), None) => format!("{a} 1D rows"),
        (None, Some(n)) => format!("{n}³ = {} 3D rows", n * n * n),
        (None, None) => "no table".to_string(),
    }
}
