//! End-to-end tests of `glassdb plot` and `glassdb report`: files are produced and non-trivial
//! (size, distinct colours, lightness spread; SVG structure), not pixel-exact; bad input gives a
//! clear error naming what is wrong, with no panic and no output file left behind.

use std::path::{Path, PathBuf};

use glassdb_mask::{CosTheta, MaskFormat, MaskImage, write_mask};
use glassdb_plot::inspect::summarize_png;

use crate::util::{
    assert_images_match, fails, glassdb, ok, read_png_planes, repo_path, write_file,
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

fn atrium_registry(dir: &Path) -> PathBuf {
    let reg = dir.join("registry.json");
    ok(glassdb()
        .args(["registry", "build"])
        .arg(repo_path("fixtures/atrium/catalog.toml"))
        .arg("-o")
        .arg(&reg));
    reg
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
    let dir = tempfile::tempdir().unwrap();
    let table = slab_table(dir.path());
    let png = dir.path().join("fit.png");
    ok(glassdb()
        .args(["plot", "fit"])
        .arg(&table)
        .arg("--compare-paper")
        .arg("-o")
        .arg(&png));
    assert_drawn_png(&png, 20_000);
    let svg = dir.path().join("fit.svg");
    ok(glassdb()
        .args(["plot", "fit"])
        .arg(&table)
        .arg("--glass")
        .arg("slab 1.7")
        .arg("-o")
        .arg(&svg));
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
    let dir = tempfile::tempdir().unwrap();
    let table = slab_table(dir.path());
    let fits = dir.path().join("fits.json");
    ok(glassdb().arg("fit").arg(&table).arg("-o").arg(&fits));
    let svg = dir.path().join("curves.svg");
    ok(glassdb()
        .args(["plot", "fit"])
        .arg(&fits)
        .arg("--data")
        .arg(&table)
        .arg("-o")
        .arg(&svg));
    assert_drawn_svg(&svg, "slab 1.5");
    assert!(
        std::fs::read_to_string(&svg)
            .unwrap()
            .contains("r measured")
    );
    // Without data: curves only, still a figure.
    let png = dir.path().join("curves.png");
    ok(glassdb()
        .args(["plot", "fit"])
        .arg(&fits)
        .arg("-o")
        .arg(&png));
    assert_drawn_png(&png, 15_000);
}

#[test]
fn registry_plot_one_colour_per_channel() {
    let dir = tempfile::tempdir().unwrap();
    let reg = atrium_registry(dir.path());
    let png = dir.path().join("reg.png");
    ok(glassdb()
        .args(["plot", "registry"])
        .arg(&reg)
        .arg("-o")
        .arg(&png));
    assert_drawn_png(&png, 20_000);
    let svg = dir.path().join("reg.svg");
    ok(glassdb()
        .args(["plot", "registry"])
        .arg(&reg)
        .args(["--id", "5", "-o"])
        .arg(&svg));
    assert_drawn_svg(&svg, "id 5");
    let text = std::fs::read_to_string(&svg).unwrap();
    for label in ["r R", "r G", "r B", "t R", "t G", "t B"] {
        assert!(text.contains(label), "legend entry `{label}` missing");
    }
    // A registry JSON given to `plot fit` is drawn the same way.
    let via_fit = dir.path().join("via_fit.png");
    ok(glassdb()
        .args(["plot", "fit"])
        .arg(&reg)
        .arg("-o")
        .arg(&via_fit));
    assert_drawn_png(&via_fit, 20_000);
}

#[test]
fn registry_plot_unknown_id_lists_the_ids_there_are() {
    let dir = tempfile::tempdir().unwrap();
    let reg = atrium_registry(dir.path());
    let out = dir.path().join("reg.png");
    let err = fails(
        glassdb()
            .args(["plot", "registry"])
            .arg(&reg)
            .args(["--id", "77", "-o"])
            .arg(&out),
    );
    assert!(err.contains("77") && err.contains("ids: 1, 5"), "{err}");
    assert!(!out.exists());
}

#[test]
fn mask_heat_map_png_and_svg() {
    let dir = tempfile::tempdir().unwrap();
    let reg = atrium_registry(dir.path());
    let mask = gradient_mask(dir.path(), [1, 5]);
    let png = dir.path().join("heat.png");
    let out = ok(glassdb()
        .args(["plot", "mask"])
        .arg(&mask)
        .arg("--registry")
        .arg(&reg)
        .arg("-o")
        .arg(&png));
    let _ = out;
    assert_drawn_png(&png, 8_000);
    let svg = dir.path().join("heat.svg");
    ok(glassdb()
        .args(["plot", "mask"])
        .arg(&mask)
        .arg("--registry")
        .arg(&reg)
        .args([
            "--quantity",
            "transmittance",
            "--channel",
            "g",
            "--side",
            "0=back",
            "-o",
        ])
        .arg(&svg));
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
    let dir = tempfile::tempdir().unwrap();
    let reg = atrium_registry(dir.path());
    let mask = gradient_mask(dir.path(), [1, 9]);
    let out = dir.path().join("heat.png");
    let err = fails(
        glassdb()
            .args(["plot", "mask"])
            .arg(&mask)
            .arg("--registry")
            .arg(&reg)
            .arg("-o")
            .arg(&out),
    );
    assert!(err.contains("id 9 (2816 pixels)"), "{err}");
    assert!(!out.exists());
    let err = fails(
        glassdb()
            .args(["plot", "mask"])
            .arg(&mask)
            .arg("--registry")
            .arg(&reg)
            .args(["--side", "0=sideways"]),
    );
    assert!(err.contains("front or back"), "{err}");
}

#[test]
fn spectral_plot_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let file = repo_path("fixtures/glazing/CLEAR_3.DAT");
    let png = dir.path().join("spec.png");
    ok(glassdb()
        .args(["plot", "spectral"])
        .arg(&file)
        .arg("-o")
        .arg(&png));
    assert_drawn_png(&png, 20_000);
    let svg = dir.path().join("spec.svg");
    ok(glassdb()
        .args(["plot", "spectral"])
        .arg(&file)
        .args(["--method", "paper", "--cmf", "stiles-burch-1955", "-o"])
        .arg(&svg));
    assert_drawn_svg(&svg, "stiles-burch-1955");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("τ R =") && text.contains("ρ B ="),
        "channel values not marked"
    );
    let lum = dir.path().join("lum.png");
    ok(glassdb()
        .args(["plot", "spectral"])
        .arg(&file)
        .args(["--method", "luminous", "-o"])
        .arg(&lum));
    assert_drawn_png(&lum, 15_000);
    let err = fails(
        glassdb()
            .args(["plot", "spectral"])
            .arg(&file)
            .args(["--method", "paper", "--space", "srgb"]),
    );
    assert!(err.contains("--space"), "{err}");
}

#[test]
fn bad_input_and_bad_output_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let table = slab_table(dir.path());
    // Unknown output format.
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(&table)
            .arg("-o")
            .arg(dir.path().join("fit.jpg")),
    );
    assert!(
        err.contains("fit.jpg") && err.contains(".png or .svg"),
        "{err}"
    );
    // Missing input.
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(dir.path().join("nope.csv")),
    );
    assert!(err.contains("nope.csv"), "{err}");
    // Malformed table: the error names file, line and column.
    let bad = write_file(dir.path(), "bad.csv", b"angle_deg,R\n0,0.04\n10,abc\n");
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(&bad)
            .arg("-o")
            .arg(dir.path().join("x.png")),
    );
    assert!(
        err.contains("bad.csv") && err.contains("line 3") && err.contains("abc"),
        "{err}"
    );
    // Malformed JSON.
    let badj = write_file(dir.path(), "bad.json", b"{\"glasses\": [ {\"name\": 3} ]}");
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(&badj)
            .arg("-o")
            .arg(dir.path().join("x.png")),
    );
    assert!(err.contains("bad.json"), "{err}");
    assert!(!dir.path().join("x.png").exists());
    // Output directory that does not exist: named, nothing written.
    let missing = dir.path().join("no/such/dir/fit.png");
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(&table)
            .arg("-o")
            .arg(&missing),
    );
    assert!(err.contains("no/such/dir"), "{err}");
    // The output may not overwrite the input.
    let svg_in = dir.path().join("in.svg");
    std::fs::copy(&table, &svg_in).unwrap();
    let before = std::fs::read(&svg_in).unwrap();
    let err = fails(
        glassdb()
            .args(["plot", "fit"])
            .arg(&svg_in)
            .arg("-o")
            .arg(&svg_in),
    );
    assert!(err.contains("in.svg"), "{err}");
    assert_eq!(
        std::fs::read(&svg_in).unwrap(),
        before,
        "input was modified"
    );
    // A mask that is not an image.
    let reg = atrium_registry(dir.path());
    let notmask = write_file(dir.path(), "m.png", b"not a png at all");
    let err = fails(
        glassdb()
            .args(["plot", "mask"])
            .arg(&notmask)
            .arg("--registry")
            .arg(&reg),
    );
    assert!(err.contains("m.png"), "{err}");
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
    let page = dir.path().join("accuracy.md");
    let figs = dir.path().join("figs");
    ok(glassdb()
        .arg("report")
        .arg("--root")
        .arg(repo_path(""))
        .arg("-o")
        .arg(&page)
        .arg("--figures")
        .arg(&figs)
        .args(["--timing-values", "2048"]));
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
    let err = fails(
        glassdb()
            .arg("report")
            .arg("--root")
            .arg(dir.path())
            .arg("-o")
            .arg(dir.path().join("a.md")),
    );
    assert!(err.contains("data/catalog.toml"), "{err}");
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
    let page = dir.path().join("accuracy.md");
    let figs = dir.path().join("figures");
    ok(glassdb()
        .arg("report")
        .arg("--root")
        .arg(repo_path(""))
        .arg("-o")
        .arg(&page)
        .arg("--figures")
        .arg(&figs)
        .args(["--timing-values", "2048"]));
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
