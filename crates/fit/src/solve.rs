//! Equality-constrained least squares for `C(θ) = Σ_k c_k cos^{p_k} θ` with `C(0°) = 1`
//! (method eqs. 11–14), solved stably and exported in the power basis.
//!
//! 1. Basis: Chebyshev polynomials `T_j(u)` of `u`, the data's cos θ range (and cos 0° = 1)
//!    mapped onto [-1, 1]; for the paper basis `cos θ · T_j(u)`, j < n. Same function space as
//!    the powers, far better conditioned.
//! 2. Constraint `g·a = 1` (g = the basis at cos θ = 1) by the null-space method: a Householder
//!    reflector `H` with `H g ∝ e1` splits `a = H w` into `w_0`, fixed by the constraint, and the
//!    free `w_1…`, found by Householder QR least squares (nalgebra) of `(A H)[:, 1..]`. The
//!    condition number reported is that of this matrix (from its singular values).
//! 3. Conversion to the power basis in double-double arithmetic, rounded once; the rounding
//!    left in `C(1) − 1` is moved into the lowest-power coefficient, so `C(0°) = 1` holds to
//!    the last bit the power form can carry (not a rescale: the fit was constrained already).
//!
//! Without a 0° row the absolute curve is fitted unconstrained and its value at cos θ = 1
//! becomes the normal value. Never the normal equations.

use nalgebra::{DMatrix, DVector};

use crate::chebyshev::{ChebyshevBasis, to_power_basis};
use crate::dd::Dd;
use crate::error::FitError;
use crate::model::{
    AngleSamples, Basis, CosPolynomial, CurveFit, FitDiagnostics, FitOptions, FitSummary, Quantity,
    SuspectPoint,
};
use crate::physical::{CHECK_SLACK, CHECK_STEP_DEG};
use crate::prepared::{Prepared, prepare};

/// Highest degree accepted (fixed or as --max-degree): at 20 the power basis on 0–90° already
/// has a condition number near 1e15.
pub const MAX_DEGREE: u32 = 20;
/// Margin (degrees) beyond the measured range before a value counts as extrapolated.
pub const EXTRAPOLATION_MARGIN_DEG: f64 = 2.0;
/// |externally studentized residual| above which a point is reported as suspect (when its
/// residual is also above tol/2 and more than 3× its neighbours').
pub const SUSPECT_STUDENTIZED: f64 = 4.0;
/// Automatic selection keeps the tolerance-meeting degree unless its leave-one-out RMS error
/// exceeds this factor times the best leave-one-out error of the lower degrees (overfitting).
pub const LOO_GUARD_FACTOR: f64 = 1.5;

/// A fit at one basis and degree, before diagnostics are packaged.
#[derive(Clone, Debug)]
pub(crate) struct Solved {
    pub basis: Basis,
    pub degree: u32,
    pub normal: f64,
    pub coefficients: Vec<f64>,
    pub max_abs: f64,
    pub max_idx: usize,
    pub rms: f64,
    pub loo_rms: Option<f64>,
    pub cond: f64,
    pub power_cond: f64,
    pub suspects: Vec<SuspectPoint>,
}

/// Number of coefficients of a basis at a degree.
pub(crate) fn coefficient_count(basis: Basis, degree: u32) -> usize {
    match basis {
        Basis::Paper => degree as usize,
        Basis::Full => degree as usize + 1,
    }
}

fn householder_nullspace(g: &DVector<f64>) -> (DMatrix<f64>, f64) {
    // H = I − 2 v vᵀ / vᵀv with v = g + sign(g0)|g| e1, so H g = −sign(g0)|g| e1.
    let m = g.len();
    let norm = g.norm();
    let s = if g[0] >= 0.0 { 1.0 } else { -1.0 };
    let mut v = g.clone();
    v[0] += s * norm;
    let vtv = v.dot(&v);
    let mut h = DMatrix::<f64>::identity(m, m);
    if vtv > 0.0 {
        h -= (2.0 / vtv) * &v * v.transpose();
    }
    (h, -s * norm)
}

fn condition_number(m: &DMatrix<f64>) -> f64 {
    if m.ncols() == 0 || m.nrows() == 0 {
        return 1.0;
    }
    let sv = m.clone().singular_values();
    let max = sv.iter().copied().fold(0.0, f64::max);
    let min = sv.iter().copied().fold(f64::INFINITY, f64::min);
    if min > 0.0 { max / min } else { f64::INFINITY }
}

/// Least squares `min |B w − rhs|` by Householder QR; returns w, the hat-matrix diagonal, and
/// whether R had a (numerically) zero pivot.
fn qr_least_squares(b: DMatrix<f64>, rhs: &DVector<f64>) -> Option<(DVector<f64>, Vec<f64>)> {
    let (n, m) = b.shape();
    if m == 0 {
        return Some((DVector::zeros(0), vec![0.0; n]));
    }
    let qr = b.qr();
    let q = qr.q();
    let r = qr.r();
    let maxdiag = (0..m).map(|j| r[(j, j)].abs()).fold(0.0, f64::max);
    if (0..m).any(|j| r[(j, j)].abs() <= 1e-13 * maxdiag) || maxdiag == 0.0 {
        return None;
    }
    let qtb = q.transpose() * rhs;
    let w = r.solve_upper_triangular(&qtb)?;
    let hat = (0..n).map(|i| q.row(i).norm_squared()).collect();
    Some((w, hat))
}

/// How the 0° value enters a fit.
#[derive(Clone, Copy, Debug, PartialEq)]
enum NormalConstraint {
    /// The measured, positive 0° value: C(1) = 1 is imposed and `C = value / normal`.
    Measured(f64),
    /// No 0° row: the absolute curve is fitted and its value at cos θ = 1 becomes the normal.
    Extrapolated,
    /// Zero everywhere (e.g. an opaque pane's transmittance): nothing to fit.
    AllZero,
}

impl NormalConstraint {
    fn of(p: &Prepared) -> Result<NormalConstraint, FitError> {
        match p.measured_normal {
            Some(v0) if v0 > 0.0 => Ok(NormalConstraint::Measured(v0)),
            Some(v0) if v0 == 0.0 && p.value.iter().all(|&v| v == 0.0) => {
                Ok(NormalConstraint::AllZero)
            }
            Some(v0) if v0 == 0.0 => Err(FitError::BadNormal {
                normal: v0,
                detail: "but the curve is not zero at other angles",
            }),
            Some(v0) => Err(FitError::BadNormal {
                normal: v0,
                detail: "negative",
            }),
            None => Ok(NormalConstraint::Extrapolated),
        }
    }

    fn measured(self) -> Option<f64> {
        match self {
            NormalConstraint::Measured(v0) => Some(v0),
            _ => None,
        }
    }
}

/// The least-squares solution in the Chebyshev-type basis.
struct ChebyshevSolution {
    /// Coefficients (double-double for the conversion to powers).
    coefficients: Vec<Dd>,
    /// Hat-matrix diagonal over the fitted rows.
    hat: Vec<f64>,
    /// Condition number of the matrix actually solved.
    cond: f64,
    /// Number of free coefficients.
    free: usize,
}

/// Solves `a·c ≈ target`, with `g·c = 1` (g = the basis at cos θ = 1) when `constrained`.
fn solve_chebyshev(
    cheb: &ChebyshevBasis,
    a: DMatrix<f64>,
    target: &DVector<f64>,
    constrained: bool,
    singular: impl Fn() -> FitError,
) -> Result<ChebyshevSolution, FitError> {
    let m = cheb.m;
    if !constrained {
        let cond = condition_number(&a);
        let (w, hat) = qr_least_squares(a, target).ok_or_else(singular)?;
        return Ok(ChebyshevSolution {
            coefficients: w.iter().map(|&v| Dd::from_f64(v)).collect(),
            hat,
            cond,
            free: m,
        });
    }
    let mut g = DVector::<f64>::zeros(m);
    cheb.at(1.0, &mut vec![0.0; m], g.as_mut_slice());
    let (h, gh0) = householder_nullspace(&g);
    let w0 = 1.0 / gh0;
    let ah = &a * &h;
    let rhs = target - ah.column(0) * w0;
    let bfree = ah.columns(1, m - 1).into_owned();
    let cond = condition_number(&bfree);
    let (wfree, hat) = qr_least_squares(bfree, &rhs).ok_or_else(singular)?;
    // a = H w in double-double
    let mut w = vec![Dd::from_f64(w0)];
    w.extend(wfree.iter().map(|&v| Dd::from_f64(v)));
    let coefficients = (0..m)
        .map(|r| (0..m).fold(Dd::ZERO, |acc, c| acc + Dd::from_f64(h[(r, c)]) * w[c]))
        .collect();
    Ok(ChebyshevSolution {
        coefficients,
        hat,
        cond,
        free: m - 1,
    })
}

/// The power-basis polynomial and normal value of a Chebyshev solution, with `C(1) = 1` as
/// exactly as the f64 Horner evaluation allows.
fn power_polynomial(
    cheb: &ChebyshevBasis,
    solution: &[Dd],
    constraint: NormalConstraint,
    powers: Vec<u32>,
) -> Result<(f64, CosPolynomial), FitError> {
    let mut power = to_power_basis(solution, cheb.map, cheb.basis);
    let normal;
    if let Some(v0) = constraint.measured() {
        normal = v0;
        // move the conversion's rounding out of C(1) into the lowest power
        let sum = power.iter().fold(Dd::ZERO, |acc, &c| acc + c);
        power[0] = power[0] - (sum - Dd::from_f64(1.0));
    } else {
        let at_one = power.iter().fold(Dd::ZERO, |acc, &c| acc + c);
        normal = at_one.to_f64();
        if !(normal > 0.0 && normal.is_finite()) {
            return Err(FitError::BadNormal {
                normal,
                detail: "extrapolated to 0° from a table without a 0° row",
            });
        }
        // C = P / normal: divide in double-double precision via f64 reciprocal refinement
        let inv = 1.0 / normal;
        for c in power.iter_mut() {
            let q = Dd::from_f64(c.to_f64() * inv);
            // one Newton correction: q + (c − q·normal)·inv
            let corr = (*c - q * Dd::from_f64(normal)).to_f64() * inv;
            *c = q + Dd::from_f64(corr);
        }
        let sum = power.iter().fold(Dd::ZERO, |acc, &c| acc + c);
        power[0] = power[0] - (sum - Dd::from_f64(1.0));
    }
    // make the f64 evaluation at cos θ = 1 (Horner, as `CosPolynomial::eval` does it) give 1
    // as exactly as rounding allows: nudge the lowest coefficient by the leftover
    let mut poly = CosPolynomial {
        basis: cheb.basis,
        powers,
        coefficients: power.iter().map(|c| c.to_f64()).collect(),
    };
    for _ in 0..4 {
        let e = poly.eval(1.0) - 1.0;
        if e == 0.0 {
            break;
        }
        poly.coefficients[0] -= e;
    }
    Ok((normal, poly))
}

/// Leave-one-out (PRESS) RMS error over the fitted rows; `None` when a point determines a
/// coefficient by itself (hat value 1).
fn leave_one_out_rms(rows: &[usize], hat: &[f64], residual: &[f64]) -> Option<f64> {
    let nr = rows.len();
    let mut press = 0.0;
    let mut loo_defined = nr > 0;
    for (r, &i) in rows.iter().enumerate() {
        let one_minus_h = 1.0 - hat[r];
        if one_minus_h < 1e-10 {
            loo_defined = false;
            break;
        }
        let e = residual[i] / one_minus_h;
        press += e * e;
    }
    loo_defined.then(|| (press / nr as f64).sqrt())
}

/// Isolated points whose externally studentized residual exceeds [`SUSPECT_STUDENTIZED`] (and
/// tol/2), worst first; none with fewer than 3 degrees of freedom.
fn suspect_points(
    p: &Prepared,
    rows: &[usize],
    hat: &[f64],
    residual: &[f64],
    free: usize,
    tol: f64,
) -> Vec<SuspectPoint> {
    let n = p.angle_deg.len();
    let dof = rows.len() as i64 - free as i64;
    let mut suspects = Vec::new();
    if dof < 3 {
        return suspects;
    }
    let ssr: f64 = rows.iter().map(|&i| residual[i] * residual[i]).sum();
    for (r, &i) in rows.iter().enumerate() {
        let one_minus_h = 1.0 - hat[r];
        if one_minus_h < 1e-10 {
            continue;
        }
        let e = residual[i];
        let s2 = (ssr - e * e / one_minus_h) / (dof - 1) as f64;
        if s2 <= 0.0 {
            continue;
        }
        let t = e / (s2.sqrt() * one_minus_h.sqrt());
        // an outlier is isolated: its neighbours fit much better (a systematic misfit,
        // e.g. at grazing incidence, spreads over consecutive points instead)
        let isolated = [i.checked_sub(1), (i + 1 < n).then_some(i + 1)]
            .into_iter()
            .flatten()
            .all(|k| residual[k].abs() < e.abs() / 3.0);
        if t.abs() > SUSPECT_STUDENTIZED && e.abs() > 0.5 * tol && isolated {
            suspects.push(SuspectPoint {
                angle_deg: p.angle_deg[i],
                residual: e,
                studentized: t,
            });
        }
    }
    suspects.sort_by(|a, b| b.studentized.abs().total_cmp(&a.studentized.abs()));
    suspects
}

/// Condition number of the power-basis design matrix over the same points (for comparison).
fn power_basis_condition(p: &Prepared, powers: &[u32]) -> f64 {
    let mut vand = DMatrix::<f64>::zeros(p.cos.len(), powers.len());
    for (i, &c) in p.cos.iter().enumerate() {
        for (j, &pw) in powers.iter().enumerate() {
            vand[(i, j)] = c.powi(pw as i32);
        }
    }
    condition_number(&vand)
}

/// Fits one basis at one degree: the constraint, the Chebyshev least squares, the power form,
/// then residual statistics (max, RMS, leave-one-out, suspects).
pub(crate) fn solve_fixed(
    p: &Prepared,
    basis: Basis,
    degree: u32,
    tol: f64,
) -> Result<Solved, FitError> {
    let m = coefficient_count(basis, degree);
    let n = p.angle_deg.len();
    if m == 0 {
        return Err(FitError::InvalidOptions(
            "the paper basis needs degree ≥ 1".into(),
        ));
    }
    if n < m {
        return Err(FitError::TooFewPoints {
            points: n,
            coefficients: m,
            degree,
            basis: basis.name(),
        });
    }
    let powers = basis.powers(degree);
    let constraint = NormalConstraint::of(p)?;
    if constraint == NormalConstraint::AllZero {
        return Ok(zero_curve(basis, degree, powers));
    }
    let constrained = constraint.measured();
    // Rows of the least-squares system: all points except the 0° row in the constrained case.
    let rows: Vec<usize> = (0..n)
        .filter(|&i| constrained.is_none() || p.angle_deg[i] != 0.0)
        .collect();
    let cheb = ChebyshevBasis::on_rows(p, &rows, basis, m, constrained.is_some());
    let a = cheb.design(p, &rows);
    let scale = constrained.unwrap_or(1.0);
    let target = DVector::from_iterator(rows.len(), rows.iter().map(|&i| p.value[i] / scale));
    let singular = || FitError::Singular { degree, points: n };
    let solution = solve_chebyshev(&cheb, a, &target, constrained.is_some(), singular)?;
    let (normal, poly) =
        power_polynomial(&cheb, &solution.coefficients, constraint, powers.clone())?;

    // residuals of the exported power-basis curve (what users evaluate)
    let residual: Vec<f64> = (0..n)
        .map(|i| normal * poly.eval(p.cos[i]) - p.value[i])
        .collect();
    let (max_idx, max_abs) =
        residual
            .iter()
            .enumerate()
            .map(|(i, r)| (i, r.abs()))
            .fold(
                (0, -1.0),
                |best, cur| if cur.1 > best.1 { cur } else { best },
            );
    let rms = (residual.iter().map(|r| r * r).sum::<f64>() / n as f64).sqrt();

    Ok(Solved {
        basis,
        degree,
        normal,
        coefficients: poly.coefficients,
        max_abs,
        max_idx,
        rms,
        loo_rms: leave_one_out_rms(&rows, &solution.hat, &residual),
        cond: solution.cond,
        power_cond: power_basis_condition(p, &powers),
        suspects: suspect_points(p, &rows, &solution.hat, &residual, solution.free, tol),
    })
}

/// An all-zero curve (e.g. the transmittance of an opaque pane): normal 0, C = the simplest
/// polynomial of the basis with C(1) = 1.
fn zero_curve(basis: Basis, degree: u32, powers: Vec<u32>) -> Solved {
    let mut coefficients = vec![0.0; powers.len()];
    coefficients[0] = 1.0;
    Solved {
        basis,
        degree,
        normal: 0.0,
        coefficients,
        max_abs: 0.0,
        max_idx: 0,
        rms: 0.0,
        loo_rms: Some(0.0),
        cond: 1.0,
        power_cond: 1.0,
        suspects: Vec::new(),
    }
}

/// Selects the degree for one basis: the smallest degree whose max |residual| ≤ tol; if its
/// leave-one-out RMS error exceeds [`LOO_GUARD_FACTOR`] × the best of the lower degrees, or no
/// degree meets tol, the degree with the best leave-one-out error (the smallest within 5% of
/// it). Degrees needing more coefficients than points are never tried.
fn select_degree(
    p: &Prepared,
    basis: Basis,
    opts: &FitOptions,
) -> Result<(Solved, &'static str), FitError> {
    if let Some(d) = opts.degree {
        return Ok((solve_fixed(p, basis, d, opts.tol)?, "fixed"));
    }
    let n = p.angle_deg.len();
    let mut fits: Vec<Solved> = Vec::new();
    let mut first_err = None;
    for d in basis.min_degree()..=opts.max_degree.max(basis.min_degree()) {
        if coefficient_count(basis, d) > n {
            break;
        }
        match solve_fixed(p, basis, d, opts.tol) {
            Ok(s) => {
                let meets = s.max_abs <= opts.tol;
                fits.push(s);
                if meets {
                    break;
                }
            }
            Err(e @ FitError::BadNormal { .. }) => return Err(e),
            Err(e) => {
                first_err.get_or_insert(e);
            }
        }
    }
    if fits.is_empty() {
        return Err(first_err.unwrap_or(FitError::TooFewPoints {
            points: n,
            coefficients: coefficient_count(basis, basis.min_degree()),
            degree: basis.min_degree(),
            basis: basis.name(),
        }));
    }
    let loo = |s: &Solved| s.loo_rms.unwrap_or(f64::INFINITY);
    let best_loo_pick = |fits: &[Solved]| -> usize {
        let best = fits.iter().map(loo).fold(f64::INFINITY, f64::min);
        if !best.is_finite() {
            return fits.len() - 1;
        }
        fits.iter()
            .position(|s| loo(s) <= 1.05 * best)
            .unwrap_or(fits.len() - 1)
    };
    let last = fits.len() - 1;
    if fits[last].max_abs <= opts.tol {
        let lower_best = fits[..last].iter().map(loo).fold(f64::INFINITY, f64::min);
        if loo(&fits[last]) > LOO_GUARD_FACTOR * lower_best {
            let i = best_loo_pick(&fits);
            return Ok((fits.swap_remove(i), "leave-one-out"));
        }
        return Ok((fits.swap_remove(last), "tolerance"));
    }
    let i = best_loo_pick(&fits);
    Ok((fits.swap_remove(i), "leave-one-out"))
}

/// Fits one measured curve: `value(θ) = normal · C(θ)` with `C(0°) = 1` (method eqs. 11–14).
/// Repeated angles are averaged. See the module docs for the solver and [`FitOptions`] for
/// degree and basis selection.
pub fn fit_curve(samples: &AngleSamples, opts: &FitOptions) -> Result<CurveFit, FitError> {
    // the inputs are validated finite numbers, so the linear algebra cannot meet NaN; a panic
    // inside it would still be a bug, reported as an internal error rather than a crash (and
    // not as a property of the data, such as a singular system)
    internal_errors(samples.angle_deg.len(), || fit_curve_inner(samples, opts))
}

/// Runs `fit`, turning a panic into [`FitError::Internal`] with the panic's message.
fn internal_errors<T>(
    points: usize,
    fit: impl FnOnce() -> Result<T, FitError>,
) -> Result<T, FitError> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(fit)).unwrap_or_else(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".to_string());
        Err(FitError::Internal { points, message })
    })
}

fn fit_curve_inner(samples: &AngleSamples, opts: &FitOptions) -> Result<CurveFit, FitError> {
    if !(opts.tol.is_finite() && opts.tol > 0.0) {
        return Err(FitError::InvalidOptions(format!(
            "tol must be positive, got {}",
            opts.tol
        )));
    }
    let highest = opts.degree.unwrap_or(opts.max_degree);
    if highest > MAX_DEGREE {
        return Err(FitError::InvalidOptions(format!(
            "degree {highest} is above {MAX_DEGREE}: beyond that the power-basis coefficients cannot carry the fit in f64"
        )));
    }
    if opts.basis == Some(Basis::Paper) && opts.degree == Some(0) {
        return Err(FitError::InvalidOptions(
            "the paper basis has no degree-0 form (powers 1…n)".into(),
        ));
    }
    let p = prepare(samples)?;
    let bases: &[Basis] = match (opts.basis, opts.quantity) {
        (Some(Basis::Paper), _) => &[Basis::Paper],
        (Some(Basis::Full), _) => &[Basis::Full],
        (None, Quantity::Reflectance) => &[Basis::Full],
        (None, Quantity::Transmittance) => &[Basis::Paper, Basis::Full],
    };
    let mut best: Option<(Solved, &'static str)> = None;
    let mut last_err = None;
    for &b in bases {
        if opts.degree == Some(0) && b == Basis::Paper {
            continue;
        }
        match select_degree(&p, b, opts) {
            Ok(s) => {
                // a curve staying within 0–1 over 0–90° beats one that does not; then the
                // smaller max error on the data wins
                let better = match &best {
                    None => true,
                    Some((cur, _)) => {
                        let (new_ok, cur_ok) = (in_unit_range(&s.0), in_unit_range(cur));
                        (new_ok && !cur_ok) || (new_ok == cur_ok && s.0.max_abs < cur.max_abs)
                    }
                };
                if better {
                    best = Some(s);
                }
            }
            Err(e) => last_err = Some(e),
        }
    }
    let Some((s, how)) = best else {
        return Err(last_err.unwrap_or_else(|| FitError::InvalidOptions("no basis to fit".into())));
    };
    Ok(package(&p, s, how, opts))
}

/// True when normal·C(θ) stays within [0, 1] on the physical-check grid.
fn in_unit_range(s: &Solved) -> bool {
    let poly = CosPolynomial {
        basis: s.basis,
        powers: s.basis.powers(s.degree),
        coefficients: s.coefficients.clone(),
    };
    let steps = (90.0 / CHECK_STEP_DEG).round() as usize;
    (0..=steps).all(|i| {
        let v = s.normal * poly.eval_angle_deg(i as f64 * CHECK_STEP_DEG);
        (-CHECK_SLACK..=1.0 + CHECK_SLACK).contains(&v)
    })
}

fn package(p: &Prepared, s: Solved, how: &'static str, opts: &FitOptions) -> CurveFit {
    let amin = p.angle_deg.first().copied().unwrap_or(0.0);
    let amax = p.angle_deg.last().copied().unwrap_or(90.0);
    let mut warnings = Vec::new();
    if p.measured_normal.is_none() {
        warnings.push(format!(
            "no 0° row: the normal value {:.6} is the fitted curve extrapolated to cos θ = 1 (data start at {amin}°)",
            s.normal
        ));
    }
    if how != "fixed" && s.max_abs > opts.tol {
        warnings.push(format!(
            "max error {:.5} (at {}°) exceeds the tolerance {} (degree {} of at most {}, {} basis)",
            s.max_abs,
            p.angle_deg.get(s.max_idx).copied().unwrap_or(0.0),
            opts.tol,
            s.degree,
            opts.max_degree,
            s.basis.name()
        ));
    }
    if amin > EXTRAPOLATION_MARGIN_DEG || amax < 90.0 - EXTRAPOLATION_MARGIN_DEG {
        warnings.push(format!(
            "the data cover only {amin}–{amax}°: values outside that range are extrapolated"
        ));
    }
    for sp in s.suspects.iter().take(5) {
        warnings.push(format!(
            "suspect point at {}°: residual {:+.5} is {:.1}× the noise of the other points",
            sp.angle_deg,
            sp.residual,
            sp.studentized.abs()
        ));
    }
    let diagnostics = FitDiagnostics {
        summary: FitSummary {
            degree: s.degree,
            rms_error: s.rms,
            max_abs_error: s.max_abs,
            max_error_angle_deg: p.angle_deg.get(s.max_idx).copied().unwrap_or(0.0),
            condition_number: finite_or(s.cond, f64::MAX),
        },
        power_basis_condition_number: Some(finite_or(s.power_cond, f64::MAX)),
        points: p.angle_deg.len(),
        angle_min_deg: Some(amin),
        angle_max_deg: Some(amax),
        normal_measured: p.measured_normal.is_some(),
        loo_rms_error: s.loo_rms,
        degree_selection: how.to_string(),
        suspect_points: s.suspects,
        warnings,
    };
    CurveFit {
        normal: s.normal,
        polynomial: CosPolynomial {
            basis: s.basis,
            powers: s.basis.powers(s.degree),
            coefficients: s.coefficients,
        },
        diagnostics,
    }
}

fn finite_or(v: f64, fallback: f64) -> f64 {
    if v.is_finite() { v } else { fallback }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_in_the_fitter_is_an_internal_error_not_a_property_of_the_data() {
        let e = internal_errors::<()>(7, || panic!("index out of bounds")).unwrap_err();
        assert!(
            matches!(&e, FitError::Internal { points: 7, message } if message == "index out of bounds"),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with("internal error in the fitter"),
            "{e}"
        );
        let formatted = internal_errors::<()>(1, || panic!("{} coefficients", 3)).unwrap_err();
        assert!(
            formatted.to_string().ends_with("3 coefficients"),
            "{formatted}"
        );
        assert_eq!(internal_errors(1, || Ok(5)).unwrap(), 5);
    }
}
