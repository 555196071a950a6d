//! The well-conditioned basis of a fit (method step 1 of `solve`): Chebyshev polynomials
//! `T_j(u)` of `u`, the fitted cos θ range mapped onto [-1, 1] (times cos θ for the paper
//! basis), and their exact conversion to the power basis in double-double (step 3).

use nalgebra::DMatrix;

use crate::dd::Dd;
use crate::model::Basis;
use crate::prepared::Prepared;

/// Chebyshev T_0..T_{m-1} at u.
fn chebyshev(u: f64, m: usize, out: &mut [f64]) {
    for j in 0..m {
        out[j] = match j {
            0 => 1.0,
            1 => u,
            _ => 2.0 * u * out[j - 1] - out[j - 2],
        };
    }
}

/// Power-of-u coefficients of T_0..T_{m-1} (exact small integers).
fn chebyshev_power_table(m: usize) -> Vec<Vec<f64>> {
    let mut t: Vec<Vec<f64>> = Vec::with_capacity(m);
    for j in 0..m {
        let row = match j {
            0 => vec![1.0],
            1 => vec![0.0, 1.0],
            _ => {
                let mut row = vec![0.0; j + 1];
                for (k, &c) in t[j - 1].iter().enumerate() {
                    row[k + 1] += 2.0 * c;
                }
                for (k, &c) in t[j - 2].iter().enumerate() {
                    row[k] -= c;
                }
                row
            }
        };
        t.push(row);
    }
    t
}

/// The affine map x ↦ u = alpha·x + beta that sends [lo, hi] onto [-1, 1].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Affine {
    alpha: f64,
    beta: f64,
}

impl Affine {
    fn new(lo: f64, hi: f64) -> Affine {
        if hi - lo > 1e-12 {
            let alpha = 2.0 / (hi - lo);
            Affine {
                alpha,
                beta: -(hi + lo) / (hi - lo),
            }
        } else {
            Affine {
                alpha: 0.0,
                beta: 0.0,
            }
        }
    }
    fn u(self, x: f64) -> f64 {
        self.alpha * x + self.beta
    }
}

/// Converts Σ_j a_j φ_j(x) (φ_j = T_j(u(x)), or x·T_j(u(x)) for the paper basis) to power
/// coefficients of x for the powers of `basis` at `degree`, in double-double.
pub(crate) fn to_power_basis(a: &[Dd], map: Affine, basis: Basis) -> Vec<Dd> {
    let m = a.len();
    let table = chebyshev_power_table(m);
    // coefficients in powers of u
    let mut b = vec![Dd::ZERO; m];
    for (j, row) in table.iter().enumerate() {
        for (k, &c) in row.iter().enumerate() {
            b[k] = b[k] + a[j] * Dd::from_f64(c);
        }
    }
    // substitute u = alpha x + beta by Horner over polynomials: q ← q·(alpha x + beta) + b_k
    let (alpha, beta) = (Dd::from_f64(map.alpha), Dd::from_f64(map.beta));
    let mut q: Vec<Dd> = vec![Dd::ZERO; m];
    for k in (0..m).rev() {
        let mut next = vec![Dd::ZERO; m];
        for (i, &qi) in q.iter().enumerate() {
            if i + 1 < m {
                next[i + 1] = next[i + 1] + qi * alpha;
            }
            next[i] = next[i] + qi * beta;
        }
        next[0] = next[0] + b[k];
        q = next;
    }
    match basis {
        Basis::Full => q,
        Basis::Paper => q, // the factor x shifts every power up by one: powers 1..=n
    }
}

/// The Chebyshev-type basis of one fit: `T_j(u(x))` (full) or `x·T_j(u(x))` (paper), j < m.
pub(crate) struct ChebyshevBasis {
    pub(crate) basis: Basis,
    pub(crate) map: Affine,
    pub(crate) m: usize,
}

impl ChebyshevBasis {
    /// The basis on the cos θ range of the fitted rows (and cos 0° = 1 when constrained).
    pub(crate) fn on_rows(
        p: &Prepared,
        rows: &[usize],
        basis: Basis,
        m: usize,
        constrained: bool,
    ) -> Self {
        let with_one = |bound: f64| if constrained { 1.0 } else { bound };
        let lo = rows
            .iter()
            .map(|&i| p.cos[i])
            .fold(f64::INFINITY, f64::min)
            .min(with_one(f64::INFINITY));
        let hi = rows
            .iter()
            .map(|&i| p.cos[i])
            .fold(f64::NEG_INFINITY, f64::max)
            .max(with_one(f64::NEG_INFINITY));
        ChebyshevBasis {
            basis,
            map: Affine::new(lo, hi),
            m,
        }
    }

    /// The m basis functions at x, into `out` (`tj` is scratch of length m).
    pub(crate) fn at(&self, x: f64, tj: &mut [f64], out: &mut [f64]) {
        chebyshev(self.map.u(x), self.m, tj);
        for j in 0..self.m {
            out[j] = if self.basis == Basis::Paper {
                x * tj[j]
            } else {
                tj[j]
            };
        }
    }

    /// The design matrix over the given rows.
    pub(crate) fn design(&self, p: &Prepared, rows: &[usize]) -> DMatrix<f64> {
        let mut a = DMatrix::<f64>::zeros(rows.len(), self.m);
        let (mut tj, mut rowbuf) = (vec![0.0; self.m], vec![0.0; self.m]);
        for (r, &i) in rows.iter().enumerate() {
            self.at(p.cos[i], &mut tj, &mut rowbuf);
            for j in 0..self.m {
                a[(r, j)] = rowbuf[j];
            }
        }
        a
    }
}
