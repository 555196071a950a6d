//! `glassdb report`: the speed-against-error tables of `docs/accuracy.md`, computed afresh on
//! every run (errors against exact physics, timings with `std::time::Instant` on this machine)
//! and the figures embedded in the page, drawn with glassdb-plot.
//!
//! References: the uncoated slab (s/p Fresnel, incoherent multiple reflections) and the WINDOW-4
//! coated-glass curves, both from `glassdb_registry::physics` (equations in `docs/registry.md`).
//! Each section of the page is one module; every input file is named by the caller
//! ([`ReportOptions`]).

#![warn(missing_docs)]

mod cos_storage;
mod degree_basis;
mod error;
mod figures;
mod gouraud;
mod measure;
mod reference;
mod spectral;
mod tables;
mod text;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use error::ReportError;

/// Inputs of the report.
#[derive(Debug, Clone)]
pub struct ReportOptions {
    /// Paths under this directory are shown relative to it in the page.
    pub root: PathBuf,
    /// The catalog whose spectral glasses the spectral table covers and whose registry the
    /// registry figure draws (the bundled catalog).
    pub catalog: PathBuf,
    /// Angle tables drawn as fit figures (measured → fitted).
    pub angle_tables: Vec<PathBuf>,
    /// A spectrum drawn under the paper and the colorimetric method (skipped when missing).
    pub spectrum_figure: Option<SpectrumFigure>,
    /// The scene for the Gouraud-vs-exact row: OBJ, camera JSON, glass mappings, catalog.
    pub gouraud_scene: Option<GouraudScene>,
    /// Where the figures are written (`None`: no figures).
    pub figures_dir: Option<PathBuf>,
    /// How the markdown refers to the figures directory (relative to the markdown file).
    pub figures_link: String,
    /// Values per timing run.
    pub timing_values: usize,
}

/// A spectrum file and the name its figures go by (`spectral_<name>_<method>.png`).
#[derive(Debug, Clone)]
pub struct SpectrumFigure {
    /// The spectral file.
    pub spectrum: PathBuf,
    /// The name its figures go by.
    pub name: String,
}

/// The scene used to compare the paper's Gouraud-interpolated cos θ with the exact one.
#[derive(Debug, Clone)]
pub struct GouraudScene {
    /// The OBJ scene.
    pub obj: PathBuf,
    /// Its camera.
    pub camera: PathBuf,
    /// `PATTERN=ID` as `glassdb mask --glass`.
    pub glass: Vec<String>,
    /// The catalog of its glasses.
    pub catalog: PathBuf,
}

/// The generated page and its figures, which [`Report::write`] writes together.
#[derive(Debug)]
pub struct Report {
    /// The page's Markdown.
    pub markdown: String,
    /// Where the figures go (written by [`Report::write`]).
    pub figures: Vec<PathBuf>,
    /// The figures, each drawn into its temporary file beside its target.
    staged: glassdb_io::StagedOutput,
}

impl Report {
    /// Writes the page to `page` and every figure: all of them land, or (on any failure) none
    /// (`glassdb_io::StagedOutput`).
    pub fn write(mut self, page: &Path) -> Result<(), ReportError> {
        self.staged.write_bytes(page, self.markdown.as_bytes())?;
        self.staged.commit()?;
        Ok(())
    }
}

/// The sections [`generate_with_progress`] reports as stages, in order (the last only when
/// figures are written).
pub const SECTIONS: [&str; 6] = [
    "degree and basis",
    "cos θ storage",
    "approximation tables",
    "spectral methods",
    "Gouraud cos θ",
    "figures",
];

/// Generates the page (and the figures when `figures_dir` is set). A section whose inputs
/// fail says so in the page ("Not computed") and the others still run; only the figures
/// fail the report.
pub fn generate(opts: &ReportOptions) -> Result<Report, ReportError> {
    generate_with_progress(opts, &glassdb_io::NoProgress)
}

/// [`generate`], telling `progress` as each of the [`SECTIONS`] begins (a stage and its step
/// among them).
pub fn generate_with_progress(
    opts: &ReportOptions,
    progress: &dyn glassdb_io::Progress,
) -> Result<Report, ReportError> {
    let total = if opts.figures_dir.is_some() {
        SECTIONS.len()
    } else {
        SECTIONS.len() - 1
    } as u64;
    let section = |k: usize| {
        progress.stage(SECTIONS[k]);
        progress.step(k as u64, total);
    };
    let mut md = String::new();
    let refs = reference::references();
    let inputs = measure::timing_inputs(opts.timing_values.max(1024));
    write_header(&mut md, &refs, inputs.len());
    section(0);
    degree_basis::section_degree_basis(&mut md, &refs, &inputs);
    section(1);
    cos_storage::section_quantisation(&mut md, &refs);
    section(2);
    tables::section_tables(&mut md, &refs, &inputs);
    section(3);
    if let Err(e) = spectral::section_spectral(&mut md, &opts.catalog) {
        not_computed(&mut md, "Spectral methods", &e);
    }
    section(4);
    let scene_mask = match &opts.gouraud_scene {
        Some(g) => match gouraud::section_gouraud(&mut md, g, &opts.root) {
            Ok(m) => Some(m),
            Err(e) => {
                not_computed(&mut md, "Gouraud-interpolated cos θ vs exact", &e);
                None
            }
        },
        None => None,
    };
    let mut staged = glassdb_io::StagedOutput::new();
    if let Some(dir) = &opts.figures_dir {
        section(5);
        figures::section_figures(&mut md, opts, dir, &refs, scene_mask.as_ref(), &mut staged)?;
    }
    progress.step(total, total);
    Ok(Report {
        markdown: md,
        figures: staged.paths().map(Path::to_path_buf).collect(),
        staged,
    })
}

/// The page's title, how to regenerate it, the machine of this run and the references.
fn write_header(md: &mut String, refs: &[reference::Reference], timing_values: usize) {
    let _ = writeln!(md, "# Accuracy: speed against error\n");
    let _ = writeln!(
        md,
        "Generated by `glassdb report`; do not edit by hand. To regenerate this page and its figures \
         (from the repository root):\n\n    cargo run --release -- report\n\n\
         (`-o` names the page, `--figures` the figure directory). Errors are against exact physics and \
         are reproducible to the last digit; timings are measured on every run with \
         `std::time::Instant` (best of 5 passes over {timing_values} values, written to a buffer) and vary with the \
         machine.\n\nMachine of this run: {}.\n",
        measure::machine_line()
    );
    let _ = writeln!(
        md,
        "References (the \"exact physics\"), from `glassdb_registry::physics` (equations in `docs/registry.md`):\n"
    );
    for r in refs {
        let _ = writeln!(md, "- **{}**: {}.", r.name, r.description);
    }
    let _ = writeln!(md);
}

/// A section that could not be computed, with the whole error chain.
fn not_computed(md: &mut String, title: &str, e: &ReportError) {
    let _ = writeln!(
        md,
        "## {title}\n\nNot computed: {}\n",
        glassdb_io::ErrorChain(e)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sections_are_reported_in_order() {
        let dir = std::env::temp_dir();
        let opts = ReportOptions {
            root: dir.clone(),
            catalog: dir.join("no-such-catalog.toml"),
            angle_tables: Vec::new(),
            spectrum_figure: None,
            gouraud_scene: None,
            figures_dir: None,
            figures_link: "figures".into(),
            timing_values: 1024,
        };
        let log = glassdb_io::StageLog::default();
        let report = generate_with_progress(&opts, &log).unwrap();
        assert_eq!(log.stages(), SECTIONS[..5]);
        assert!(
            report.markdown.contains("Not computed"),
            "the missing catalog"
        );
    }
}
