//! Resampling a measured spectrum onto a reference grid, exactly as colour-science 0.4.7's
//! `SpectralDistribution.align` does where it is right:
//!
//! - uniformly spaced data (every step bit-for-bit equal, colour's `is_uniform`) use the
//!   Sprague (1880) quintic interpolator, including colour's four boundary points built with
//!   the `SPRAGUE_C_COEFFICIENTS`; at least 6 samples;
//! - irregular spacing uses the not-a-knot cubic spline (`scipy.interpolate.interp1d(kind =
//!   "cubic")`, i.e. `make_interp_spline(k=3)`); at least 4 samples;
//! - outside the data the end values are held constant (colour's `Extrapolator` "Constant").
//!
//! Where colour is wrong we differ (documented in `docs/spectral.md`): we always evaluate at the
//! grid's own wavelengths (colour re-spaces onto `start, start + 1, …` when the data start off
//! the grid, e.g. at 382.5 nm) and hold the *data's* end values.

use std::cell::RefCell;

use crate::error::SpectralError;

/// A wavelength array of finite, strictly increasing values.
pub(crate) fn validate_grid(wavelength_nm: &[f64]) -> Result<(), SpectralError> {
    let mut previous = f64::NEG_INFINITY;
    for (index, &w) in wavelength_nm.iter().enumerate() {
        if !w.is_finite() {
            return Err(SpectralError::NonFinite {
                what: "wavelength",
                index,
            });
        }
        if w <= previous {
            return Err(SpectralError::NotIncreasing {
                index,
                previous_nm: previous,
                next_nm: w,
            });
        }
        previous = w;
    }
    Ok(())
}

/// As many finite values as wavelengths.
pub(crate) fn validate_values(wavelength_nm: &[f64], values: &[f64]) -> Result<(), SpectralError> {
    if wavelength_nm.len() != values.len() {
        return Err(SpectralError::LengthMismatch {
            wavelengths: wavelength_nm.len(),
            values: values.len(),
        });
    }
    match values.iter().position(|v| !v.is_finite()) {
        Some(index) => Err(SpectralError::NonFinite {
            what: "value",
            index,
        }),
        None => Ok(()),
    }
}

/// Checks what every interpolator needs: equal lengths, finite numbers, strictly increasing
/// wavelengths, enough points. Returns whether the spacing is uniform (Sprague) or not (spline).
pub(crate) fn validate(wavelength_nm: &[f64], values: &[f64]) -> Result<bool, SpectralError> {
    validate_values(wavelength_nm, values)?;
    validate_grid(wavelength_nm)?;
    let uniform = is_uniform(wavelength_nm);
    let (needed, interpolator) = if uniform {
        (6, "Sprague")
    } else {
        (4, "cubic spline")
    };
    if wavelength_nm.len() < needed {
        return Err(SpectralError::TooFewPoints {
            points: wavelength_nm.len(),
            needed,
            interpolator,
        });
    }
    Ok(uniform)
}

/// colour's `is_uniform`: every step exactly equal to the first (fewer than 2 points count as uniform).
pub(crate) fn is_uniform(x: &[f64]) -> bool {
    let mut steps = x.windows(2).map(|p| (p[1] - p[0]).abs());
    match steps.next() {
        None => true,
        Some(first) => steps.all(|s| s == first),
    }
}

/// colour's Sprague weights for the five polynomial coefficients over six neighbours.
const SPRAGUE_W: [[f64; 6]; 5] = [
    [2.0, -16.0, 0.0, 16.0, -2.0, 0.0],
    [-1.0, 16.0, -30.0, 16.0, -1.0, 0.0],
    [-9.0, 39.0, -70.0, 66.0, -33.0, 7.0],
    [13.0, -64.0, 126.0, -124.0, 61.0, -12.0],
    [-5.0, 25.0, -50.0, 50.0, -25.0, 5.0],
];

/// colour's `SPRAGUE_C_COEFFICIENTS` for the two extra points at each end.
const SPRAGUE_C: [[f64; 6]; 4] = [
    [884.0, -1960.0, 3033.0, -2648.0, 1080.0, -180.0],
    [508.0, -540.0, 488.0, -367.0, 144.0, -24.0],
    [-24.0, 144.0, -367.0, 488.0, -540.0, 508.0],
    [-180.0, 1080.0, -2648.0, 3033.0, -1960.0, 884.0],
];

/// The Sprague interpolant over `n ≥ 6` uniformly spaced samples, with the padded node and
/// value arrays (`xp`, `yp`, length `n + 4`) addressed lazily instead of allocated.
struct Sprague<'a> {
    x: &'a [f64],
    y: &'a [f64],
    step: f64,
    /// yp1, yp2 (before the data) and yp3, yp4 (after).
    pad: [f64; 4],
}

impl<'a> Sprague<'a> {
    fn new(x: &'a [f64], y: &'a [f64]) -> Self {
        let n = y.len();
        let heads = [&y[0..6], &y[0..6], &y[n - 6..], &y[n - 6..]];
        let mut pad = [0.0; 4];
        for (k, p) in pad.iter_mut().enumerate() {
            let s: f64 = SPRAGUE_C[k].iter().zip(heads[k]).map(|(c, v)| c * v).sum();
            *p = s / 209.0;
        }
        Sprague {
            x,
            y,
            step: (x[1] - x[0]).abs(),
            pad,
        }
    }

    fn len_padded(&self) -> usize {
        self.x.len() + 4
    }

    /// `xp[j]`.
    fn xp(&self, j: usize) -> f64 {
        let n = self.x.len();
        match j {
            0 => self.x[0] - self.step * 2.0,
            1 => self.x[0] - self.step,
            _ if j < n + 2 => self.x[j - 2],
            _ if j == n + 2 => self.x[n - 1] + self.step,
            _ => self.x[n - 1] + self.step * 2.0,
        }
    }

    /// `yp[j]` with numpy's wrap-around for `j = -1` (it only occurs with a zero weight sum).
    fn yp(&self, j: isize) -> f64 {
        let n = self.y.len() as isize;
        let j = if j < 0 { j + n + 4 } else { j };
        match j {
            0 => self.pad[0],
            1 => self.pad[1],
            _ if j < n + 2 => self.y[(j - 2) as usize],
            _ if j == n + 2 => self.pad[2],
            _ => self.pad[3],
        }
    }

    /// Value at `t` given `i = searchsorted(xp, t) - 1`.
    fn eval_at(&self, i: usize, t: f64) -> f64 {
        let x0 = self.xp(i);
        let x1 = self.xp(i + 1);
        let big_x = (t - x0) / (x1 - x0);
        let ii = i as isize;
        let r_s = [
            self.yp(ii - 2),
            self.yp(ii - 1),
            self.yp(ii),
            self.yp(ii + 1),
            self.yp(ii + 2),
            self.yp(ii + 3),
        ];
        let mut y = 0.0;
        let mut power = 1.0;
        for w in &SPRAGUE_W {
            let a: f64 = w.iter().zip(&r_s).map(|(w, r)| w * r).sum::<f64>() / 24.0;
            power *= big_x;
            y += a * power;
        }
        self.yp(ii) + y
    }
}

/// The linear map from uniformly spaced values `y(x)` to `Σ_j weights[j]·Sprague(grid[j])`:
/// per data sample, per channel, its weight ([`for_each_on_grid`]'s uniform branch with the
/// values left symbolic: each grid value is the padded values around it times the Sprague
/// polynomial's coefficients, and each padded end value a combination of six data values).
pub(crate) fn sprague_kernel(
    x: &[f64],
    grid: &[f64],
    weights: &[[f64; 3]],
    kernel: &mut Vec<[f64; 3]>,
) {
    let n = x.len();
    kernel.clear();
    kernel.resize(n, [0.0; 3]);
    // The nodes only: `Sprague::xp` does not look at the values.
    let sp = Sprague::new(x, x);
    let add = |kernel: &mut Vec<[f64; 3]>, i: usize, w: &[f64; 3], f: f64| {
        let k = &mut kernel[i];
        k[0] += w[0] * f;
        k[1] += w[1] * f;
        k[2] += w[2] * f;
    };
    // padded value j (numpy's wrap-around for j = -1) times f, onto the data samples
    let add_padded = |kernel: &mut Vec<[f64; 3]>, j: isize, w: &[f64; 3], f: f64| {
        let j = if j < 0 { j + n as isize + 4 } else { j } as usize;
        let pad = match j {
            0 => Some((0, 0)),
            1 => Some((1, 0)),
            _ if j < n + 2 => None,
            _ if j == n + 2 => Some((2, n - 6)),
            _ => Some((3, n - 6)),
        };
        match pad {
            None => add(kernel, j - 2, w, f),
            Some((k, first)) => {
                for (q, c) in SPRAGUE_C[k].iter().enumerate() {
                    add(kernel, first + q, w, f * c / 209.0);
                }
            }
        }
    };
    let mut cnt = 0usize;
    for (j, &t) in grid.iter().enumerate() {
        let Some(w) = weights.get(j) else { break };
        if t < x[0] {
            add(kernel, 0, w, 1.0);
            continue;
        }
        if t > x[n - 1] {
            add(kernel, n - 1, w, 1.0);
            continue;
        }
        while cnt < sp.len_padded() && sp.xp(cnt) < t {
            cnt += 1;
        }
        let i = cnt.saturating_sub(1).max(1);
        let (x0, x1) = (sp.xp(i), sp.xp(i + 1));
        let big_x = (t - x0) / (x1 - x0);
        let mut coefficients = [0.0f64; 6];
        coefficients[2] = 1.0;
        let mut power = 1.0;
        for row in &SPRAGUE_W {
            power *= big_x;
            for (c, wm) in coefficients.iter_mut().zip(row) {
                *c += wm * power / 24.0;
            }
        }
        for (m, c) in coefficients.iter().enumerate() {
            add_padded(kernel, i as isize - 2 + m as isize, w, *c);
        }
    }
}

/// Not-a-knot cubic spline slopes (`scipy.interpolate.CubicSpline(bc_type="not-a-knot")`, the
/// same interpolant as `make_interp_spline(k=3)`), solved as a tridiagonal system in `O(n)`.
/// Needs `n ≥ 4`; `slopes` and `scratch` are resized to `n`.
fn spline_slopes(x: &[f64], y: &[f64], slopes: &mut Vec<f64>, scratch: &mut Vec<f64>) {
    let n = x.len();
    slopes.clear();
    slopes.resize(n, 0.0);
    scratch.clear();
    scratch.resize(n, 0.0);
    // Row i: lower·s[i-1] + diag·s[i] + upper·s[i+1] = rhs; Thomas elimination with `scratch`
    // holding the modified upper diagonal and `slopes` the modified right-hand side. The steps
    // and secant slopes of the previous row are carried along (one division per interval).
    let mut dx_prev = x[1] - x[0];
    let mut m_prev = (y[1] - y[0]) / dx_prev;
    let mut dx_cur = x[2] - x[1];
    let mut m_cur = (y[2] - y[1]) / dx_cur;
    {
        let d = x[2] - x[0];
        let rhs = ((dx_prev + 2.0 * d) * dx_cur * m_prev + dx_prev * dx_prev * m_cur) / d;
        let inv = 1.0 / dx_cur;
        scratch[0] = d * inv;
        slopes[0] = rhs * inv;
    }
    for i in 1..n - 1 {
        if i > 1 {
            dx_prev = dx_cur;
            m_prev = m_cur;
            dx_cur = x[i + 1] - x[i];
            m_cur = (y[i + 1] - y[i]) / dx_cur;
        }
        // Interior row i couples s[i-1], s[i], s[i+1] through dx[i-1] = dx_prev, dx[i] = dx_cur.
        let (lower, diag, upper) = (dx_cur, 2.0 * (dx_prev + dx_cur), dx_prev);
        let rhs = 3.0 * (dx_cur * m_prev + dx_prev * m_cur);
        let inv = 1.0 / (diag - lower * scratch[i - 1]);
        scratch[i] = upper * inv;
        slopes[i] = (rhs - lower * slopes[i - 1]) * inv;
    }
    {
        // Last row: dx_prev = dx[n-3], dx_cur = dx[n-2].
        let d = x[n - 1] - x[n - 3];
        let rhs = (dx_cur * dx_cur * m_prev + (2.0 * d + dx_cur) * dx_prev * m_cur) / d;
        let (lower, diag) = (d, dx_prev);
        let inv = 1.0 / (diag - lower * scratch[n - 2]);
        scratch[n - 1] = 0.0;
        slopes[n - 1] = (rhs - lower * slopes[n - 2]) * inv;
    }
    for i in (0..n - 1).rev() {
        slopes[i] -= scratch[i] * slopes[i + 1];
    }
}

/// The cubic of one spline segment in Horner form around its left end.
#[derive(Clone, Copy)]
struct Segment {
    x0: f64,
    c: [f64; 4],
}

impl Segment {
    fn new(x: &[f64], y: &[f64], s: &[f64], k: usize) -> Self {
        let h = x[k + 1] - x[k];
        let m = (y[k + 1] - y[k]) / h;
        let c2 = (3.0 * m - 2.0 * s[k] - s[k + 1]) / h;
        let c3 = (s[k] + s[k + 1] - 2.0 * m) / (h * h);
        Segment {
            x0: x[k],
            c: [y[k], s[k], c2, c3],
        }
    }

    fn eval(&self, t: f64) -> f64 {
        let u = t - self.x0;
        self.c[0] + u * (self.c[1] + u * (self.c[2] + u * self.c[3]))
    }
}

/// Samples kept on each side of the grid's span when solving the spline. The influence of a
/// sample on the spline decays at least by 1/2 per interval (the system is diagonally dominant
/// by a factor 2), so 48 samples away it is below 2^-48 ≈ 4e-15 of the values. Truncating there
/// changes the result by less than that (far less for real spacing, where the decay is about
/// 0.27 per sample), and a 300–40 000 nm file costs no more than its visible part.
const SPLINE_MARGIN: usize = 48;

thread_local! {
    /// Per-thread buffers for spline slopes, so that integrating a spectrum does not allocate
    /// once a thread has warmed up.
    static SCRATCH: RefCell<(Vec<f64>, Vec<f64>)> = const { RefCell::new((Vec::new(), Vec::new())) };
}

/// The end value `y` holds at `t` when `t` lies before the first or after the last sample.
#[inline]
fn end_value_beyond(x: &[f64], y: &[f64], t: f64) -> Option<f64> {
    let last = x.len() - 1;
    if t < x[0] {
        Some(y[0])
    } else if t > x[last] {
        Some(y[last])
    } else {
        None
    }
}

/// The sample range `lo..hi` the spline over `grid` needs: the samples covering the grid plus
/// [`SPLINE_MARGIN`] on each side, or all of them when that leaves fewer than four.
fn spline_window(x: &[f64], grid: &[f64]) -> (usize, usize) {
    let n = x.len();
    let (g0, g1) = (
        grid.first().copied().unwrap_or(x[0]),
        grid.last().copied().unwrap_or(x[n - 1]),
    );
    let lo = x.partition_point(|&w| w < g0).saturating_sub(SPLINE_MARGIN);
    let hi = (x.partition_point(|&w| w <= g1) + SPLINE_MARGIN).min(n);
    if hi - lo < 4 { (0, n) } else { (lo, hi) }
}

/// Evaluates the interpolant of validated data `(x, y)` at every ascending `grid` point and
/// hands `(grid index, value)` to `sink`. Grid points outside `[x[0], x[n-1]]` get the data's
/// end values (the caller decides whether that is allowed).
pub(crate) fn for_each_on_grid(
    x: &[f64],
    y: &[f64],
    uniform: bool,
    grid: &[f64],
    mut sink: impl FnMut(usize, f64),
) {
    if uniform {
        let sp = Sprague::new(x, y);
        // cnt = number of xp strictly below t (numpy searchsorted, side "left").
        let mut cnt = 0usize;
        for (j, &t) in grid.iter().enumerate() {
            if let Some(end) = end_value_beyond(x, y, t) {
                sink(j, end);
                continue;
            }
            while cnt < sp.len_padded() && sp.xp(cnt) < t {
                cnt += 1;
            }
            sink(j, sp.eval_at(cnt.saturating_sub(1).max(1), t));
        }
    } else {
        SCRATCH.with(|cell| {
            let mut guard = cell.borrow_mut();
            let (slopes, scratch) = &mut *guard;
            let (lo, hi) = spline_window(x, grid);
            let (xw, yw) = (&x[lo..hi], &y[lo..hi]);
            spline_slopes(xw, yw, slopes, scratch);
            let nw = xw.len();
            let mut k = 0usize;
            let mut seg = Segment::new(xw, yw, slopes, 0);
            for (j, &t) in grid.iter().enumerate() {
                if let Some(end) = end_value_beyond(x, y, t) {
                    sink(j, end);
                    continue;
                }
                if k + 2 < nw && xw[k + 1] < t {
                    while k + 2 < nw && xw[k + 1] < t {
                        k += 1;
                    }
                    seg = Segment::new(xw, yw, slopes, k);
                }
                sink(j, seg.eval(t));
            }
        });
    }
}

/// The spline path as a linear functional: `kernel[i][c]` is the weight of sample `y[i]` in
/// channel `c` of `Σ_j weights[j][c] · spline(grid[j])` (end values held outside the data).
/// Depends on the wavelengths only, so it is computed once per wavelength array and reused for
/// every spectrum on it (T, Rf, Rb of a glass; many products measured on one grid).
///
/// Derivation: inside segment `k` the spline is the cubic Hermite form
/// `y_k·h00 + y_{k+1}·h01 + h·s_k·h10 + h·s_{k+1}·h11`, so the channels are `αᵀy + βᵀs` with
/// `A·s = B·y` the not-a-knot system of [`spline_slopes`]; then `βᵀs = (A⁻ᵀβ)ᵀ B y`, one
/// transposed tridiagonal solve for all three channels.
pub(crate) fn spline_kernel(
    x: &[f64],
    grid: &[f64],
    weights: &[[f64; 3]],
    kernel: &mut Vec<[f64; 3]>,
) {
    let n = x.len();
    kernel.clear();
    kernel.resize(n, [0.0; 3]);
    let (lo, hi) = spline_window(x, grid);
    let xw = &x[lo..hi];
    let dxs: Vec<f64> = xw.windows(2).map(|p| p[1] - p[0]).collect();
    let beta = hermite_weights(x, (lo, hi), &dxs, grid, weights, kernel);
    let z = transposed_slopes_solve(xw, &dxs, beta);
    add_slope_weights(xw, &dxs, &z, &mut kernel[lo..]);
}

/// `dst += w · f`, per channel.
#[inline]
fn add3(dst: &mut [f64; 3], w: &[f64; 3], f: f64) {
    dst[0] += w[0] * f;
    dst[1] += w[1] * f;
    dst[2] += w[2] * f;
}

/// The Hermite form's weights: the samples' (α) go straight into `kernel`, the slopes' (β,
/// over the window `lo..hi` of `x`) are returned; grid points outside the data take the end
/// values.
fn hermite_weights(
    x: &[f64],
    (lo, hi): (usize, usize),
    dxs: &[f64],
    grid: &[f64],
    weights: &[[f64; 3]],
    kernel: &mut [[f64; 3]],
) -> Vec<[f64; 3]> {
    let n = x.len();
    let (first, last) = (x[0], x[n - 1]);
    let xw = &x[lo..hi];
    let nw = xw.len();
    let mut beta = vec![[0.0f64; 3]; nw];
    let mut k = 0usize;
    let mut inv_h = 1.0 / dxs[0];
    for (j, &t) in grid.iter().enumerate() {
        let Some(w) = weights.get(j) else { break };
        if t < first {
            add3(&mut kernel[0], w, 1.0);
            continue;
        }
        if t > last {
            add3(&mut kernel[n - 1], w, 1.0);
            continue;
        }
        if k + 2 < nw && xw[k + 1] < t {
            while k + 2 < nw && xw[k + 1] < t {
                k += 1;
            }
            inv_h = 1.0 / dxs[k];
        }
        let h = dxs[k];
        let u = (t - xw[k]) * inv_h;
        let (u2, u3) = (u * u, u * u * u);
        add3(&mut kernel[lo + k], w, 2.0 * u3 - 3.0 * u2 + 1.0);
        add3(&mut kernel[lo + k + 1], w, -2.0 * u3 + 3.0 * u2);
        add3(&mut beta[k], w, h * (u3 - 2.0 * u2 + u));
        add3(&mut beta[k + 1], w, h * (u3 - u2));
    }
    beta
}

/// Solves `Aᵀ z = β` (A: the not-a-knot rows of [`spline_slopes`] over the window `xw`) by
/// Thomas' algorithm, the three channels at once.
fn transposed_slopes_solve(xw: &[f64], dxs: &[f64], beta: Vec<[f64; 3]>) -> Vec<[f64; 3]> {
    let nw = xw.len();
    let dx = |i: usize| dxs[i];
    // Aᵀ (A: the rows of spline_slopes) as three diagonals: Aᵀ row i has
    // sub = upper_A(i-1), diag_A(i), super = lower_A(i+1).
    let diag_a = |i: usize| -> f64 {
        if i == 0 {
            dx(1)
        } else if i == nw - 1 {
            dx(nw - 3)
        } else {
            2.0 * (dx(i - 1) + dx(i))
        }
    };
    let upper_a = |i: usize| -> f64 { if i == 0 { xw[2] - xw[0] } else { dx(i - 1) } };
    let lower_a = |i: usize| -> f64 {
        if i == nw - 1 {
            xw[nw - 1] - xw[nw - 3]
        } else {
            dx(i)
        }
    };
    // Thomas on Aᵀ z = β: first the scalar chain (the only divisions), then the three
    // right-hand sides, which no longer wait on a division.
    let mut inv_m = vec![0.0f64; nw];
    let mut cprime = vec![0.0f64; nw];
    let mut c_prev = 0.0;
    for i in 0..nw {
        let m = if i == 0 {
            diag_a(0)
        } else {
            diag_a(i) - upper_a(i - 1) * c_prev
        };
        let inv = 1.0 / m;
        inv_m[i] = inv;
        c_prev = if i + 1 < nw {
            lower_a(i + 1) * inv
        } else {
            0.0
        };
        cprime[i] = c_prev;
    }
    let mut z = beta;
    let mut prev = [0.0f64; 3];
    for i in 0..nw {
        let sub = if i == 0 { 0.0 } else { upper_a(i - 1) };
        let zi = &mut z[i];
        for c in 0..3 {
            zi[c] = (zi[c] - sub * prev[c]) * inv_m[i];
        }
        prev = *zi;
    }
    for i in (0..nw - 1).rev() {
        let next = z[i + 1];
        for c in 0..3 {
            z[i][c] -= cprime[i] * next[c];
        }
    }
    z
}

/// Adds `Bᵀz` to the window's kernel: the right-hand side is linear in the secant slopes
/// `m_i = (y_{i+1} - y_i) / dx_i`.
fn add_slope_weights(xw: &[f64], dxs: &[f64], z: &[[f64; 3]], kernel: &mut [[f64; 3]]) {
    let nw = xw.len();
    let dx = |i: usize| dxs[i];
    let mut g = vec![[0.0f64; 3]; nw - 1];
    {
        let d = xw[2] - xw[0];
        add3(&mut g[0], &z[0], (dx(0) + 2.0 * d) * dx(1) / d);
        add3(&mut g[1], &z[0], dx(0) * dx(0) / d);
    }
    for i in 1..nw - 1 {
        add3(&mut g[i - 1], &z[i], 3.0 * dx(i));
        add3(&mut g[i], &z[i], 3.0 * dx(i - 1));
    }
    {
        let d = xw[nw - 1] - xw[nw - 3];
        add3(&mut g[nw - 3], &z[nw - 1], dx(nw - 2) * dx(nw - 2) / d);
        add3(
            &mut g[nw - 2],
            &z[nw - 1],
            (2.0 * d + dx(nw - 2)) * dx(nw - 3) / d,
        );
    }
    for (i, gi) in g.iter().enumerate() {
        let inv = 1.0 / dx(i);
        add3(&mut kernel[i + 1], gi, inv);
        add3(&mut kernel[i], gi, -inv);
    }
}

/// Resamples `values(wavelength_nm)` onto `grid_nm` (ascending) the way the integrators do:
/// Sprague or not-a-knot spline inside the data, the end values held constant outside it when
/// `extrapolate` is set (otherwise partial coverage is an error).
pub fn resample(
    wavelength_nm: &[f64],
    values: &[f64],
    grid_nm: &[f64],
    extrapolate: bool,
) -> Result<Vec<f64>, SpectralError> {
    let uniform = validate(wavelength_nm, values)?;
    check_coverage(wavelength_nm, grid_nm, extrapolate, "resampling")?;
    let mut out = vec![0.0; grid_nm.len()];
    for_each_on_grid(wavelength_nm, values, uniform, grid_nm, |j, v| out[j] = v);
    Ok(out)
}

/// Errors unless the data cover the grid (or overlap it, with `extrapolate`).
pub(crate) fn check_coverage(
    x: &[f64],
    grid: &[f64],
    extrapolate: bool,
    method: &str,
) -> Result<(), SpectralError> {
    let (Some(&g0), Some(&g1), Some(&x0), Some(&x1)) =
        (grid.first(), grid.last(), x.first(), x.last())
    else {
        return Ok(());
    };
    if x1 < g0 || x0 > g1 {
        return Err(SpectralError::NoOverlap {
            have_start_nm: x0,
            have_end_nm: x1,
            need_start_nm: g0,
            need_end_nm: g1,
        });
    }
    if !extrapolate && (x0 > g0 || x1 < g1) {
        return Err(SpectralError::PartialCoverage {
            method: method.to_owned(),
            have_start_nm: x0,
            have_end_nm: x1,
            need_start_nm: g0,
            need_end_nm: g1,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sprague_reproduces_nodes_and_quadratics() {
        // Sprague returns the samples at the nodes and reproduces low-order polynomials two
        // intervals away from the ends; in the end intervals colour's boundary points make it
        // deviate (colour.SpragueInterpolator gives 5.87421053e-04 at 401 nm here, not 1e-4).
        let x: Vec<f64> = (0..12).map(|i| 400.0 + 10.0 * i as f64).collect();
        let y: Vec<f64> = x.iter().map(|w| ((w - 400.0) / 100.0).powi(2)).collect();
        let grid: Vec<f64> = (400..=510).map(f64::from).collect();
        let out = resample(&x, &y, &grid, false).unwrap();
        for (g, v) in grid.iter().zip(&out) {
            let exact = ((g - 400.0) / 100.0).powi(2);
            let node = (g - 400.0) % 10.0 == 0.0;
            if node || (420.0..=490.0).contains(g) {
                assert!((v - exact).abs() < 1e-12, "{g}: {v} vs {exact}");
            }
        }
        assert!((out[1] - 5.87421053e-04).abs() < 1e-12);
    }

    #[test]
    fn spline_reproduces_cubics_exactly() {
        // Not-a-knot splines reproduce any cubic on any spacing.
        let x = [300.0, 310.0, 335.0, 360.0, 420.0, 421.0, 500.0, 800.0];
        let f = |w: f64| {
            0.2 + 1e-3 * (w - 500.0) - 2e-6 * (w - 500.0).powi(2) + 3e-9 * (w - 500.0).powi(3)
        };
        let y: Vec<f64> = x.iter().map(|&w| f(w)).collect();
        let grid: Vec<f64> = (300..=800).map(f64::from).collect();
        let out = resample(&x, &y, &grid, false).unwrap();
        for (g, v) in grid.iter().zip(&out) {
            assert!((v - f(*g)).abs() < 1e-12, "{g}: {v} vs {}", f(*g));
        }
    }

    #[test]
    fn four_point_spline_is_the_interpolating_cubic() {
        let x = [1.0, 2.0, 4.0, 7.0];
        let y = [1.0, -1.0, 2.0, 0.5];
        // Lagrange cubic through the four points.
        let lag = |t: f64| {
            let mut s = 0.0;
            for i in 0..4 {
                let mut l = 1.0;
                for j in 0..4 {
                    if i != j {
                        l *= (t - x[j]) / (x[i] - x[j]);
                    }
                }
                s += y[i] * l;
            }
            s
        };
        let grid = [1.0, 1.5, 3.0, 5.5, 7.0];
        let out = resample(&x, &y, &grid, false).unwrap();
        for (g, v) in grid.iter().zip(&out) {
            assert!((v - lag(*g)).abs() < 1e-12);
        }
    }

    /// `sprague_kernel` or `spline_kernel`.
    type KernelBuilder = fn(&[f64], &[f64], &[[f64; 3]], &mut Vec<[f64; 3]>);

    /// `Σ kernel·y` against the direct evaluation of the same interpolant onto `grid`, for a
    /// wiggly spectrum on `x` and arbitrary weights.
    fn assert_kernel_is_direct(
        x: &[f64],
        grid: &[f64],
        uniform: bool,
        build: KernelBuilder,
        rel_tol: f64,
    ) {
        let y: Vec<f64> = x
            .iter()
            .map(|w| 0.5 + 0.3 * (w / 37.0).sin() * (w / 211.0).cos())
            .collect();
        let weights: Vec<[f64; 3]> = grid
            .iter()
            .map(|g| [1.0, (g / 50.0).sin(), 1e-3 * g])
            .collect();
        let mut direct = [0.0; 3];
        for_each_on_grid(x, &y, uniform, grid, |j, v| {
            for (d, w) in direct.iter_mut().zip(&weights[j]) {
                *d += w * v;
            }
        });
        let mut kernel = Vec::new();
        build(x, grid, &weights, &mut kernel);
        for (c, d) in direct.iter().enumerate() {
            let k: f64 = kernel.iter().zip(&y).map(|(k, v)| k[c] * v).sum();
            assert!(
                (k - d).abs() < rel_tol * d.abs().max(1.0),
                "{c}: {k} vs {d}"
            );
        }
    }

    #[test]
    fn sprague_kernel_equals_direct_evaluation() {
        let x: Vec<f64> = (0..120).map(|i| 300.0 + 5.0 * f64::from(i)).collect();
        let grid: Vec<f64> = (250..=950).map(|g| f64::from(g) + 0.3).collect();
        assert_kernel_is_direct(&x, &grid, true, sprague_kernel, 1e-10);
    }

    #[test]
    fn spline_kernel_equals_direct_evaluation() {
        // Irregular grid 300–2500 nm with a wiggly spectrum; grid 360–780 plus points outside.
        let mut x: Vec<f64> = (0..60).map(|i| 300.0 + 5.0 * f64::from(i)).collect();
        x.extend((0..=170).map(|i| 600.0 + 11.0 * f64::from(i)));
        let grid: Vec<f64> = (250..=800).map(f64::from).collect();
        assert_kernel_is_direct(&x, &grid, false, spline_kernel, 1e-11);
    }

    #[test]
    fn too_few_points_and_bad_order_are_errors() {
        assert!(matches!(
            resample(&[1.0, 2.0, 3.0, 4.0, 5.0], &[0.0; 5], &[2.0], false),
            Err(SpectralError::TooFewPoints { needed: 6, .. })
        ));
        assert!(matches!(
            resample(&[1.0, 2.0, 4.0], &[0.0; 3], &[2.0], false),
            Err(SpectralError::TooFewPoints { needed: 4, .. })
        ));
        assert!(matches!(
            resample(&[1.0, 3.0, 2.0, 4.0], &[0.0; 4], &[2.0], false),
            Err(SpectralError::NotIncreasing { .. })
        ));
        assert!(matches!(
            resample(&[1.0, 2.0, 3.5, f64::NAN], &[0.0; 4], &[2.0], false),
            Err(SpectralError::NonFinite { .. })
        ));
    }
}
