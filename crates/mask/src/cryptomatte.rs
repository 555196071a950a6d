//! Masks straight from a render: Cryptomatte (Psyop's specification, v1.1) for which glass is
//! where and how much of each pixel it covers, a renderer AOV (or the Normal and Position
//! passes with the camera position) for cos θ, and optionally a plane AOV.
//!
//! Cryptomatte in brief: a layer `NAME` has channels `NAME00.r/g/b/a`, `NAME01.r/…`, …, holding
//! ranked (id, coverage) pairs per pixel (`00.r` id of rank 0, `00.g` its coverage, `00.b` id of
//! rank 1, `00.a` its coverage, …). An id is the MurmurHash3_32 of a name, stored as the bits of
//! an `f32` (`conversion: uint32_to_float32`); the header attributes
//! `cryptomatte/<key>/{name,hash,conversion,manifest}` give the layer's name and the manifest
//! (JSON `{"name": "hex hash"}`), or `manif_file`, a JSON side file beside the image.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

use glassdb_image::{ExrFile, ExrHeaders, ExrPart, ImageWindows, ReadMemory};

use crate::aov::{GlassAovs, cos_from_geometry, planes_from_geometry};
use crate::channels::{MaskHeader, PixelError, decode_channels, locate_channel, plan_channels};
use crate::{CosTheta, GlassNames, MaskError, MaskImage, PlacedMask};

/// How an AOV relates to the glass it describes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AovWeighting {
    /// Written by the glass materials only (0 elsewhere): the filtered value is the glass's
    /// value times its coverage, so it is divided by the pixel's glass coverage.
    #[default]
    GlassOnly,
    /// Written by every material: taken as it is (at a pane's edge it mixes in what lies
    /// behind).
    EveryMaterial,
}

/// Where cos θ comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum CosSource {
    /// An AOV channel holding |N·I| (e.g. Blender: Geometry Normal · Incoming, absolute).
    Aov {
        /// The AOV's channel name.
        channel: String,
    },
    /// World-space Normal and Position passes (channel layers, e.g. `Normal`, `Position`, with
    /// `.X/.Y/.Z` or `.R/.G/.B`) and the camera position: cos θ = |N·(P − C)| / |P − C|.
    Geometry {
        /// The Normal pass's layer name.
        normal: String,
        /// The Position pass's layer name.
        position: String,
        /// Where the camera is (the view rays' origin).
        camera_origin: [f64; 3],
    },
}

/// How to build a mask from a render's Cryptomatte.
#[derive(Debug, Clone, PartialEq)]
pub struct CryptomatteOptions {
    /// The Cryptomatte layer: its name as in `cryptomatte/<key>/name` (`ViewLayer.CryptoMaterial`)
    /// or its last component (`CryptoMaterial`); `None`: the only layer, or the one named
    /// `…CryptoMaterial`.
    pub layer: Option<String>,
    /// Which manifest names are glass, with their registration ids.
    pub glass: GlassNames,
    /// Where cos θ comes from.
    pub cos: CosSource,
    /// Where each glass pixel's plane index comes from.
    pub planes: PlaneSource,
    /// How the AOVs were written.
    pub weighting: AovWeighting,
}

/// Where the plane of each glass pixel comes from.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum PlaneSource {
    /// Every glass pixel on plane 0 (one plane).
    #[default]
    Single,
    /// An AOV holding the plane index (written by each glass material).
    Aov(String),
    /// The Normal and Position passes matched against the planes' equations `[a, b, c, d]`
    /// (`planes.json`): the plane nearest the pixel's position among those whose normal is
    /// within `max_angle_deg` of the pixel's normal (either orientation).
    Geometry {
        /// The Normal pass's layer name.
        normal: String,
        /// The Position pass's layer name.
        position: String,
        /// The planes' equations, in plane order.
        equations: Vec<[f64; 4]>,
        /// The largest angle between a pixel's normal and its plane's, degrees.
        max_angle_deg: f64,
    },
}

/// One Cryptomatte layer found in a file's header.
#[derive(Debug, Clone, PartialEq)]
pub struct CryptomatteLayer {
    /// Its layer name.
    pub name: String,
    /// Name → hash, from the manifest.
    pub manifest: BTreeMap<String, u32>,
}

fn layout(path: &Path, detail: String) -> MaskError {
    MaskError::Layout {
        path: path.to_path_buf(),
        detail,
    }
}

/// The Cryptomatte layers a file's header describes, with their manifests (read from the
/// header or the `manif_file` side file, relative to the image's folder).
pub fn cryptomatte_layers(
    attributes: &[(usize, String, String)],
    path: &Path,
) -> Result<Vec<CryptomatteLayer>, MaskError> {
    let mut by_key: BTreeMap<&str, HashMap<&str, &str>> = BTreeMap::new();
    for (_, name, value) in attributes {
        if let Some(rest) = name.strip_prefix("cryptomatte/")
            && let Some((key, field)) = rest.split_once('/')
        {
            by_key.entry(key).or_default().insert(field, value.as_str());
        }
    }
    let mut layers = Vec::new();
    for (key, fields) in by_key {
        let name = fields
            .get("name")
            .ok_or_else(|| layout(path, format!("Cryptomatte {key} has no name attribute")))?;
        if let Some(hash) = fields.get("hash").filter(|h| **h != "MurmurHash3_32") {
            return Err(layout(
                path,
                format!("Cryptomatte {name}: hash {hash:?} is not MurmurHash3_32"),
            ));
        }
        if let Some(c) = fields
            .get("conversion")
            .filter(|c| **c != "uint32_to_float32")
        {
            return Err(layout(
                path,
                format!("Cryptomatte {name}: conversion {c:?} is not uint32_to_float32"),
            ));
        }
        let json = match (fields.get("manifest"), fields.get("manif_file")) {
            (Some(m), _) => m.to_string(),
            (None, Some(file)) => read_side_manifest(path, file)?,
            (None, None) => {
                return Err(layout(
                    path,
                    format!(
                        "Cryptomatte {name} has no manifest (neither manifest nor manif_file): its ids cannot be named"
                    ),
                ));
            }
        };
        layers.push(CryptomatteLayer {
            name: name.to_string(),
            manifest: parse_manifest(&json, name, path)?,
        });
    }
    Ok(layers)
}

fn read_side_manifest(image: &Path, file: &str) -> Result<String, MaskError> {
    let side: PathBuf = image.parent().unwrap_or(Path::new("")).join(file);
    let read_err = |source| MaskError::Read {
        path: side.clone(),
        source,
    };
    glassdb_io::read_input_string(&side, crate::MANIFEST_FILE).map_err(read_err)
}

/// `{"name": "hex"}` → name → hash.
fn parse_manifest(
    json: &str,
    layer: &str,
    path: &Path,
) -> Result<BTreeMap<String, u32>, MaskError> {
    let map: BTreeMap<String, String> = serde_json::from_str(json)
        .map_err(|e| layout(path, format!("Cryptomatte {layer}: the manifest is not a JSON object of names and hex hashes: {e}")))?;
    map.into_iter()
        .map(|(name, hex)| {
            u32::from_str_radix(hex.trim_start_matches("0x"), 16)
                .map(|h| (name.clone(), h))
                .map_err(|_| layout(path, format!("Cryptomatte {layer}: manifest entry {name:?} has hash {hex:?}, not 8 hex digits")))
        })
        .collect()
}

/// Chooses the layer `wanted` names (full name or its last component), or the only one, or
/// the one named `…CryptoMaterial`.
fn choose_layer<'a>(
    layers: &'a [CryptomatteLayer],
    wanted: Option<&str>,
    path: &Path,
) -> Result<&'a CryptomatteLayer, MaskError> {
    let names = || {
        layers
            .iter()
            .map(|l| l.name.clone())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let fits = |l: &&CryptomatteLayer, w: &str| l.name == w || l.name.ends_with(&format!(".{w}"));
    let found: Vec<&CryptomatteLayer> = match wanted {
        Some(w) => layers.iter().filter(|l| fits(l, w)).collect(),
        None if layers.len() == 1 => layers.iter().collect(),
        None => layers
            .iter()
            .filter(|l| fits(l, "CryptoMaterial"))
            .collect(),
    };
    match found.as_slice() {
        [one] => Ok(one),
        [] if layers.is_empty() => Err(layout(
            path,
            "has no Cryptomatte layer (no cryptomatte/…/name attribute)".into(),
        )),
        _ => Err(layout(
            path,
            format!(
                "{} Cryptomatte layer{} (it has: {})",
                if found.is_empty() {
                    "no matching"
                } else {
                    "more than one matching"
                },
                wanted.map(|w| format!(" {w:?}")).unwrap_or_default(),
                names()
            ),
        )),
    }
}

/// The (part, channel) of each rank channel of `layer`: `NAME00.r`, `.g`, `.b`, `.a`, `NAME01.r`,
/// … (any case), in rank order, as long as a level exists.
fn rank_channels(parts: &[ExrPart], layer: &str) -> Vec<[(usize, usize); 4]> {
    let find = |name: &str| {
        parts.iter().enumerate().find_map(|(p, part)| {
            (0..part.channels.len()).find_map(|c| {
                part.qualified_name(c)
                    .filter(|q| q.eq_ignore_ascii_case(name))
                    .map(|_| (p, c))
            })
        })
    };
    let mut levels = Vec::new();
    for level in 0..100 {
        let channels: Option<Vec<(usize, usize)>> = ["r", "g", "b", "a"]
            .iter()
            .map(|c| find(&format!("{layer}{level:02}.{c}")))
            .collect();
        match channels {
            Some(c) => levels.push([c[0], c[1], c[2], c[3]]),
            None => break,
        }
    }
    levels
}

/// A required channel by the name a user gives.
fn locate(parts: &[ExrPart], name: &str, path: &Path) -> Result<(usize, usize), MaskError> {
    locate_channel(parts, name, None, true, path)?.ok_or_else(|| MaskError::MissingChannel {
        path: path.to_path_buf(),
        channel: name.to_string(),
        available: glassdb_image::all_channel_names(parts),
    })
}

/// The three channels of a vector pass: `NAME.X/.Y/.Z` or `NAME.R/.G/.B`.
fn locate_vector(
    parts: &[ExrPart],
    name: &str,
    path: &Path,
) -> Result<[(usize, usize); 3], MaskError> {
    for letters in [["X", "Y", "Z"], ["R", "G", "B"], ["x", "y", "z"]] {
        let found: Result<Vec<_>, _> = letters
            .iter()
            .map(|l| locate(parts, &format!("{name}.{l}"), path))
            .collect();
        if let Ok(f) = found {
            return Ok([f[0], f[1], f[2]]);
        }
    }
    Err(MaskError::MissingChannel {
        path: path.to_path_buf(),
        channel: format!("{name}.X/.Y/.Z"),
        available: glassdb_image::all_channel_names(parts),
    })
}

/// What the header decided for a Cryptomatte mask: the glass ids of the manifest's hashes and
/// the channels to decode (the ranks', then cos θ's, then the planes').
pub(crate) struct CryptomattePlan {
    /// hash → glass id, for the glass names only.
    glass_of: HashMap<u32, u16>,
    /// hash → name, for every manifest entry (for messages).
    names_of: HashMap<u32, String>,
    wanted: Vec<(usize, usize)>,
    rank_count: usize,
    windows: ImageWindows,
    stores_planes: bool,
}

/// Checks a Cryptomatte mask from the file's headers alone: the layer and its manifest (header
/// or side file), that the glass patterns name something in it, that the rank channels and the
/// cos θ and plane channels exist, and that they can be decoded (`max_pixels`, one data
/// window).
pub(crate) fn plan_cryptomatte(
    headers: &ExrHeaders,
    path: &Path,
    opts: &CryptomatteOptions,
    max_pixels: u64,
) -> Result<CryptomattePlan, MaskError> {
    let parts = &headers.parts[..];
    let layers = cryptomatte_layers(&headers.text_attributes, path)?;
    let layer = choose_layer(&layers, opts.layer.as_deref(), path)?;
    let unmatched = opts
        .glass
        .unmatched(layer.manifest.keys().map(String::as_str));
    if !unmatched.is_empty() {
        return Err(MaskError::UnmatchedGlassNames {
            path: path.to_path_buf(),
            layer: layer.name.clone(),
            patterns: unmatched,
            names: layer.manifest.keys().cloned().collect(),
        });
    }
    // Every entry used as glass is checked against its name; pixels store the hash with the
    // exponent fix-up, whichever the manifest wrote.
    let mut glass_of: HashMap<u32, u16> = HashMap::new();
    for (name, &hash) in &layer.manifest {
        if let Some(id) = opts.glass.id_of(name) {
            let expected = murmur3_32(name.as_bytes(), 0);
            if hash != expected && hash != float_encoded(expected) {
                return Err(MaskError::ManifestHash {
                    path: path.to_path_buf(),
                    layer: layer.name.clone(),
                    name: name.clone(),
                    manifest: hash,
                    expected: float_encoded(expected),
                });
            }
            glass_of.insert(float_encoded(expected), id);
        }
    }
    let names_of: HashMap<u32, String> = layer
        .manifest
        .iter()
        .map(|(name, &hash)| (float_encoded(hash), name.clone()))
        .collect();
    let ranks = rank_channels(parts, &layer.name);
    if ranks.is_empty() {
        return Err(MaskError::MissingChannel {
            path: path.to_path_buf(),
            channel: format!("{}00.r", layer.name),
            available: glassdb_image::all_channel_names(parts),
        });
    }
    let mut wanted: Vec<(usize, usize)> = ranks.iter().flatten().copied().collect();
    let rank_count = wanted.len();
    match &opts.cos {
        CosSource::Aov { channel } => wanted.push(locate(parts, channel, path)?),
        CosSource::Geometry {
            normal, position, ..
        } => {
            wanted.extend(locate_vector(parts, normal, path)?);
            wanted.extend(locate_vector(parts, position, path)?);
        }
    }
    match &opts.planes {
        PlaneSource::Single => {}
        PlaneSource::Aov(plane) => wanted.push(locate(parts, plane, path)?),
        PlaneSource::Geometry {
            normal, position, ..
        } => {
            wanted.extend(locate_vector(parts, normal, path)?);
            wanted.extend(locate_vector(parts, position, path)?);
        }
    }
    let windows = plan_channels(parts, &wanted, path, max_pixels)?;
    Ok(CryptomattePlan {
        glass_of,
        names_of,
        wanted,
        rank_count,
        windows,
        stores_planes: opts.planes != PlaneSource::Single,
    })
}

impl CryptomattePlan {
    /// The header's facts and the memory reading costs, for a file of `file_len` bytes: every
    /// wanted channel as f32 and the dominant glass's id, coverage and total coverage while
    /// reading; id, plane (u16), cos θ and coverage (f32) after.
    pub(crate) fn header(&self, file_len: u64) -> MaskHeader {
        let pixels = self.windows.data.pixel_count();
        let per_pixel = 2 + 2 + 4 + 4;
        let planes = ReadMemory::exr_planes(file_len, pixels, self.wanted.len());
        MaskHeader {
            windows: self.windows,
            stores_planes: self.stores_planes,
            has_coordinates: true,
            bytes_per_pixel: per_pixel,
            memory: ReadMemory {
                transient: planes.transient.saturating_add(planes.kept),
                kept: 0,
            }
            // The dominant glass's total coverage, dropped at the end.
            .with_transient(pixels.saturating_mul(4))
            .keeping(pixels.saturating_mul(per_pixel)),
        }
    }
}

/// Decodes the channels `plan` chose and builds the mask.
pub(crate) fn decode_cryptomatte(
    exr: &ExrFile<'_>,
    path: &Path,
    opts: &CryptomatteOptions,
    plan: CryptomattePlan,
) -> Result<PlacedMask, MaskError> {
    let CryptomattePlan {
        glass_of,
        names_of,
        wanted,
        rank_count,
        stores_planes,
        ..
    } = plan;
    let (windows, planes) = decode_channels(exr, &wanted, path)?;
    let (ranks_data, rest) = planes.split_at(rank_count);
    let pixel = PixelError {
        path,
        width: windows.data.width,
    };
    let glass = dominant_glass(ranks_data, &glass_of, &names_of, &pixel)?;
    let aovs = GlassAovs {
        id: &glass.id,
        divide: |v: f32, i: usize| match opts.weighting {
            AovWeighting::GlassOnly if glass.total[i] > 0.0 => v / glass.total[i],
            _ => v,
        },
        pixel: &pixel,
    };
    let (cos, after_cos) = match &opts.cos {
        CosSource::Aov { channel } => (aovs.cos(&rest[0], channel)?, &rest[1..]),
        CosSource::Geometry { camera_origin, .. } => (
            cos_from_geometry(&rest[..6], &glass.id, *camera_origin, &pixel)?,
            &rest[6..],
        ),
    };
    let plane = match &opts.planes {
        PlaneSource::Single => vec![0; glass.id.len()],
        PlaneSource::Aov(name) => aovs.planes(&after_cos[0], name)?,
        PlaneSource::Geometry {
            equations,
            max_angle_deg,
            ..
        } => planes_from_geometry(after_cos, &glass.id, equations, *max_angle_deg, &pixel)?,
    };
    let partial = glass
        .coverage
        .iter()
        .zip(&glass.id)
        .any(|(&c, &g)| g != 0 && c < 1.0);
    Ok(PlacedMask {
        image: MaskImage {
            width: windows.data.width as u32,
            height: windows.data.height as u32,
            id: glass.id,
            cos_theta: CosTheta::Float(cos),
            plane,
            coverage: partial.then_some(glass.coverage),
        },
        windows,
        stores_planes,
        has_coordinates: true,
    })
}

/// Per pixel: the glass id with the largest coverage, that coverage, and the coverage of all
/// glass together.
struct DominantGlass {
    id: Vec<u16>,
    coverage: Vec<f32>,
    total: Vec<f32>,
}

/// How far above 1 a rank's coverage may round.
const COVERAGE_ROUNDING: f32 = 1e-4;

/// Sums each glass's coverage over the ranks (`ranks` alternates id and coverage planes) and
/// keeps the largest; ids that are not glass (or not in the manifest) count as no glass. A
/// coverage that is not a finite value in [0, 1] is refused, naming the pixel, the value and
/// the name its id has in the manifest (`names_of`).
fn dominant_glass(
    ranks: &[Vec<f32>],
    glass_of: &HashMap<u32, u16>,
    names_of: &HashMap<u32, String>,
    pixel: &PixelError<'_>,
) -> Result<DominantGlass, MaskError> {
    let n = ranks.first().map_or(0, Vec::len);
    let mut out = DominantGlass {
        id: vec![0; n],
        coverage: vec![0.0; n],
        total: vec![0.0; n],
    };
    let mut per_glass: Vec<(u16, f32)> = Vec::with_capacity(8);
    for i in 0..n {
        per_glass.clear();
        for (rank, pair) in ranks.chunks_exact(2).enumerate() {
            let cov = pair[1][i];
            if !(cov.is_finite() && (0.0..=1.0 + COVERAGE_ROUNDING).contains(&cov)) {
                let bits = pair[0][i].to_bits();
                let name = names_of.get(&bits).map_or_else(
                    || format!("id {bits:08x} (not in the manifest)"),
                    |n| glassdb_io::quoted(n).to_string(),
                );
                return Err(pixel.at(
                    i,
                    format!(
                        "Cryptomatte rank {rank} gives {name} the coverage {cov}, not a value in [0, 1]"
                    ),
                ));
            }
            if cov == 0.0 {
                continue;
            }
            let Some(&g) = glass_of.get(&pair[0][i].to_bits()) else {
                continue;
            };
            out.total[i] += cov;
            match per_glass.iter_mut().find(|(gid, _)| *gid == g) {
                Some(slot) => slot.1 += cov,
                None => per_glass.push((g, cov)),
            }
        }
        let best = per_glass
            .iter()
            .copied()
            .reduce(|a, b| if b.1 > a.1 { b } else { a });
        if let Some((g, c)) = best {
            out.id[i] = g;
            out.coverage[i] = c.min(1.0);
        }
    }
    Ok(out)
}

/// MurmurHash3 (x86, 32-bit) of `data` with `seed`: Cryptomatte's hash of a name (seed 0, the
/// name's UTF-8 bytes).
pub fn murmur3_32(data: &[u8], seed: u32) -> u32 {
    const C1: u32 = 0xcc9e_2d51;
    const C2: u32 = 0x1b87_3593;
    let mix = |k: u32| k.wrapping_mul(C1).rotate_left(15).wrapping_mul(C2);
    let mut h = seed;
    let mut blocks = data.chunks_exact(4);
    for b in &mut blocks {
        h ^= mix(u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        h = h.rotate_left(13).wrapping_mul(5).wrapping_add(0xe654_6b64);
    }
    let tail = blocks.remainder();
    if !tail.is_empty() {
        let k = tail
            .iter()
            .rev()
            .fold(0u32, |k, &byte| (k << 8) | u32::from(byte));
        h ^= mix(k);
    }
    h ^= data.len() as u32;
    h ^= h >> 16;
    h = h.wrapping_mul(0x85eb_ca6b);
    h ^= h >> 13;
    h = h.wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// A hash as Cryptomatte stores it in a pixel (the bits of an `f32`): an exponent of all
/// zeros or all ones (a denormal, infinite or NaN float) has its lowest bit flipped, as the
/// specification says (Blender clamps it to 1 or 254: the same bits).
pub fn float_encoded(hash: u32) -> u32 {
    let exponent = (hash >> 23) & 0xff;
    if exponent == 0 || exponent == 0xff {
        hash ^ (1 << 23)
    } else {
        hash
    }
}
