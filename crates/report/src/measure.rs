//! How the report measures: dense angle grids, the largest difference over them, and
//! single-threaded timings over deterministic inputs, with the machine they ran on.

use std::hint::black_box;
use std::time::Instant;

/// Dense angle grid 0…`max_deg` in `step_deg` steps.
pub(crate) fn dense_angles(max_deg: f64, step_deg: f64) -> Vec<f64> {
    let n = (max_deg / step_deg).round() as usize;
    (0..=n)
        .map(|k| (k as f64 * step_deg).min(max_deg))
        .collect()
}

/// Largest |f(θ) − g(θ)| over the angles, and where.
pub(crate) fn max_abs_diff(
    angles: &[f64],
    f: impl Fn(f64) -> f64,
    g: impl Fn(f64) -> f64,
) -> (f64, f64) {
    let mut worst = (0.0, 0.0);
    for &a in angles {
        let d = (f(a) - g(a)).abs();
        if d.is_nan() || d > worst.0 {
            worst = (d, a);
        }
    }
    worst
}

/// Deterministic pseudo-random cos θ values (θ uniform in 0–89°): the timing inputs.
pub(crate) fn timing_inputs(n: usize) -> Vec<f64> {
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    (0..n)
        .map(|_| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            (u * 89.0).to_radians().cos()
        })
        .collect()
}

/// Best-of-5 time per value (ns) of `f` mapped over `inputs` into an output buffer.
pub(crate) fn ns_per_value(inputs: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut out = vec![0.0f64; inputs.len()];
    let mut best = f64::INFINITY;
    for _ in 0..6 {
        let xs = black_box(inputs);
        let t = Instant::now();
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = f(x);
        }
        black_box(&out);
        best = best.min(t.elapsed().as_secs_f64());
    }
    best * 1e9 / inputs.len().max(1) as f64
}

/// The machine and build of this run, for the page's header.
pub(crate) fn machine_line() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let profile = if cfg!(debug_assertions) {
        "debug build: timings NOT representative, rerun with --release"
    } else {
        "release build"
    };
    format!(
        "{cpu}, {threads} hardware threads available, {} {}, {profile}; timings single-threaded",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}
