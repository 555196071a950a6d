//! Measures the screen for inconsistent readings (`docs/fit.md`, "Inconsistent points") on
//! every bundled and fixture angle table, and on the same tables with one typo each: for every
//! reading of every table, a digit dropped (÷10), the decimal point shifted right (×10), percent
//! in a fraction column (×100), and R and T swapped on its row. Three detectors are compared:
//!
//! - the reader and the screen as `glassdb fit` runs them (`parse_angle_table`, then
//!   `GlassAngleTable::screen`: the monotonic bound);
//! - a leave-one-out residual against a robust scale: each reading predicted by a full-basis
//!   cubic fitted without it, flagged when the prediction misses it by more than 8 × 1.4826 ×
//!   the median miss and by more than 0.03;
//! - the reader and the fit's own suspect points (externally studentized residuals of the
//!   chosen fit): the detectors before the screen.
//!
//!     cargo run --release -p glassdb-fit --example typo_screen [-- --misses]
//!
//! A typo counts where it changes the value by more than 0.02 (smaller ones are within what
//! the fit tolerates); it is found when the detector names that reading and nothing else.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glassdb_fit::{
    AngleSamples, Basis, FitOptions, GlassAngleTable, Quantity, fit_curve, parse_angle_table,
    read_angle_table,
};

#[path = "../tests/common/inputs.rs"]
#[allow(dead_code)] // the shared inputs include tables this example does not use
mod inputs;

/// One glass's readings: (angle, R, T), ascending.
type Rows = Vec<(f64, Option<f64>, Option<f64>)>;

fn rows_of(t: &GlassAngleTable) -> Rows {
    t.rows
        .iter()
        .map(|r| {
            let at = |s: &Option<AngleSamples>| {
                s.as_ref().and_then(|s| {
                    s.angle_deg
                        .iter()
                        .position(|&a| a == r.angle_deg)
                        .map(|i| s.value[i])
                })
            };
            (r.angle_deg, at(&t.reflectance), at(&t.transmittance))
        })
        .collect()
}

/// The table as CSV text: the header on line 1, reading i on line i + 2.
fn csv(rows: &Rows) -> String {
    let cell = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v}"));
    let mut s = String::from("angle_deg,R,T\n");
    for &(a, r, t) in rows {
        s.push_str(&format!("{a},{},{}\n", cell(r), cell(t)));
    }
    s
}

/// What a detector names: (quantity, angle) pairs, or the lines a reader error names.
#[derive(Default)]
struct Named {
    readings: Vec<(Quantity, f64)>,
    lines: Vec<u64>,
}

/// The lines a reader error names.
fn error_lines(e: &glassdb_fit::FitError) -> Vec<u64> {
    e.to_string()
        .split("line ")
        .skip(1)
        .filter_map(|s| s.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok())
        .collect()
}

fn shipped(text: &str) -> Named {
    let mut named = Named::default();
    match parse_angle_table(text.as_bytes(), Path::new("t.csv"), "t", false) {
        Err(e) => named.lines = error_lines(&e),
        Ok(tables) => {
            for t in &tables {
                let s = t.screen();
                named
                    .readings
                    .extend(s.points.iter().map(|p| (p.quantity, p.angle_deg)));
                for q in s.reversed {
                    named.readings.push((q, f64::NAN));
                }
            }
        }
    }
    named
}

fn samples(rows: &Rows, q: Quantity) -> AngleSamples {
    let mut s = AngleSamples::default();
    for &(a, r, t) in rows {
        let v = if q == Quantity::Reflectance { r } else { t };
        if let Some(v) = v {
            s.angle_deg.push(a);
            s.value.push(v);
        }
    }
    s
}

fn leave_one_out(rows: &Rows) -> Named {
    let mut named = Named::default();
    for q in [Quantity::Reflectance, Quantity::Transmittance] {
        let s = samples(rows, q);
        let n = s.angle_deg.len();
        if n < 6 {
            continue;
        }
        let opts = FitOptions {
            degree: Some(3),
            basis: Some(Basis::Full),
            ..FitOptions::new(q)
        };
        let misses: Vec<f64> = (0..n)
            .map(|i| {
                let mut rest = s.clone();
                rest.angle_deg.remove(i);
                rest.value.remove(i);
                fit_curve(&rest, &opts)
                    .map_or(f64::NAN, |c| s.value[i] - c.eval_angle_deg(s.angle_deg[i]))
            })
            .collect();
        let mut abs: Vec<f64> = misses.iter().map(|m| m.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let scale = 1.4826 * abs[n / 2];
        for (i, m) in misses.iter().enumerate() {
            if m.abs() > 8.0 * scale && m.abs() > 0.03 {
                named.readings.push((q, s.angle_deg[i]));
            }
        }
    }
    named
}

fn suspects(text: &str) -> Named {
    let mut named = Named::default();
    // the reader names a value above 1 either way (before: as a table in percent)
    let tables = match parse_angle_table(text.as_bytes(), Path::new("t.csv"), "t", false) {
        Ok(tables) => tables,
        Err(e) => {
            named.lines = error_lines(&e);
            return named;
        }
    };
    for t in &tables {
        for (q, s) in [
            (Quantity::Reflectance, &t.reflectance),
            (Quantity::Transmittance, &t.transmittance),
        ] {
            if let Some(c) = s
                .as_ref()
                .and_then(|s| fit_curve(s, &FitOptions::new(q)).ok())
            {
                named.readings.extend(
                    c.diagnostics
                        .suspect_points
                        .iter()
                        .map(|p| (q, p.angle_deg)),
                );
            }
        }
    }
    named
}

/// Found (only the typo's readings named), found among others, missed; and how often
/// `glassdb fit` refuses the table by any of its checks (reader, screen, fit far from the data,
/// unphysical fit).
#[derive(Default, Clone, Copy)]
struct Score {
    cases: usize,
    exact: usize,
    extra: usize,
    refused: usize,
}

/// Scores one typo case `(sparse, kind)` with the three screens: the shipped one (counting
/// whether it refuses the table), leave-one-out and the suspects. True when the shipped screen
/// found nothing (a miss).
fn score_case(
    scores: &mut BTreeMap<(bool, usize, usize), Score>,
    (sparse, k): (bool, usize),
    typo: &Rows,
    want: &[(Quantity, f64)],
    line: u64,
) -> bool {
    let text = csv(typo);
    let s = scores.entry((sparse, k, 0)).or_default();
    let found = s.exact + s.extra;
    s.refused += usize::from(refused(&text));
    score(s, &shipped(&text), want, line);
    let missed = s.exact + s.extra == found;
    score(
        scores.entry((sparse, k, 1)).or_default(),
        &leave_one_out(typo),
        want,
        line,
    );
    score(
        scores.entry((sparse, k, 2)).or_default(),
        &suspects(&text),
        want,
        line,
    );
    missed
}

/// True when `glassdb fit`'s defaults refuse the table (any check).
fn refused(text: &str) -> bool {
    match parse_angle_table(text.as_bytes(), Path::new("t.csv"), "t", false) {
        Err(_) => true,
        Ok(tables) => tables
            .iter()
            .any(|t| glassdb_fit::fit_glass(t, &glassdb_fit::GlassFitOptions::default()).is_err()),
    }
}

fn score(score: &mut Score, named: &Named, want: &[(Quantity, f64)], line: u64) {
    score.cases += 1;
    let hit = |&(q, a): &(Quantity, f64)| named.readings.contains(&(q, a));
    if !named.lines.is_empty() {
        if named.lines == [line] {
            score.exact += 1;
        } else if named.lines.contains(&line) {
            score.extra += 1;
        }
    } else if want.iter().any(hit) {
        if named.readings.iter().all(|r| want.contains(r)) {
            score.exact += 1;
        } else {
            score.extra += 1;
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let list_misses = std::env::args().any(|a| a == "--misses");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut tables: Vec<(String, Rows)> = Vec::new();
    for (rel, percent) in [
        ("data/angles/clear_6mm_fresnel.csv", false),
        ("data/angles/bronze_coated_window4.csv", false),
        ("fixtures/atrium/angles_clear.csv", false),
        ("fixtures/atrium/angles_tinted.csv", false),
        ("fixtures/fit/two_glasses_percent.csv", true),
    ] {
        for t in read_angle_table(&root.join(rel), percent)? {
            let name = rel.rsplit('/').next().unwrap_or(rel);
            tables.push((format!("{name} ({})", t.name), rows_of(&t)));
        }
    }
    // the flagship table as a hand-written one would sample it
    let clear = tables[0].1.clone();
    for step in [5.0, 10.0, 15.0] {
        let rows = clear
            .iter()
            .copied()
            .filter(|r| r.0 % step == 0.0)
            .collect();
        tables.push((format!("clear_6mm_fresnel.csv every {step}°"), rows));
    }

    // measurement noise: the flagship table with σ = 0.002 (the default tolerance) and 0.004
    // added to every reading but the 0° one, five seeds each
    let mut noisy: Vec<(String, Rows)> = Vec::new();
    for sigma in [0.002, 0.004] {
        for seed in 1..=5u64 {
            let noise = inputs::gaussian(seed, 2 * clear.len());
            let rows = clear
                .iter()
                .enumerate()
                .map(|(i, &(a, r, t))| {
                    let add = |v: Option<f64>, k: usize| {
                        v.map(|v| {
                            if a == 0.0 {
                                v
                            } else {
                                (v + sigma * noise[k]).clamp(0.0, 1.0)
                            }
                        })
                    };
                    (a, add(r, 2 * i), add(t, 2 * i + 1))
                })
                .collect();
            noisy.push((
                format!("clear_6mm_fresnel.csv + noise σ = {sigma}, seed {seed}"),
                rows,
            ));
        }
    }
    println!("Clean tables (nothing should be named):\n");
    println!(
        "| table | readings | reader + screen | leave-one-out | reader + fit's suspect points | `glassdb fit` refuses |"
    );
    println!("|---|---:|---|---|---|---|");
    for (name, rows) in tables.iter().chain(&noisy) {
        let text = csv(rows);
        let show = |n: Named| {
            if n.readings.is_empty() && n.lines.is_empty() {
                "none".to_string()
            } else {
                let mut v: Vec<String> = n
                    .readings
                    .iter()
                    .map(|(q, a)| format!("{} {a}°", &q.name()[..1].to_uppercase()))
                    .collect();
                v.extend(n.lines.iter().map(|l| format!("line {l}")));
                v.join(", ")
            }
        };
        println!(
            "| {name} | {} | {} | {} | {} | {} |",
            rows.len(),
            show(shipped(&text)),
            show(leave_one_out(rows)),
            show(suspects(&text)),
            if refused(&text) { "yes" } else { "no" }
        );
    }

    let kinds: [(&str, f64); 3] = [
        ("digit dropped (÷10)", 0.1),
        ("decimal point shifted (×10)", 10.0),
        ("percent in a fraction column (×100)", 100.0),
    ];
    let mut scores: BTreeMap<(bool, usize, usize), Score> = BTreeMap::new();
    for (name, rows) in &tables {
        let sparse = rows.len() <= 10;
        for i in 0..rows.len() {
            let line = i as u64 + 2;
            for (k, &(_, factor)) in kinds.iter().enumerate() {
                for q in [Quantity::Reflectance, Quantity::Transmittance] {
                    let mut typo = rows.clone();
                    let cell = if q == Quantity::Reflectance {
                        &mut typo[i].1
                    } else {
                        &mut typo[i].2
                    };
                    let Some(v) = *cell else { continue };
                    if (v * factor - v).abs() <= 0.02 {
                        continue;
                    }
                    *cell = Some(v * factor);
                    let want = [(q, rows[i].0)];
                    let missed = score_case(&mut scores, (sparse, k), &typo, &want, line);
                    if list_misses && missed {
                        eprintln!(
                            "screen misses: {name}: {} {}° {v} × {factor}",
                            q.name(),
                            rows[i].0
                        );
                    }
                }
            }
            let (a, r, t) = rows[i];
            if let (Some(r), Some(t)) = (r, t)
                && (r - t).abs() > 0.02
            {
                let mut typo = rows.clone();
                typo[i] = (a, Some(t), Some(r));
                let want = [(Quantity::Reflectance, a), (Quantity::Transmittance, a)];
                let missed = score_case(&mut scores, (sparse, kinds.len()), &typo, &want, line);
                if list_misses && missed {
                    eprintln!("screen misses: {name}: R and T swapped at {a}° (R {r}, T {t})");
                }
            }
        }
    }
    for (sparse, which) in [
        (false, "the tables of 19 to 91 readings"),
        (true, "the tables of 6 to 10 readings (hand-written style)"),
    ] {
        println!(
            "\nOne typo, in {which}, at every reading where it changes the value by more than \
             0.02 (found: the typo's reading named alone; + others: named among others; the \
             rest missed):\n"
        );
        println!(
            "| typo | cases | reader + screen | leave-one-out | reader + fit's suspect points | `glassdb fit` refuses (any check) |"
        );
        println!("|---|---:|---|---|---|---:|");
        let names = [
            "digit dropped (÷10)",
            "decimal point shifted (×10)",
            "percent in a fraction column (×100)",
            "R and T swapped on a row",
        ];
        for (k, name) in names.iter().enumerate() {
            let get = |d: usize| scores.get(&(sparse, k, d)).copied().unwrap_or_default();
            let cell = |d: usize| {
                let s = get(d);
                format!(
                    "{} found, {} + others, {} missed",
                    s.exact,
                    s.extra,
                    s.cases - s.exact - s.extra
                )
            };
            println!(
                "| {name} | {} | {} | {} | {} | {} |",
                get(0).cases,
                cell(0),
                cell(1),
                cell(2),
                get(0).refused
            );
        }
    }
    Ok(())
}
