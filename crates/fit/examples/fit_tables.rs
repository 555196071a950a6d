//! Prints the measured tables of `docs/fit.md`: for each bundled angle table and curve,
//! degree × basis → max |fitted − measured| over all data, over 0–85°, at the data's last
//! angle, leave-one-out RMS and the condition numbers; then what the defaults choose.
//!
//!     cargo run --release -p glassdb-fit --example fit_tables [TABLE.csv ...]

use std::path::PathBuf;

use glassdb_fit::{AngleSamples, Basis, FitOptions, Quantity, fit_curve, read_angle_table};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if files.is_empty() {
        files = vec![
            root.join("data/angles/clear_6mm_fresnel.csv"),
            root.join("data/angles/bronze_coated_window4.csv"),
        ];
    }
    for f in files {
        for table in read_angle_table(&f, false)? {
            for (q, s) in [
                (Quantity::Reflectance, &table.reflectance),
                (Quantity::Transmittance, &table.transmittance),
            ] {
                let Some(s) = s else { continue };
                println!(
                    "\n### {} — {} ({} angles)\n",
                    table.name,
                    q.name(),
                    s.angle_deg.len()
                );
                println!(
                    "| degree | basis | max err (all data) | max err 0–85° | err at {}° | LOO RMS | cond (solved) | cond (power basis) |",
                    s.angle_deg.last().copied().unwrap_or(90.0)
                );
                println!("|---:|---|---:|---:|---:|---:|---:|---:|");
                let max_deg = (s.angle_deg.len() as u32).saturating_sub(1).min(12);
                for d in 1..=max_deg {
                    for b in [Basis::Paper, Basis::Full] {
                        let opts = FitOptions {
                            degree: Some(d),
                            basis: Some(b),
                            ..FitOptions::new(q)
                        };
                        match fit_curve(s, &opts) {
                            Ok(c) => {
                                let e85 = max_err(s, |a| c.eval_angle_deg(a), 85.0);
                                let last = s.angle_deg.len() - 1;
                                let elast = c.eval_angle_deg(s.angle_deg[last]) - s.value[last];
                                println!(
                                    "| {d} | {} | {:.2e} | {:.2e} | {:+.2e} | {} | {:.3} | {:.3e} |",
                                    b.name(),
                                    c.diagnostics.summary.max_abs_error,
                                    e85,
                                    elast,
                                    c.diagnostics
                                        .loo_rms_error
                                        .map_or("-".into(), |v| format!("{v:.2e}")),
                                    c.diagnostics.summary.condition_number,
                                    c.diagnostics
                                        .power_basis_condition_number
                                        .unwrap_or(f64::NAN)
                                );
                            }
                            Err(e) => println!("| {d} | {} | {e} | | | | | |", b.name()),
                        }
                    }
                }
                if q == Quantity::Reflectance {
                    let probe: Vec<f64> = [45.0, 60.0, 70.0, 80.0, 85.0, 89.0, 90.0]
                        .into_iter()
                        .filter(|a| s.angle_deg.contains(a))
                        .collect();
                    println!("\nfitted − measured near grazing incidence:\n");
                    println!(
                        "| degree | basis |{}",
                        probe.iter().map(|a| format!(" {a}° |")).collect::<String>()
                    );
                    println!("|---:|---|{}", "---:|".repeat(probe.len()));
                    for d in [4u32, 6, 8] {
                        for b in [Basis::Paper, Basis::Full] {
                            let opts = FitOptions {
                                degree: Some(d),
                                basis: Some(b),
                                ..FitOptions::new(q)
                            };
                            let Ok(c) = fit_curve(s, &opts) else { continue };
                            let cells: String = probe
                                .iter()
                                .map(|&a| {
                                    let i = s.angle_deg.iter().position(|&x| x == a).unwrap_or(0);
                                    format!(" {:+.4} |", c.eval_angle_deg(a) - s.value[i])
                                })
                                .collect();
                            println!("| {d} | {} |{cells}", b.name());
                        }
                    }
                }
                let c = fit_curve(s, &FitOptions::new(q))?;
                println!(
                    "\ndefault: {} basis, degree {} ({}), max err {:.2e} at {}°, max err 0–85° {:.2e}",
                    c.polynomial.basis.name(),
                    c.diagnostics.summary.degree,
                    c.diagnostics.degree_selection,
                    c.diagnostics.summary.max_abs_error,
                    c.diagnostics.summary.max_error_angle_deg,
                    max_err(s, |a| c.eval_angle_deg(a), 85.0)
                );
            }
        }
    }
    Ok(())
}

fn max_err(s: &AngleSamples, f: impl Fn(f64) -> f64, up_to: f64) -> f64 {
    s.angle_deg
        .iter()
        .zip(&s.value)
        .filter(|(a, _)| **a <= up_to)
        .map(|(&a, &v)| (f(a) - v).abs())
        .fold(0.0, f64::max)
}
