//! `glassdb fit` (fit C_r, C_t to an angle table, method eqs. 11–14) and `glassdb eval`
//! (evaluate a fit file at given angles). All computation is in `glassdb_fit`.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_fit::{
    Basis, CurveFit, DEFAULT_MAX_DEGREE, DEFAULT_TOL, EXTRAPOLATION_MARGIN_DEG, ExpectedFile,
    FileContent, FitError, FitFile, FitOptions, GlassFit, GlassFitOptions, Quantity,
};

use crate::cmd::table::{Column, TextTable};

/// The basis names accepted by `--basis`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum BasisArg {
    /// Powers 1…n, no constant (the paper's form: forces the value at 90° to 0).
    Paper,
    /// Powers 0…n.
    Full,
}

impl From<BasisArg> for Basis {
    fn from(b: BasisArg) -> Basis {
        match b {
            BasisArg::Paper => Basis::Paper,
            BasisArg::Full => Basis::Full,
        }
    }
}

#[derive(Debug, clap::Args)]
pub struct FitArgs {
    /// Angle table (CSV): columns angle_deg (or theta_deg), R and/or T (fractions), optional glass.
    pub table: PathBuf,
    /// R and T are in percent (0–100) instead of fractions.
    #[arg(long)]
    pub percent: bool,
    /// Fixed polynomial degree (default: smallest degree meeting --tol, leave-one-out guarded).
    #[arg(long)]
    pub degree: Option<u32>,
    /// Tolerance on max |fitted − measured| over the data (absolute, fraction).
    #[arg(long, default_value_t = DEFAULT_TOL)]
    pub tol: f64,
    /// Highest degree tried by automatic selection.
    #[arg(long, default_value_t = DEFAULT_MAX_DEGREE)]
    pub max_degree: u32,
    /// Basis for both curves (default: full for R; for T the more accurate of paper and full).
    #[arg(long, value_enum)]
    pub basis: Option<BasisArg>,
    /// Print the fits as JSON (docs/fit-json.md) instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Write the fits as JSON to this file (atomically).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Failed physical checks (r, t outside 0–1, r + t > 1) are errors, not warnings.
    #[arg(long, conflicts_with = "force")]
    pub strict: bool,
    /// Write the fit even when readings are inconsistent with their neighbours, or the fit
    /// misses the data by more than 10 × --tol or fails a physical check over 0–90° (each
    /// becomes a warning, kept in the JSON).
    #[arg(long)]
    pub force: bool,
}

#[derive(Debug, clap::Args)]
pub struct EvalArgs {
    /// A fit file written by `glassdb fit --json` / `-o`.
    pub fits: PathBuf,
    /// Angles in degrees: START:END:STEP (END included), or a comma list such as 0,45,60.
    #[arg(long, default_value = "0:90:10")]
    pub angles: String,
    /// Only this glass.
    #[arg(long)]
    pub glass: Option<String>,
    /// Print JSON: {"glasses": [{"name", "angle_deg": [...], "reflectance": [...], "transmittance": [...]}]}.
    #[arg(long)]
    pub json: bool,
}

pub fn run_fit(args: FitArgs) -> anyhow::Result<ExitCode> {
    let tables =
        glassdb_fit::read_angle_table(&args.table, args.percent).map_err(anyhow::Error::new)?;
    let reflectance = FitOptions {
        degree: args.degree,
        tol: args.tol,
        max_degree: args.max_degree,
        basis: args.basis.map(Basis::from),
        quantity: Quantity::Reflectance,
    };
    let opts = GlassFitOptions {
        transmittance: FitOptions {
            quantity: Quantity::Transmittance,
            ..reflectance.clone()
        },
        reflectance,
        strict: args.strict,
        force: args.force,
    };
    let mut file = FitFile::default();
    for table in &tables {
        file.glasses.push(glassdb_fit::fit_glass(table, &opts)?);
    }
    // What every reader of fit files refuses is not written: a curve beyond the physical range
    // by more than its tolerance (smaller violations are warnings, errors with --strict).
    file.validate(&args.table)?;
    if let Some(out) = &args.output {
        glassdb_io::refuse_input_as_output(out)?;
        glassdb_io::write_bytes_atomic(out, file.to_json().as_bytes())?;
    }
    for g in &file.glasses {
        for w in glass_warnings(g) {
            eprintln!("warning: {w}");
        }
    }
    if args.json {
        out!("{}", file.to_json());
    } else {
        out!("{}", fit_report(&file, &args));
    }
    Ok(ExitCode::SUCCESS)
}

fn glass_warnings(g: &GlassFit) -> Vec<String> {
    let mut out: Vec<String> = g
        .warnings
        .iter()
        .map(|w| format!("glass `{}`: {w}", g.name))
        .collect();
    for (q, c) in [
        ("reflectance", &g.reflectance),
        ("transmittance", &g.transmittance),
    ] {
        if let Some(c) = c {
            out.extend(
                c.diagnostics
                    .warnings
                    .iter()
                    .map(|w| format!("glass `{}`, {q}: {w}", g.name)),
            );
        }
    }
    out
}

/// The readable report's table of curves: one row per curve of a glass.
const CURVE_TABLE: TextTable<10> = TextTable {
    columns: [
        Column::left("  ", 13),
        Column::right(" ", 9),
        Column::right(" ", 5),
        Column::right(" ", 3),
        Column::right(" ", 6),
        Column::right(" ", 10),
        Column::right(" ", 10),
        Column::right(" ", 7),
        Column::right(" ", 10),
        Column::right(" ", 10),
    ],
};

/// The angles (degrees) at which the readable report gives each fitted r(θ) and t(θ).
const PROBE_ANGLES_DEG: [f64; 7] = [0.0, 30.0, 45.0, 60.0, 75.0, 85.0, 90.0];

/// The readable report's table of r(θ) and t(θ) at [`PROBE_ANGLES_DEG`].
const PROBE_TABLE: TextTable<8> = TextTable {
    columns: [
        Column::left("  ", 8),
        Column::right("", 9),
        Column::right("", 9),
        Column::right("", 9),
        Column::right("", 9),
        Column::right("", 9),
        Column::right("", 9),
        Column::right("", 9),
    ],
};

/// The readable report: one block per glass, one row per curve, then its coefficients.
fn fit_report(file: &FitFile, args: &FitArgs) -> String {
    let mut s = String::new();
    let how = match args.degree {
        Some(d) => format!("degree {d}"),
        None => format!("tol {}, max degree {}", args.tol, args.max_degree),
    };
    let _ = writeln!(
        s,
        "{}: {} glass(es), {how}",
        args.table.display(),
        file.glasses.len()
    );
    for g in &file.glasses {
        let _ = writeln!(s, "\nglass {}", g.name);
        let titles = [
            "curve", "normal", "basis", "deg", "points", "rms err", "max err", "at °", "loo rms",
            "cond",
        ];
        let _ = writeln!(s, "{}", CURVE_TABLE.line(titles));
        for (q, c) in [
            ("reflectance", &g.reflectance),
            ("transmittance", &g.transmittance),
        ] {
            let Some(c) = c else { continue };
            let d = &c.diagnostics;
            let loo = d
                .loo_rms_error
                .map_or_else(|| "-".to_string(), |v| format!("{v:.6}"));
            let row = [
                q.to_string(),
                format!("{:.6}", c.normal),
                c.polynomial.basis.name().to_string(),
                d.summary.degree.to_string(),
                d.points.to_string(),
                format!("{:.6}", d.summary.rms_error),
                format!("{:.6}", d.summary.max_abs_error),
                trim_num(d.summary.max_error_angle_deg),
                loo,
                format!("{:.3e}", d.summary.condition_number),
            ];
            let _ = writeln!(s, "{}", CURVE_TABLE.line(row));
        }
        for (sym, c) in [("C_r", &g.reflectance), ("C_t", &g.transmittance)] {
            let Some(c) = c else { continue };
            let _ = writeln!(s, "  {sym}(θ) = {}", polynomial_text(c));
            for sp in &c.diagnostics.suspect_points {
                let _ = writeln!(
                    s,
                    "    suspect point at {}°: residual {:+.5} ({:.1}σ of the other points)",
                    trim_num(sp.angle_deg),
                    sp.residual,
                    sp.studentized.abs()
                );
            }
        }
        let titles: [String; 8] = std::array::from_fn(|k| match k {
            0 => "θ (°)".to_string(),
            k => trim_num(PROBE_ANGLES_DEG[k - 1]),
        });
        let _ = writeln!(s, "{}", PROBE_TABLE.line(titles));
        for (sym, c) in [("r(θ)", &g.reflectance), ("t(θ)", &g.transmittance)] {
            let Some(c) = c else { continue };
            let row: [String; 8] = std::array::from_fn(|k| match k {
                0 => sym.to_string(),
                k => format!("{:.5}", c.eval_angle_deg(PROBE_ANGLES_DEG[k - 1])),
            });
            let _ = writeln!(s, "{}", PROBE_TABLE.line(row));
        }
        let warnings = glass_warnings(g).len();
        if warnings > 0 {
            let _ = writeln!(s, "  {warnings} warning(s): see stderr");
        }
    }
    s
}

fn polynomial_text(c: &CurveFit) -> String {
    let p = &c.polynomial;
    let mut out = String::new();
    for (i, (&pw, &co)) in p.powers.iter().zip(&p.coefficients).enumerate() {
        let sign = if co < 0.0 { "−" } else { "+" };
        if i == 0 {
            if co < 0.0 {
                out.push('−');
            }
        } else {
            let _ = write!(out, " {sign} ");
        }
        let term = match pw {
            0 => String::new(),
            1 => "·cos θ".to_string(),
            k => format!("·cos^{k} θ"),
        };
        let _ = write!(out, "{:.9}{term}", co.abs());
    }
    out
}

fn trim_num(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// Parses `START:END:STEP` (END included) or a comma list; every angle within 0–90°.
pub fn parse_angles(spec: &str) -> anyhow::Result<Vec<f64>> {
    let num = |t: &str| -> anyhow::Result<f64> {
        let v: f64 = t
            .trim()
            .parse()
            .with_context(|| format!("--angles: `{}` is not a number", t.trim()))?;
        if !v.is_finite() {
            bail!("--angles: `{}` is not a finite number", t.trim());
        }
        Ok(v)
    };
    let angles: Vec<f64> = if spec.contains(':') {
        let parts: Vec<&str> = spec.split(':').collect();
        let [a, b, step] = parts[..] else {
            bail!("--angles: expected START:END:STEP, got `{spec}`");
        };
        let (a, b, step) = (num(a)?, num(b)?, num(step)?);
        if step <= 0.0 {
            bail!("--angles: the step must be positive, got {step}");
        }
        if b < a {
            bail!("--angles: END {b} is below START {a}");
        }
        let count = ((b - a) / step + 1e-9).floor() as u64 + 1;
        if count > 100_000 {
            bail!("--angles: {count} angles is too many (at most 100000)");
        }
        (0..count).map(|i| a + i as f64 * step).collect()
    } else {
        spec.split(',').map(num).collect::<anyhow::Result<_>>()?
    };
    if angles.is_empty() {
        bail!("--angles: no angles given");
    }
    if let Some(bad) = angles.iter().find(|a| !(0.0..=90.0).contains(*a)) {
        bail!("--angles: {bad}° is outside 0–90°");
    }
    Ok(angles)
}

pub fn run_eval(args: EvalArgs) -> anyhow::Result<ExitCode> {
    let angles = parse_angles(&args.angles)?;
    let file = glassdb_fit::read_fit_file(&args.fits)?;
    let glasses: Vec<&GlassFit> = match &args.glass {
        Some(name) => {
            let g = file.glass(name).with_context(|| {
                let names: Vec<&str> = file.glasses.iter().map(|g| g.name.as_str()).collect();
                format!(
                    "{}: no glass `{name}` (glasses: {})",
                    args.fits.display(),
                    names.join(", ")
                )
            })?;
            vec![g]
        }
        None => file.glasses.iter().collect(),
    };
    if glasses.is_empty() {
        bail!("{}: the fit file has no glasses", args.fits.display());
    }
    for g in &glasses {
        for (q, c) in [
            ("reflectance", &g.reflectance),
            ("transmittance", &g.transmittance),
        ] {
            let Some(c) = c else { continue };
            let outside: Vec<String> = angles
                .iter()
                .filter(|&&a| c.is_extrapolated(a, EXTRAPOLATION_MARGIN_DEG))
                .map(|&a| trim_num(a))
                .collect();
            if !outside.is_empty() {
                eprintln!(
                    "warning: glass `{}`, {q}: {}° outside the measured {}–{}° (extrapolated)",
                    g.name,
                    outside.join(", "),
                    trim_num(c.diagnostics.angle_min_deg.unwrap_or(0.0)),
                    trim_num(c.diagnostics.angle_max_deg.unwrap_or(90.0)),
                );
            }
        }
    }
    if args.json {
        let out: Vec<serde_json::Value> = glasses
            .iter()
            .map(|g| {
                let mut o = serde_json::Map::new();
                o.insert("name".into(), g.name.clone().into());
                o.insert("angle_deg".into(), angles.clone().into());
                let curves = [
                    ("reflectance", &g.reflectance),
                    ("transmittance", &g.transmittance),
                ];
                for (key, curve) in curves {
                    if let Some(c) = curve {
                        let values: Vec<f64> =
                            angles.iter().map(|&a| c.eval_angle_deg(a)).collect();
                        o.insert(key.into(), values.into());
                    }
                }
                serde_json::Value::Object(o)
            })
            .collect();
        let doc = serde_json::json!({ "glasses": out });
        outln!("{}", serde_json::to_string_pretty(&doc)?);
    } else {
        let mut s = String::new();
        for g in &glasses {
            let _ = writeln!(s, "glass {}", g.name);
            let _ = writeln!(s, "  {:>9} {:>10} {:>10}", "angle_deg", "r", "t");
            for &a in &angles {
                let r = g
                    .reflectance_at(a)
                    .map_or_else(|| "-".to_string(), |v| format!("{v:.6}"));
                let t = g
                    .transmittance_at(a)
                    .map_or_else(|| "-".to_string(), |v| format!("{v:.6}"));
                let _ = writeln!(s, "  {:>9} {r:>10} {t:>10}", trim_num(a));
            }
        }
        out!("{s}");
    }
    Ok(ExitCode::SUCCESS)
}

/// The hint for a fit error: which command reads the file given, which flag answers the
/// error (`super::hints` asks this for every [`FitError`] it has no hint of its own for).
pub fn hint(e: &FitError) -> Option<String> {
    const FORCE: &str =
        "or pass --force to write the fit anyway, with the findings as warnings in it";
    match e {
        FitError::OtherFile {
            path,
            kind: FileContent::FitFile,
            ..
        } => Some(format!(
            "a fit file is evaluated by `glassdb eval {}`; `glassdb fit` reads an angle table (CSV: angle_deg,R,T)",
            path.display()
        )),
        FitError::OtherFile {
            path,
            kind: FileContent::AngleTable,
            ..
        } => Some(format!(
            "fit the table first: `glassdb fit {} -o fits.json`, then `glassdb eval fits.json`",
            path.display()
        )),
        FitError::OtherFile {
            kind: FileContent::Binary(_),
            expected,
            ..
        } => Some(match expected {
            ExpectedFile::FitFile => "`glassdb eval` reads the JSON that `glassdb fit -o` writes".into(),
            ExpectedFile::AngleTable => "`glassdb fit` reads an angle table: CSV text with columns angle_deg, R and/or T (docs/fit.md, \"Input\"); images are read by `compose` and `glassdb view`".into(),
        }),
        FitError::ValuesAboveOne { .. } => Some(
            "correct those cells to fractions; a table in percent throughout takes --percent"
                .into(),
        ),
        FitError::MixedUnits { .. } => Some(
            "write every R and T column in the same unit (--percent reads them as percent)".into(),
        ),
        FitError::FractionsReadAsPercent { .. } => Some("drop --percent".into()),
        FitError::InconsistentPoints { .. } | FitError::ReversedCurve { .. } => Some(format!(
            "correct the readings named (docs/fit.md, \"Inconsistent points\"), {FORCE}"
        )),
        FitError::FarFromData { .. } => Some(format!(
            "check the reading named; a higher degree (--degree, --max-degree) or the other --basis may follow the data; {FORCE}"
        )),
        FitError::UnphysicalFit {
            beyond_data: true, ..
        } => Some(format!(
            "add a 90° row (R = 1, T = 0 at grazing incidence, for any glazing) so that the curve is not extrapolated there, {FORCE}"
        )),
        FitError::UnphysicalFit { .. } => Some(format!(
            "a fixed --degree or the other --basis may stay physical; {FORCE}"
        )),
        _ => None,
    }
}
