//! `glassdb spectral FILE`: a glass's spectra to per-channel factors and luminous values.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_spectral::{
    ColorimetricSettings, Illuminant, IntegrationSettings, Integrator, LuminousGrid, Method,
    Observer, ReadOptions, RgbCmf, RgbSpace, SpectralData, WhiteBalance, luminous,
    read_spectral_file,
};
use serde_json::{Value, json};

use crate::cmd::table::{Column, TextTable};

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// The paper's eqs. 15–20: ∫ρ·c̄ / ∫c̄ with RGB colour-matching functions (--cmf).
    Paper,
    /// RGB(value × illuminant) / RGB(illuminant) in a linear working space (default).
    Colorimetric,
    /// ISO 9050 / EN 410 luminous value (D65 × V(λ), 380–780 nm at 10 nm) in all channels.
    Luminous,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CmfArg {
    #[value(name = "wright-guild-1931")]
    WrightGuild1931,
    #[value(name = "stiles-burch-1955")]
    StilesBurch1955,
    #[value(name = "stiles-burch-1959")]
    StilesBurch1959,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ObserverArg {
    Cie1931,
    Cie1964,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SpaceArg {
    /// Linear Rec.709 / sRGB (alias rec709).
    #[value(name = "srgb", alias = "rec709")]
    Srgb,
    /// Linear Rec.2020.
    Rec2020,
    /// ACEScg (AP1).
    Acescg,
    /// ACES2065-1 (AP0).
    #[value(name = "aces2065-1")]
    Aces2065_1,
    /// Display P3 (linear).
    #[value(name = "display-p3")]
    DisplayP3,
    /// CIE XYZ (the identity).
    Xyz,
}

impl SpaceArg {
    /// The library's RGB space.
    pub fn space(self) -> RgbSpace {
        match self {
            SpaceArg::Srgb => RgbSpace::Srgb,
            SpaceArg::Rec2020 => RgbSpace::Rec2020,
            SpaceArg::Acescg => RgbSpace::AcesCg,
            SpaceArg::Aces2065_1 => RgbSpace::Aces2065_1,
            SpaceArg::DisplayP3 => RgbSpace::DisplayP3,
            SpaceArg::Xyz => RgbSpace::Xyz,
        }
    }
}

/// How a spectral file is read and becomes three numbers: the method, its options and the
/// input flags (shared by `glassdb spectral` and `glassdb plot spectral`).
#[derive(Debug, clap::Args)]
pub struct SpectralSettingsArgs {
    /// How a spectrum becomes three numbers.
    #[arg(long, value_enum, default_value = "colorimetric")]
    pub method: MethodArg,
    /// RGB colour-matching functions for --method paper [default: wright-guild-1931].
    #[arg(long, value_enum)]
    pub cmf: Option<CmfArg>,
    /// Standard observer for --method colorimetric [default: cie1931].
    #[arg(long, value_enum)]
    pub observer: Option<ObserverArg>,
    /// Illuminant for --method colorimetric [default: D65]: D50, D55, D65, D75, A, E,
    /// FL1–FL12 (alias F1–F12), LED-B1…B5, LED-BH1, LED-RGB1, LED-V1, LED-V2, or a light's
    /// spectrum as a CSV file (wavelength_nm,power).
    #[arg(long, value_name = "NAME|FILE.csv")]
    pub illuminant: Option<String>,
    /// The white the camera is balanced to, for --method colorimetric: `light` (the
    /// illuminant's own white: it renders white; colour-science's default) or a CIE
    /// illuminant (D65: the illuminant renders in its own colour, as a lamp does in a render
    /// balanced to daylight) [default: light].
    #[arg(long, value_name = "light|NAME")]
    pub white_balance: Option<WhiteBalance>,
    /// Linear RGB working space for --method colorimetric [default: srgb].
    #[arg(long, value_enum)]
    pub space: Option<SpaceArg>,
    /// CSV values are percent (0–100) instead of fractions.
    #[arg(long)]
    pub percent: bool,
    /// Hold the spectrum's end values constant where it does not cover a method's grid
    /// (otherwise partial coverage is an error).
    #[arg(long)]
    pub extrapolate: bool,
}

/// Spectral transmittance/reflectance to per-channel and luminous values.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Spectral data: CSV (wavelength_nm or wavelength_um, T, R/Rf, Rb), LBNL Optics/IGDB text
    /// (.DAT, .LOF, .afg, .oag, …) or IGSDB JSON.
    pub file: PathBuf,
    #[command(flatten)]
    pub settings: SpectralSettingsArgs,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

impl SpectralSettingsArgs {
    /// Integration settings: the method and whether to extrapolate.
    pub fn settings(&self) -> anyhow::Result<IntegrationSettings> {
        Ok(IntegrationSettings {
            method: self.method()?,
            extrapolate: self.extrapolate,
        })
    }

    /// How to read the file.
    pub fn read_options(&self) -> ReadOptions {
        ReadOptions {
            percent: self.percent,
        }
    }

    /// The library's [`Method`], refusing options that do not apply to the chosen method.
    pub fn method(&self) -> anyhow::Result<Method> {
        let colorimetric_flags = self.observer.is_some()
            || self.illuminant.is_some()
            || self.space.is_some()
            || self.white_balance.is_some();
        Ok(match self.method {
            MethodArg::Paper => {
                if colorimetric_flags {
                    bail!(
                        "--observer, --illuminant, --white-balance and --space apply to --method colorimetric, not paper"
                    );
                }
                Method::Paper(match self.cmf.unwrap_or(CmfArg::WrightGuild1931) {
                    CmfArg::WrightGuild1931 => RgbCmf::WrightGuild1931,
                    CmfArg::StilesBurch1955 => RgbCmf::StilesBurch1955,
                    CmfArg::StilesBurch1959 => RgbCmf::StilesBurch1959,
                })
            }
            MethodArg::Colorimetric => {
                if self.cmf.is_some() {
                    bail!("--cmf applies to --method paper, not colorimetric");
                }
                Method::Colorimetric(ColorimetricSettings {
                    observer: match self.observer.unwrap_or(ObserverArg::Cie1931) {
                        ObserverArg::Cie1931 => Observer::Cie1931,
                        ObserverArg::Cie1964 => Observer::Cie1964,
                    },
                    illuminant: match &self.illuminant {
                        Some(text) => Illuminant::from_name_or_file(text)
                            .map_err(anyhow::Error::new)
                            .context("--illuminant")?,
                        None => Illuminant::default(),
                    },
                    space: self.space.unwrap_or(SpaceArg::Srgb).space(),
                    white_balance: self.white_balance.unwrap_or_default(),
                })
            }
            MethodArg::Luminous => {
                if colorimetric_flags || self.cmf.is_some() {
                    bail!(
                        "--cmf, --observer, --illuminant, --white-balance and --space do not apply to --method luminous"
                    );
                }
                Method::Luminous
            }
        })
    }
}

/// One quantity's results.
struct QuantityResult {
    key: &'static str,
    label: &'static str,
    rgb: [f64; 3],
    luminous_iso: f64,
    luminous_1nm: f64,
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let (data, method, results) = integrate_file(&args)?;
    let out = if args.json {
        let mut s = serde_json::to_string_pretty(&to_json(&data, &method, &results))?;
        s.push('\n');
        s
    } else {
        to_text(&data, &method, &results)
    };
    out!("{out}");
    Ok(ExitCode::SUCCESS)
}

/// What `glassdb spectral --json` prints, for the command and the Python package alike.
pub fn report_json(args: &Args) -> anyhow::Result<Value> {
    let (data, method, results) = integrate_file(args)?;
    Ok(to_json(&data, &method, &results))
}

/// The file of `args` read, checked and integrated as its settings say.
fn integrate_file(args: &Args) -> anyhow::Result<(SpectralData, Method, Vec<QuantityResult>)> {
    let settings = args.settings.settings()?;
    let method = settings.method.clone();
    let data = read_spectral_file(&args.file, &args.settings.read_options())
        .map_err(anyhow::Error::new)?;
    let integrator = Integrator::new(&settings)?;
    // the energy checks of the registry build, on the data and on the integrated channels
    glassdb_spectral::check_spectrum_balance(
        &data.wavelength_nm,
        data.transmittance.as_deref(),
        &[
            data.reflectance_front.as_deref(),
            data.reflectance_back.as_deref(),
        ],
    )
    .with_context(|| data.source.clone())?;
    let results = integrate_all(&data, &integrator, settings.extrapolate)?;
    check_channel_balance(&data, &results)?;
    Ok((data, method, results))
}

fn integrate_all(
    data: &SpectralData,
    integrator: &Integrator,
    extrapolate: bool,
) -> anyhow::Result<Vec<QuantityResult>> {
    let quantities = [
        ("transmittance", "transmittance", &data.transmittance),
        (
            "reflectance",
            "reflectance (front)",
            &data.reflectance_front,
        ),
        (
            "reflectance_back",
            "reflectance (back)",
            &data.reflectance_back,
        ),
    ];
    let wl = &data.wavelength_nm;
    let mut results = Vec::new();
    for (key, label, values) in quantities {
        let Some(values) = values else { continue };
        let context = || format!("{}: {label}", data.source);
        let rgb = integrator
            .channels(wl, values)
            .map_err(anyhow::Error::new)
            .with_context(context)?;
        let luminous_iso = luminous(wl, values, LuminousGrid::Iso9050, extrapolate)
            .map_err(anyhow::Error::new)
            .with_context(context)?;
        let luminous_1nm = luminous(wl, values, LuminousGrid::OneNm, extrapolate)
            .map_err(anyhow::Error::new)
            .with_context(context)?;
        results.push(QuantityResult {
            key,
            label,
            rgb,
            luminous_iso,
            luminous_1nm,
        });
    }
    Ok(results)
}

/// t + r ≤ 1 per channel for each side the file has, as the registry build checks it.
fn check_channel_balance(data: &SpectralData, results: &[QuantityResult]) -> anyhow::Result<()> {
    let rgb = |key: &str| results.iter().find(|r| r.key == key).map(|r| r.rgb);
    let Some(t) = rgb("transmittance") else {
        return Ok(());
    };
    for (key, side) in [("reflectance", "front"), ("reflectance_back", "back")] {
        if let Some(r) = rgb(key) {
            glassdb_spectral::check_channel_balance(t, r, side, &data.wavelength_nm)
                .with_context(|| data.source.clone())?;
        }
    }
    Ok(())
}

fn to_json(data: &SpectralData, method: &Method, results: &[QuantityResult]) -> Value {
    let (cmf, observer, illuminant, space, white_balance) = match method {
        Method::Paper(c) => (Some(c.name()), None, None, None, None),
        Method::Colorimetric(c) => (
            None,
            Some(c.observer.name()),
            Some(c.illuminant.name()),
            Some(c.space.name()),
            Some(c.white_balance.name()),
        ),
        Method::Luminous => (None, None, None, None, None),
    };
    let name = method.kind().name();
    let mut obj = json!({
        "method": name,
        "cmf": cmf,
        "observer": observer,
        "illuminant": illuminant,
        "space": space,
        "white_balance": white_balance,
        "file": data.source,
        "product": data.product,
    });
    if let Some(map) = obj.as_object_mut() {
        for r in results {
            map.insert(
                r.key.to_owned(),
                json!({"rgb": r.rgb, "luminous": r.luminous_iso, "luminous_1nm": r.luminous_1nm}),
            );
        }
    }
    obj
}

/// The readable report's table: one row per quantity, its RGB and luminous values.
const QUANTITY_TABLE: TextTable<6> = TextTable {
    columns: [
        Column::left("", 22),
        Column::right("", 10),
        Column::right("", 10),
        Column::right("", 10),
        Column::right("", 14),
        Column::right("", 14),
    ],
};

fn to_text(data: &SpectralData, method: &Method, results: &[QuantityResult]) -> String {
    let mut s = String::new();
    let p = &data.product;
    let _ = writeln!(s, "{}", data.source);
    let details: Vec<String> = [
        p.name.clone(),
        p.manufacturer.clone(),
        p.product_type.clone(),
        p.coated_side.as_ref().map(|c| format!("coated side {c}")),
        p.thickness_mm.map(|t| format!("{t} mm")),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !details.is_empty() {
        let _ = writeln!(s, "  {}", details.join(", "));
    }
    let wl = &data.wavelength_nm;
    if let (Some(first), Some(last)) = (wl.first(), wl.last()) {
        let _ = writeln!(s, "  {} samples, {first}–{last} nm", wl.len());
    }
    if !p.other_incidence_angles_deg.is_empty() {
        let angles: Vec<String> = p
            .other_incidence_angles_deg
            .iter()
            .map(|a| format!("{a}°"))
            .collect();
        let _ = writeln!(
            s,
            "  normal incidence read; the file also has {} (not read)",
            angles.join(", ")
        );
    }
    let _ = writeln!(s, "method: {method}");
    let titles = ["", "R", "G", "B", "luminous", "luminous 1nm"];
    let _ = writeln!(s, "{}", QUANTITY_TABLE.line(titles));
    for r in results {
        let v = |x: f64| format!("{x:.6}");
        let row = [
            r.label.to_string(),
            v(r.rgb[0]),
            v(r.rgb[1]),
            v(r.rgb[2]),
            v(r.luminous_iso),
            v(r.luminous_1nm),
        ];
        let _ = writeln!(s, "{}", QUANTITY_TABLE.line(row));
    }
    s
}
