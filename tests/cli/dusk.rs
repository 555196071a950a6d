//! The bundled dusk facade (`fixtures/dusk/`, issue 29): the README's first command composites
//! it with one table per light group. Run exactly as the README writes it, then again as float
//! EXR with the one-table registry and with `--surfaces 1`, to check what the picture is meant
//! to show: the tungsten group through the tinted unit in its own light's colour, and every
//! unit's double image.

use std::path::Path;

use crate::first_contact::readme_commands;
use crate::util::{
    Planes, compose, element_where, json_rgb, ok, read_exr_planes, read_png_planes, repo_root,
};

/// The README's first command's compose arguments (after `target/release/compose`).
fn readme_job() -> Vec<String> {
    let (first, _) = readme_commands();
    let (_, job) = first.split_once("&&").expect("build && job");
    let mut args: Vec<String> = job.split_whitespace().map(str::to_string).collect();
    assert_eq!(args.remove(0), "target/release/compose", "{job}");
    args
}

/// `args` with the output `-o` replaced by `out`, then `extra`.
fn with_output(args: &[String], out: &Path, extra: &[&str]) -> Vec<String> {
    let mut args = args.to_vec();
    let o = args
        .iter()
        .position(|a| a == "-o")
        .expect("the job names its output");
    args[o + 1] = out.display().to_string();
    args.extend(extra.iter().map(|s| s.to_string()));
    args
}

/// `args` with the value of `flag` replaced by `value`.
fn with_value(args: &[String], flag: &str, value: &str) -> Vec<String> {
    let mut args = args.to_vec();
    let i = args
        .iter()
        .position(|a| a == flag)
        .unwrap_or_else(|| panic!("{flag} in {args:?}"));
    args[i + 1] = value.to_string();
    args
}

/// The argument after `flag`.
fn value_of<'a>(args: &'a [String], flag: &str) -> &'a str {
    let i = args
        .iter()
        .position(|a| a == flag)
        .unwrap_or_else(|| panic!("{flag} in {args:?}"));
    &args[i + 1]
}

/// The composite as float EXR (its RGB alone) with `extra` arguments.
fn composite(args: &[String], dir: &Path, name: &str, extra: &[&str]) -> Planes {
    let out = dir.join(name);
    let mut all = vec!["--data-type", "float", "--keep-channels", "none"];
    all.extend_from_slice(extra);
    ok(compose()
        .args(with_output(args, &out, &all))
        .current_dir(repo_root()));
    read_exr_planes(&out)
}

/// Channel `name`, or the composite's `ViewLayer.Combined.<name>` (the layer compose writes the
/// groups' sum to when the passes hold no beauty).
fn channel<'a>(p: &'a Planes, name: &str) -> &'a [f64] {
    let beauty = format!("ViewLayer.Combined.{name}");
    let i = p
        .names
        .iter()
        .position(|n| n == name || *n == beauty)
        .unwrap_or_else(|| panic!("{name} in {:?}", p.names));
    &p.channels[i]
}

fn luminance(p: &Planes, i: usize) -> f64 {
    0.2126 * channel(p, "R")[i] + 0.7152 * channel(p, "G")[i] + 0.0722 * channel(p, "B")[i]
}

fn median(mut v: Vec<f64>) -> f64 {
    assert!(!v.is_empty());
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// t0 of glass `id` in the registry's table of light `light`.
fn t0(registry: &serde_json::Value, light: &str, id: u64) -> [f64; 3] {
    let table = registry["tables"]
        .as_array()
        .unwrap()
        .iter()
        .find(|t| t["light"] == light)
        .unwrap_or_else(|| panic!("no table of light {light}"));
    json_rgb(&element_where(&table["glasses"], "id", id)["t0"])
}

#[test]
fn the_readme_composites_the_dusk_facade_with_a_table_per_light() {
    let args = readme_job();
    assert_eq!(value_of(&args, "--light-groups"), "sun,warm", "{args:?}");
    let dir = tempfile::tempdir().unwrap();
    // Exactly as the README writes it (the output in a temporary folder).
    let png = dir.path().join("dusk.png");
    ok(compose()
        .args(with_output(&args, &png, &[]))
        .current_dir(repo_root()));
    let picture = read_png_planes(&png);
    assert!(
        picture.width >= 960 && picture.height >= 540,
        "{}x{}",
        picture.width,
        picture.height
    );

    // The same passes with one D65 table for both groups.
    let per_group = composite(&args, dir.path(), "per_group.exr", &[]);
    let one = with_value(&args, "--registry", "fixtures/dusk/registry_one_table.json");
    let one_table = composite(&one, dir.path(), "one_table.exr", &[]);
    let mask = read_exr_planes(&repo_root().join(value_of(&args, "--mask")));
    let trans = read_exr_planes(&repo_root().join(value_of(&args, "--trans")));
    let registry: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(repo_root().join(value_of(&args, "--registry"))).unwrap(),
    )
    .unwrap();
    let (ids, coverage) = (channel(&mask, "id"), channel(&mask, "coverage"));
    let n = ids.len();
    assert_eq!(n, per_group.width * per_group.height);

    // Off the glass both are the sum of the groups' transmission passes: the same floats.
    for i in (0..n).filter(|&i| ids[i] == 0.0) {
        for c in ["R", "G", "B"] {
            assert_eq!(
                channel(&per_group, c)[i],
                channel(&one_table, c)[i],
                "pixel {i} {c}"
            );
        }
    }

    // The sun group is composited with the same table both times, so per-group − one-table
    // is the tungsten group's change alone: on the tinted unit (id 14), where the glass passes
    // tungsten light, trans_warm·(t_A − t_D65)(θ) (plus what it reflects of the lamps, rare),
    // i.e. per channel (per-group − one-table) / trans_warm = (t0_A − t0_D65)·C_t(cos θ), the
    // angle curve C_t ≤ 1 and near 1 at this facade's angles.
    let warm = |i: usize| {
        ["R", "G", "B"].map(|c| channel(&trans, &format!("ViewLayer.Combined_warm.{c}"))[i])
    };
    let lum = |v: [f64; 3]| 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2];
    let (ta, td) = (t0(&registry, "warm", 14), t0(&registry, "sun", 14));
    let warm_lit: Vec<usize> = (0..n)
        .filter(|&i| ids[i] == 14.0 && coverage[i] >= 1.0)
        .filter(|&i| warm(i).iter().all(|&v| v > 0.05))
        .collect();
    assert!(
        warm_lit.len() > 5_000,
        "{} warm-lit pixels of the tinted unit",
        warm_lit.len()
    );
    for (c, name) in ["R", "G", "B"].iter().enumerate() {
        let per_light = median(
            warm_lit
                .iter()
                .map(|&i| {
                    (channel(&per_group, name)[i] - channel(&one_table, name)[i]) / warm(i)[c]
                })
                .collect(),
        );
        let want = ta[c] - td[c];
        assert!(
            (per_light - 0.9 * want).abs() <= 0.15 * want.abs() + 0.002,
            "{name}: (per-group − one-table) / tungsten light {per_light:.4} on the tinted \
             unit's glass, the tables' t0 differ by {want:.4}"
        );
    }
    // A visible change in the tinted unit's warm-lit glass, a small one on the clear unit's.
    let change = |id: f64| {
        let px: Vec<usize> = (0..n)
            .filter(|&i| ids[i] == id && coverage[i] >= 1.0 && lum(warm(i)) > 0.1)
            .collect();
        median(
            px.iter()
                .map(|&i| (channel(&per_group, "R")[i] / channel(&one_table, "R")[i] - 1.0).abs())
                .collect(),
        )
    };
    let (tinted, clear) = (change(14.0), change(11.0));
    assert!(
        tinted > 0.08 && clear < 0.3 * tinted,
        "red changes by {tinted:.4} (tinted), {clear:.4} (clear)"
    );
}

#[test]
fn the_dusk_facades_units_show_their_ghosts() {
    let args = readme_job();
    let dir = tempfile::tempdir().unwrap();
    let ghosts = composite(&args, dir.path(), "ghosts.exr", &[]);
    // One pass per plane, the inner pane's reflectance on the outer pane's image.
    let single = composite(&args, dir.path(), "single.exr", &["--surfaces", "1"]);
    let mask = read_exr_planes(&repo_root().join(value_of(&args, "--mask")));
    let ids = channel(&mask, "id");
    // ghosts − single = r_inner · (inner pane's image − outer pane's image): where a light
    // column's inner image falls the composite gains light, where only the outer one is it
    // loses some; both, by far more than the passes' noise, on each unit.
    for id in [11.0, 14.0] {
        let d: Vec<f64> = (0..ids.len())
            .filter(|&i| ids[i] == id)
            .map(|i| luminance(&ghosts, i) - luminance(&single, i))
            .collect();
        let (lo, hi) = d
            .iter()
            .fold((0.0f64, 0.0f64), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        assert!(
            hi > 0.1 && lo < -0.1,
            "glass id {id}: ghosts − one image from {lo:.4} to {hi:.4}"
        );
    }
}
