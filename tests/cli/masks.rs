//! Masks as renderers make them (issue 13): Cryptomatte read per its specification from real
//! Cycles renders (Blender 3.4 single-part and 5.0 multi-part; `fixtures/blender/` and
//! `fixtures/blender/masks/`), checked against the same render's Material Index pass (exact,
//! not filtered: it agrees with Cryptomatte's dominant glass wherever one glass covers the
//! whole pixel), a coverage AOV, the object index (plane + 1) of a separate render, and cos θ
//! computed another way (Normal and Position passes and the camera).

use std::path::Path;

use glassdb_mask::{
    AovWeighting, CosSource, CosTheta, CryptomatteOptions, GlassMapping, GlassNames,
    MaskReadOptions, PlacedMask, PlaneSource, read_placed_mask,
};

use crate::util::{compose, fails, mask_from, ok, repo_path};

fn crypto(cos: CosSource, plane_aov: Option<&str>, weighting: AovWeighting) -> MaskReadOptions {
    let glass = GlassNames::new(&[
        GlassMapping::parse("Glass_clear=1").unwrap(),
        GlassMapping::parse("Tinted*=5").unwrap(),
    ])
    .unwrap();
    MaskReadOptions {
        cryptomatte: Some(CryptomatteOptions {
            layer: None,
            glass,
            cos,
            planes: plane_aov.map_or(PlaneSource::Single, |p| PlaneSource::Aov(p.to_string())),
            weighting,
        }),
        ..MaskReadOptions::default()
    }
}

fn facing() -> CosSource {
    CosSource::Aov {
        channel: "facing".into(),
    }
}

/// A mask whose id (and cos θ) are plain channels of the file.
fn channels(path: &Path, id: &str, cos: &str) -> PlacedMask {
    let mut o = MaskReadOptions::default();
    o.exr_channels.id = id.into();
    o.exr_channels.cos_theta = cos.into();
    o.exr_channels.plane = "(none)".into();
    o.exr_channels.coverage = "(none)".into();
    read_placed_mask(path, &o).unwrap()
}

/// The samples of the channel whose name ends with `.NAME` for the first of `names` found
/// (Blender 3 and 5 spell some passes differently), read with the `exr` crate.
fn channel(path: &Path, names: &[&str]) -> Vec<f32> {
    let (_, _, parts) = crate::passes::read_parts(path);
    let all: Vec<(String, Vec<f32>)> = parts.into_iter().flat_map(|p| p.channels).collect();
    names
        .iter()
        .find_map(|name| {
            let suffix = format!(".{name}");
            all.iter()
                .find(|(n, _)| n.ends_with(&suffix))
                .map(|c| c.1.clone())
        })
        .unwrap_or_else(|| panic!("{}: none of {names:?}", path.display()))
}

fn floats(c: &CosTheta) -> &[f32] {
    match c {
        CosTheta::Float(v) => v,
        _ => panic!("float cos θ expected"),
    }
}

/// Pixels fully covered by one glass in a Cryptomatte mask.
fn covered(m: &PlacedMask) -> Vec<usize> {
    let coverage = m.image.coverage.as_ref().expect("edges are partly covered");
    (0..m.image.pixel_count())
        .filter(|&i| m.image.id[i] != 0 && coverage[i] >= 0.999)
        .collect()
}

#[test]
fn cryptomatte_ids_agree_with_the_material_index_pass_on_covered_pixels() {
    for render in [
        "fixtures/blender/b34/multilayer.exr",
        "fixtures/blender/b50/multilayer.exr",
    ] {
        let path = repo_path(render);
        let options = crypto(facing(), None, AovWeighting::EveryMaterial);
        let mask = read_placed_mask(&path, &options).unwrap();
        let index = channels(&path, "IndexMA", "facing");
        assert_eq!(mask.windows, index.windows);
        let full = covered(&mask);
        assert!(full.len() > 600, "{render}: {} covered pixels", full.len());
        for &i in &full {
            assert_eq!(mask.image.id[i], index.image.id[i], "{render} pixel {i}");
            // cos θ on covered pixels is the AOV itself.
            let (a, b) = (
                floats(&mask.image.cos_theta)[i],
                floats(&index.image.cos_theta)[i],
            );
            assert!((a - b).abs() < 1e-6, "{render} pixel {i}: {a} vs {b}");
        }
        // Wherever the Material Index pass sees glass, Cryptomatte has that glass at some
        // coverage (the index pass holds one sample's value; coverage counts all of them).
        for (i, (&m, &c)) in index.image.id.iter().zip(&mask.image.id).enumerate() {
            assert!(
                m == 0 || c != 0,
                "{render} pixel {i}: index {m}, Cryptomatte none"
            );
        }
    }
}

#[test]
fn glass_only_aovs_are_divided_by_coverage_and_give_planes_and_cos_theta() {
    let dir = repo_path("fixtures/blender/masks");
    let camera: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("camera.0001.json")).unwrap())
            .unwrap();
    let m = &camera["matrix_world"];
    let origin: [f64; 3] = std::array::from_fn(|r| m[r][3].as_f64().unwrap());
    for version in ["b34", "b50"] {
        let beauty = dir.join(version).join("beauty.0001.exr");
        let options = crypto(facing(), Some("plane"), AovWeighting::GlassOnly);
        let mask = read_placed_mask(&beauty, &options).unwrap();
        assert!(mask.stores_planes);
        // Coverage: Cryptomatte's glass coverage is the `glass_coverage` AOV (1 on glass).
        let aov = channel(&beauty, &["glass_coverage.X"]);
        let coverage = mask.image.coverage.as_ref().unwrap();
        for (i, (&c, &a)) in coverage.iter().zip(&aov).enumerate() {
            if mask.image.id[i] != 0 {
                assert!(
                    (c - a).abs() < 1e-6,
                    "{version} pixel {i}: coverage {c} vs AOV {a}"
                );
            }
        }
        // Planes: the index render's Object Index is plane + 1 (fixtures/blender/masks/README.md).
        let index = dir.join(version).join("index.0001.exr");
        let object_index = channel(&index, &["IndexOB.X", "Object Index.X"]);
        let full = covered(&mask);
        let wrong_plane = full
            .iter()
            .filter(|&&i| f32::from(mask.image.plane[i] + 1) != object_index[i])
            .count();
        assert!(full.len() > 2500, "{version}: {} covered", full.len());
        assert!(
            wrong_plane <= 1,
            "{version}: {wrong_plane} covered pixels on the wrong plane"
        );
        let planes: std::collections::BTreeSet<u16> =
            full.iter().map(|&i| mask.image.plane[i]).collect();
        assert_eq!(planes.into_iter().collect::<Vec<_>>(), [0, 1, 2]);
        // cos θ: the AOV route against the Normal and Position passes with the camera position.
        let geometry = CosSource::Geometry {
            normal: "Normal".into(),
            position: "Position".into(),
            camera_origin: origin,
        };
        let by_geometry =
            read_placed_mask(&beauty, &crypto(geometry, None, AovWeighting::GlassOnly)).unwrap();
        let (a, g) = (
            floats(&mask.image.cos_theta),
            floats(&by_geometry.image.cos_theta),
        );
        let worst = full
            .iter()
            .map(|&i| (a[i] - g[i]).abs())
            .fold(0f32, f32::max);
        assert!(
            worst < 5e-3,
            "{version}: cos θ by AOV and by geometry differ by {worst}"
        );
        // Without dividing, edge pixels come out too small (the issue's 65° for a ≤ 35° pane).
        let raw = read_placed_mask(
            &beauty,
            &crypto(facing(), None, AovWeighting::EveryMaterial),
        )
        .unwrap();
        let edge = (0..coverage.len())
            .find(|&i| mask.image.id[i] != 0 && coverage[i] < 0.5)
            .unwrap();
        assert!(floats(&raw.image.cos_theta)[edge] < a[edge] * 0.6);
    }
}

#[test]
fn cryptomatte_errors_name_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let render = repo_path("fixtures/blender/b34/multilayer.exr");
    let base = |extra: &[&str]| {
        let mut c = compose();
        c.arg("--refl").arg(&render).arg("--trans").arg(&render);
        c.arg("--mask")
            .arg(&render)
            .arg("--mask-cryptomatte")
            .args(extra);
        c.arg("-o").arg(dir.path().join("o.exr"));
        c
    };
    let err = fails(&mut base(&[]));
    assert!(err.contains("--mask-glass"), "{err}");
    let err = fails(&mut base(&["--mask-glass", "Mirror*=3"]));
    for part in ["Mirror*", "Glass_clear", "CryptoMaterial"] {
        assert!(err.contains(part), "{part}: {err}");
    }
    let err = fails(&mut base(&["CryptoLight", "--mask-glass", "Glass*=1"]));
    assert!(
        err.contains("CryptoLight") && err.contains("ViewLayer.CryptoObject"),
        "{err}"
    );
    // An unknown channel, and a normal without the position it needs.
    for (channels, named) in [("cos=Nope", "Nope"), ("normal=Normal", "position=")] {
        let args = ["--mask-glass", "Glass*=1", "--mask-channels", channels];
        let err = fails(&mut base(&args));
        assert!(err.contains(named), "{err}");
    }
    // The pass fixture's AOV is written by every material: read as glass-only it is refused
    // only where dividing makes it exceed 1; read as written it composites.
    ok(&mut base(&[
        "--mask-glass",
        "Glass*=1",
        "--mask-aovs",
        "every-material",
    ]));
}

#[test]
fn planes_from_normals_match_the_plane_aov() {
    // planes.json from `glassdb mirror` on the scene Blender rendered; the Normal and Position
    // passes pick each glass pixel's plane, as the plane AOV does.
    let dir = tempfile::tempdir().unwrap();
    let scene = repo_path("fixtures/blender/masks/scene.obj");
    ok(crate::util::glassdb()
        .arg("mirror")
        .arg(&scene)
        .args([
            "--glass-material",
            "Glass*",
            "--glass-material",
            "Tinted*",
            "--out-dir",
        ])
        .arg(dir.path()));
    let planes = glassdb_scene::PlanesFile::load(&dir.path().join("planes.json")).unwrap();
    assert_eq!(planes.planes.len(), 3);
    let equations: Vec<[f64; 4]> = planes.planes.iter().map(|p| p.equation).collect();
    for version in ["b34", "b50"] {
        let beauty = repo_path(&format!("fixtures/blender/masks/{version}/beauty.0001.exr"));
        let by_aov = read_placed_mask(
            &beauty,
            &crypto(facing(), Some("plane"), AovWeighting::GlassOnly),
        )
        .unwrap();
        let mut options = crypto(facing(), None, AovWeighting::GlassOnly);
        if let Some(c) = options.cryptomatte.as_mut() {
            c.planes = PlaneSource::Geometry {
                normal: "Normal".into(),
                position: "Position".into(),
                equations: equations.clone(),
                max_angle_deg: 10.0,
            };
        }
        let by_geometry = read_placed_mask(&beauty, &options).unwrap();
        let full = covered(&by_aov);
        let differ = full
            .iter()
            .filter(|&&i| by_aov.image.plane[i] != by_geometry.image.plane[i])
            .count();
        assert_eq!(
            differ,
            0,
            "{version}: {differ} of {} covered pixels",
            full.len()
        );
    }
}

/// The glass ids Blender's index render of `frame` has per pixel (Material Index; the portrait
/// of Blender 5 is the emission stand-in, fixtures/blender/masks/README.md).
fn blender_ids(version: &str, file: &str) -> Vec<f32> {
    let path = repo_path(&format!("fixtures/blender/masks/{version}/{file}"));
    if file.contains("emission") {
        return crate::passes::read_parts(&path).2[0].channels["R"].clone();
    }
    channel(&path, &["IndexMA.X", "Material Index.X"])
}

/// Agreement of `glassdb mask` (8-bit PNG: G = id) with Blender's ids, as a fraction.
fn agreement(mask: &Path, ids: &[f32]) -> f64 {
    let png = crate::util::read_png_planes(mask);
    let ours = &png.channels[1];
    assert_eq!(ours.len(), ids.len(), "{}", mask.display());
    let same = ours
        .iter()
        .zip(ids)
        .filter(|(a, b)| **a as f32 == **b)
        .count();
    same as f64 / ids.len() as f64
}

#[test]
fn glassdb_mask_agrees_with_blenders_material_index_for_an_animated_shifted_camera() {
    // scene.obj and the cameras Blender rendered (lens shift, AUTO fit, an animated camera; a
    // portrait with vertical fit and 2:1 pixels); the index renders sample each pixel's centre
    // once, as glassdb mask does. The U-shaped pane is one concave polygon in the OBJ.
    let fixture = repo_path("fixtures/blender/masks");
    let dir = tempfile::tempdir().unwrap();
    let glass = ["--glass", "Glass_clear=1", "--glass", "Tinted*=5"];
    let out = dir.path().join("mask.####.png");
    ok(
        mask_from(fixture.join("scene.obj"), fixture.join("cameras.json"))
            .args(["--frames", "1-3"])
            .args(glass)
            .arg("-o")
            .arg(&out),
    );
    let portrait = dir.path().join("portrait.png");
    ok(mask_from(
        fixture.join("scene.obj"),
        fixture.join("camera_portrait.json"),
    )
    .args(glass)
    .arg("-o")
    .arg(&portrait));
    for version in ["b34", "b50"] {
        for frame in 1..=3 {
            let ids = blender_ids(version, &format!("index.{frame:04}.exr"));
            let a = agreement(&dir.path().join(format!("mask.{frame:04}.png")), &ids);
            assert!(
                a >= 0.999,
                "{version} frame {frame}: {:.4} % agree",
                a * 100.0
            );
        }
        let file = if version == "b34" {
            "index_portrait.exr"
        } else {
            "index_portrait_emission.exr"
        };
        let a = agreement(&portrait, &blender_ids(version, file));
        assert!(a >= 0.999, "{version} portrait: {:.4} % agree", a * 100.0);
    }
}

#[test]
fn the_cryptomatte_mask_agrees_with_glassdb_mask_and_so_do_the_composites() {
    // The README's Blender example: Cycles' passes through the Cryptomatte mask, against the
    // same passes through `glassdb mask` of the scene and camera Blender rendered.
    let fixture = repo_path("fixtures/blender/masks");
    let dir = tempfile::tempdir().unwrap();
    let readme = std::fs::read_to_string(repo_path("README.md")).unwrap();
    let block: String = readme
        .split("```sh\nD=fixtures/blender/masks/b34\n")
        .nth(1)
        .and_then(|rest| rest.split("```").next())
        .expect("the README's Blender example")
        .replace("\\\n", " ");
    let words: Vec<String> = block
        .split_whitespace()
        .map(|w| {
            w.trim_matches('\'')
                .replace("$D", "fixtures/blender/masks/b34")
        })
        .collect();
    let args = &words[words.iter().position(|w| w == "--").unwrap() + 1..];
    let out_at = args.iter().position(|w| w == "-o").unwrap();
    let crypto_out = dir.path().join("crypto.exr");
    let mut readme_cmd = compose();
    readme_cmd
        .current_dir(crate::util::repo_root())
        .args(&args[..out_at])
        .arg("-o")
        .arg(&crypto_out);
    ok(&mut readme_cmd);

    let mask = dir.path().join("mask.exr");
    ok(
        mask_from(fixture.join("scene.obj"), fixture.join("camera.0001.json"))
            .args(["--glass", "Glass_clear=1", "--glass", "Tinted*=5"])
            .arg("-o")
            .arg(&mask),
    );
    let beauty = fixture.join("b34/beauty.0001.exr");
    let crypto = read_placed_mask(
        &beauty,
        &crypto(facing(), Some("plane"), AovWeighting::GlassOnly),
    )
    .unwrap();
    let ours = read_placed_mask(&mask, &MaskReadOptions::default()).unwrap();
    let full = covered(&crypto);
    let (c, o) = (
        floats(&crypto.image.cos_theta),
        floats(&ours.image.cos_theta),
    );
    for &i in &full {
        assert_eq!(crypto.image.id[i], ours.image.id[i], "pixel {i}");
        assert_eq!(crypto.image.plane[i], ours.image.plane[i], "pixel {i}");
        assert!(
            (c[i] - o[i]).abs() <= 1.0 / 255.0,
            "pixel {i}: cos θ {} vs {}",
            c[i],
            o[i]
        );
    }
    // The composites: the same on every pixel without glass in either mask, and within what
    // cos θ's 8-bit step changes on every fully covered pixel.
    let plain_out = dir.path().join("plain.exr");
    let d = fixture.join("b34");
    let mut plain = compose();
    plain.arg("--trans").arg(d.join("trans.0001.exr"));
    for k in 0..3 {
        plain
            .arg("--refl")
            .arg(d.join(format!("refl_{k}.0001.exr")));
    }
    ok(plain.arg("--mask").arg(&mask).arg("-o").arg(&plain_out));
    let (_, _, a) = crate::passes::read_parts(&crypto_out);
    let (_, _, b) = crate::passes::read_parts(&plain_out);
    assert!(
        a[0].channels.contains_key("ViewLayer.Combined.R"),
        "the layer keeps its names"
    );
    for ch in ["R", "G", "B"] {
        let name = format!("ViewLayer.Combined.{ch}");
        let (x, y) = (&a[0].channels[&name], &b[0].channels[&name]);
        for i in 0..x.len() {
            if crypto.image.id[i] == 0 && ours.image.id[i] == 0 {
                assert_eq!(x[i], y[i], "{ch} pixel {i} without glass");
            }
        }
        for &i in &full {
            assert!(
                (x[i] - y[i]).abs() <= 0.01 * y[i].abs().max(0.05),
                "{ch} pixel {i}: {} vs {}",
                x[i],
                y[i]
            );
        }
    }
}

/// The Blender 3.4 render `fixtures/blender/b34/multilayer.exr` written again into `path`
/// (float, ZIP) after `edit` changed its attributes or samples, as the `exr` crate reads them
/// exactly.
fn rewritten_render(path: &Path, edit: impl FnOnce(&mut glassdb_image::ExactExr)) {
    let render = repo_path("fixtures/blender/b34/multilayer.exr");
    let bytes = std::fs::read(&render).unwrap();
    let mut exact = glassdb_image::read_exr_exact(&bytes, 1 << 24).unwrap();
    let headers = glassdb_image::read_exr_headers(&bytes).unwrap();
    edit(&mut exact);
    let image = glassdb_image::ExrImageOut {
        display_window: headers[0].display_window,
        attributes: exact.attributes,
        parts: exact
            .parts
            .into_iter()
            .map(|p| glassdb_image::ExrPartOut {
                data_window: p.data_window,
                attributes: p.attributes,
                planes: p
                    .channels
                    .into_iter()
                    .map(|(name, s)| glassdb_image::ExrPlane {
                        name,
                        samples: glassdb_image::PlaneSamples::Exact(s),
                        linear: false,
                    })
                    .collect(),
            })
            .collect(),
    };
    let mut out = std::io::Cursor::new(Vec::new());
    let options = glassdb_image::ExrWriteOptions {
        storage: glassdb_image::ExrStorage::Float,
        compression: exr::compression::Compression::ZIP16,
        zip_level: None,
    };
    glassdb_image::write_exr_image(&mut out, image, options).unwrap();
    std::fs::write(path, out.into_inner()).unwrap();
}

/// Every text attribute map of `exact` (the shared one and each part's).
fn attribute_maps(
    exact: &mut glassdb_image::ExactExr,
) -> Vec<
    &mut std::collections::HashMap<
        exr::meta::attribute::Text,
        exr::meta::attribute::AttributeValue,
    >,
> {
    let mut maps = vec![&mut exact.attributes.other];
    maps.extend(exact.parts.iter_mut().map(|p| &mut p.attributes.other));
    maps
}

#[test]
fn a_manifest_side_file_names_the_ids_like_the_header_manifest() {
    // The same render with its manifest moved out of the header into `manif_file` (the
    // specification's side file, relative to the image).
    use exr::meta::attribute::{AttributeValue, Text};
    let dir = tempfile::tempdir().unwrap();
    let render = repo_path("fixtures/blender/b34/multilayer.exr");
    let mut manifests = Vec::new();
    let copy = dir.path().join("side.exr");
    rewritten_render(&copy, |exact| {
        for other in attribute_maps(exact) {
            let keys: Vec<Text> = other
                .keys()
                .filter(|k| k.to_string().ends_with("/manifest"))
                .cloned()
                .collect();
            for key in keys {
                if let Some(AttributeValue::Text(json)) = other.remove(&key) {
                    let file = format!("manifest{}.json", manifests.len());
                    manifests.push((file.clone(), json.to_string()));
                    let side = key.to_string().replace("/manifest", "/manif_file");
                    other.insert(
                        Text::from(side.as_str()),
                        AttributeValue::Text(Text::from(file.as_str())),
                    );
                }
            }
        }
    });
    assert_eq!(manifests.len(), 2, "material and object manifests");
    for (file, json) in &manifests {
        std::fs::write(dir.path().join(file), json).unwrap();
    }
    let options = crypto(facing(), None, AovWeighting::EveryMaterial);
    let from_header = read_placed_mask(&render, &options).unwrap();
    let from_side = read_placed_mask(&copy, &options).unwrap();
    assert_eq!(from_side.image, from_header.image);
    // Without the side file the ids cannot be named: an error naming the file.
    std::fs::remove_file(dir.path().join(&manifests[0].0)).unwrap();
    std::fs::remove_file(dir.path().join(&manifests[1].0)).unwrap();
    let err = read_placed_mask(&copy, &options).unwrap_err().to_string();
    assert!(err.contains("manifest"), "{err}");
}

/// Blender 3.4's own manifests (material and object) give every name the MurmurHash3_32 the
/// specification says, as stored in pixels (exponent fix-up); no entry of those renders needs
/// the fix-up, which the hash's unit vectors check.
#[test]
fn blender_manifests_hold_the_murmur3_of_each_name() {
    let render = repo_path("fixtures/blender/b34/multilayer.exr");
    let attributes =
        glassdb_image::read_exr_text_attributes(&std::fs::read(&render).unwrap()).unwrap();
    let layers = glassdb_mask::cryptomatte_layers(&attributes, &render).unwrap();
    assert_eq!(layers.len(), 2);
    let mut entries = 0;
    for layer in &layers {
        for (name, &hash) in &layer.manifest {
            let want = glassdb_mask::murmur3_32(name.as_bytes(), 0);
            assert_eq!(hash, glassdb_mask::float_encoded(want), "{name}");
            entries += 1;
        }
    }
    assert_eq!(entries, 14);
    // Reference values of MurmurHash3_x86_32 (Appleby's SMHasher) and the fix-up.
    assert_eq!(glassdb_mask::murmur3_32(b"", 0), 0);
    assert_eq!(glassdb_mask::murmur3_32(b"", 1), 0x514e_28b7);
    assert_eq!(glassdb_mask::murmur3_32(b"hello", 0), 0x248b_fa47);
    assert_eq!(
        glassdb_mask::murmur3_32(b"The quick brown fox jumps over the lazy dog", 0),
        0x2e4f_f723
    );
    assert_eq!(glassdb_mask::float_encoded(0x0012_3456), 0x0092_3456);
    assert_eq!(glassdb_mask::float_encoded(0xff80_0001), 0xff00_0001);
    assert_eq!(glassdb_mask::float_encoded(0x3f80_0000), 0x3f80_0000);
}

/// A manifest that gives a glass another object's hash (the floor would turn into glass) is
/// refused naming the entry; a coverage that is NaN, above 1 or negative is refused naming
/// the pixel, the value and the name.
#[test]
fn a_corrupt_manifest_or_coverage_is_refused_naming_it() {
    use exr::meta::attribute::{AttributeValue, Text};
    let dir = tempfile::tempdir().unwrap();
    let options = crypto(facing(), None, AovWeighting::EveryMaterial);
    let swapped = dir.path().join("swapped.exr");
    rewritten_render(&swapped, |exact| {
        for other in attribute_maps(exact) {
            for value in other.values_mut() {
                if let AttributeValue::Text(json) = value
                    && json.to_string().contains("\"Glass_clear\":\"ee9bb9e0\"")
                {
                    let text = json.to_string().replace(
                        "\"Glass_clear\":\"ee9bb9e0\"",
                        "\"Glass_clear\":\"6a2fb16e\"",
                    );
                    *value = AttributeValue::Text(Text::from(text.as_str()));
                }
            }
        }
    });
    let err = read_placed_mask(&swapped, &options)
        .unwrap_err()
        .to_string();
    for part in [
        "swapped.exr",
        "\"Glass_clear\"",
        "6a2fb16e",
        "ee9bb9e0",
        "corrupt",
    ] {
        assert!(err.contains(part), "lacks {part}: {err}");
    }

    for (value, shown) in [(f32::NAN, "NaN"), (5.0, "5"), (-3.0, "-3")] {
        let bad = dir.path().join("coverage.exr");
        let mut at = None;
        rewritten_render(&bad, |exact| {
            for part in &mut exact.parts {
                let width = part.data_window.width;
                let ids: Vec<f32> = match part
                    .channels
                    .iter()
                    .find(|(n, _)| n.ends_with("CryptoMaterial00.r"))
                {
                    Some((_, exr::prelude::FlatSamples::F32(v))) => v.clone(),
                    _ => continue,
                };
                if let Some((_, exr::prelude::FlatSamples::F32(cov))) = part
                    .channels
                    .iter_mut()
                    .find(|(n, _)| n.ends_with("CryptoMaterial00.g"))
                {
                    // A pixel whose first rank is a named id (not empty).
                    let i = ids.iter().position(|&id| id != 0.0).unwrap();
                    cov[i] = value;
                    at = Some((i % width, i / width));
                }
            }
        });
        let (x, y) = at.expect("a CryptoMaterial00.g channel");
        let err = read_placed_mask(&bad, &options).unwrap_err().to_string();
        for part in [
            format!("pixel (x {x}, y {y})"),
            format!("coverage {shown},"),
            "rank 0 gives \"".to_string(),
        ] {
            assert!(err.contains(&part), "lacks {part}: {err}");
        }
    }
}

/// Blender 3.4 writes a name's raw MurmurHash3_32 in the manifest and the bits with the
/// exponent fix-up in the pixels (fixtures/blender/cryptomatte_fixup): both names of that
/// render (exponents all ones and all zeros) are found in its pixels.
#[test]
fn names_whose_hash_needs_the_exponent_fix_up_are_found() {
    let render = repo_path("fixtures/blender/cryptomatte_fixup/fixup.exr");
    let glass = GlassNames::new(&[
        GlassMapping::parse("Glass_42=1").unwrap(),
        GlassMapping::parse("Glass_339=2").unwrap(),
    ])
    .unwrap();
    let options = MaskReadOptions {
        cryptomatte: Some(CryptomatteOptions {
            layer: None,
            glass,
            cos: CosSource::Geometry {
                normal: "Normal".into(),
                position: "Position".into(),
                camera_origin: [0.0, 0.0, 5.0],
            },
            planes: PlaneSource::Single,
            weighting: AovWeighting::EveryMaterial,
        }),
        ..MaskReadOptions::default()
    };
    let mask = read_placed_mask(&render, &options);
    let mask = match mask {
        Ok(m) => m,
        Err(e) => panic!("{e}"),
    };
    for id in [1, 2] {
        let n = mask.image.id.iter().filter(|&&g| g == id).count();
        assert!(
            n >= 8,
            "glass {id} on {n} of {} pixels",
            mask.image.id.len()
        );
    }
}
