//! Section "Polynomial degree and basis against exact physics": the fit error of each degree in
//! the paper and the full basis, what `glassdb fit` chooses, and what evaluating costs.

use std::fmt::Write as _;

use glassdb_fit::{Basis, FitOptions, Quantity, cos_deg, fit_curve};
use glassdb_registry::Side;

use crate::measure::{dense_angles, max_abs_diff, ns_per_value};
use crate::reference::{Reference, fit_fixed, samples};
use crate::text::fmt_err;

/// Writes the section: one degree table per reference, then the evaluation cost.
pub(crate) fn section_degree_basis(md: &mut String, refs: &[Reference], inputs: &[f64]) {
    let _ = writeln!(md, "## Polynomial degree and basis against exact physics\n");
    let _ = writeln!(
        md,
        "Each reference sampled at 0–90° in 1° steps (91 points) and fitted by `glassdb_fit::fit_curve` \
         at a fixed degree n in the paper basis (powers 1…n, no constant: the paper's eqs. 12–13) and \
         the full basis (powers 0…n); the table gives max |fit − exact| over 0–89° (0.05° grid) and \
         where it occurs. The paper basis forces C(90°) = 0, so its reflectance error near grazing \
         stays large at every degree.\n"
    );
    let grid = dense_angles(89.0, 0.05);
    for r in refs {
        degree_table(md, r, &grid);
    }
    evaluation_cost(md, refs, inputs);
}

/// The quantities of a fit, in the order of the table's columns.
const QUANTITIES: [Quantity; 2] = [Quantity::Reflectance, Quantity::Transmittance];

/// One reference: max |fit − exact| per degree and basis, then `glassdb fit`'s defaults.
fn degree_table(md: &mut String, r: &Reference, grid: &[f64]) {
    let _ = writeln!(md, "### {}\n", r.name);
    let _ = writeln!(md, "| n | r, paper | r, full | t, paper | t, full |");
    let _ = writeln!(md, "|---|---|---|---|---|");
    let sampled = QUANTITIES.map(|q| samples(r, q));
    for degree in 1..=8u32 {
        let mut cells = Vec::new();
        for (s, q) in sampled.iter().zip(QUANTITIES) {
            for basis in [Basis::Paper, Basis::Full] {
                cells.push(match fit_fixed(s, q, degree, basis) {
                    Some(f) => fmt_err(max_abs_diff(
                        grid,
                        |a| f.eval_angle_deg(a),
                        |a| r.eval_quantity(q, cos_deg(a)),
                    )),
                    None => "—".into(),
                });
            }
        }
        // cells: r paper, r full, t paper, t full (the header's order).
        let _ = writeln!(md, "| {degree} | {} |", cells.join(" | "));
    }
    // What glassdb fit chooses by default.
    let mut defaults = Vec::new();
    for (s, q) in sampled.iter().zip(QUANTITIES) {
        if let Ok(f) = fit_curve(s, &FitOptions::new(q)) {
            let e = max_abs_diff(
                grid,
                |a| f.eval_angle_deg(a),
                |a| r.eval_quantity(q, cos_deg(a)),
            );
            defaults.push(format!(
                "{}: {} basis, n = {} → {}",
                q.name(),
                f.polynomial.basis.name(),
                f.polynomial.degree(),
                fmt_err(e)
            ));
        }
    }
    let _ = writeln!(
        md,
        "\n`glassdb fit` defaults (tol 0.002, max degree 8): {}.\n",
        defaults.join("; ")
    );
}

/// Subsection "Evaluation cost": the curve's Horner evaluation, and a whole pixel.
fn evaluation_cost(md: &mut String, refs: &[Reference], inputs: &[f64]) {
    let _ = writeln!(md, "### Evaluation cost\n");
    let _ = writeln!(
        md,
        "Time per value of `CosPolynomial::eval` (Horner; the registry's curves are the same \
         type), and per pixel of `GlassRecord::eval` (r and t of three channels, clamped to the \
         physical range), over pseudo-random cos θ (θ uniform in 0–89°).\n"
    );
    let _ = writeln!(md, "| n (full basis) | CosPolynomial::eval ns/value |");
    let _ = writeln!(md, "|---|---|");
    let sr = samples(&refs[0], Quantity::Reflectance);
    for degree in [2u32, 4, 6, 8] {
        let Some(fr) = fit_fixed(&sr, Quantity::Reflectance, degree, Basis::Full) else {
            continue;
        };
        let poly = fr.polynomial.clone();
        let horner = ns_per_value(inputs, |c| poly.eval(c));
        let _ = writeln!(md, "| {degree} | {horner:.2} |");
    }
    let _ = writeln!(md);
    pixel_cost(md, inputs);
}

/// Per-pixel cost of `GlassRecord::eval` for the first glasses of the default registry.
fn pixel_cost(md: &mut String, inputs: &[f64]) {
    match glassdb_registry::default_registry() {
        Ok(reg) => {
            for g in reg.default_table().glasses.iter().take(4) {
                let degrees: Vec<String> = g
                    .c_r
                    .iter()
                    .chain(&g.c_t)
                    .map(|c| c.fit.degree.to_string())
                    .collect();
                let pixel = ns_per_value(inputs, |c| {
                    let (r, t) = g.eval(Side::Front, c);
                    r[0] + r[1] + r[2] + t[0] + t[1] + t[2]
                });
                let _ = writeln!(
                    md,
                    "- `GlassRecord::eval` of default-registry glass {} (curve degrees r: {}, t: {}): {pixel:.1} ns per pixel (r and t, three channels).",
                    g.label(),
                    degrees[..3].join("/"),
                    degrees[3..].join("/")
                );
            }
            let _ = writeln!(md);
        }
        Err(e) => {
            let _ = writeln!(
                md,
                "(default registry unavailable for the per-pixel timing: {})\n",
                glassdb_io::ErrorChain(&e)
            );
        }
    }
}
