//! `glassdb report`: the speed-against-error tables of `docs/accuracy.md`, computed afresh on
//! every run (errors against exact physics, timings with `std::time::Instant` on this machine)
//! and the figures embedded in the page, drawn with this crate's plots.
//!
//! References: the uncoated slab (s/p Fresnel, incoherent multiple reflections) and the WINDOW-4
//! coated-glass curves, both from `glassdb_registry::physics` (equations in `docs/registry.md`).

use std::fmt::Write as _;
use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glassdb_fit::{
    AngleSamples, Basis, CosPolynomial, CurveFit, FitOptions, Quantity, cos_deg, fit_curve,
};
use glassdb_registry::catalog::{NormalSource, parse_catalog, resolve};
use glassdb_registry::physics::{CoatedCurve, UncoatedSlab};
use glassdb_registry::{BuildOptions, Registry, Side, build_registry};
use glassdb_scene::{
    Camera, CosEncoding, CosMode, GlassMapping, PlaneSource, PlaneTolerance, RasterOptions,
    build_mask_scene, load_obj, rasterize, to_mask_image,
};
use glassdb_spectral::{
    IntegrationSettings, Integrator, Method, ReadOptions, RgbCmf, SpectralData, luminous_iso9050,
    read_spectral_file,
};

use crate::PlotError;
use crate::chart::{LegendCorner, Line, Panel, palette};
use crate::figure::{Cell, GridFigure};
use crate::plots::fit::{FitPlotOptions, fit_figure_from_table};
use crate::plots::mask::{MaskPlotOptions, mask_figure_of};
use crate::plots::registry::{RegistryPlotOptions, registry_figure_of};
use crate::plots::spectral::{SpectralPlotOptions, spectral_figure};

/// Inputs of the report (all paths relative to the repository root by default).
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Repository root: paths under it are shown relative to it in the page.
    pub root: PathBuf,
    /// The bundled catalog whose spectral glasses the spectral table covers.
    pub catalog: PathBuf,
    /// Angle tables drawn as fit figures (measured → fitted).
    pub angle_tables: Vec<PathBuf>,
    /// The scene for the Gouraud-vs-exact row: OBJ, camera JSON, glass mappings, catalog.
    pub gouraud_scene: Option<GouraudScene>,
    /// Where the figures are written (`None`: no figures).
    pub figures_dir: Option<PathBuf>,
    /// How the markdown refers to the figures directory (relative to the markdown file).
    pub figures_link: String,
    /// Values per timing run.
    pub timing_values: usize,
}

/// The scene used to compare the paper's Gouraud-interpolated cos θ with the exact one.
#[derive(Debug, Clone)]
pub struct GouraudScene {
    pub obj: PathBuf,
    pub camera: PathBuf,
    /// `PATTERN=ID` as `glassdb mask --glass`.
    pub glass: Vec<String>,
    pub catalog: PathBuf,
}

impl ReportOptions {
    /// The defaults for a run from the repository root.
    pub fn repository_defaults(root: &Path) -> Self {
        ReportOptions {
            root: root.to_path_buf(),
            catalog: root.join("data/catalog.toml"),
            angle_tables: vec![
                root.join("data/angles/clear_6mm_fresnel.csv"),
                root.join("data/angles/bronze_coated_window4.csv"),
            ],
            gouraud_scene: Some(GouraudScene {
                obj: root.join("fixtures/atrium/atrium.obj"),
                camera: root.join("fixtures/atrium/camera.json"),
                glass: vec!["GlassClear=1".into(), "GlassTinted=5".into()],
                catalog: root.join("fixtures/atrium/catalog.toml"),
            }),
            figures_dir: Some(root.join("docs/figures")),
            figures_link: "figures".into(),
            timing_values: 1 << 20,
        }
    }
}

/// The generated page and the figures written for it.
#[derive(Debug, Clone)]
pub struct Report {
    pub markdown: String,
    pub figures: Vec<PathBuf>,
}

/// An exact angle dependence used as reference: (r, t) at cos θ.
#[derive(Clone)]
struct Reference {
    name: &'static str,
    description: String,
    kind: RefKind,
}

#[derive(Clone, Copy)]
enum RefKind {
    Slab(UncoatedSlab),
    Coated {
        curve: CoatedCurve,
        t0: f64,
        r0: f64,
    },
}

impl Reference {
    fn eval(&self, cos: f64) -> (f64, f64) {
        match self.kind {
            RefKind::Slab(s) => s.at(cos),
            RefKind::Coated { curve, t0, r0 } => curve.at(t0, r0, cos),
        }
    }
}

fn references() -> Vec<Reference> {
    let n: f64 = 1.52;
    let rho0 = ((n - 1.0) / (n + 1.0)).powi(2);
    let clear6 = UncoatedSlab::from_normal(0.88, 0.08);
    vec![
        Reference {
            name: "slab n=1.52",
            description: "uncoated slab, n = 1.52, no absorption (s/p Fresnel, incoherent multiple reflections)".into(),
            kind: RefKind::Slab(UncoatedSlab { rho0, n, internal_transmittance: 1.0 }),
        },
        Reference {
            name: "clear 6 mm",
            description: format!(
                "uncoated absorbing slab solved from T0 = 0.88, R0 = 0.08 (n = {:.4}, internal transmittance {:.4})",
                clear6.n, clear6.internal_transmittance
            ),
            kind: RefKind::Slab(clear6),
        },
        Reference {
            name: "coated bronze",
            description: "coated glass T0 = 0.30, R0 = 0.20 with the WINDOW-4 bronze curve (as glassdb-registry applies it)".into(),
            kind: RefKind::Coated { curve: CoatedCurve::Bronze, t0: 0.30, r0: 0.20 },
        },
        Reference {
            name: "coated clear",
            description: "coated glass T0 = 0.80, R0 = 0.10 with the WINDOW-4 clear curve".into(),
            kind: RefKind::Coated { curve: CoatedCurve::Clear, t0: 0.80, r0: 0.10 },
        },
    ]
}

/// Dense angle grid 0…`max_deg` in `step_deg` steps.
fn dense_angles(max_deg: f64, step_deg: f64) -> Vec<f64> {
    let n = (max_deg / step_deg).round() as usize;
    (0..=n)
        .map(|k| (k as f64 * step_deg).min(max_deg))
        .collect()
}

/// The fit samples: 0–90° in 1° steps from the reference.
fn samples(r: &Reference, quantity: Quantity) -> AngleSamples {
    let angle_deg: Vec<f64> = (0..=90).map(f64::from).collect();
    let value = angle_deg
        .iter()
        .map(|&a| {
            let (rv, tv) = r.eval(cos_deg(a));
            if quantity == Quantity::Reflectance {
                rv
            } else {
                tv
            }
        })
        .collect();
    AngleSamples { angle_deg, value }
}

fn fit_fixed(s: &AngleSamples, q: Quantity, degree: u32, basis: Basis) -> Option<CurveFit> {
    let mut o = FitOptions::new(q);
    o.degree = Some(degree);
    o.basis = Some(basis);
    fit_curve(s, &o).ok()
}

/// Largest |f(θ) − g(θ)| over the angles, and where.
fn max_abs_diff(angles: &[f64], f: impl Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> (f64, f64) {
    let mut worst = (0.0, 0.0);
    for &a in angles {
        let d = (f(a) - g(a)).abs();
        if d.is_nan() || d > worst.0 {
            worst = (d, a);
        }
    }
    worst
}

fn fmt_err((e, a): (f64, f64)) -> String {
    format!("{} ({a:.1}°)", sci(e))
}

/// A compact error: 3 significant digits, scientific below 0.01.
fn sci(e: f64) -> String {
    if !e.is_finite() {
        return format!("{e}");
    }
    if e == 0.0 {
        "0".into()
    } else if e < 0.01 {
        format!("{e:.2e}")
    } else {
        format!("{e:.3}")
    }
}

/// Deterministic pseudo-random cos θ values (θ uniform in 0–89°): the timing inputs.
fn timing_inputs(n: usize) -> Vec<f64> {
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
fn ns_per_value(inputs: &[f64], f: impl Fn(f64) -> f64) -> f64 {
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

fn machine_line() -> String {
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

/// `path` relative to the repository root when it lies under it (for the page's text).
fn shown(opts_root: &Path, path: &Path) -> String {
    let strip = |p: &Path| {
        p.components()
            .filter(|c| !matches!(c, std::path::Component::CurDir))
            .collect::<PathBuf>()
    };
    match strip(path).strip_prefix(strip(opts_root)) {
        Ok(rel) => rel.display().to_string(),
        Err(_) => path.display().to_string(),
    }
}

/// Generates the page (and the figures when `figures_dir` is set).
pub fn generate(opts: &ReportOptions) -> Result<Report, PlotError> {
    let mut md = String::new();
    let mut figures = Vec::new();
    let refs = references();
    let inputs = timing_inputs(opts.timing_values.max(1024));

    let _ = writeln!(md, "# Accuracy: speed against error\n");
    let _ = writeln!(
        md,
        "Generated by `glassdb report`; do not edit by hand. To regenerate this page and its figures \
         (from the repository root):\n\n    cargo run --release -- report\n\n\
         (`-o` names the page, `--figures` the figure directory). Errors are against exact physics and \
         are reproducible to the last digit; timings are measured on every run with \
         `std::time::Instant` (best of 5 passes over {} values, written to a buffer) and vary with the \
         machine.\n\nMachine of this run: {}.\n",
        inputs.len(),
        machine_line()
    );
    let _ = writeln!(
        md,
        "References (the \"exact physics\"), from `glassdb_registry::physics` (equations in `docs/registry.md`):\n"
    );
    for r in &refs {
        let _ = writeln!(md, "- **{}**: {}.", r.name, r.description);
    }
    let _ = writeln!(md);

    section_degree_basis(&mut md, &refs, &inputs);
    section_quantisation(&mut md, &refs);
    section_tables(&mut md, &refs, &inputs);
    if let Err(e) = section_spectral(&mut md, &opts.catalog) {
        let _ = writeln!(
            md,
            "## Spectral methods\n\nNot computed: {}\n",
            glassdb_io::ErrorChain(&e)
        );
    }
    let gouraud = match &opts.gouraud_scene {
        Some(g) => section_gouraud(&mut md, g, &opts.root).map(Some),
        None => Ok(None),
    };
    let mask_for_figure = match gouraud {
        Ok(v) => v,
        Err(e) => {
            let _ = writeln!(
                md,
                "## Gouraud-interpolated cos θ vs exact\n\nNot computed: {}\n",
                glassdb_io::ErrorChain(&e)
            );
            None
        }
    };
    if let Some(dir) = &opts.figures_dir {
        section_figures(
            &mut md,
            opts,
            dir,
            &refs,
            mask_for_figure.as_ref(),
            &mut figures,
        )?;
    }
    Ok(Report {
        markdown: md,
        figures,
    })
}

fn section_degree_basis(md: &mut String, refs: &[Reference], inputs: &[f64]) {
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
        let _ = writeln!(md, "### {}\n", r.name);
        let _ = writeln!(md, "| n | r, paper | r, full | t, paper | t, full |");
        let _ = writeln!(md, "|---|---|---|---|---|");
        let sr = samples(r, Quantity::Reflectance);
        let st = samples(r, Quantity::Transmittance);
        for degree in 1..=8u32 {
            let mut cells = Vec::new();
            for (s, q, pick) in [
                (&sr, Quantity::Reflectance, 0usize),
                (&st, Quantity::Transmittance, 1usize),
            ] {
                for basis in [Basis::Paper, Basis::Full] {
                    cells.push(match fit_fixed(s, q, degree, basis) {
                        Some(f) => fmt_err(max_abs_diff(
                            &grid,
                            |a| f.eval_angle_deg(a),
                            |a| {
                                let (rv, tv) = r.eval(cos_deg(a));
                                if pick == 0 { rv } else { tv }
                            },
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
        for (s, q, pick) in [
            (&sr, Quantity::Reflectance, 0usize),
            (&st, Quantity::Transmittance, 1usize),
        ] {
            if let Ok(f) = fit_curve(s, &FitOptions::new(q)) {
                let e = max_abs_diff(
                    &grid,
                    |a| f.eval_angle_deg(a),
                    |a| {
                        let (rv, tv) = r.eval(cos_deg(a));
                        if pick == 0 { rv } else { tv }
                    },
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
    match glassdb_registry::default_registry() {
        Ok(reg) => {
            for g in reg.glasses.iter().take(4) {
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

/// How a mask stores cos θ.
#[derive(Clone, Copy)]
enum CosStorage {
    Bits8,
    Bits16,
    Half,
    Float32,
}

impl CosStorage {
    fn name(self) -> &'static str {
        match self {
            CosStorage::Bits8 => "8-bit (paper's mask, code/255)",
            CosStorage::Bits16 => "16-bit PNG (code/65535)",
            CosStorage::Half => "half float (EXR)",
            CosStorage::Float32 => "float (EXR)",
        }
    }
    fn store(self, c: f64) -> f64 {
        match self {
            CosStorage::Bits8 => (c * 255.0).round() / 255.0,
            CosStorage::Bits16 => (c * 65535.0).round() / 65535.0,
            CosStorage::Half => half::f16::from_f64(c).to_f64(),
            CosStorage::Float32 => c as f32 as f64,
        }
    }
}

const STORAGES: [CosStorage; 4] = [
    CosStorage::Bits8,
    CosStorage::Bits16,
    CosStorage::Half,
    CosStorage::Float32,
];

fn section_quantisation(md: &mut String, refs: &[Reference]) {
    let _ = writeln!(md, "## cos θ storage: 8 bits vs 16 bits vs float\n");
    let _ = writeln!(
        md,
        "Error from storing cos θ alone (the exact physics evaluated at the stored cos θ against the \
         true one), max over θ = 0–89° on a 0.001° grid, with the angle where it occurs. Near grazing \
         incidence cos θ changes little per degree, so one 8-bit step (1/255) spans several degrees \
         (last column: largest angle error the storage causes, max |θ(stored) − θ|).\n"
    );
    let grid = dense_angles(89.0, 0.001);
    let mut header = String::from("| storage |");
    let mut rule = String::from("|---|");
    for r in refs {
        let _ = write!(header, " max \\|Δr\\| {} |", r.name);
        rule.push_str("---|");
    }
    header.push_str(" max \\|Δt\\| slab n=1.52 | max \\|Δθ\\| |");
    rule.push_str("---|---|");
    let _ = writeln!(md, "{header}\n{rule}");
    for st in STORAGES {
        let mut row = format!("| {} |", st.name());
        for r in refs {
            let e = max_abs_diff(
                &grid,
                |a| r.eval(st.store(cos_deg(a))).0,
                |a| r.eval(cos_deg(a)).0,
            );
            let _ = write!(row, " {} |", fmt_err(e));
        }
        let et = max_abs_diff(
            &grid,
            |a| refs[0].eval(st.store(cos_deg(a))).1,
            |a| refs[0].eval(cos_deg(a)).1,
        );
        let dtheta = max_abs_diff(
            &grid,
            |a| st.store(cos_deg(a)).clamp(0.0, 1.0).acos().to_degrees(),
            |a| a,
        );
        let _ = writeln!(
            row,
            " {} | {:.3}° ({:.1}°) |",
            fmt_err(et),
            dtheta.0,
            dtheta.1
        );
        md.push_str(&row);
    }
    let _ = writeln!(md);
}

/// A table of `n` values of f at cos θ = i/(n−1), in f32 as the registry stores them.
struct CosTable {
    values: Vec<f32>,
}

impl CosTable {
    fn new(n: usize, f: impl Fn(f64) -> f64) -> Self {
        let last = (n - 1) as f64;
        CosTable {
            values: (0..n).map(|i| f(i as f64 / last) as f32).collect(),
        }
    }
    #[inline]
    fn nearest(&self, c: f64) -> f64 {
        let last = (self.values.len() - 1) as f64;
        let i = (c.clamp(0.0, 1.0) * last).round() as usize;
        self.values.get(i).copied().unwrap_or(0.0) as f64
    }
    #[inline]
    fn linear(&self, c: f64) -> f64 {
        let last = self.values.len() - 1;
        let x = c.clamp(0.0, 1.0) * last as f64;
        let i = (x.floor() as usize).min(last.saturating_sub(1));
        let f = x - i as f64;
        let a = self.values.get(i).copied().unwrap_or(0.0) as f64;
        let b = self.values.get(i + 1).copied().unwrap_or(0.0) as f64;
        a + (b - a) * f
    }
}

fn section_tables(md: &mut String, refs: &[Reference], inputs: &[f64]) {
    let _ = writeln!(md, "## Lookup table vs polynomial vs finer table\n");
    let r = &refs[0];
    let sr = samples(r, Quantity::Reflectance);
    let Ok(fit) = fit_curve(&sr, &FitOptions::new(Quantity::Reflectance)) else {
        let _ = writeln!(md, "(the reflectance fit failed; table not computed)\n");
        return;
    };
    let poly: CosPolynomial = fit.polynomial.clone();
    let normal = fit.normal;
    let _ = writeln!(
        md,
        "Reflectance of the {} reference, fitted by `glassdb fit` defaults ({} basis, n = {}). For a \
         float cos θ (EXR mask) each way of getting r is compared with the exact physics and with the \
         polynomial itself (the table's own error), over θ = 0–89° (0.001° grid); tables hold f32 \
         values at cos θ = i/(N−1) as `GlassRecord::tables_256` does. For 8-bit masks the 256-entry \
         table is exact (the mask can only hold those 256 values).\n",
        r.name,
        poly.basis.name(),
        poly.degree()
    );
    let grid = dense_angles(89.0, 0.001);
    let exact = |a: f64| r.eval(cos_deg(a)).0;
    let p = |c: f64| normal * poly.eval(c);
    let t256 = CosTable::new(256, p);
    let t4096 = CosTable::new(4096, p);
    let t65536 = CosTable::new(65536, p);
    type Way<'a> = (&'a str, Box<dyn Fn(f64) -> f64 + 'a>);
    let ways: Vec<Way> = vec![
        ("exact physics (Fresnel slab)", Box::new(|c| r.eval(c).0)),
        ("polynomial (Horner)", Box::new(p)),
        ("256-entry table, nearest", Box::new(|c| t256.nearest(c))),
        (
            "256-entry table, linear interpolation",
            Box::new(|c| t256.linear(c)),
        ),
        ("4096-entry table, nearest", Box::new(|c| t4096.nearest(c))),
        (
            "4096-entry table, linear interpolation",
            Box::new(|c| t4096.linear(c)),
        ),
        (
            "65536-entry table, nearest",
            Box::new(|c| t65536.nearest(c)),
        ),
    ];
    let _ = writeln!(
        md,
        "| method | max \\|r − exact\\| | max \\|r − polynomial\\| | ns/value |"
    );
    let _ = writeln!(md, "|---|---|---|---|");
    for (name, f) in &ways {
        let e_exact = max_abs_diff(&grid, |a| f(cos_deg(a)), exact);
        let e_poly = max_abs_diff(&grid, |a| f(cos_deg(a)), |a| p(cos_deg(a)));
        let ns = ns_per_value(inputs, f);
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {ns:.2} |",
            fmt_err(e_exact),
            fmt_err(e_poly)
        );
    }
    let _ = writeln!(md);
}

/// One quantity of one glass under every method.
struct SpectralRow {
    glass: String,
    quantity: &'static str,
    paper: Vec<[f64; 3]>,
    srgb: [f64; 3],
    luminous: f64,
}

fn spectral_methods() -> (Vec<(RgbCmf, &'static str)>, IntegrationSettings) {
    (
        vec![
            (RgbCmf::WrightGuild1931, "WG 1931"),
            (RgbCmf::StilesBurch1955, "SB 1955"),
            (RgbCmf::StilesBurch1959, "SB 1959"),
        ],
        // Colorimetric: CIE 1931, D65, linear sRGB, no extrapolation.
        IntegrationSettings::default(),
    )
}

fn integrate(
    settings: IntegrationSettings,
    data: &SpectralData,
    values: &[f64],
) -> Result<[f64; 3], PlotError> {
    let strict = Integrator::new(&settings)?;
    match strict.channels(&data.wavelength_nm, values) {
        Ok(v) => Ok(v),
        Err(_) => {
            let lenient = Integrator::new(&IntegrationSettings {
                extrapolate: true,
                ..settings
            })?;
            Ok(lenient.channels(&data.wavelength_nm, values)?)
        }
    }
}

fn fmt_rgb(v: [f64; 3]) -> String {
    format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2])
}

fn section_spectral(md: &mut String, catalog: &Path) -> Result<(), PlotError> {
    let text = std::fs::read_to_string(catalog).map_err(|source| PlotError::Read {
        path: catalog.into(),
        source,
    })?;
    let specs = parse_catalog(&text, catalog)?;
    let (cmfs, srgb_settings) = spectral_methods();
    let mut rows = Vec::new();
    for spec in &specs {
        let NormalSource::Spectral { path, percent } = &spec.normal else {
            continue;
        };
        let file = resolve(catalog, path);
        let data = read_spectral_file(&file, &ReadOptions { percent: *percent })?;
        for (quantity, values) in [
            ("τ", &data.transmittance),
            ("ρ front", &data.reflectance_front),
        ] {
            let Some(values) = values else { continue };
            let mut paper = Vec::new();
            for (cmf, _) in &cmfs {
                paper.push(integrate(
                    IntegrationSettings {
                        method: Method::Paper(*cmf),
                        extrapolate: false,
                    },
                    &data,
                    values,
                )?);
            }
            let srgb = integrate(srgb_settings, &data, values)?;
            let luminous = luminous_iso9050(&data.wavelength_nm, values)?;
            rows.push(SpectralRow {
                glass: format!("{} {}", spec.id, spec.name),
                quantity,
                paper,
                srgb,
                luminous,
            });
        }
    }
    let _ = writeln!(
        md,
        "## Spectral methods: paper RGB vs colorimetric sRGB vs luminous\n"
    );
    let _ = writeln!(
        md,
        "Every glass of `{}` with spectral data, normal incidence. Paper: eqs. 15–20 with each RGB \
         colour-matching function set; sRGB: the colorimetric method (CIE 1931 observer, D65, sRGB \
         primaries; `glassdb spectral` default); luminous: ISO 9050 (D65 × V(λ), 380–780 nm at \
         10 nm). Differences: the largest channel difference between any paper CMF set and sRGB, \
         and the sRGB luminance (0.2126 R + 0.7152 G + 0.0722 B, which is Y relative to the white) \
         minus the luminous value.\n",
        catalog
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default()
    );
    let mut header = String::from("| glass | | ");
    for (_, name) in &cmfs {
        let _ = write!(header, "paper {name} | ");
    }
    header.push_str("sRGB (D65) | luminous | max \\|paper − sRGB\\| | Y(sRGB) − luminous |");
    let _ = writeln!(md, "{header}");
    let _ = writeln!(md, "|---|---|{}---|---|---|---|", "---|".repeat(cmfs.len()));
    let mut worst_paper: f64 = 0.0;
    let mut worst_lum: f64 = 0.0;
    for row in &rows {
        let d_paper = row
            .paper
            .iter()
            .flat_map(|p| p.iter().zip(&row.srgb).map(|(a, b)| (a - b).abs()))
            .fold(0.0, f64::max);
        let y = 0.2126 * row.srgb[0] + 0.7152 * row.srgb[1] + 0.0722 * row.srgb[2];
        worst_paper = worst_paper.max(d_paper);
        worst_lum = worst_lum.max((y - row.luminous).abs());
        let paper: Vec<String> = row.paper.iter().map(|p| fmt_rgb(*p)).collect();
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {:.4} | {:.4} | {:+.1e} |",
            row.glass,
            row.quantity,
            paper.join(" | "),
            fmt_rgb(row.srgb),
            row.luminous,
            d_paper,
            y - row.luminous
        );
    }
    let _ = writeln!(
        md,
        "\nOver these glasses the paper method differs from the colorimetric one by up to {worst_paper:.4} \
         in a channel, and the colorimetric luminance from the ISO 9050 luminous value by up to \
         {worst_lum:.4} (the 1 nm vs 10 nm grids and sRGB's rounded matrix).\n"
    );
    Ok(())
}
/// What the Gouraud section hands to the figures: the exact mask and its registry.
struct SceneMask {
    mask: glassdb_mask::MaskImage,
    registry: Registry,
    name: String,
}

fn section_gouraud(md: &mut String, g: &GouraudScene, root: &Path) -> Result<SceneMask, PlotError> {
    let scene = load_obj(&g.obj)?;
    let camera = Camera::load(&g.camera)?;
    let mappings = g
        .glass
        .iter()
        .map(|s| GlassMapping::parse(s))
        .collect::<Result<Vec<_>, _>>()?;
    let source = PlaneSource::Detect(PlaneTolerance::default_for(&scene));
    let exact_scene = build_mask_scene(&scene, &mappings, &source, false)?;
    let t = Instant::now();
    let exact = rasterize(
        &exact_scene.raster,
        &camera,
        &RasterOptions {
            cos: CosMode::Exact,
            samples: 1,
        },
    )?;
    let exact_ms = t.elapsed().as_secs_f64() * 1e3;
    let pane_scene = build_mask_scene(&scene, &mappings, &source, true)?;
    let registry = build_registry(&g.catalog, &BuildOptions::default())?;
    let lum = |v: [f64; 3]| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
    let r_of = |id: u16, c: f64| registry.glass(id).map(|gl| lum(gl.eval(Side::Front, c).0));

    let name = g
        .obj
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let _ = writeln!(
        md,
        "## Gouraud-interpolated cos θ (the paper's mesh) vs exact per pixel\n"
    );
    let _ = writeln!(
        md,
        "The paper computes cos θ at the nodes of a mesh over each pane and interpolates linearly \
         (Gouraud). `glassdb mask --cos gouraud --mesh N` reproduces that; here it is compared, pixel \
         by pixel, with the exact cos θ of each pixel's ray, on the `{name}` scene ({}×{}, glasses {}), \
         with the reflectance (luminance of r(θ), front side) of the registry built from `{}`. \
         Pixels compared: glass in both masks with the same id. For scale, the last row is the exact \
         cos θ stored in 8 bits.\n",
        camera.width,
        camera.height,
        g.glass.join(", "),
        shown(root, &g.catalog)
    );
    let _ = writeln!(
        md,
        "| cos θ | pixels | max \\|Δcos θ\\| | mean \\|Δcos θ\\| | max \\|Δr\\| | mean \\|Δr\\| | raster ms (one run) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for mesh in [1u32, 2, 4, 8, 16, 32] {
        let t = Instant::now();
        let Ok(gour) = rasterize(
            &pane_scene.raster,
            &camera,
            &RasterOptions {
                cos: CosMode::Gouraud { mesh },
                samples: 1,
            },
        ) else {
            continue;
        };
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let (mut n, mut max_c, mut sum_c, mut max_r, mut sum_r) =
            (0usize, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for i in 0..exact.id.len().min(gour.id.len()) {
            let id = exact.id[i];
            if id == 0 || gour.id[i] != id {
                continue;
            }
            let (ce, cg) = (exact.cos_theta[i] as f64, gour.cos_theta[i] as f64);
            let dc = (ce - cg).abs();
            let dr = match (r_of(id, ce), r_of(id, cg)) {
                (Some(a), Some(b)) => (a - b).abs(),
                _ => continue,
            };
            n += 1;
            max_c = max_c.max(dc);
            sum_c += dc;
            max_r = max_r.max(dr);
            sum_r += dr;
        }
        let nf = n.max(1) as f64;
        let _ = writeln!(
            md,
            "| Gouraud, mesh {mesh}×{mesh} | {n} | {} | {} | {} | {} | {ms:.1} |",
            sci(max_c),
            sci(sum_c / nf),
            sci(max_r),
            sci(sum_r / nf)
        );
    }
    let (mut n, mut max_c, mut sum_c, mut max_r, mut sum_r) =
        (0usize, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for i in 0..exact.id.len() {
        let id = exact.id[i];
        if id == 0 {
            continue;
        }
        let ce = exact.cos_theta[i] as f64;
        let cq = (ce * 255.0).round() / 255.0;
        let (Some(a), Some(b)) = (r_of(id, ce), r_of(id, cq)) else {
            continue;
        };
        n += 1;
        max_c = max_c.max((ce - cq).abs());
        sum_c += (ce - cq).abs();
        max_r = max_r.max((a - b).abs());
        sum_r += (a - b).abs();
    }
    let nf = n.max(1) as f64;
    let _ = writeln!(
        md,
        "| exact, stored in 8 bits | {n} | {} | {} | {} | {} | {exact_ms:.1} (exact) |\n",
        sci(max_c),
        sci(sum_c / nf),
        sci(max_r),
        sci(sum_r / nf)
    );
    let mask = to_mask_image(exact, CosEncoding::Quantized8);
    Ok(SceneMask {
        mask,
        registry,
        name,
    })
}

/// Saves a figure into the figures directory and links it from the page.
fn add_figure<F: crate::Figure>(
    md: &mut String,
    opts: &ReportOptions,
    dir: &Path,
    file: &str,
    caption: &str,
    fig: &F,
    figures: &mut Vec<PathBuf>,
) -> Result<(), PlotError> {
    let path = dir.join(file);
    crate::save(fig, &path)?;
    let kb = std::fs::metadata(&path)
        .map(|m| m.len() / 1024)
        .unwrap_or(0);
    let _ = writeln!(
        md,
        "![{caption}]({}/{file})\n\n*{caption}* ({kb} KB)\n",
        opts.figures_link
    );
    figures.push(path);
    Ok(())
}

fn log10_error_panel(title: &str, refs: &[Reference]) -> Panel {
    let mut p = Panel::new(
        crate::plots::ANGLE_AXIS,
        "log10 |Δr| (reflectance error)",
        (0.0, 89.0),
    );
    p.title = Some(title.to_string());
    p.legend = Some(LegendCorner::LowerRight);
    let grid = dense_angles(89.0, 0.05);
    let r = &refs[0];
    for (k, st) in [CosStorage::Bits8, CosStorage::Bits16, CosStorage::Half]
        .into_iter()
        .enumerate()
    {
        // Worst error within each 0.5° bin, so the plot shows the envelope, not the sawtooth.
        let mut pts = Vec::new();
        for chunk in grid.chunks(10) {
            let mut worst: f64 = 0.0;
            let mut at = 0.0;
            for &a in chunk {
                // Sub-sample finely inside the bin: quantisation error depends on the exact cos.
                for s in 0..20 {
                    let aa = a + 0.05 * s as f64 / 20.0;
                    let e = (r.eval(st.store(cos_deg(aa))).0 - r.eval(cos_deg(aa)).0).abs();
                    if e > worst {
                        worst = e;
                        at = aa;
                    }
                }
            }
            if worst > 0.0 {
                pts.push((at, worst.log10()));
            }
        }
        p.lines
            .push(Line::new(Some(st.name().to_string()), palette(k), pts));
    }
    p
}

fn section_figures(
    md: &mut String,
    opts: &ReportOptions,
    dir: &Path,
    refs: &[Reference],
    scene_mask: Option<&SceneMask>,
    figures: &mut Vec<PathBuf>,
) -> Result<(), PlotError> {
    std::fs::create_dir_all(dir).map_err(|source| PlotError::Read {
        path: dir.into(),
        source,
    })?;
    let _ = writeln!(md, "## Figures\n");
    let _ = writeln!(
        md,
        "Drawn by the same code as `glassdb plot` (the command for each is given with its caption).\n"
    );
    for table in &opts.angle_tables {
        let stem = table
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let fig = fit_figure_from_table(
            table,
            &FitPlotOptions {
                compare_paper: true,
                ..FitPlotOptions::default()
            },
        )?;
        add_figure(
            md,
            opts,
            dir,
            &format!("fit_{stem}.png"),
            &format!(
                "`glassdb plot fit {} --compare-paper`: measured (exact) points, default fit (solid) and paper basis (dashed), residuals below",
                shown(&opts.root, table)
            ),
            &fig,
            figures,
        )?;
    }
    let lowe = opts.catalog.parent().map(|d| d.join("glazing/LOW-E_5.LOF"));
    if let Some(lowe) = lowe.filter(|p| p.exists()) {
        for (method, tag, label) in [
            (
                Method::Paper(RgbCmf::WrightGuild1931),
                "paper_wg1931",
                "--method paper",
            ),
            (
                spectral_methods().1.method,
                "srgb",
                "(colorimetric sRGB, the default)",
            ),
        ] {
            let fig = spectral_figure(
                &lowe,
                &SpectralPlotOptions {
                    settings: IntegrationSettings {
                        method,
                        extrapolate: false,
                    },
                    read: ReadOptions::default(),
                },
            )?;
            add_figure(
                md,
                opts,
                dir,
                &format!("spectral_lowe_{tag}.png"),
                &format!(
                    "`glassdb plot spectral {} {label}`",
                    shown(&opts.root, &lowe)
                ),
                &fig,
                figures,
            )?;
        }
    }
    if let Ok(reg) = glassdb_registry::default_registry() {
        let ids: Vec<u16> = [2u16, 4, 6, 8]
            .into_iter()
            .filter(|id| reg.glass(*id).is_some())
            .collect();
        let fig = registry_figure_of(
            &reg,
            "default registry (data/catalog.toml)",
            &RegistryPlotOptions { ids: ids.clone() },
        )?;
        let id_args: Vec<String> = ids.iter().map(|i| format!("--id {i}")).collect();
        add_figure(
            md,
            opts,
            dir,
            "registry_default.png",
            &format!(
                "`glassdb plot registry registry.json {}` (registry built from data/catalog.toml)",
                id_args.join(" ")
            ),
            &fig,
            figures,
        )?;
    }
    if let Some(sm) = scene_mask {
        let fig = mask_figure_of(
            &sm.mask,
            &sm.registry,
            &format!("{} (exact cos θ, 8-bit mask)", sm.name),
            &MaskPlotOptions::default(),
        )?;
        add_figure(
            md,
            opts,
            dir,
            "mask_atrium_reflectance.png",
            "`glassdb plot mask mask.png --registry registry.json` of the atrium fixture (mask from `glassdb mask`): reflectance rises towards grazing view",
            &fig,
            figures,
        )?;
    }
    let fig = GridFigure {
        title: "Reflectance error from storing cos θ".into(),
        subtitle: Some(format!(
            "{}: worst error in each 0.5° bin",
            refs[0].description
        )),
        cells: vec![Cell {
            main: log10_error_panel("exact physics at stored vs true cos θ", refs),
            lower: None,
        }],
        columns: 1,
        cell_size: (820, 480),
    };
    add_figure(
        md,
        opts,
        dir,
        "cos_storage_error.png",
        "reflectance error against angle for each cos θ storage (report only)",
        &fig,
        figures,
    )?;
    Ok(())
}
