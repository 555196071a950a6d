//! The flags that name one frame's inputs (passes, mask, planes, frames, limits) and how they are
//! read: shared by `compose` and `view`, which read the same inputs, so that both accept the
//! same masks (Cryptomatte included), layers and multi-part reflection files.

use std::collections::BTreeMap;
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{Context, bail};
use glassdb_colour::RgbSpace;
use glassdb_compose::{
    DecodeSettings, FrameFiles, GroupPassFile, InputLayers, OutsidePolicy, UnknownIds,
};
use glassdb_mask::{
    AovWeighting, CosSource, CryptomatteOptions, ExrMaskChannels, GlassMapping, GlassNames,
    MaskReadOptions, PlaneSource,
};
use glassdb_pass::{InputTransfer, PassReadOptions};
use glassdb_side::Side;

#[derive(Debug, clap::Args)]
pub struct FrameInputArgs {
    /// Reflection pass (EXR or PNG; `FILE.exr:LAYER` picks its layer). Repeat for several
    /// glass planes: the k-th is plane k of the mask (R channel of a PNG mask, `plane` channel
    /// of an EXR mask). It may cover only part of the frame (an EXR data window); one EXR whose
    /// layers or parts are `plane0`, `plane1`, … gives every plane's.
    #[arg(long, required = true, value_name = "FILE[:LAYER]")]
    pub refl: Vec<PathBuf>,
    /// Reflection pass of a unit's pane group behind the first, `K.G=FILE[:LAYER]`: plane K's
    /// group G (1: the second pane group the camera's rays meet), the scene mirrored about that
    /// group's mid-plane (docs/compose.md, "Units"). One --refl EXR whose layers or parts are
    /// `planeK.groupG` gives them too.
    #[arg(long = "refl-group", value_name = "K.G=FILE[:LAYER]", value_parser = parse_group_spec)]
    pub refl_group: Vec<GroupPassFile>,
    /// How many of a unit's pane groups get a reflection pass of their own: `1` composites one
    /// pass per plane, the deeper groups' reflectance added to it (no double image; faster).
    /// Default: every group, each from its own pass.
    #[arg(long, value_name = "N")]
    pub surfaces: Option<NonZeroUsize>,
    /// Transmission pass (the scene without glass; `FILE.exr:LAYER` picks its layer); its
    /// alpha, windows, attributes and other channels are kept.
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub trans: PathBuf,
    /// Glass mask: 8-bit RGB PNG (G = id, B = cos θ·255, R = plane), 16-bit RGB PNG, EXR with
    /// `id` and `cos_theta` channels (`FILE.exr:LAYER` reads them in LAYER), a render's
    /// Cryptomatte with --mask-cryptomatte, or (compose) a binary PNG with --glass
    /// (docs/mask.md).
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub mask: PathBuf,
    /// EXR layer of every pass without its own: a layer (`ViewLayer.Combined`, `Combined`), a
    /// Nuke layer (`diffuse`) or a view (`left`) (default: the only RGB layer, the bare R, G,
    /// B, or the one named …Combined).
    #[arg(long, value_name = "NAME")]
    pub layer: Option<String>,
    /// EXR layer of the transmission pass (over --layer).
    #[arg(long, value_name = "NAME")]
    pub trans_layer: Option<String>,
    /// EXR layer of every reflection pass (over --layer; `FILE:LAYER` sets one pass's).
    #[arg(long, value_name = "NAME")]
    pub refl_layer: Option<String>,
    /// EXR layer the mask channel names are in, e.g. `ViewLayer` (then `id=IndexMA` reads
    /// `ViewLayer.IndexMA.X`).
    #[arg(long, value_name = "NAME")]
    pub mask_layer: Option<String>,
    /// How PNG passes are encoded.
    #[arg(long, value_enum, default_value_t = TransferArg::Srgb)]
    pub input_transfer: TransferArg,
    /// The passes' linear RGB space, over what their headers say (`colorInteropID`,
    /// `chromaticities`; untagged passes are linear Rec.709): srgb (= rec709), rec2020, acescg,
    /// aces2065-1, display-p3, xyz. The registry's table in that space is used.
    #[arg(long, value_name = "SPACE")]
    pub input_space: Option<RgbSpace>,
    /// EXR mask channel names, e.g. `id=IndexMA,cos=facing` (keys id, cos, plane, coverage;
    /// with --mask-cryptomatte: cos, plane, or normal and position with --camera).
    #[arg(long, value_name = "KEY=NAME,...")]
    pub mask_channels: Option<String>,
    /// Build the mask from the render's Cryptomatte layer (e.g. `CryptoMaterial`; without a
    /// value the only layer, or the one named …CryptoMaterial), the glasses named by
    /// --mask-glass, cos θ from an AOV (`--mask-channels cos=facing`, the default) or from the
    /// Normal and Position passes and --camera; planes from a plane AOV
    /// (`--mask-channels plane=NAME`) or, with several --refl and --planes, from the Normal and
    /// Position passes matched against planes.json.
    #[arg(long, value_name = "LAYER", num_args = 0..=1, default_missing_value = "")]
    pub mask_cryptomatte: Option<String>,
    /// PATTERN=ID: Cryptomatte names (materials or objects) matching the glob PATTERN are glass
    /// with registration id ID (repeat; the first match wins).
    #[arg(long, value_name = "PATTERN=ID")]
    pub mask_glass: Vec<String>,
    /// How the cos θ and plane AOVs were written: by the glass materials only (`glass-only`,
    /// 0 elsewhere: divided by the glass coverage at edges) or by every material.
    #[arg(long, value_enum, default_value_t = AovsArg::GlassOnly)]
    pub mask_aovs: AovsArg,
    /// Camera JSON (docs/scene.md): its position gives the view ray for cos θ from the Normal
    /// and Position passes.
    #[arg(long, value_name = "JSON")]
    pub camera: Option<PathBuf>,
    /// Plane K shows the glass's back face (`K=back`) or front face (`K=front`, the default).
    #[arg(long, value_name = "K=SIDE")]
    pub side: Vec<String>,
    /// `planes.json` from `glassdb mirror`: the side of every plane (--side overrides it).
    #[arg(long, value_name = "JSON")]
    pub planes: Option<PathBuf>,
    /// Frames of an animation, e.g. `1-240` or `1,5,10-20`: `####` in --refl, --trans, --mask
    /// (and compose's -o) is replaced by the zero-padded frame number.
    #[arg(long, value_name = "LIST")]
    pub frames: Option<String>,
    /// Refuse inputs with more pixels than this (checked before decoding).
    #[arg(long, value_name = "N", default_value_t = glassdb_mask::DEFAULT_MAX_PIXELS)]
    pub max_pixels: u64,
    /// Refuse a frame that would hold more memory than SIZE, estimated from the inputs'
    /// headers before anything is decoded (e.g. 8G, 512M; K, M, G, T are powers of 1024);
    /// frames of --frames in flight together share it [default: 8G, or half the machine's
    /// memory if that is less].
    #[arg(long, value_name = "SIZE", value_parser = parse_size)]
    pub max_memory: Option<u64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum TransferArg {
    Srgb,
    Linear,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AovsArg {
    GlassOnly,
    EveryMaterial,
}

/// How far (degrees) a glass pixel's Normal pass may lie from its plane's normal when planes are
/// matched from geometry (a pass is filtered at edges; panes meet at far larger angles).
const PLANE_MATCH_DEG: f64 = 10.0;

impl FrameInputArgs {
    /// The files of the frame (layers split off).
    pub fn files(&self) -> FrameFiles {
        FrameFiles {
            refl: self.refl.iter().map(|r| split_layer(r).0).collect(),
            groups: self.refl_group.clone(),
            trans: split_layer(&self.trans).0,
            mask: split_layer(&self.mask).0,
        }
    }

    /// How a frame is read from these inputs (passes, layers, mask, space, memory limit), with
    /// the rest as given. Declares the inputs besides the passes and the mask
    /// ([`FrameInputArgs::side_inputs`]): no output may replace one.
    pub fn decode_settings(
        &self,
        outside: OutsidePolicy,
        unknown: UnknownIds,
        registry_label: String,
    ) -> anyhow::Result<DecodeSettings> {
        let side_inputs: Vec<PathBuf> = self.side_inputs().collect();
        glassdb_io::declare_inputs(side_inputs.iter().map(PathBuf::as_path));
        Ok(DecodeSettings {
            pass: self.pass_options(),
            layers: self.layers(),
            mask: self.mask_options()?,
            input_space: self.input_space,
            unknown,
            outside,
            max_groups: self.surfaces,
            registry_label,
            max_memory: self.max_memory(),
        })
    }

    /// How the passes are read: the default layer, PNG transfer and pixel limit.
    pub fn pass_options(&self) -> PassReadOptions {
        PassReadOptions {
            layer: self.layer.clone(),
            transfer: match self.input_transfer {
                TransferArg::Srgb => InputTransfer::Srgb,
                TransferArg::Linear => InputTransfer::Linear,
            },
            max_pixels: self.max_pixels,
            light_mix: None,
        }
    }

    /// Each pass's own layer: `FILE:LAYER`, then --trans-layer / --refl-layer.
    pub fn layers(&self) -> InputLayers {
        InputLayers {
            trans: split_layer(&self.trans)
                .1
                .or_else(|| self.trans_layer.clone()),
            refl: self
                .refl
                .iter()
                .map(|r| split_layer(r).1.or_else(|| self.refl_layer.clone()))
                .collect(),
        }
    }

    /// How the mask is read: its channels or its Cryptomatte, its layer and pixel limit.
    pub fn mask_options(&self) -> anyhow::Result<MaskReadOptions> {
        let cryptomatte = match &self.mask_cryptomatte {
            Some(layer) => Some(self.cryptomatte_options(layer)?),
            None => None,
        };
        Ok(MaskReadOptions {
            exr_channels: match (&self.mask_channels, &cryptomatte) {
                (Some(s), None) => parse_mask_channels(s)?,
                _ => ExrMaskChannels::default(),
            },
            cryptomatte,
            binary_glass_id: None,
            max_pixels: self.max_pixels,
            layer: split_layer(&self.mask)
                .1
                .or_else(|| self.mask_layer.clone()),
        })
    }

    /// The side each plane shows: from `planes.json` (when given), then each `--side K=SIDE`.
    pub fn plane_sides(&self) -> anyhow::Result<BTreeMap<usize, Side>> {
        let passes = self.refl.len();
        let mut sides = match &self.planes {
            Some(p) => glassdb_scene::sides_from_planes_json(p, passes)?,
            None => Default::default(),
        };
        for spec in &self.side {
            let (k, side) = parse_side_spec(spec)?;
            if k >= passes {
                bail!(
                    "--side {spec}: plane {k} has no reflection pass ({passes} given; planes count from 0)"
                );
            }
            sides.insert(k, side);
        }
        Ok(sides)
    }

    /// The inputs besides the passes and the mask (planes.json, the camera): no output may
    /// replace one.
    pub fn side_inputs(&self) -> impl Iterator<Item = PathBuf> + '_ {
        self.planes.iter().chain(&self.camera).cloned()
    }

    /// --max-memory, or the default limit.
    pub fn max_memory(&self) -> u64 {
        self.max_memory.unwrap_or_else(default_max_memory)
    }

    /// The frames of --frames (none without it).
    pub fn frame_numbers(&self) -> anyhow::Result<Vec<u32>> {
        Ok(match &self.frames {
            Some(spec) => glassdb_io::parse_frame_list(spec)?,
            None => Vec::new(),
        })
    }

    /// One `--refl FILE.exr` (no layer named) whose file holds the passes of several planes as
    /// layers or parts `plane0`, `plane1`, … becomes one `--refl FILE.exr:planeK` per plane. In
    /// a sequence the first frame whose file can be read decides (every frame of a shot has the
    /// same planes; a frame without a layer then fails naming it).
    pub fn expand_plane_layers(&mut self) -> anyhow::Result<()> {
        let [refl] = self.refl.as_slice() else {
            return Ok(());
        };
        if split_layer(refl).1.is_some() || self.refl_layer.is_some() {
            return Ok(());
        }
        let candidates: Vec<PathBuf> = match &self.frames {
            Some(spec) if glassdb_io::is_frame_pattern(refl) => glassdb_io::parse_frame_list(spec)?
                .into_iter()
                .filter_map(|f| glassdb_io::expand_frame_pattern(refl, f).ok())
                .filter(|p| p.is_file())
                .take(1)
                .collect(),
            _ => vec![refl.clone()],
        };
        let Some(first) = candidates.first() else {
            return Ok(());
        };
        // A file that cannot be read is reported by the frame that reads it, after the other
        // inputs' checks; only misnumbered plane layers are this function's to report.
        match glassdb_pass::plane_layers_of(first, self.max_pixels) {
            Ok(Some(layers)) => {
                let file = refl.to_string_lossy().into_owned();
                self.refl = layers
                    .iter()
                    .map(|l| PathBuf::from(format!("{file}:{l}")))
                    .collect();
                if self.refl_group.is_empty() {
                    // The same file's pane-group layers `planeK.groupG` (issue 27).
                    let groups = glassdb_pass::plane_group_layers_of(first, self.max_pixels)
                        .unwrap_or_default();
                    self.refl_group = groups
                        .into_iter()
                        .map(|(k, g, layer)| GroupPassFile {
                            plane: k as usize,
                            group: g as usize,
                            path: PathBuf::from(&file),
                            layer: Some(layer),
                        })
                        .collect();
                }
                Ok(())
            }
            Err(e @ glassdb_pass::PassError::PlaneLayers { .. }) => Err(e.into()),
            Ok(None) | Err(_) => Ok(()),
        }
    }

    /// The Cryptomatte mask options: the layer, the glasses, cos θ from an AOV (`cos=`, default
    /// `facing`) or from `normal=` and `position=` with the camera, the plane AOV (`plane=`).
    fn cryptomatte_options(&self, layer: &str) -> anyhow::Result<CryptomatteOptions> {
        if self.mask_glass.is_empty() {
            bail!(
                "--mask-cryptomatte needs --mask-glass PATTERN=ID for each glass (e.g. 'Glass*=1')"
            );
        }
        let mappings = self
            .mask_glass
            .iter()
            .map(|g| GlassMapping::parse(g))
            .collect::<Result<Vec<_>, _>>()?;
        let spec = self.mask_channels.as_deref().unwrap_or("");
        let pairs = parse_channel_spec(spec, &["cos", "plane", "normal", "position"])?;
        let get = |k: &str| {
            pairs
                .iter()
                .find(|(key, _)| key == k)
                .map(|(_, v)| v.clone())
        };
        let planes = match (&self.planes, get("plane")) {
            (_, Some(aov)) => PlaneSource::Aov(aov),
            (Some(file), None) if self.refl.len() > 1 => {
                let planes = glassdb_scene::PlanesFile::load(file)?;
                PlaneSource::Geometry {
                    normal: get("normal").unwrap_or_else(|| "Normal".into()),
                    position: get("position").unwrap_or_else(|| "Position".into()),
                    equations: planes.planes.iter().map(|p| p.equation).collect(),
                    max_angle_deg: PLANE_MATCH_DEG,
                }
            }
            _ => PlaneSource::Single,
        };
        let cos = match (get("cos"), get("normal"), get("position")) {
            (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
                bail!(
                    "--mask-channels: give cos=AOV, or normal= and position= with --camera, not both"
                )
            }
            (_, Some(normal), Some(position)) => {
                let camera = self.camera.as_ref().context(
                    "cos θ from the Normal and Position passes needs the camera position: --camera camera.json",
                )?;
                CosSource::Geometry {
                    normal,
                    position,
                    camera_origin: glassdb_scene::Camera::load(camera)?.origin,
                }
            }
            (_, Some(_), None) | (_, None, Some(_)) => {
                bail!("--mask-channels: cos θ from geometry needs both normal= and position=")
            }
            (cos, None, None) => CosSource::Aov {
                channel: cos.unwrap_or_else(|| "facing".into()),
            },
        };
        Ok(CryptomatteOptions {
            layer: (!layer.is_empty()).then(|| layer.to_string()),
            glass: GlassNames::new(&mappings)?,
            cos,
            planes,
            weighting: match self.mask_aovs {
                AovsArg::GlassOnly => AovWeighting::GlassOnly,
                AovsArg::EveryMaterial => AovWeighting::EveryMaterial,
            },
        })
    }
}

/// `--max-memory`: a number of bytes with an optional unit K, M, G or T (powers of 1024; `KiB`,
/// `MB`, `g` … are read the same), e.g. `8G`, `512M`, `1.5G`, `1048576`.
pub(crate) fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(split);
    let unit = unit.trim().to_ascii_uppercase();
    let unit = unit
        .strip_suffix("IB")
        .or_else(|| unit.strip_suffix('B'))
        .unwrap_or(&unit);
    let shift = match unit {
        "" => 0,
        "K" => 10,
        "M" => 20,
        "G" => 30,
        "T" => 40,
        _ => {
            return Err(format!(
                "{text:?}: the unit must be K, M, G or T (e.g. 8G, 512M)"
            ));
        }
    };
    let value: f64 = number
        .parse()
        .map_err(|_| format!("{text:?} is not a size (e.g. 8G, 512M)"))?;
    let bytes = value * (1u64 << shift) as f64;
    if !(bytes.is_finite() && bytes >= 1.0 && bytes < u64::MAX as f64) {
        return Err(format!("{text:?} is not a size of at least one byte"));
    }
    Ok(bytes as u64)
}

/// The default memory limit: 8 GiB, or half the machine's memory (or of the control group's
/// limit) where that is less, leaving the rest to the system and to other work.
pub(crate) fn default_max_memory() -> u64 {
    let half = machine_memory().map_or(u64::MAX, |m| m / 2);
    glassdb_compose::memory::DEFAULT_MAX_MEMORY.min(half)
}

/// The memory this process may use: the machine's (Linux `/proc/meminfo`), or the control
/// group's limit (`/sys/fs/cgroup/memory.max`) when lower; `None` where neither is known.
fn machine_memory() -> Option<u64> {
    let total = std::fs::read_to_string("/proc/meminfo").ok().and_then(|m| {
        m.lines()
            .find_map(|l| l.strip_prefix("MemTotal:"))
            .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
            .map(|kib| kib.saturating_mul(1024))
    });
    let cgroup = std::fs::read_to_string("/sys/fs/cgroup/memory.max")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok());
    match (total, cgroup) {
        (Some(t), Some(c)) => Some(t.min(c)),
        (t, c) => t.or(c),
    }
}

/// `--mask-channels KEY=NAME,…` as (key, name) pairs, keys checked against `keys`.
fn parse_channel_spec(spec: &str, keys: &[&str]) -> anyhow::Result<Vec<(String, String)>> {
    let known = keys.join(", ");
    spec.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|item| {
            let (key, name) = item.split_once('=').with_context(|| {
                format!("--mask-channels: {item:?} is not KEY=NAME (keys: {known})")
            })?;
            let key = match key.trim() {
                "cos_theta" => "cos",
                k => k,
            };
            if !keys.contains(&key) {
                bail!("--mask-channels: unknown key {key:?} here (keys: {known})");
            }
            Ok((key.to_string(), name.trim().to_string()))
        })
        .collect()
}

/// `--mask-channels id=…,cos=…,plane=…,coverage=…` over the defaults.
fn parse_mask_channels(spec: &str) -> anyhow::Result<ExrMaskChannels> {
    let mut ch = ExrMaskChannels::default();
    for (key, name) in parse_channel_spec(spec, &["id", "cos", "plane", "coverage"])? {
        match key.as_str() {
            "id" => ch.id = name,
            "cos" => ch.cos_theta = name,
            "plane" => ch.plane = name,
            _ => ch.coverage = name,
        }
    }
    Ok(ch)
}

/// `FILE.exr:LAYER` → (`FILE.exr`, `LAYER`): split at the last `:` when what precedes it ends
/// in `.exr` (any case) and what follows has no path separator; anything else is a plain path.
pub(crate) fn split_layer(arg: &Path) -> (PathBuf, Option<String>) {
    let text = arg.to_string_lossy();
    if let Some((file, layer)) = text.rsplit_once(':')
        && file.to_ascii_lowercase().ends_with(".exr")
        && !layer.is_empty()
        && !layer.contains(['/', '\\'])
    {
        return (PathBuf::from(file), Some(layer.to_string()));
    }
    (arg.to_path_buf(), None)
}

/// Parses a `--refl-group` value, `K.G=FILE[:LAYER]`.
fn parse_group_spec(spec: &str) -> anyhow::Result<GroupPassFile> {
    let bad = || {
        anyhow::anyhow!(
            "expected PLANE.GROUP=FILE[:LAYER] with GROUP 1 or more, e.g. 0.1=refl_0_1.exr"
        )
    };
    let (key, file) = spec.split_once('=').ok_or_else(bad)?;
    let (plane, group) = key.split_once('.').ok_or_else(bad)?;
    let plane: usize = plane.trim().parse().map_err(|_| bad())?;
    let group: usize = group.trim().parse().map_err(|_| bad())?;
    if group == 0 || file.is_empty() {
        return Err(bad());
    }
    let (path, layer) = split_layer(Path::new(file));
    Ok(GroupPassFile {
        plane,
        group,
        path,
        layer,
    })
}

/// Parses a `--side` value, `K=front` / `K=back` (plane index K).
fn parse_side_spec(spec: &str) -> anyhow::Result<(usize, Side)> {
    let bad =
        || anyhow::anyhow!("--side {spec:?}: expected PLANE=front or PLANE=back, e.g. 2=back");
    let (k, side) = spec.split_once('=').ok_or_else(bad)?;
    let k: usize = k.trim().parse().map_err(|_| bad())?;
    let side: Side = side.parse().map_err(|_| bad())?;
    Ok((k, side))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_layer_specs_split_only_after_an_exr_name() {
        let split = |s: &str| split_layer(Path::new(s));
        assert_eq!(
            split("r.exr:left"),
            (PathBuf::from("r.exr"), Some("left".into()))
        );
        assert_eq!(
            split("dir/R.####.EXR:ViewLayer.Combined"),
            (
                PathBuf::from("dir/R.####.EXR"),
                Some("ViewLayer.Combined".into())
            )
        );
        for plain in ["r.exr", "a:b/r.exr", "mask.png:x", "r.exr:", "r.exr:a/b"] {
            assert_eq!(split(plain), (PathBuf::from(plain), None), "{plain}");
        }
    }

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_size("8G"), Ok(8 << 30));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5g"), Ok(3 << 29));
        assert_eq!(parse_size("2 TB"), Ok(2 << 40));
        assert_eq!(parse_size("4096"), Ok(4096));
        assert!(parse_size("8X").is_err());
        assert!(parse_size("G").is_err());
        assert!(parse_size("0").is_err());
        assert!(parse_size("-1G").is_err());
        assert!(default_max_memory() <= glassdb_compose::memory::DEFAULT_MAX_MEMORY);
    }

    #[test]
    fn side_specs_parse() {
        assert_eq!(parse_side_spec("2=back").unwrap(), (2, Side::Back));
        assert_eq!(parse_side_spec("0=Front").unwrap(), (0, Side::Front));
        assert!(parse_side_spec("x=back").is_err());
        assert!(parse_side_spec("1=left").is_err());
    }
}
