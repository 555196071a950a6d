//! Section "Lookup table vs polynomial vs finer table": each way of getting r for a float
//! cos θ, against the exact physics and the polynomial, with its cost. The 256- and
//! 65536-entry tables are indexed by the masks' own codec ([`CosCode`]).

use std::fmt::Write as _;

use glassdb_fit::{CosPolynomial, FitOptions, Quantity, cos_deg, fit_curve};
use glassdb_mask::CosCode;

use crate::measure::{dense_angles, max_abs_diff, ns_per_value};
use crate::reference::{Reference, samples};
use crate::text::fmt_err;

/// Where a table's entries lie over cos θ ∈ [0, 1].
#[derive(Clone, Copy)]
enum Grid {
    /// At the cos θ of every code of a mask codec: the table a mask of that width indexes.
    Code(CosCode),
    /// At cos θ = i/steps, i = 0…steps.
    Steps(usize),
}

impl Grid {
    fn intervals(self) -> usize {
        match self {
            Grid::Code(code) => usize::from(code.max_code()),
            Grid::Steps(n) => n,
        }
    }

    fn cos_at(self, i: usize) -> f64 {
        match self {
            Grid::Code(code) => code.decode(i as u16),
            Grid::Steps(n) => i as f64 / n as f64,
        }
    }

    /// The index of the entry nearest to `c` (clamped to [0, 1]).
    fn nearest(self, c: f64) -> usize {
        match self {
            Grid::Code(code) => usize::from(code.encode(c)),
            Grid::Steps(n) => (c.clamp(0.0, 1.0) * n as f64).round() as usize,
        }
    }
}

/// A table of f over a [`Grid`], in f32 as the compositor stores them.
struct CosTable {
    grid: Grid,
    values: Vec<f32>,
}

impl CosTable {
    fn new(grid: Grid, f: impl Fn(f64) -> f64) -> Self {
        CosTable {
            grid,
            values: (0..=grid.intervals())
                .map(|i| f(grid.cos_at(i)) as f32)
                .collect(),
        }
    }

    #[inline]
    fn nearest(&self, c: f64) -> f64 {
        self.values
            .get(self.grid.nearest(c))
            .copied()
            .unwrap_or(0.0) as f64
    }

    #[inline]
    fn linear(&self, c: f64) -> f64 {
        let last = self.values.len() - 1;
        let x = c.clamp(0.0, 1.0) * last as f64;
        let i = (x.floor() as usize).min(last.saturating_sub(1));
        let f = x - i as f64;
        let a = self.values.get(i).copied().unwrap_or(0.0) as f64;
        let b = self.values.get(i + 1).copied().unwrap_or(0.0) as f64;
        a + (b - a) * f
    }
}

/// Writes the section for the first reference's reflectance.
pub(crate) fn section_tables(md: &mut String, refs: &[Reference], inputs: &[f64]) {
    let _ = writeln!(md, "## Lookup table vs polynomial vs finer table\n");
    let r = &refs[0];
    let sr = samples(r, Quantity::Reflectance);
    let Ok(fit) = fit_curve(&sr, &FitOptions::new(Quantity::Reflectance)) else {
        let _ = writeln!(md, "(the reflectance fit failed; table not computed)\n");
        return;
    };
    let poly: CosPolynomial = fit.polynomial.clone();
    let normal = fit.normal;
    let _ = writeln!(
        md,
        "Reflectance of the {} reference, fitted by `glassdb fit` defaults ({} basis, n = {}). For a \
         float cos θ (EXR mask) each way of getting r is compared with the exact physics and with the \
         polynomial itself (the table's own error), over θ = 0–89° (0.001° grid); tables hold f32 \
         values at cos θ = i/(N−1) as the compositor's `GlassLut` does. For 8-bit masks the 256-entry \
         table is exact (the mask can only hold those 256 values).\n",
        r.name,
        poly.basis.name(),
        poly.degree()
    );
    let grid = dense_angles(89.0, 0.001);
    let exact = |a: f64| r.eval(cos_deg(a)).0;
    let p = |c: f64| normal * poly.eval(c);
    let t256 = CosTable::new(Grid::Code(CosCode::Bits8), p);
    let t4096 = CosTable::new(Grid::Steps(4095), p);
    let t65536 = CosTable::new(Grid::Code(CosCode::Bits16), p);
    type Way<'a> = (&'a str, Box<dyn Fn(f64) -> f64 + 'a>);
    let ways: Vec<Way<'_>> = vec![
        ("exact physics (Fresnel slab)", Box::new(|c| r.eval(c).0)),
        ("polynomial (Horner)", Box::new(p)),
        ("256-entry table, nearest", Box::new(|c| t256.nearest(c))),
        (
            "256-entry table, linear interpolation",
            Box::new(|c| t256.linear(c)),
        ),
        ("4096-entry table, nearest", Box::new(|c| t4096.nearest(c))),
        (
            "4096-entry table, linear interpolation",
            Box::new(|c| t4096.linear(c)),
        ),
        (
            "65536-entry table, nearest",
            Box::new(|c| t65536.nearest(c)),
        ),
    ];
    let _ = writeln!(
        md,
        "| method | max \\|r − exact\\| | max \\|r − polynomial\\| | ns/value |"
    );
    let _ = writeln!(md, "|---|---|---|---|");
    for (name, f) in &ways {
        let e_exact = max_abs_diff(&grid, |a| f(cos_deg(a)), exact);
        let e_poly = max_abs_diff(&grid, |a| f(cos_deg(a)), |a| p(cos_deg(a)));
        let ns = ns_per_value(inputs, f);
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {ns:.2} |",
            fmt_err(e_exact),
            fmt_err(e_poly)
        );
    }
    let _ = writeln!(md);
}
