//! Benchmark inputs for `scripts/bench_light_groups.sh`: a frame split into G light groups as
//! Cycles writes it, and the same passes one group per file.
//!
//! - `OUT/groups/{trans,refl}.exr`: `ViewLayer.Combined` (the sum) and
//!   `ViewLayer.Combined_g1` … `ViewLayer.Combined_gG` (R, G, B each);
//! - `OUT/g1/{trans,refl}.exr` … `OUT/gG/…`: `ViewLayer.Combined` and that group's layer only,
//!   the same samples (for G independent single-group composites of the same passes);
//! - `OUT/mask.png`: the benchmarks' 8-bit mask (half the frame glass, ids 2 and 6).
//!
//! `cargo run --release -p glassdb-compose --example make_light_group_bench_inputs -- OUT_DIR WIDTH HEIGHT G half|float COMPRESSION`

use std::path::{Path, PathBuf};

mod bench_passes;

use glassdb_encode::parse_exr_compression;
use glassdb_image::{DEFAULT_ZIP_LEVEL, ExrPlane, ExrStorage, ExrWriteOptions, write_exr_planes};

/// Writes `path` with the layer `ViewLayer.Combined` (`combined`) and one layer per group.
fn write_layers(
    path: &Path,
    (w, h): (usize, usize),
    combined: &[Vec<f32>; 3],
    groups: &[(usize, &[Vec<f32>; 3])],
    options: ExrWriteOptions,
) -> Result<(), Box<dyn std::error::Error>> {
    let mut planes = Vec::new();
    let layers = std::iter::once(("ViewLayer.Combined".to_string(), combined)).chain(
        groups
            .iter()
            .map(|(k, rgb)| (format!("ViewLayer.Combined_g{k}"), *rgb)),
    );
    for (layer, rgb) in layers {
        for (c, plane) in ["R", "G", "B"].iter().zip(rgb) {
            planes.push(ExrPlane::new(&format!("{layer}.{c}"), plane.clone()));
        }
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path)?);
    write_exr_planes(file, w, h, planes, options)?;
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 7 {
        return Err(
            "usage: make_light_group_bench_inputs OUT_DIR WIDTH HEIGHT G half|float COMPRESSION"
                .into(),
        );
    }
    let out = PathBuf::from(&a[1]);
    let (w, h, groups): (usize, usize, usize) = (a[2].parse()?, a[3].parse()?, a[4].parse()?);
    let options = ExrWriteOptions {
        storage: if a[5] == "half" {
            ExrStorage::Half
        } else {
            ExrStorage::Float
        },
        compression: parse_exr_compression(&a[6])?,
        zip_level: Some(DEFAULT_ZIP_LEVEL),
    };
    for (name, base) in [("trans", [0.6, 0.5, 0.4]), ("refl", [0.9, 1.0, 1.2])] {
        let per_group: Vec<[Vec<f32>; 3]> = (1..=groups)
            .map(|k| {
                let share = 1.0 / groups as f32;
                let seed = ((k as u64) << 36) + u64::from(name == "refl") * (1 << 44);
                bench_passes::gradient_planes(w, h, seed, base.map(|b| b * share))
            })
            .collect();
        let mut combined = [vec![0f32; w * h], vec![0f32; w * h], vec![0f32; w * h]];
        for g in &per_group {
            for (sum, plane) in combined.iter_mut().zip(g) {
                sum.iter_mut().zip(plane).for_each(|(s, v)| *s += v);
            }
        }
        let all: Vec<(usize, &[Vec<f32>; 3])> = per_group
            .iter()
            .enumerate()
            .map(|(i, g)| (i + 1, g))
            .collect();
        std::fs::create_dir_all(out.join("groups"))?;
        write_layers(
            &out.join("groups").join(format!("{name}.exr")),
            (w, h),
            &combined,
            &all,
            options,
        )?;
        for &(k, g) in &all {
            let dir = out.join(format!("g{k}"));
            std::fs::create_dir_all(&dir)?;
            write_layers(
                &dir.join(format!("{name}.exr")),
                (w, h),
                &combined,
                &[(k, g)],
                options,
            )?;
        }
    }
    bench_passes::write_half_glass_mask(&out, w as u32, h as u32)?;
    println!(
        "wrote {}/{{groups, g1…g{groups}}}/{{trans,refl}}.exr and mask.png ({w}×{h}, {groups} groups, {}, {})",
        out.display(),
        a[5],
        a[6]
    );
    Ok(())
}
