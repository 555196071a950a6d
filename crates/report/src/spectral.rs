//! Section "Spectral methods": every glass of the catalog with spectral data, integrated by the
//! paper's RGB method (each colour-matching set), the colorimetric sRGB method and ISO 9050.

use std::fmt::Write as _;
use std::path::Path;

use glassdb_registry::catalog::{GlassBuild, LayerSpec, NormalSource, parse_catalog, resolve};
use glassdb_spectral::{
    IntegrationSettings, Integrator, Method, ReadOptions, RgbCmf, SpectralData, luminous_iso9050,
    read_spectral_file,
};

use crate::ReportError;
use crate::text::{file_name, fmt_rgb};

/// One quantity of one glass under every method.
struct SpectralRow {
    glass: String,
    quantity: &'static str,
    paper: Vec<[f64; 3]>,
    srgb: [f64; 3],
    luminous: f64,
}

/// The paper's colour-matching sets (with their column names) and the colorimetric settings.
pub(crate) fn spectral_methods() -> (Vec<(RgbCmf, &'static str)>, IntegrationSettings) {
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

/// Integrates without extrapolation, or with it when the data does not cover the range.
fn integrate(
    settings: IntegrationSettings,
    data: &SpectralData,
    values: &[f64],
) -> Result<[f64; 3], ReportError> {
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

/// Writes the section for every spectral glass of `catalog`.
pub(crate) fn section_spectral(md: &mut String, catalog: &Path) -> Result<(), ReportError> {
    let rows = spectral_rows(catalog)?;
    let cmfs = spectral_methods().0;
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
        file_name(catalog)
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

/// Reads every spectral glass of the catalog and integrates its τ and front ρ by each method.
fn spectral_rows(catalog: &Path) -> Result<Vec<SpectralRow>, ReportError> {
    let text = glassdb_io::read_input_string(catalog, glassdb_registry::CATALOG_FILE).map_err(
        |source| ReportError::Read {
            path: catalog.into(),
            source,
        },
    )?;
    let specs = parse_catalog(&text, catalog)?;
    let (cmfs, srgb_settings) = spectral_methods();
    let mut rows = Vec::new();
    for spec in &specs {
        let GlassBuild::Single(LayerSpec {
            normal: NormalSource::Spectral { path, percent },
            ..
        }) = &spec.build
        else {
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
            let srgb = integrate(srgb_settings.clone(), &data, values)?;
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
    Ok(rows)
}
