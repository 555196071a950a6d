//! The CIE reference tables, embedded in the binary (`data/cie/` and `data/illuminants/`,
//! exported bit-exactly from colour-science 0.4.7; provenance and licences in each folder's
//! README).

use std::sync::{Arc, OnceLock};

use crate::error::SpectralError;
use crate::illuminant::CieIlluminant;
use crate::integrate::Observer;

const CIE_1931: &str = include_str!("../../../data/cie/cie_1931_2deg_xyz_cmfs.csv");
const CIE_1964: &str = include_str!("../../../data/cie/cie_1964_10deg_xyz_cmfs.csv");
const WG_1931: &str = include_str!("../../../data/cie/wright_guild_1931_2deg_rgb_cmfs.csv");
const SB_1955: &str = include_str!("../../../data/cie/stiles_burch_1955_2deg_rgb_cmfs.csv");
const SB_1959: &str = include_str!("../../../data/cie/stiles_burch_1959_10deg_rgb_cmfs.csv");

/// The bundled illuminants' files, in [`CieIlluminant::ALL`]'s order.
macro_rules! illuminant_files {
    ($($name:literal),+ $(,)?) => {
        [$(($name, include_str!(concat!("../../../data/illuminants/", $name, ".csv")))),+]
    };
}
const ILLUMINANTS: [(&str, &str); 27] = illuminant_files!(
    "D50", "D55", "D65", "D75", "A", "E", "FL1", "FL2", "FL3", "FL4", "FL5", "FL6", "FL7", "FL8",
    "FL9", "FL10", "FL11", "FL12", "LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1",
    "LED-RGB1", "LED-V1", "LED-V2",
);
const WHITES: &str = include_str!("../../../data/illuminants/whites.csv");

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
}

/// colour's `LinearInterpolator` (numpy `interp`) of the samples `(x, y)` at `t` (`x`
/// strictly increasing, at least one sample), end values held outside them.
pub(crate) fn linear_at(x: &[f64], y: &[f64], t: f64) -> f64 {
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

/// All embedded tables, parsed once.
#[derive(Debug)]
pub(crate) struct Tables {
    pub cie_1931: Table,
    pub cie_1964: Table,
    /// The bundled illuminants, in [`CieIlluminant::ALL`]'s order.
    pub illuminants: Vec<Table>,
    /// Each illuminant's white in CIE xy, per observer (`Observer as usize`).
    pub whites: Vec<[[f64; 2]; 2]>,
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
                illuminants: ILLUMINANTS
                    .iter()
                    .map(|(name, text)| Table::parse(name, text, 1))
                    .collect::<Result<_, _>>()?,
                whites: parse_whites()?,
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

/// `whites.csv`: `illuminant,observer,x,y`, a row for every bundled illuminant and observer.
fn parse_whites() -> Result<Vec<[[f64; 2]; 2]>, SpectralError> {
    let corrupt = |message: String| SpectralError::EmbeddedTable {
        table: "whites.csv",
        message,
    };
    let mut whites = vec![[[f64::NAN; 2]; 2]; CieIlluminant::ALL.len()];
    for (i, line) in WHITES.lines().enumerate().skip(1) {
        let fields: Vec<&str> = line.split(',').collect();
        let row = || corrupt(format!("line {}", i + 1));
        let [name, observer, x, y] = fields.as_slice() else {
            return Err(row());
        };
        let illuminant = name.parse::<CieIlluminant>().map_err(|_| row())?;
        let observer = observer.parse::<Observer>().map_err(|_| row())?;
        let xy = [x, y].map(|v| v.parse::<f64>().unwrap_or(f64::NAN));
        whites[illuminant.index()][observer as usize] = xy;
    }
    if whites.iter().flatten().flatten().any(|v| !v.is_finite()) {
        return Err(corrupt("an illuminant or observer has no white".into()));
    }
    Ok(whites)
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
        let d65 = &t.illuminants[CieIlluminant::D65.index()];
        assert_eq!(shape(d65), (300.0, 780.0, 97));
        assert_eq!(
            shape(&t.illuminants[CieIlluminant::A.index()]),
            (300.0, 780.0, 97)
        );
        assert_eq!(
            shape(&t.illuminants[CieIlluminant::E.index()]),
            (360.0, 830.0, 95)
        );
        for led in [
            CieIlluminant::Fl1,
            CieIlluminant::Fl12,
            CieIlluminant::LedV2,
        ] {
            assert_eq!(shape(&t.illuminants[led.index()]), (380.0, 780.0, 81));
        }
        assert_eq!(shape(&t.wright_guild_1931), (380.0, 780.0, 81));
        assert_eq!(shape(&t.stiles_burch_1955), (390.0, 730.0, 69));
        assert_eq!(shape(&t.stiles_burch_1959), (390.0, 830.0, 89));
        // D65 is normalised to 100 at 560 nm; ȳ peaks at 1 near 555 nm (CIE 15).
        assert_eq!(d65.columns[0][d65.index_of(560.0).unwrap()], 100.0);
        assert_eq!(
            t.cie_1931.columns[1][t.cie_1931.index_of(555.0).unwrap()],
            1.0
        );
        // Linear interpolation: D65 at 362 nm lies 2/5 of the way from 360 to 365.
        let (d360, d365) = (d65.columns[0][12], d65.columns[0][13]);
        assert!(
            (linear_at(&d65.wavelength_nm, &d65.columns[0], 362.0) - (d360 + 0.4 * (d365 - d360)))
                .abs()
                < 1e-12
        );
        // Every illuminant has a white for both observers; D65's is the spaces' D65 exactly.
        assert_eq!(t.whites.len(), CieIlluminant::ALL.len());
        for (name, illuminant) in ILLUMINANTS.iter().map(|f| f.0).zip(CieIlluminant::ALL) {
            assert_eq!(name, illuminant.name());
        }
        assert_eq!(
            t.whites[CieIlluminant::D65.index()][Observer::Cie1931 as usize],
            glassdb_colour::D65_XY
        );
        assert_eq!(t.whites[CieIlluminant::LedB3.index()][0], [0.3756, 0.3723]);
    }
}
