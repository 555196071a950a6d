//! The CIE reference tables, embedded in the binary (`data/cie/`, exported bit-exactly from
//! colour-science 0.4.7; provenance and licences in `data/cie/README.md`).

use std::sync::{Arc, OnceLock};

use crate::error::SpectralError;

const CIE_1931: &str = include_str!("../../../data/cie/cie_1931_2deg_xyz_cmfs.csv");
const CIE_1964: &str = include_str!("../../../data/cie/cie_1964_10deg_xyz_cmfs.csv");
const D65: &str = include_str!("../../../data/cie/illuminant_d65.csv");
const ILL_A: &str = include_str!("../../../data/cie/illuminant_a.csv");
const WG_1931: &str = include_str!("../../../data/cie/wright_guild_1931_2deg_rgb_cmfs.csv");
const SB_1955: &str = include_str!("../../../data/cie/stiles_burch_1955_2deg_rgb_cmfs.csv");
const SB_1959: &str = include_str!("../../../data/cie/stiles_burch_1959_10deg_rgb_cmfs.csv");

/// A table of one or three functions of wavelength on an ascending grid.
#[derive(Debug, Clone)]
pub(crate) struct Table {
    pub wavelength_nm: Vec<f64>,
    /// One column per function (1 for illuminants, 3 for CMFs).
    pub columns: Vec<Vec<f64>>,
}

impl Table {
    fn parse(name: &'static str, text: &str, n_columns: usize) -> Result<Table, SpectralError> {
        let corrupt = |message: String| SpectralError::EmbeddedTable {
            table: name,
            message,
        };
        let mut wavelength_nm = Vec::new();
        let mut columns = vec![Vec::new(); n_columns];
        for (i, line) in text.lines().enumerate().skip(1) {
            if line.trim().is_empty() {
                continue;
            }
            let mut fields = line.split(',');
            let mut next = || -> Result<f64, SpectralError> {
                fields
                    .next()
                    .and_then(|f| f.trim().parse::<f64>().ok())
                    .ok_or_else(|| corrupt(format!("line {}", i + 1)))
            };
            wavelength_nm.push(next()?);
            for c in columns.iter_mut() {
                c.push(next()?);
            }
        }
        if wavelength_nm.len() < 2 || wavelength_nm.windows(2).any(|p| p[1] <= p[0]) {
            return Err(corrupt("wavelengths not ascending".into()));
        }
        Ok(Table {
            wavelength_nm,
            columns,
        })
    }

    /// Index of an exact wavelength in the table.
    pub fn index_of(&self, wavelength_nm: f64) -> Option<usize> {
        self.wavelength_nm.iter().position(|&w| w == wavelength_nm)
    }

    /// colour's `LinearInterpolator` (numpy `interp`) at `t`, end values held outside.
    pub fn linear(&self, column: usize, t: f64) -> f64 {
        let x = &self.wavelength_nm;
        let y = &self.columns[column];
        let n = x.len();
        if t <= x[0] {
            return y[0];
        }
        if t >= x[n - 1] {
            return y[n - 1];
        }
        let j = x.partition_point(|&w| w <= t) - 1;
        if x[j] == t {
            return y[j];
        }
        let slope = (y[j + 1] - y[j]) / (x[j + 1] - x[j]);
        slope * (t - x[j]) + y[j]
    }
}

/// All embedded tables, parsed once.
#[derive(Debug)]
pub(crate) struct Tables {
    pub cie_1931: Table,
    pub cie_1964: Table,
    pub d65: Table,
    pub a: Table,
    pub wright_guild_1931: Table,
    pub stiles_burch_1955: Table,
    pub stiles_burch_1959: Table,
}

static TABLES: OnceLock<Result<Tables, Arc<SpectralError>>> = OnceLock::new();

/// The parsed tables (parsed on first use; an error here is a build defect).
pub(crate) fn tables() -> Result<&'static Tables, SpectralError> {
    let parsed = TABLES.get_or_init(|| {
        let all = || -> Result<Tables, SpectralError> {
            Ok(Tables {
                cie_1931: Table::parse("cie_1931_2deg_xyz_cmfs.csv", CIE_1931, 3)?,
                cie_1964: Table::parse("cie_1964_10deg_xyz_cmfs.csv", CIE_1964, 3)?,
                d65: Table::parse("illuminant_d65.csv", D65, 1)?,
                a: Table::parse("illuminant_a.csv", ILL_A, 1)?,
                wright_guild_1931: Table::parse("wright_guild_1931_2deg_rgb_cmfs.csv", WG_1931, 3)?,
                stiles_burch_1955: Table::parse("stiles_burch_1955_2deg_rgb_cmfs.csv", SB_1955, 3)?,
                stiles_burch_1959: Table::parse(
                    "stiles_burch_1959_10deg_rgb_cmfs.csv",
                    SB_1959,
                    3,
                )?,
            })
        };
        all().map_err(Arc::new)
    });
    parsed
        .as_ref()
        .map_err(|source| SpectralError::EmbeddedData {
            what: "data/cie tables",
            source: Arc::clone(source),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tables_parse_with_documented_shapes() {
        let t = tables().unwrap();
        let shape = |t: &Table| {
            (
                t.wavelength_nm[0],
                *t.wavelength_nm.last().unwrap(),
                t.wavelength_nm.len(),
            )
        };
        assert_eq!(shape(&t.cie_1931), (360.0, 830.0, 471));
        assert_eq!(shape(&t.cie_1964), (360.0, 830.0, 471));
        assert_eq!(shape(&t.d65), (300.0, 780.0, 97));
        assert_eq!(shape(&t.a), (300.0, 780.0, 97));
        assert_eq!(shape(&t.wright_guild_1931), (380.0, 780.0, 81));
        assert_eq!(shape(&t.stiles_burch_1955), (390.0, 730.0, 69));
        assert_eq!(shape(&t.stiles_burch_1959), (390.0, 830.0, 89));
        // D65 is normalised to 100 at 560 nm; ȳ peaks at 1 near 555 nm (CIE 15).
        assert_eq!(t.d65.columns[0][t.d65.index_of(560.0).unwrap()], 100.0);
        assert_eq!(
            t.cie_1931.columns[1][t.cie_1931.index_of(555.0).unwrap()],
            1.0
        );
        // Linear interpolation: D65 at 362 nm lies 2/5 of the way from 360 to 365.
        let (d360, d365) = (t.d65.columns[0][12], t.d65.columns[0][13]);
        assert!((t.d65.linear(0, 362.0) - (d360 + 0.4 * (d365 - d360))).abs() < 1e-12);
    }
}
