//! The not-a-knot cubic spline of irregularly spaced spectra (`scipy.interpolate.interp1d(kind =
//! "cubic")`): its slopes, its evaluation segment by segment over the window of the data a grid
//! needs, and the same spline as a linear functional of the samples (the integrators' kernel).

/// Not-a-knot cubic spline slopes (`scipy.interpolate.CubicSpline(bc_type="not-a-knot")`, the
/// same interpolant as `make_interp_spline(k=3)`), solved as a tridiagonal system in `O(n)`.
/// Needs `n ≥ 4`; `slopes` and `scratch` are resized to `n`.
pub(crate) fn spline_slopes(x: &[f64], y: &[f64], slopes: &mut Vec<f64>, scratch: &mut Vec<f64>) {
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
pub(crate) struct Segment {
    x0: f64,
    c: [f64; 4],
}

impl Segment {
    pub(crate) fn new(x: &[f64], y: &[f64], s: &[f64], k: usize) -> Self {
        let h = x[k + 1] - x[k];
        let m = (y[k + 1] - y[k]) / h;
        let c2 = (3.0 * m - 2.0 * s[k] - s[k + 1]) / h;
        let c3 = (s[k] + s[k + 1] - 2.0 * m) / (h * h);
        Segment {
            x0: x[k],
            c: [y[k], s[k], c2, c3],
        }
    }

    pub(crate) fn eval(&self, t: f64) -> f64 {
        let u = t - self.x0;
        self.c[0] + u * (self.c[1] + u * (self.c[2] + u * self.c[3]))
    }
}

/// Samples kept on each side of the grid's span when solving the spline. The influence of a
/// sample on the spline decays at least by 1/2 per interval (the system is diagonally dominant
/// by a factor 2), so 48 samples away it is below 2^-48 ≈ 4e-15 of the values. Truncating there
/// changes the result by less than that (far less for real spacing, where the decay is about
/// 0.27 per sample), and a 300–40 000 nm file costs no more than its visible part.
pub(crate) const SPLINE_MARGIN: usize = 48;

/// The end value `y` holds at `t` when `t` lies before the first or after the last sample.
#[inline]
pub(crate) fn end_value_beyond(x: &[f64], y: &[f64], t: f64) -> Option<f64> {
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
pub(crate) fn spline_window(x: &[f64], grid: &[f64]) -> (usize, usize) {
    let n = x.len();
    let (g0, g1) = (
        grid.first().copied().unwrap_or(x[0]),
        grid.last().copied().unwrap_or(x[n - 1]),
    );
    let lo = x.partition_point(|&w| w < g0).saturating_sub(SPLINE_MARGIN);
    let hi = (x.partition_point(|&w| w <= g1) + SPLINE_MARGIN).min(n);
    if hi - lo < 4 { (0, n) } else { (lo, hi) }
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
pub(crate) fn spline_kernel(x: &[f64], grid: &[f64], weights: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut kernel = vec![[0.0; 3]; x.len()];
    let (lo, hi) = spline_window(x, grid);
    let xw = &x[lo..hi];
    let dxs: Vec<f64> = xw.windows(2).map(|p| p[1] - p[0]).collect();
    let beta = hermite_weights(x, (lo, hi), &dxs, grid, weights, &mut kernel);
    let z = transposed_slopes_solve(xw, &dxs, beta);
    add_slope_weights(xw, &dxs, &z, &mut kernel[lo..]);
    kernel
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
