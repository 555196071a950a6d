//! Test inputs shared by the fit crate's tests and the command-line tests (`tests/cli/fit.rs`
//! includes this file by path), so that both check the same tables.

/// Deterministic N(0, 1) draws (64-bit LCG + Box–Muller), so the tests never change.
pub fn gaussian(seed: u64, n: usize) -> Vec<f64> {
    let mut state = seed;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2) = (uniform(), uniform());
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        })
        .collect()
}

/// An angle table (R and T at 0°, 10°, …, 90°) with R = 0.1 + 0.001·i and
/// T = `t_at_normal` − 0.001·i at 10·i degrees: R + T = 0.1 + `t_at_normal` at every angle.
pub fn r_plus_t_csv(t_at_normal: f64) -> String {
    let rows: String = (0..=9)
        .map(|i| {
            format!(
                "{},{},{}\n",
                i * 10,
                0.1 + 0.001 * i as f64,
                t_at_normal - 0.001 * i as f64
            )
        })
        .collect();
    format!("angle_deg,R,T\n{rows}")
}

/// The table of [`r_plus_t_csv`] with R + T = 1.02 at every angle, so the fitted r + t
/// exceeds 1.
pub fn r_plus_t_above_one_csv() -> String {
    r_plus_t_csv(0.92)
}
