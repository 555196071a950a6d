//! `glassdb report`: regenerates `docs/accuracy.md` (speed against error of every approximation)
//! and its figures. All the work is in `glassdb_report`; this names the repository's files.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_report::{GouraudScene, ReportOptions, SpectrumFigure, generate_with_progress};

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Where to write the page.
    #[arg(short, long, default_value = "docs/accuracy.md")]
    pub output: PathBuf,
    /// Directory for the figures (PNG), linked from the page by a relative path.
    #[arg(long, default_value = "docs/figures")]
    pub figures: PathBuf,
    /// Write no figures.
    #[arg(long)]
    pub no_figures: bool,
    /// Repository root (holding data/ and fixtures/).
    #[arg(long, default_value = ".")]
    pub root: PathBuf,
    /// Values per timing pass (more: steadier timings, slower run).
    #[arg(long, default_value_t = 1 << 20)]
    pub timing_values: usize,
}

/// The report's inputs in the repository at `root`.
fn repository_inputs(root: &Path) -> ReportOptions {
    ReportOptions {
        root: root.to_path_buf(),
        catalog: root.join("data/catalog.toml"),
        angle_tables: vec![
            root.join("data/angles/clear_6mm_fresnel.csv"),
            root.join("data/angles/bronze_coated_window4.csv"),
        ],
        spectrum_figure: Some(SpectrumFigure {
            spectrum: root.join("data/glazing/LOW-E_5.LOF"),
            name: "lowe".into(),
        }),
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

/// `figures` as the page at `page` should link it: relative when it lies under the page's folder.
fn link_to(page: &Path, figures: &Path) -> String {
    let base = page
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let strip = |p: &Path| {
        p.components()
            .filter(|c| !matches!(c, std::path::Component::CurDir))
            .collect::<PathBuf>()
    };
    match strip(figures).strip_prefix(strip(base)) {
        Ok(rel) if !rel.as_os_str().is_empty() => rel.display().to_string(),
        _ => figures.display().to_string(),
    }
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    if !args.root.join("data/catalog.toml").is_file() {
        bail!(
            "{} does not look like the glassdb repository (no data/catalog.toml): run from the repository root or pass --root",
            args.root.display()
        );
    }
    if args.timing_values == 0 {
        bail!("--timing-values must be at least 1");
    }
    let mut opts = repository_inputs(&args.root);
    opts.timing_values = args.timing_values;
    opts.figures_dir = (!args.no_figures).then(|| args.figures.clone());
    opts.figures_link = link_to(&args.output, &args.figures);
    if cfg!(debug_assertions) {
        eprintln!(
            "note: a debug build; the timings will not be representative (use cargo run --release -- report)"
        );
    }
    let spinner = crate::cmd::progress::Spinner::on_terminal("report");
    let report = generate_with_progress(&opts, &spinner)?;
    spinner.finish();
    let figures = report.figures.clone();
    report
        .write(&args.output)
        .with_context(|| format!("cannot write the report to {}", args.output.display()))?;
    for f in &figures {
        eprintln!("wrote {}", f.display());
    }
    eprintln!("wrote {}", args.output.display());
    Ok(ExitCode::SUCCESS)
}
