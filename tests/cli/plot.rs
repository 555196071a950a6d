//! End-to-end tests of `glassdb plot` and `glassdb report`: files are produced and non-trivial
//! (size, distinct colours, lightness spread; SVG structure), not pixel-exact; bad input gives a
//! clear error naming what is wrong, with no panic and no output file left behind.

use std::path::{Path, PathBuf};
use std::process::Command;

use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_plot::inspect::summarize_png;
use tempfile::TempDir;

use crate::util::{
    assert_images_match, fails_naming, glassdb, ok, read_png_planes, registry_build, repo_path,
    write_file,
};

/// Asserts a PNG figure is really drawn: plausible size and many colours with contrast.
fn assert_drawn_png(path: &Path, min_bytes: u64) {
    let bytes = std::fs::metadata(path)
        .unwrap_or_else(|e| panic!("{} missing: {e}", path.display()))
        .len();
    assert!(
        bytes >= min_bytes,
        "{} is only {bytes} bytes",
        path.display()
    );
    assert!(
        bytes < 2_000_000,
        "{} is {bytes} bytes: too big for a figure",
        path.display()
    );
    let s = summarize_png(path).unwrap();
    assert!(s.width >= 400 && s.height >= 300, "{s:?}");
    assert!(
        s.distinct_colours >= 50,
        "too few colours (blank or flat figure): {s:?}"
    );
    assert!(s.luma_std >= 15.0, "no contrast: {s:?}");
    assert!(
        s.inked_fraction >= 0.03 && s.inked_fraction <= 0.95,
        "{s:?}"
    );
}

/// Asserts an SVG figure has its title and many drawn elements.
fn assert_drawn_svg(path: &Path, title_fragment: &str) {
    let svg = std::fs::read_to_string(path).unwrap();
    assert!(
        svg.starts_with("<svg") || svg.contains("<svg "),
        "not an SVG: {}",
        &svg[..svg.len().min(200)]
    );
    assert!(svg.trim_end().ends_with("</svg>"), "SVG is truncated");
    assert!(
        svg.contains(title_fragment),
        "title `{title_fragment}` missing from the SVG"
    );
    let elements = svg.matches("<polyline").count()
        + svg.matches("<path").count()
        + svg.matches("<rect").count();
    assert!(elements >= 20, "only {elements} drawn elements");
    assert!(svg.matches("<text").count() >= 10, "axis labels missing");
}

/// An angle table with two glasses, from the Fresnel slab formula (n = 1.5, no absorption):
/// R = 2ρ/(1+ρ), T = (1−ρ)/(1+ρ) per polarisation, averaged; measured only to 70°.
fn slab_table(dir: &Path) -> PathBuf {
    let mut csv = String::from("glass,angle_deg,R,T\n");
    for (name, n) in [("slab 1.5", 1.5f64), ("slab 1.7", 1.7)] {
        for a in (0..=70).step_by(5) {
            let th = (a as f64).to_radians();
            let (c, s) = (th.cos(), th.sin());
            let ct = (1.0 - (s / n).powi(2)).sqrt();
            let rs = ((c - n * ct) / (c + n * ct)).powi(2);
            let rp = ((n * c - ct) / (n * c + ct)).powi(2);
            let r = 0.5 * (2.0 * rs / (1.0 + rs) + 2.0 * rp / (1.0 + rp));
            csv.push_str(&format!("{name},{a},{r:.8},{:.8}\n", 1.0 - r));
        }
    }
    write_file(dir, "slab.csv", csv.as_bytes())
}

/// A temporary folder that a test's inputs and figures go into.
struct Figures(TempDir);

impl Figures {
    fn new() -> Self {
        Figures(tempfile::tempdir().unwrap())
    }

    fn path(&self) -> &Path {
        self.0.path()
    }

    /// Runs `plot` with `-o <folder>/<name>` and returns the path of the figure it wrote.
    fn draw(&self, name: &str, mut plot: Command) -> PathBuf {
        let out = self.path().join(name);
        ok(plot.arg("-o").arg(&out));
        out
    }
}

/// A temporary folder with the atrium's registry built in it, and the registry's path.
fn atrium_registry() -> (Figures, PathBuf) {
    let dir = Figures::new();
    let reg = atrium_registry_in(dir.path());
    (dir, reg)
}

fn atrium_registry_in(dir: &Path) -> PathBuf {
    let reg = dir.join("registry.json");
    ok(&mut registry_build(
        &repo_path("fixtures/atrium/catalog.toml"),
        &reg,
        &[],
    ));
    reg
}

/// `glassdb plot <kind> <input> [args…]`.
fn plot(kind: &str, input: &Path, args: &[&str]) -> Command {
    let mut cmd = glassdb();
    cmd.args(["plot", kind]).arg(input).args(args);
    cmd
}

/// `glassdb plot <kind> <input> [args…] -o <out>`.
fn plot_to(kind: &str, input: &Path, args: &[&str], out: &Path) -> Command {
    let mut cmd = plot(kind, input, args);
    cmd.arg("-o").arg(out);
    cmd
}

/// `glassdb plot mask <mask> --registry <registry> [args…]`.
fn plot_mask(mask: &Path, registry: &Path, args: &[&str]) -> Command {
    let mut cmd = plot("mask", mask, &["--registry"]);
    cmd.arg(registry).args(args);
    cmd
}

/// Runs `glassdb report` of this repository into `dir/accuracy.md`, its figures into
/// `dir/<figures>`; returns the page's and the figures' paths.
fn report(dir: &Path, figures: &str) -> (PathBuf, PathBuf) {
    let page = dir.join("accuracy.md");
    let figs = dir.join(figures);
    ok(glassdb()
        .arg("report")
        .arg("--root")
        .arg(repo_path(""))
        .arg("-o")
        .arg(&page)
        .arg("--figures")
        .arg(&figs)
        .args(["--timing-values", "2048"]));
    (page, figs)
}

/// A 96×64 mask: glass id 1 on the left half, id 5 on the right, cos θ falling from 1 at the
/// top to 0.05 at the bottom; a no-glass band in the middle.
fn gradient_mask(dir: &Path, ids: [u16; 2]) -> PathBuf {
    let (w, h) = (96u32, 64u32);
    let mut id = Vec::new();
    let mut cos = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let glass = if x < 44 {
                ids[0]
            } else if x >= 52 {
                ids[1]
            } else {
                0
            };
            id.push(glass);
            let c = 1.0 - 0.95 * y as f64 / (h - 1) as f64;
            cos.push(if glass == 0 {
                0
            } else {
                (c * 255.0).round() as u8
            });
        }
    }
    let mask = MaskImage {
        width: w,
        height: h,
        id,
        cos_theta: CosTheta::Quantized8(cos),
        plane: vec![0; (w * h) as usize],
        coverage: None,
    };
    let path = dir.join("mask.png");
    write_mask(&path, &mask, MaskFormat::Png8).unwrap();
    path
}

#[test]
fn fit_of_a_measured_table_to_png_and_svg() {
    let dir = Figures::new();
    let table = slab_table(dir.path());
    let png = dir.draw("fit.png", plot("fit", &table, &["--compare-paper"]));
    assert_drawn_png(&png, 20_000);
    let svg = dir.draw("fit.svg", plot("fit", &table, &["--glass", "slab 1.7"]));
    assert_drawn_svg(&svg, "slab 1.7");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        !text.contains("slab 1.5"),
        "--glass should keep only the named glass"
    );
    // The measured range (0–70°) is shaded and labelled, so extrapolation beyond 70° shows.
    assert!(
        text.contains("measured range 0–70°"),
        "measured range legend missing"
    );
    assert!(text.contains("fit − measured"), "residual panel missing");
}

#[test]
fn fit_file_with_measured_points_overlaid() {
    let dir = Figures::new();
    let table = slab_table(dir.path());
    let fits = dir.path().join("fits.json");
    // measured to 70° only, the fit is refused for what it does beyond (r + t > 1 at 90°)
    // unless forced: the figure is to show that extrapolation
    ok(glassdb()
        .arg("fit")
        .arg(&table)
        .args(["--force", "-o"])
        .arg(&fits));
    let mut with_data = plot("fit", &fits, &["--data"]);
    with_data.arg(&table);
    let svg = dir.draw("curves.svg", with_data);
    assert_drawn_svg(&svg, "slab 1.5");
    assert!(
        std::fs::read_to_string(&svg)
            .unwrap()
            .contains("r measured")
    );
    // Without data: curves only, still a figure.
    assert_drawn_png(&dir.draw("curves.png", plot("fit", &fits, &[])), 15_000);
}

#[test]
fn registry_plot_one_colour_per_channel() {
    let (dir, reg) = atrium_registry();
    assert_drawn_png(&dir.draw("reg.png", plot("registry", &reg, &[])), 20_000);
    let svg = dir.draw("reg.svg", plot("registry", &reg, &["--id", "5"]));
    assert_drawn_svg(&svg, "id 5");
    let text = std::fs::read_to_string(&svg).unwrap();
    for label in ["r R", "r G", "r B", "t R", "t G", "t B"] {
        assert!(text.contains(label), "legend entry `{label}` missing");
    }
    // A registry JSON given to `plot fit` is drawn the same way.
    assert_drawn_png(&dir.draw("via_fit.png", plot("fit", &reg, &[])), 20_000);
}

#[test]
fn registry_plot_unknown_id_lists_the_ids_there_are() {
    let (dir, reg) = atrium_registry();
    let out = dir.path().join("reg.png");
    let cmd = &mut plot_to("registry", &reg, &["--id", "77"], &out);
    fails_naming(cmd, &["77", "ids: 1, 5"]);
    assert!(!out.exists());
}

#[test]
fn mask_heat_map_png_and_svg() {
    let (dir, reg) = atrium_registry();
    let mask = gradient_mask(dir.path(), [1, 5]);
    assert_drawn_png(&dir.draw("heat.png", plot_mask(&mask, &reg, &[])), 8_000);
    let transmittance_g_back = [
        "--quantity",
        "transmittance",
        "--channel",
        "g",
        "--side",
        "0=back",
    ];
    let heat_svg = plot_mask(&mask, &reg, &transmittance_g_back);
    let svg = dir.draw("heat.svg", heat_svg);
    assert_drawn_svg(&svg, "transmittance");
    let text = std::fs::read_to_string(&svg).unwrap();
    // 2 × 44 × 64 glass pixels; the colour range reaches transmittance near 0 at cos θ = 0.05.
    assert!(
        text.contains("5632 glass pixels of 96×64"),
        "pixel count missing"
    );
    assert!(
        std::fs::metadata(&svg).unwrap().len() < 1_500_000,
        "SVG heat map too large"
    );
}

#[test]
fn mask_with_ids_missing_from_the_registry_is_an_error_listing_them() {
    let (dir, reg) = atrium_registry();
    let mask = gradient_mask(dir.path(), [1, 9]);
    let out = dir.path().join("heat.png");
    fails_naming(
        plot_mask(&mask, &reg, &["-o"]).arg(&out),
        &["id 9 (2816 pixels)"],
    );
    assert!(!out.exists());
    let sideways = &mut plot_mask(&mask, &reg, &["--side", "0=sideways"]);
    fails_naming(sideways, &["front or back"]);
}

#[test]
fn spectral_plot_every_method() {
    let dir = Figures::new();
    let file = repo_path("fixtures/glazing/CLEAR_3.DAT");
    assert_drawn_png(&dir.draw("spec.png", plot("spectral", &file, &[])), 20_000);
    let paper_1955 = plot(
        "spectral",
        &file,
        &["--method", "paper", "--cmf", "stiles-burch-1955"],
    );
    let svg = dir.draw("spec.svg", paper_1955);
    assert_drawn_svg(&svg, "stiles-burch-1955");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("τ R =") && text.contains("ρ B ="),
        "channel values not marked"
    );
    let luminous = plot("spectral", &file, &["--method", "luminous"]);
    assert_drawn_png(&dir.draw("lum.png", luminous), 15_000);
    let paper_srgb = ["--method", "paper", "--space", "srgb"];
    fails_naming(&mut plot("spectral", &file, &paper_srgb), &["--space"]);
}

#[test]
fn bad_input_and_bad_output_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let table = slab_table(dir.path());
    let fit_to = |input: &Path, out: &Path| plot_to("fit", input, &[], out);
    // Unknown output format.
    let jpg = dir.path().join("fit.jpg");
    fails_naming(&mut fit_to(&table, &jpg), &["fit.jpg", ".png or .svg"]);
    // Missing input.
    let nope = dir.path().join("nope.csv");
    fails_naming(&mut plot("fit", &nope, &[]), &["nope.csv"]);
    // Malformed table: the error names file, line and column.
    let bad = write_file(dir.path(), "bad.csv", b"angle_deg,R\n0,0.04\n10,abc\n");
    let x_png = dir.path().join("x.png");
    fails_naming(&mut fit_to(&bad, &x_png), &["bad.csv", "line 3", "abc"]);
    // Malformed JSON.
    let badj = write_file(dir.path(), "bad.json", b"{\"glasses\": [ {\"name\": 3} ]}");
    fails_naming(&mut fit_to(&badj, &x_png), &["bad.json"]);
    assert!(!x_png.exists());
    // Output directory that does not exist: named, nothing written.
    let missing = dir.path().join("no/such/dir/fit.png");
    fails_naming(&mut fit_to(&table, &missing), &["no/such/dir"]);
    // The output may not overwrite the input.
    let svg_in = dir.path().join("in.svg");
    std::fs::copy(&table, &svg_in).unwrap();
    let before = std::fs::read(&svg_in).unwrap();
    fails_naming(&mut fit_to(&svg_in, &svg_in), &["in.svg"]);
    assert_eq!(
        std::fs::read(&svg_in).unwrap(),
        before,
        "input was modified"
    );
    // A mask that is not an image.
    let reg = atrium_registry_in(dir.path());
    let notmask = write_file(dir.path(), "m.png", b"not a png at all");
    fails_naming(&mut plot_mask(&notmask, &reg, &[]), &["m.png"]);
    // No leftover temporary files from the failed runs.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(".glassdb-tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left behind");
}

#[test]
fn report_writes_every_table_and_figure() {
    let dir = tempfile::tempdir().unwrap();
    let (page, figs) = report(dir.path(), "figs");
    let md = std::fs::read_to_string(&page).unwrap();
    for heading in [
        "## Polynomial degree and basis against exact physics",
        "### Evaluation cost",
        "## cos θ storage: 8 bits vs 16 bits vs float",
        "## Lookup table vs polynomial vs finer table",
        "## Spectral methods: paper RGB vs colorimetric sRGB vs luminous",
        "## Gouraud-interpolated cos θ (the paper's mesh) vs exact per pixel",
        "## Figures",
    ] {
        assert!(md.contains(heading), "section `{heading}` missing");
    }
    assert!(!md.contains("Not computed"), "a section failed:\n{md}");
    // Hand computation: an 8-bit cos θ rounds to 1 for θ < acos(1 − 1/510) = 3.5886°, the
    // largest angle error of that storage; the 0.001° grid finds it at 3.588°.
    assert!(
        md.contains("| 3.588° (3.6°) |"),
        "8-bit angle error row wrong"
    );
    // Every bundled glass with spectral data appears.
    for id_name in ["1 Clear float 3 mm", "4 Pilkington Energy Advantage"] {
        assert!(
            md.contains(id_name),
            "{id_name} missing from the spectral table"
        );
    }
    let mut linked = 0;
    for entry in std::fs::read_dir(&figs).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            md.contains(&format!("figs/{name}")),
            "{name} not linked from the page"
        );
        assert!(
            std::fs::metadata(&path).unwrap().len() < 200 * 1024,
            "{name} is over 200 KB"
        );
        assert_drawn_png(&path, 10_000);
        linked += 1;
    }
    assert!(linked >= 6, "only {linked} figures");
}

#[test]
fn report_outside_the_repository_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let outside = &mut glassdb();
    outside.arg("report").arg("--root").arg(dir.path());
    fails_naming(
        outside.arg("-o").arg(dir.path().join("a.md")),
        &["data/catalog.toml"],
    );
    assert!(!dir.path().join("a.md").exists());
}

#[test]
fn committed_figures_are_small_and_drawn() {
    // Every figure docs/accuracy.md embeds exists, is under 200 KB and is really drawn.
    let page = std::fs::read_to_string(repo_path("docs/accuracy.md"))
        .expect("docs/accuracy.md (run glassdb report)");
    let mut n = 0;
    for piece in page.split("](figures/").skip(1) {
        let Some(name) = piece.split(')').next() else {
            continue;
        };
        let path = repo_path("docs/figures").join(name);
        let bytes = std::fs::metadata(&path)
            .unwrap_or_else(|e| panic!("{name} embedded but missing: {e}"))
            .len();
        assert!(bytes < 200 * 1024, "{name} is over 200 KB");
        assert_drawn_png(&path, 10_000);
        n += 1;
    }
    assert!(n >= 6, "only {n} figures embedded in docs/accuracy.md");
}

/// docs/accuracy.md with what varies from run to run blanked: the machine line, the timing
/// columns and values, the number of timed values and the figures' file sizes (the PNG encoder's
/// output size differs between builds; the pixels do not). What is left, every error and every
/// figure caption, must be what `glassdb report` computes now.
fn accuracy_page_without_timings(md: &str) -> String {
    let mut out = Vec::new();
    let mut timed_columns: Vec<usize> = Vec::new();
    for line in md.lines() {
        if line.starts_with("Machine of this run") {
            out.push("Machine of this run: …".to_string());
            continue;
        }
        if line.contains("timings are measured on every run") {
            let mut blanked = String::new();
            for c in line.chars() {
                if !c.is_ascii_digit() {
                    blanked.push(c);
                } else if !blanked.ends_with('#') {
                    blanked.push('#');
                }
            }
            out.push(blanked);
            continue;
        }
        if line.starts_with('|') {
            // `\|` inside a cell (|Δr|) is not a column separator.
            let escaped = line.replace("\\|", "\u{1}");
            let cells: Vec<String> = escaped
                .split('|')
                .map(|c| c.replace('\u{1}', "\\|"))
                .collect();
            if cells
                .iter()
                .any(|c| c.contains("ns/value") || c.contains(" ms "))
            {
                timed_columns = (0..cells.len())
                    .filter(|&k| cells[k].contains("ns/value") || cells[k].contains(" ms "))
                    .collect();
            }
            let cells: Vec<String> = cells
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    let header_or_rule =
                        c.contains("ns/value") || c.contains(" ms ") || c.contains("---");
                    if timed_columns.contains(&k) && !header_or_rule {
                        " t ".to_string()
                    } else {
                        c.to_string()
                    }
                })
                .collect();
            out.push(cells.join("|"));
            continue;
        }
        timed_columns.clear();
        let mut line = line.to_string();
        if let Some(end) = line.find(" ns per pixel") {
            let start = line[..end].rfind(' ').map_or(0, |s| s + 1);
            line.replace_range(start..end, "t");
        }
        if let Some(start) = line.rfind(" (").filter(|_| line.ends_with(" KB)")) {
            line.replace_range(start.., " (size)");
        }
        out.push(line);
    }
    out.join("\n")
}

#[test]
fn docs_accuracy_page_and_figures_are_fresh() {
    // The committed page and figures are what `glassdb report` makes of today's code (timings
    // aside): a change to any approximation that the page measures must come with the page.
    let dir = tempfile::tempdir().unwrap();
    let (page, figs) = report(dir.path(), "figures");
    let fresh = accuracy_page_without_timings(&std::fs::read_to_string(&page).unwrap());
    let committed = accuracy_page_without_timings(
        &std::fs::read_to_string(repo_path("docs/accuracy.md")).unwrap(),
    );
    let stale: Vec<String> = fresh
        .lines()
        .zip(committed.lines())
        .enumerate()
        .filter(|(_, (f, c))| f != c)
        .map(|(k, (f, c))| format!("line {}:\n  committed: {c}\n  now:       {f}", k + 1))
        .take(5)
        .collect();
    assert!(
        stale.is_empty() && fresh.lines().count() == committed.lines().count(),
        "docs/accuracy.md is stale; regenerate it with `cargo run --release -- report`:\n{}",
        stale.join("\n")
    );
    for entry in std::fs::read_dir(&figs).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let stem = name.trim_end_matches(".png");
        assert_images_match(
            &format!("docs_figure_{stem}"),
            &read_png_planes(&path),
            &read_png_planes(&repo_path("docs/figures").join(&name)),
            0.0,
        );
    }
}
