//! Nothing unbounded (issue 15): compose reads and compares every input's header before it
//! decodes any pixel, and refuses a frame whose memory, estimated from the headers, is over
//! `--max-memory`.
//!
//! The header-first tests are structural, not timed: each "bomb" is a small file whose header
//! claims a huge image and whose pixel data is corrupt. A compositor that compares headers
//! first reports the size mismatch; one that decodes first would report the corruption (after
//! allocating the huge image). The same corrupt file at the right size must still fail as
//! corrupt, so the decoder does reach the pixel data when the sizes agree.

use std::path::PathBuf;

use crate::util::{
    atrium_planes_file, compose, doc_after, fails, fails_naming, ok, read_exr_planes, repo_path,
};

/// CRC-32 (ISO-HDLC, PNG's chunk checksum).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

/// An 8-bit RGB PNG whose header says `width × height` and whose one IDAT chunk is not zlib
/// data (every chunk's checksum is right: only decompressing the pixels finds the fault).
fn corrupt_png(width: u32, height: u32) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit, RGB, deflate, adaptive, not interlaced
    png_chunk(&mut out, b"IHDR", &ihdr);
    png_chunk(&mut out, b"IDAT", b"this is not zlib data, not at all");
    png_chunk(&mut out, b"IEND", &[]);
    out
}

/// A valid 8-bit RGB PNG of one grey level.
fn grey_png(width: u32, height: u32, level: u8) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = png::Encoder::new(&mut out, width, height);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let mut w = e.write_header().unwrap();
    w.write_image_data(&vec![level; (width * height * 3) as usize])
        .unwrap();
    w.finish().unwrap();
    out
}

/// A packed 8-bit mask PNG (R plane 0, G id 1, B cos θ 255) over the whole frame.
fn glass_mask_png(width: u32, height: u32) -> Vec<u8> {
    let mut out = Vec::new();
    let mut e = png::Encoder::new(&mut out, width, height);
    e.set_color(png::ColorType::Rgb);
    e.set_depth(png::BitDepth::Eight);
    let mut w = e.write_header().unwrap();
    let px: Vec<u8> = (0..width * height).flat_map(|_| [0u8, 1, 255]).collect();
    w.write_image_data(&px).unwrap();
    w.finish().unwrap();
    out
}

/// Overwrites every `box2i` attribute named `name` (`dataWindow`, `displayWindow`) of an EXR
/// with (0, 0)–(`width` − 1, `height` − 1); returns how many were changed. The offset tables and
/// pixel data stay as they were, so the file is corrupt past its headers.
fn patch_exr_windows(bytes: &mut [u8], name: &str, width: i32, height: i32) -> usize {
    let key: Vec<u8> = [name.as_bytes(), b"\0box2i\0", &16u32.to_le_bytes()].concat();
    let mut changed = 0;
    let mut i = 0;
    while i + key.len() + 16 <= bytes.len() {
        if bytes[i..].starts_with(&key) {
            let v = i + key.len();
            for (k, value) in [0, 0, width - 1, height - 1].into_iter().enumerate() {
                bytes[v + 4 * k..v + 4 * k + 4].copy_from_slice(&value.to_le_bytes());
            }
            changed += 1;
            i = v + 16;
        } else {
            i += 1;
        }
    }
    changed
}

struct Frame {
    dir: tempfile::TempDir,
}

impl Frame {
    /// 64×48 transmission and reflection PNGs and a mask PNG of glass 1 everywhere.
    fn new() -> Frame {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("t.png"), grey_png(64, 48, 100)).unwrap();
        std::fs::write(dir.path().join("r.png"), grey_png(64, 48, 50)).unwrap();
        std::fs::write(dir.path().join("m.png"), glass_mask_png(64, 48)).unwrap();
        Frame { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn cmd(&self, refl: &str, trans: &str, mask: &str, out: &str) -> std::process::Command {
        let mut c = compose();
        c.arg("--refl")
            .arg(self.path(refl))
            .arg("--trans")
            .arg(self.path(trans))
            .arg("--mask")
            .arg(self.path(mask))
            .arg("-o")
            .arg(self.path(out));
        c
    }
}

fn assert_not_decoded(err: &str) {
    assert!(
        !err.contains("cannot be decoded") && !err.contains("incomplete"),
        "the pixels were decoded before the sizes were compared:\n{err}"
    );
}

#[test]
fn a_png_bomb_beside_smaller_passes_is_refused_for_its_size_before_decoding() {
    let f = Frame::new();
    // 12000×10000 (120 M pixels, under the default pixel limit): decoded, 360 MB of samples
    // and 1.4 GB of f32 planes; as a file, 101 bytes.
    let bomb = corrupt_png(12_000, 10_000);
    assert!(bomb.len() < 200);
    std::fs::write(f.path("bomb.png"), &bomb).unwrap();
    for (refl, trans, mask) in [
        ("r.png", "t.png", "bomb.png"),
        ("bomb.png", "t.png", "m.png"),
        ("r.png", "bomb.png", "m.png"),
    ] {
        let err = fails_naming(
            &mut f.cmd(refl, trans, mask, "o.exr"),
            &["bomb.png", "12000×10000", "64×48", "same size"],
        );
        assert_not_decoded(&err);
        assert!(!f.path("o.exr").exists());
    }
    // At the frame's size the same corrupt file is decoded, and refused as corrupt.
    std::fs::write(f.path("bad.png"), corrupt_png(64, 48)).unwrap();
    for (refl, mask) in [("r.png", "bad.png"), ("bad.png", "m.png")] {
        fails_naming(
            &mut f.cmd(refl, "t.png", mask, "o.exr"),
            &["bad.png", "PNG data cannot be decoded"],
        );
    }
    ok(&mut f.cmd("r.png", "t.png", "m.png", "o.exr"));
}

#[test]
fn an_exr_bomb_is_refused_for_its_windows_before_decoding() {
    let f = Frame::new();
    // A real 64×48 EXR (with an id and cos θ channel: a mask) whose headers are made to claim
    // 10000×10000; its offset table and blocks are those of the 64×48 image.
    let mask = glassdb_image::encode_exr_f32(
        64,
        48,
        vec![
            ("id", vec![1.0; 64 * 48]),
            ("cos_theta", vec![1.0; 64 * 48]),
        ],
    )
    .unwrap();
    let mut bomb = mask.clone();
    assert_eq!(
        patch_exr_windows(&mut bomb, "dataWindow", 10_000, 10_000),
        1
    );
    assert_eq!(
        patch_exr_windows(&mut bomb, "displayWindow", 10_000, 10_000),
        1
    );
    std::fs::write(f.path("bomb.exr"), &bomb).unwrap();
    std::fs::write(f.path("mask.exr"), &mask).unwrap();
    ok(&mut f.cmd("r.png", "t.png", "mask.exr", "o.exr"));
    let err = fails_naming(
        &mut f.cmd("r.png", "t.png", "bomb.exr", "o.exr"),
        &["bomb.exr", "10000×10000", "64×48"],
    );
    assert_not_decoded(&err);
    // Only the data window claims more: the frames agree, so it is decoded and found corrupt.
    let mut bad = mask.clone();
    patch_exr_windows(&mut bad, "dataWindow", 64, 4_000);
    std::fs::write(f.path("bad.exr"), &bad).unwrap();
    let err = fails(&mut f.cmd("r.png", "t.png", "bad.exr", "o.exr"));
    assert!(err.contains("bad.exr") && err.contains("OpenEXR"), "{err}");
}

#[test]
fn a_cryptomatte_mask_bomb_is_refused_for_its_windows_before_decoding() {
    let f = Frame::new();
    let render = repo_path("fixtures/blender/b34/multilayer.exr");
    let mut bomb = std::fs::read(&render).unwrap();
    assert!(patch_exr_windows(&mut bomb, "dataWindow", 10_000, 10_000) >= 1);
    assert!(patch_exr_windows(&mut bomb, "displayWindow", 10_000, 10_000) >= 1);
    let bomb_path = f.path("crypto_bomb.exr");
    std::fs::write(&bomb_path, &bomb).unwrap();
    let mut c = compose();
    c.arg("--refl").arg(&render).arg("--trans").arg(&render);
    c.arg("--mask").arg(&bomb_path).args([
        "--mask-cryptomatte",
        "--mask-glass",
        "Glass*=1",
        "--mask-aovs",
        "every-material",
    ]);
    c.arg("-o").arg(f.path("o.exr"));
    let err = fails_naming(&mut c, &["crypto_bomb.exr", "10000×10000"]);
    assert_not_decoded(&err);
}

#[test]
fn max_memory_refuses_a_frame_naming_the_estimate_the_limit_and_the_largest_inputs() {
    let f = Frame::new();
    let err = fails_naming(
        f.cmd("r.png", "t.png", "m.png", "o.exr")
            .args(["--max-memory", "100K"]),
        &[
            "t.png",
            "would hold about",
            "over the memory limit of 100 KiB",
            "the largest shares: ",
            "r.png",
            "--max-memory",
        ],
    );
    assert!(!f.path("o.exr").exists(), "{err}");
    // The library's message names no flag; the hint (from the binary) does.
    let (message, hint) = err.split_once("\nhint: ").unwrap();
    assert!(!message.contains("--"), "{err}");
    assert!(hint.contains("--max-memory SIZE"), "{err}");
    // Within the limit it composites, and --stats shows the estimate against the limit.
    let stdout =
        ok(f.cmd("r.png", "t.png", "m.png", "o.exr")
            .args(["--max-memory", "64M", "--stats"]));
    assert!(
        stdout.contains("memory       about") && stdout.contains("(limit 64 MiB)"),
        "{stdout}"
    );
    // The default is stated in --help; sizes are checked.
    let help = ok(compose().arg("--help"));
    assert!(help.contains("--max-memory <SIZE>"), "{help}");
    fails_naming(
        f.cmd("r.png", "t.png", "m.png", "o.exr")
            .args(["--max-memory", "8X"]),
        &["8X", "K, M, G or T"],
    );
}

#[test]
fn frames_of_a_sequence_share_the_limit_and_one_over_it_fails_alone() {
    let f = Frame::new();
    // Frame 1 is 64×48; frames 2 and 3 are 640×480 (100 times the pixels each).
    for (frame, (w, h)) in [(1, (64, 48)), (2, (640, 480)), (3, (640, 480))] {
        std::fs::write(f.path(&format!("t.{frame:04}.png")), grey_png(w, h, 100)).unwrap();
        std::fs::write(f.path(&format!("r.{frame:04}.png")), grey_png(w, h, 50)).unwrap();
        std::fs::write(f.path(&format!("m.{frame:04}.png")), glass_mask_png(w, h)).unwrap();
    }
    let run = |limit: &str| {
        let mut c = f.cmd("r.####.png", "t.####.png", "m.####.png", "o.####.exr");
        c.args(["--frames", "1-3", "--max-memory", limit]);
        c
    };
    let err = fails_naming(
        &mut run("40M"),
        &[
            "frame 2",
            "t.0002.png",
            "frame 3",
            "over the memory limit of 40 MiB",
            "2 of 3 frame(s) failed",
        ],
    );
    assert!(!err.contains("frame 1"), "{err}");
    assert!(f.path("o.0001.exr").exists() && !f.path("o.0002.exr").exists());
    // Frames 2 and 3 (about 46 MiB each, with the program's own 32 MiB) each fit alone but
    // not together: they run one after the other.
    let stdout = ok(run("80M").arg("--stats"));
    assert!(f.path("o.0002.exr").exists() && f.path("o.0003.exr").exists());
    let estimates: Vec<&str> = stdout.lines().filter(|l| l.starts_with("memory")).collect();
    assert_eq!(estimates.len(), 3, "{stdout}");
}

/// A multi-part `--refl` of many planes (written by OpenEXR: the atrium's three passes, then
/// 1×1 parts up to `parts`), in `dir`.
fn padded_planes_file(dir: &std::path::Path, parts: usize) -> PathBuf {
    atrium_planes_file(&dir.join(format!("planes{parts}.exr")), Some(parts))
}

/// 300 parts compose as their three real planes do (each pass's headers parsed once for the
/// file, not once per plane: 3.5 s before, docs/performance.md); more than
/// glassdb_image::MAX_EXR_PARTS is refused from the headers.
#[test]
fn a_refl_file_of_many_parts_composes_and_one_of_too_many_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let a = |f: &str| repo_path("fixtures/atrium").join(f);
    let many = padded_planes_file(dir.path(), 300);
    let base = |cmd: &mut std::process::Command| {
        cmd.arg("--trans")
            .arg(a("trans.exr"))
            .arg("--mask")
            .arg(a("mask.png"));
    };
    let from_parts = dir.path().join("parts.exr");
    let mut cmd = compose();
    base(&mut cmd);
    ok(cmd.arg("--refl").arg(&many).arg("-o").arg(&from_parts));
    let separate = dir.path().join("separate.exr");
    let mut cmd = compose();
    base(&mut cmd);
    for k in 0..3 {
        cmd.arg("--refl").arg(a(&format!("refl_{k}.exr")));
    }
    ok(cmd.arg("-o").arg(&separate));
    let (got, want) = (read_exr_planes(&from_parts), read_exr_planes(&separate));
    assert_eq!(got.channels, want.channels);

    let too_many = padded_planes_file(dir.path(), glassdb_image::MAX_EXR_PARTS + 1);
    let mut cmd = compose();
    base(&mut cmd);
    let said = fails_naming(
        cmd.arg("--refl")
            .arg(&too_many)
            .arg("-o")
            .arg(dir.path().join("no.exr")),
        &["planes1025.exr", "more than 1024 parts"],
    );
    assert!(said.len() < 1000, "{said}");
    assert!(!dir.path().join("no.exr").exists());
}

/// Every kind of input's size limit, in the order of the table in docs/reliability.md: each
/// declared by the library that reads that kind of file (the JSON limit by glassdb-io, the
/// format's).
fn input_limits() -> [glassdb_io::InputLimit; 10] {
    [
        glassdb_registry::CATALOG_FILE,
        glassdb_io::limits::JSON,
        glassdb_scene::CAMERA_FILE,
        glassdb_fit::ANGLE_TABLE_FILE,
        glassdb_spectral::SPECTRAL_FILE,
        glassdb_scene::OBJ_FILE,
        glassdb_scene::MTL_FILE,
        glassdb_image::IMAGE_FILE,
        glassdb_colour::display::CUBE_FILE,
        glassdb_mask::MANIFEST_FILE,
    ]
}

#[test]
fn the_documented_table_lists_every_limit_in_order() {
    let table = doc_after("docs/reliability.md", "| kind | limit | read by |");
    let documented: Vec<&str> = table
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .filter_map(|l| l.split('|').nth(2).map(str::trim))
        .collect();
    let limits: Vec<String> = input_limits().iter().map(|l| l.size_text()).collect();
    assert_eq!(documented, limits);
}
