//! `glassdb registry build|show|check`: the id-indexed glass table of a scene
//! (`docs/registry.md`). All logic lives in `glassdb_registry`; this module parses arguments
//! and formats output.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use glassdb_registry::{
    AngleCurve, Application, BuildOptions, ColourBasis, GlassRecord, MaskIds, Registry,
    SCHEMA_VERSION, Side, UnitElement, UnitRecord,
};
use glassdb_spectral::{
    Illuminant, IntegrationSettings, Method, MethodKind, Observer, RgbCmf, RgbSpace,
};

#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, clap::Subcommand)]
pub enum Command {
    /// Build a registry JSON from a catalog (catalog.toml), optionally only for the ids that
    /// the given masks use.
    Build(BuildArgs),
    /// Print a readable table of a registry (id, name, r0, t0, τv, ρv, fit, r/t at 0/45/60/75°).
    Show(ShowArgs),
    /// Validate a registry; non-zero exit on any failure.
    Check(CheckArgs),
}

#[derive(Debug, clap::Args)]
// clap's own usage line in an error lists the options given as if required
// (`--space <SPACE[,SPACE...]>` after a mistyped `-o`): this one says what is required.
#[command(override_usage = "glassdb registry build <CATALOG> --output <OUTPUT> [OPTIONS]")]
pub struct BuildArgs {
    /// The catalog (`[[glass]]` tables; paths in it are relative to it).
    pub catalog: PathBuf,
    /// Output registry JSON (written atomically).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Masks of the scene: only the ids they use are built. Repeatable.
    #[arg(long = "mask", value_name = "MASK")]
    pub masks: Vec<PathBuf>,
    /// Spectral method: colorimetric (default), paper or luminous.
    #[arg(long, default_value = "colorimetric")]
    pub method: String,
    /// RGB colour-matching functions for --method paper.
    #[arg(long, default_value = "wright-guild-1931")]
    pub cmf: String,
    /// Observer for --method colorimetric: cie1931 or cie1964.
    #[arg(long, default_value = "cie1931")]
    pub observer: String,
    /// Illuminant for --method colorimetric: D65, A or E.
    #[arg(long, default_value = "D65")]
    pub illuminant: String,
    /// RGB working space(s) for --method colorimetric, comma-separated: srgb (alias rec709),
    /// rec2020, acescg, aces2065-1, display-p3, xyz. One table per space, the first the
    /// default; compose picks the one its passes are in. Default: srgb.
    #[arg(long, value_name = "SPACES")]
    pub space: Option<String>,
    /// Hold end values where a spectrum does not cover the method's range (else an error).
    #[arg(long)]
    pub extrapolate: bool,
    /// Fit tolerance on r and t (absolute).
    #[arg(long, default_value_t = glassdb_fit::DEFAULT_TOL)]
    pub tol: f64,
    /// Highest polynomial degree of the angle curves.
    #[arg(long, default_value_t = 12)]
    pub max_degree: u32,
    /// Apply the physical angle model per channel instead of per wavelength (for comparison).
    #[arg(long)]
    pub per_channel: bool,
}

#[derive(Debug, clap::Args)]
pub struct ShowArgs {
    /// Registry JSON.
    pub registry: PathBuf,
    /// Show back-side reflectance instead of the front.
    #[arg(long)]
    pub back: bool,
    /// The table to show: an RGB space (srgb, acescg, …), paper-rgb or luminous (default: the
    /// registry's first table).
    #[arg(long, value_name = "SPACE")]
    pub space: Option<ColourBasis>,
}

#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Registry JSON files.
    #[arg(required = true)]
    pub registries: Vec<PathBuf>,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    match args.command {
        Command::Build(a) => build(a),
        Command::Show(a) => show(a),
        Command::Check(a) => check(a),
    }
}

fn parse<T: std::str::FromStr<Err = String>>(value: &str, flag: &str) -> anyhow::Result<T> {
    value
        .parse::<T>()
        .map_err(|e| anyhow::anyhow!("--{flag}: {e}"))
}

/// The spectral settings of each table to build: one per `--space` for the colorimetric
/// method, else the one method.
fn table_settings(a: &BuildArgs) -> anyhow::Result<Vec<IntegrationSettings>> {
    let with = |method| IntegrationSettings {
        method,
        extrapolate: a.extrapolate,
    };
    let kind = parse::<MethodKind>(&a.method, "method")?;
    if kind != MethodKind::Colorimetric {
        if let Some(space) = &a.space {
            anyhow::bail!(
                "--space {space}: only --method colorimetric integrates into an RGB space (--method {kind} has its own channels)"
            );
        }
        return Ok(vec![with(match kind {
            MethodKind::Paper => Method::Paper(parse::<RgbCmf>(&a.cmf, "cmf")?),
            _ => Method::Luminous,
        })]);
    }
    let observer = parse::<Observer>(&a.observer, "observer")?;
    let illuminant = parse::<Illuminant>(&a.illuminant, "illuminant")?;
    let mut spaces: Vec<RgbSpace> = Vec::new();
    for name in a.space.as_deref().unwrap_or("srgb").split(',') {
        let space = parse::<RgbSpace>(name.trim(), "space")?;
        if spaces.contains(&space) {
            anyhow::bail!("--space: {space} is listed twice (rec709 and srgb are one space)");
        }
        spaces.push(space);
    }
    Ok(spaces
        .into_iter()
        .map(|space| {
            with(Method::Colorimetric {
                observer,
                illuminant,
                space,
            })
        })
        .collect())
}

/// The registry `glassdb registry build` writes (`a.output` is not written here), for the
/// command and the Python package alike.
pub fn build_registry(a: &BuildArgs) -> anyhow::Result<Registry> {
    if !(a.tol.is_finite() && a.tol > 0.0) {
        anyhow::bail!("--tol must be a positive number, got {}", a.tol);
    }
    if a.max_degree == 0 || a.max_degree > 20 {
        anyhow::bail!("--max-degree must be 1–20, got {}", a.max_degree);
    }
    let opts = BuildOptions {
        tables: table_settings(a)?,
        mask_ids: mask_ids(&a.masks)?,
        fit_tol: a.tol,
        max_degree: a.max_degree,
        application: if a.per_channel {
            Application::PerChannel
        } else {
            Application::PerWavelength
        },
    };
    glassdb_registry::build_registry(&a.catalog, &opts).map_err(anyhow::Error::new)
}

fn build(a: BuildArgs) -> anyhow::Result<ExitCode> {
    // The catalog, every spectral file and angle table it names, and the masks.
    let mut inputs = glassdb_registry::catalog_inputs(&a.catalog).map_err(anyhow::Error::new)?;
    inputs.extend(a.masks.iter().cloned());
    glassdb_io::declare_inputs(inputs.iter().map(PathBuf::as_path));
    glassdb_io::refuse_input_as_output(&a.output)?;
    let registry = build_registry(&a)?;
    registry.write_json(&a.output)?;
    let glasses = &registry.default_table().glasses;
    let ids: Vec<String> = glasses.iter().map(|g| g.id.to_string()).collect();
    eprintln!(
        "wrote {} ({} glass{}: id {}; {})",
        a.output.display(),
        glasses.len(),
        if glasses.len() == 1 { "" } else { "es" },
        if ids.is_empty() {
            "none".to_string()
        } else {
            ids.join(", ")
        },
        tables_text(&registry)
    );
    Ok(ExitCode::SUCCESS)
}

/// The ids the given masks use (None without masks), read here so that the registry library
/// knows nothing of masks.
fn mask_ids(masks: &[PathBuf]) -> anyhow::Result<Option<MaskIds>> {
    if masks.is_empty() {
        return Ok(None);
    }
    let mut ids = MaskIds::default();
    for path in masks {
        let mask = glassdb_mask::read_mask(path, &glassdb_mask::MaskReadOptions::default())
            .with_context(|| format!("mask {}", path.display()))?;
        if matches!(mask.cos_theta, glassdb_mask::CosTheta::Quantized8(_))
            && ids.eight_bit_mask.is_none()
        {
            ids.eight_bit_mask = Some(path.clone());
        }
        for (id, n) in mask.id_pixel_counts() {
            *ids.pixel_counts.entry(id).or_insert(0) += n;
        }
    }
    Ok(Some(ids))
}

fn rgb(v: &[f64; 3]) -> String {
    format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2])
}

fn show(a: ShowArgs) -> anyhow::Result<ExitCode> {
    let registry = Registry::from_json_file(&a.registry).map_err(anyhow::Error::new)?;
    let side = if a.back { Side::Back } else { Side::Front };
    let table = registry
        .table_or_error(a.space, &a.registry.display().to_string())
        .map_err(anyhow::Error::new)?;
    outln!(
        "{}: schema {SCHEMA_VERSION}, {}, {} glasses",
        a.registry.display(),
        tables_text(&registry),
        table.glasses.len()
    );
    outln!(
        "showing the {} table (spectral method {}); values per channel in it",
        table.basis(),
        method_text(&table.spectral)
    );
    if a.back {
        outln!("reflectance: back side (r0_back, c_r_back)");
    }
    outln!();
    for g in &table.glasses {
        print_glass(g, side);
        outln!();
    }
    Ok(ExitCode::SUCCESS)
}

/// The tables a registry holds, e.g. `2 tables: srgb (default), acescg`.
fn tables_text(registry: &Registry) -> String {
    let bases: Vec<String> = registry.bases().iter().map(ToString::to_string).collect();
    match bases.as_slice() {
        [one] => format!("1 table: {one}"),
        [first, rest @ ..] => format!(
            "{} tables: {first} (default), {}",
            bases.len(),
            rest.join(", ")
        ),
        [] => "no table".to_string(),
    }
}

/// The method and its options, e.g. `colorimetric cie1931 D65 srgb`.
fn method_text(s: &IntegrationSettings) -> String {
    let kind = s.method.kind();
    match s.method {
        Method::Paper(cmf) => format!("{kind} {cmf}"),
        Method::Colorimetric {
            observer,
            illuminant,
            space,
        } => format!("{kind} {observer} {illuminant} {space}"),
        Method::Luminous => kind.to_string(),
    }
}

fn print_glass(g: &GlassRecord, side: Side) {
    let (r0, c_r) = match side {
        Side::Front => (&g.r0, &g.c_r),
        Side::Back => (&g.r0_back, &g.c_r_back),
    };
    outln!("id {:>5}  {}", g.id, g.name);
    let lum = match &g.luminous {
        Some(l) => format!(
            "τv {:.4}  ρv {:.4}  ρv back {:.4}",
            l.transmittance, l.reflectance, l.reflectance_back
        ),
        None => "τv –  ρv – (no spectrum)".to_string(),
    };
    outln!("  r0 (R G B) {}   t0 {}   {lum}", rgb(r0), rgb(&g.t0));
    let m = &g.angle_model;
    let mut model = format!("{} ({})", m.kind, m.applied);
    if let Some(max) = m.measured_max_angle_deg {
        model.push_str(&format!(", measured to {max}°"));
    }
    if let Some(c) = &m.continued_by {
        model.push_str(&format!(", continued by {c}"));
    }
    if !m.chosen_by.is_empty() {
        model.push_str(&format!("; chosen by {}", m.chosen_by));
    }
    outln!("  angle model: {model}");
    if let Some(u) = &g.unit {
        print_unit(u, side);
    }
    let fit_line = |label: &str, curves: &[AngleCurve; 3]| {
        let parts: Vec<String> = curves
            .iter()
            .map(|c| {
                format!(
                    "deg {} max err {:.1e} at {:.0}°",
                    c.fit.degree, c.fit.max_abs_error, c.fit.max_error_angle_deg
                )
            })
            .collect();
        outln!("  {label}: {}", parts.join(" | "));
    };
    fit_line(
        if side == Side::Back {
            "C_r_back"
        } else {
            "C_r"
        },
        c_r,
    );
    fit_line("C_t", &g.c_t);
    outln!("  {:>6}  {:>22}  {:>22}", "angle", "r (R G B)", "t (R G B)");
    for deg in [0.0f64, 45.0, 60.0, 75.0] {
        let (r, t) = g.eval(side, deg.to_radians().cos());
        outln!("  {:>5}°  {:>22}  {:>22}", deg, rgb(&r), rgb(&t));
    }
}

/// A unit's build-up, its layers, its WINDOW values and its pane groups.
fn print_unit(u: &UnitRecord, side: Side) {
    let parts: Vec<String> = u
        .elements
        .iter()
        .map(|e| match e {
            UnitElement::Gap(g) => format!("{} mm {}", g.thickness_mm, g.gas),
            UnitElement::Layer(l) => {
                let name = l
                    .provenance
                    .spectral
                    .as_ref()
                    .map(|f| f.path.clone())
                    .or_else(|| l.provenance.angles.as_ref().map(|f| f.path.clone()))
                    .unwrap_or_else(|| "r0/t0 values".into());
                let thickness = l
                    .thickness_mm
                    .map(|t| format!(", {t} mm"))
                    .unwrap_or_default();
                let flipped = if l.flipped { ", flipped" } else { "" };
                format!("{name} ({}{flipped}{thickness})", l.model)
            }
        })
        .collect();
    let total = u
        .thickness_mm
        .map(|t| format!(", {t:.2} mm"))
        .unwrap_or_default();
    outln!(
        "  unit: {}{total}; combined {}",
        parts.join(" | "),
        u.combined
    );
    for (name, v) in [("photopic", &u.photopic), ("solar", &u.solar)] {
        if let Some(v) = v {
            outln!(
                "  WINDOW {name} at 0°: T {:.4}  R out {:.4}  R in {:.4}",
                v.transmittance,
                v.reflectance,
                v.reflectance_back
            );
        }
    }
    let layers = u.elements.iter().filter_map(|e| match e {
        UnitElement::Layer(l) => Some(l),
        UnitElement::Gap(_) => None,
    });
    for (k, l) in layers.enumerate() {
        let absorbed = l
            .absorptance
            .map(|a| {
                format!(
                    "; absorbs (solar) {:.4} from outdoors, {:.4} from indoors",
                    a.front, a.back
                )
            })
            .unwrap_or_default();
        outln!(
            "  layer {}: r0 {}  t0 {}  r0_back {}{absorbed}",
            k + 1,
            rgb(&l.r0),
            rgb(&l.t0),
            rgb(&l.r0_back)
        );
    }
    for (k, grp) in u.groups.iter().enumerate() {
        let depth = match side {
            Side::Front => grp.depth_mm,
            Side::Back => grp.depth_back_mm,
        };
        let layers: Vec<String> = grp.layers.iter().map(|i| (i + 1).to_string()).collect();
        outln!(
            "  pane group {} (layer {}): {}share of r at 0°, 45°, 75°: {} | {} | {}",
            k + 1,
            layers.join(", "),
            depth
                .map(|d| format!("mid-plane {d:.2} mm deep, "))
                .unwrap_or_default(),
            rgb(&grp.eval(side, 1.0)),
            rgb(&grp.eval(side, 45f64.to_radians().cos())),
            rgb(&grp.eval(side, 75f64.to_radians().cos()))
        );
    }
}

fn check(a: CheckArgs) -> anyhow::Result<ExitCode> {
    let mut failed = 0usize;
    for path in &a.registries {
        match Registry::from_json_file(path) {
            Ok(r) => outln!(
                "{}: ok (schema {SCHEMA_VERSION}, {} glasses, {})",
                path.display(),
                r.default_table().glasses.len(),
                tables_text(&r)
            ),
            Err(e) => {
                eprintln!("FAILED: {}", super::hints::with_hints(&e.into()));
                failed += 1;
            }
        }
    }
    if failed > 0 {
        let n = a.registries.len();
        return Err(anyhow::anyhow!(
            "{failed} of {n} registr{} failed validation",
            if n == 1 { "y" } else { "ies" }
        ))
        .context("registry check");
    }
    Ok(ExitCode::SUCCESS)
}
