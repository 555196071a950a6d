//! `glassdb registry build|show|check`: the id-indexed glass table of a scene
//! (`docs/registry.md`). All logic lives in `glassdb_registry`; this module parses arguments
//! and formats output.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use glassdb_registry::{
    AngleCurve, Application, BuildOptions, ColourBasis, GlassRecord, MaskIds, NamedLight, Registry,
    Side, UnitElement, UnitRecord,
};
use glassdb_spectral::{
    ColorimetricSettings, Illuminant, IntegrationSettings, Method, MethodKind, Observer, RgbCmf,
    RgbSpace, WhiteBalance,
};

use crate::cmd::table::{Column, TextTable};

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
    /// Illuminant for --method colorimetric [default: D65]: D50, D55, D65, D75, A, E,
    /// FL1–FL12, LED-B1…B5, LED-BH1, LED-RGB1, LED-V1, LED-V2, or an SPD CSV file
    /// (wavelength_nm,power). For several lights, use --light instead.
    #[arg(long, value_name = "NAME|FILE.csv")]
    pub illuminant: Option<String>,
    /// A named light, NAME=ILLUMINANT (e.g. sun=D65, warm=A, led=LED-B3, lamp=lamp.csv):
    /// one table per space is built under each light, the first light the default; each table
    /// names its light (the light group it is for). Repeatable.
    #[arg(long = "light", value_name = "NAME=ILLUMINANT")]
    pub lights: Vec<String>,
    /// The white the camera is balanced to: `light` (each light renders white: CAT02 from the
    /// light's own white) or a CIE illuminant (D65: every light renders in its own colour, as
    /// lamps do in a render balanced to daylight) [default: light].
    #[arg(long, value_name = "light|NAME")]
    pub white_balance: Option<WhiteBalance>,
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
    /// The light whose table to show (default: the registry's first light).
    #[arg(long, value_name = "NAME")]
    pub light: Option<String>,
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
        if !a.lights.is_empty() || a.illuminant.is_some() || a.white_balance.is_some() {
            anyhow::bail!(
                "--light, --illuminant and --white-balance apply to --method colorimetric (--method {kind} has no illuminant)"
            );
        }
        return Ok(vec![with(match kind {
            MethodKind::Paper => Method::Paper(parse::<RgbCmf>(&a.cmf, "cmf")?),
            _ => Method::Luminous,
        })]);
    }
    let observer = parse::<Observer>(&a.observer, "observer")?;
    if !a.lights.is_empty() && a.illuminant.is_some() {
        anyhow::bail!(
            "--illuminant with --light: give each light's illuminant in --light NAME=ILLUMINANT"
        );
    }
    let illuminant = match &a.illuminant {
        Some(text) => Illuminant::from_name_or_file(text)
            .map_err(anyhow::Error::new)
            .context("--illuminant")?,
        None => Illuminant::default(),
    };
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
            with(Method::Colorimetric(ColorimetricSettings {
                observer,
                illuminant: illuminant.clone(),
                space,
                white_balance: a.white_balance.unwrap_or_default(),
            }))
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
    let lights = a
        .lights
        .iter()
        .map(|arg| NamedLight::parse(arg))
        .collect::<Result<Vec<_>, _>>()
        .map_err(anyhow::Error::new)
        .context("--light")?;
    let opts = BuildOptions {
        tables: table_settings(a)?,
        lights,
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
    // The catalog, every spectral file and angle table it names, the masks and the lights'
    // SPD files.
    let mut inputs = glassdb_registry::catalog_inputs(&a.catalog).map_err(anyhow::Error::new)?;
    inputs.extend(a.masks.iter().cloned());
    inputs.extend(a.illuminant.iter().map(PathBuf::from));
    inputs.extend(
        a.lights
            .iter()
            .filter_map(|l| l.split_once('=').map(|(_, i)| PathBuf::from(i))),
    );
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
    let source = a.registry.display().to_string();
    let table = match &a.light {
        Some(light) => {
            let basis = a.space.unwrap_or_else(|| registry.default_table().basis());
            registry.table_under(basis, light, &source)
        }
        None => registry.table_or_error(a.space, &source),
    }
    .map_err(anyhow::Error::new)?;
    outln!(
        "{}: schema {}, {}, {} glasses",
        a.registry.display(),
        registry.schema_version(),
        tables_text(&registry),
        table.glasses.len()
    );
    outln!(
        "showing the {} table (spectral method {}); values per channel in it",
        table.label(),
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

/// The tables a registry holds, e.g. `2 tables: srgb (default), acescg`, or with lights
/// `4 tables: srgb (default), acescg × lights sun (D65, default), warm (A)`.
fn tables_text(registry: &Registry) -> String {
    let bases: Vec<String> = registry.bases().iter().map(ToString::to_string).collect();
    let spaces = match bases.as_slice() {
        [one] => one.clone(),
        [first, rest @ ..] => format!("{first} (default), {}", rest.join(", ")),
        [] => String::new(),
    };
    let n = registry.tables().len();
    let tables = format!("{n} table{}", if n == 1 { "" } else { "s" });
    if registry.default_light().is_none() {
        return format!("{tables}: {spaces}");
    }
    let lights: Vec<String> = registry
        .lights()
        .iter()
        .enumerate()
        .map(|(k, l)| {
            let described = l.describe();
            match (k, described.strip_suffix(')')) {
                (0, Some(open)) => format!("{open}, default)"),
                _ => described,
            }
        })
        .collect();
    format!("{tables}: {spaces} × lights {}", lights.join(", "))
}

/// The method and its options, e.g. `colorimetric cie1931 D65 srgb` (and the camera's white
/// balance when it is not the light's own).
fn method_text(s: &IntegrationSettings) -> String {
    let kind = s.method.kind();
    match &s.method {
        Method::Paper(cmf) => format!("{kind} {cmf}"),
        Method::Colorimetric(c) => {
            let text = format!("{kind} {} {} {}", c.observer, c.illuminant, c.space);
            match c.white_balance {
                WhiteBalance::Light => text,
                WhiteBalance::Fixed(w) => format!("{text}, camera balanced to {w}"),
            }
        }
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
    let table = TextTable {
        columns: [
            Column::right("  ", 6),
            Column::right("  ", 22),
            Column::right("  ", 22),
        ],
    };
    outln!("{}", table.line(["angle", "r (R G B)", "t (R G B)"]));
    for deg in [0.0f64, 45.0, 60.0, 75.0] {
        let (r, t) = g.eval(side, deg.to_radians().cos());
        outln!("{}", table.line([format!("{deg}°"), rgb(&r), rgb(&t)]));
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
                "{}: ok (schema {}, {} glasses, {})",
                path.display(),
                r.schema_version(),
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
