//! Section "Figures": the figures of the page, drawn by glassdb-plot (the same code as
//! `glassdb plot`), saved into the figures directory and linked from the page.

use std::fmt::Write as _;
use std::path::Path;

use glassdb_fit::cos_deg;
use glassdb_io::StagedOutput;
use glassdb_mask::CosCode;
use glassdb_plot::chart::{LegendCorner, Line, Panel, Stroke, palette};
use glassdb_plot::figure::{Cell, GridFigure};
use glassdb_plot::plots::fit::{FitPlotOptions, fit_figure_from_table};
use glassdb_plot::plots::mask::{MaskPlotOptions, mask_figure_of};
use glassdb_plot::plots::registry::{RegistryPlotOptions, registry_figure_of};
use glassdb_plot::plots::spectral::{SpectralPlotOptions, spectral_figure};
use glassdb_plot::{Figure, plots::ANGLE_AXIS};
use glassdb_registry::{BuildOptions, build_registry};
use glassdb_spectral::{IntegrationSettings, Method, ReadOptions, RgbCmf};

use crate::cos_storage::CosStorage;
use crate::gouraud::SceneMask;
use crate::measure::dense_angles;
use crate::reference::Reference;
use crate::spectral::spectral_methods;
use crate::text::shown;
use crate::{ReportError, ReportOptions, SpectrumFigure};

/// Where the figures go, what has been staged, and the page that links them.
struct FigureSink<'a> {
    /// The page's text.
    md: &'a mut String,
    dir: &'a Path,
    /// How the page links the directory.
    link: &'a str,
    /// The figures, each in its temporary file until the report is written.
    staged: &'a mut StagedOutput,
}

impl FigureSink<'_> {
    /// Stages a figure for the figures directory and links it from the page.
    fn add<F: Figure>(&mut self, file: &str, caption: &str, fig: &F) -> Result<(), ReportError> {
        let path = self.dir.join(file);
        let (bytes, _) = glassdb_plot::render_for(fig, &path)?;
        self.staged.write_bytes(&path, &bytes)?;
        let kb = bytes.len() / 1024;
        let _ = writeln!(
            self.md,
            "![{caption}]({}/{file})\n\n*{caption}* ({kb} KB)\n",
            self.link
        );
        Ok(())
    }
}

/// Writes the section and stages the figures for `dir` in `staged`.
pub(crate) fn section_figures(
    md: &mut String,
    opts: &ReportOptions,
    dir: &Path,
    refs: &[Reference],
    scene_mask: Option<&SceneMask>,
    staged: &mut StagedOutput,
) -> Result<(), ReportError> {
    glassdb_io::create_output_folder(dir, "figures directory")?;
    let _ = writeln!(md, "## Figures\n");
    let _ = writeln!(
        md,
        "Drawn by the same code as `glassdb plot` (the command for each is given with its caption).\n"
    );
    let mut sink = FigureSink {
        md,
        dir,
        link: &opts.figures_link,
        staged,
    };
    fit_figures(opts, &mut sink)?;
    if let Some(spectrum) = opts
        .spectrum_figure
        .as_ref()
        .filter(|s| s.spectrum.exists())
    {
        spectral_figures(opts, spectrum, &mut sink)?;
    }
    registry_figure(opts, &mut sink)?;
    if let Some(sm) = scene_mask {
        mask_figure(sm, &mut sink)?;
    }
    cos_storage_figure(refs, &mut sink)?;
    Ok(())
}

/// One fit figure per angle table: measured points, default fit and paper basis.
fn fit_figures(opts: &ReportOptions, sink: &mut FigureSink<'_>) -> Result<(), ReportError> {
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
        sink.add(
            &format!("fit_{stem}.png"),
            &format!(
                "`glassdb plot fit {} --compare-paper`: measured (exact) points, default fit (solid) and paper basis (dashed), residuals below",
                shown(&opts.root, table)
            ),
            &fig,
        )?;
    }
    Ok(())
}

/// The spectrum integrated by the paper method and by the colorimetric default.
fn spectral_figures(
    opts: &ReportOptions,
    spectrum: &SpectrumFigure,
    sink: &mut FigureSink<'_>,
) -> Result<(), ReportError> {
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
            &spectrum.spectrum,
            &SpectralPlotOptions {
                settings: IntegrationSettings {
                    method,
                    extrapolate: false,
                },
                read: ReadOptions::default(),
            },
        )?;
        sink.add(
            &format!("spectral_{}_{tag}.png", spectrum.name),
            &format!(
                "`glassdb plot spectral {} {label}`",
                shown(&opts.root, &spectrum.spectrum)
            ),
            &fig,
        )?;
    }
    Ok(())
}

/// Curves of a few glasses of the catalog's registry.
fn registry_figure(opts: &ReportOptions, sink: &mut FigureSink<'_>) -> Result<(), ReportError> {
    let Ok(reg) = build_registry(&opts.catalog, &BuildOptions::default()) else {
        return Ok(());
    };
    let catalog = shown(&opts.root, &opts.catalog);
    let ids: Vec<u16> = [2u16, 4, 6, 8]
        .into_iter()
        .filter(|id| reg.default_table().glass(*id).is_some())
        .collect();
    let fig = registry_figure_of(
        &reg,
        &format!("default registry ({catalog})"),
        &RegistryPlotOptions {
            ids: ids.clone(),
            basis: None,
        },
    )?;
    let id_args: Vec<String> = ids.iter().map(|i| format!("--id {i}")).collect();
    sink.add(
        "registry_default.png",
        &format!(
            "`glassdb plot registry registry.json {}` (registry built from {catalog})",
            id_args.join(" ")
        ),
        &fig,
    )
}

/// The reflectance heat map of the Gouraud section's exact mask.
fn mask_figure(sm: &SceneMask, sink: &mut FigureSink<'_>) -> Result<(), ReportError> {
    let fig = mask_figure_of(
        &sm.mask,
        &sm.registry,
        &format!("{} (exact cos θ, 8-bit mask)", sm.name),
        &MaskPlotOptions::default(),
    )?;
    let stem = sm.name.split('.').next().unwrap_or_default();
    sink.add(
        &format!("mask_{stem}_reflectance.png"),
        &format!(
            "`glassdb plot mask mask.png --registry registry.json` of the {stem} fixture (mask from `glassdb mask`): reflectance rises towards grazing view"
        ),
        &fig,
    )
}

/// Reflectance error against angle for each cos θ storage.
fn cos_storage_figure(refs: &[Reference], sink: &mut FigureSink<'_>) -> Result<(), ReportError> {
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
    sink.add(
        "cos_storage_error.png",
        "reflectance error against angle for each cos θ storage (report only)",
        &fig,
    )
}

/// log10 of the worst reflectance error per 0.5° bin of the first reference, per storage.
fn log10_error_panel(title: &str, refs: &[Reference]) -> Panel {
    let mut p = Panel::new(ANGLE_AXIS, "log10 |Δr| (reflectance error)", (0.0, 89.0));
    p.title = Some(title.to_string());
    p.legend = Some(LegendCorner::LowerRight);
    let grid = dense_angles(89.0, 0.05);
    let r = &refs[0];
    let storages = [
        CosStorage::Code(CosCode::Bits8),
        CosStorage::Code(CosCode::Bits16),
        CosStorage::Half,
    ];
    for (k, st) in storages.into_iter().enumerate() {
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
        p.lines.push(Line::new(
            Some(st.name().to_string()),
            palette(k),
            Stroke::SOLID,
            pts,
        ));
    }
    p
}
