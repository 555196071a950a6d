//! `compose` / `glassdb compose`: reflection and transmission passes through an id + cos θ mask
//! (docs/compose.md). All logic lives in `glassdb_compose`; this module parses arguments,
//! prints the report and drives the progress display (stages of one frame, or a bar over the
//! frames of a sequence).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_compose::colour::RegistryLuts;
use glassdb_compose::frames_report::FramesReport;
use glassdb_compose::io::{ExrDataType, OutputOptions, PassReadOptions, parse_exr_compression};
use glassdb_compose::pixels::{InputTransfer, PngBits};
use glassdb_compose::sequence::{self, FrameDone, FrameOutcome, SequenceOptions};
use glassdb_compose::view::ViewTransform;
use glassdb_compose::{
    ComposeJob, ComposeSettings, FrameReport, InputLayers, OutsidePolicy, UnknownIds,
    compose_frame_with_progress,
};
use glassdb_mask::{
    AovWeighting, CosSource, CryptomatteOptions, ExrMaskChannels, GlassMapping, GlassNames,
    MaskReadOptions, PlaneSource,
};
use glassdb_registry::{ColourBasis, Registry, Side};
use glassdb_spectral::RgbSpace;

use crate::cmd::progress::Spinner;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Reflection pass (EXR or PNG; `FILE.exr:LAYER` picks its layer). Repeat for several
    /// glass planes: the k-th is plane k of the mask (R channel of a PNG mask, `plane` channel
    /// of an EXR mask). It may cover only part of the frame (an EXR data window).
    #[arg(long, required = true, value_name = "FILE[:LAYER]")]
    pub refl: Vec<PathBuf>,
    /// Transmission pass (the scene without glass; `FILE.exr:LAYER` picks its layer); its
    /// alpha, windows, attributes and other channels are kept.
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub trans: PathBuf,
    /// Glass mask: 8-bit RGB PNG (G = id, B = cos θ·255, R = plane), 16-bit RGB PNG, EXR with
    /// `id` and `cos_theta` channels (`FILE.exr:LAYER` reads them in LAYER), or a binary PNG
    /// with --glass (docs/mask.md).
    #[arg(long, value_name = "FILE[:LAYER]")]
    pub mask: PathBuf,
    /// Registry JSON (`glassdb registry build`); default: the bundled data/registry.json (built
    /// from data/catalog.toml).
    #[arg(long, value_name = "JSON")]
    pub registry: Option<PathBuf>,
    /// Output, .exr or .png (default: beside the transmission pass, `<name>.composite.<ext>`).
    #[arg(short, long, value_name = "FILE")]
    pub output: Option<PathBuf>,
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
    /// Glass pixels of a plane that its (cropped) reflection pass does not cover: refuse
    /// (`error`), composite them without reflection (`no-reflection`), or leave them as the
    /// transmission pass (`transmission`).
    #[arg(long, value_enum, default_value_t = OutsideArg::Error)]
    pub outside_pass: OutsideArg,
    /// EXR output: keep the transmission file's other channels and parts (`all`: Z, AOVs,
    /// other views) or write only the composite (`none`). Its attributes are always kept.
    #[arg(long, value_enum, default_value_t = KeepArg::All)]
    pub keep_channels: KeepArg,
    /// EXR output: write the composite as a new layer NAME (`NAME.R`, …) beside the original
    /// channels instead of replacing the transmission pass's RGB.
    #[arg(long, value_name = "NAME")]
    pub output_layer: Option<String>,
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
    /// Read the mask as the paper's binary mask (white = glass, black = not) showing glass ID
    /// at its normal-incidence values.
    #[arg(long, value_name = "ID")]
    pub glass: Option<u16>,
    /// Plane K shows the glass's back face (`K=back`) or front face (`K=front`, the default).
    #[arg(long, value_name = "K=SIDE")]
    pub side: Vec<String>,
    /// `planes.json` from `glassdb mirror`: the side of every plane (--side overrides it).
    #[arg(long, value_name = "JSON")]
    pub planes: Option<PathBuf>,
    /// Mask ids with no registry entry: refuse (`error`) or leave the pixels as the
    /// transmission pass (`passthrough`).
    #[arg(long, value_enum, default_value_t = UnknownArg::Error)]
    pub unknown: UnknownArg,
    /// EXR output sample type (default: the transmission pass's).
    #[arg(long, value_enum)]
    pub data_type: Option<DataTypeArg>,
    /// EXR output compression: none, rle, zips, zip, piz, pxr24, b44, b44a, dwaa, dwab
    /// (default zip).
    #[arg(long, value_name = "NAME")]
    pub compression: Option<String>,
    /// zlib level of zip and zips EXR output: 1 is fastest (files about 5 % larger), 9 smallest
    /// [default: 4, OpenEXR's].
    #[arg(long, value_name = "0-9", value_parser = clap::value_parser!(u32).range(0..=9))]
    pub zip_level: Option<u32>,
    /// PNG output bits per sample (default: the transmission pass's, 8 for EXR input).
    #[arg(long, value_parser = ["8", "16"])]
    pub png_bits: Option<String>,
    /// View transform of PNG output: `standard` (the sRGB transfer, clipped) or a `.cube` LUT
    /// (1D, 3D, or a 1D shaper then 3D, e.g. AgX, Filmic or ACES baked by `ociobakelut --format
    /// resolve_cube`; docs/colour.md) whose output is display-encoded. EXR output stays
    /// scene-linear, so --view with a .exr output is refused. [default: standard]
    #[arg(long, value_name = "standard|FILE.cube")]
    pub view: Option<String>,
    /// Dither for 8-bit PNG output.
    #[arg(long, value_enum, default_value_t = DitherArg::Ordered)]
    pub dither: DitherArg,
    /// Frames of an animation, e.g. `1-240` or `1,5,10-20`: `####` in --refl, --trans, --mask
    /// and -o is replaced by the zero-padded frame number.
    #[arg(long, value_name = "LIST")]
    pub frames: Option<String>,
    /// With --frames: leave a frame whose output already exists and is complete (a regular
    /// file that decodes whole), so that a rerun composites only what is missing
    /// (docs/farm.md).
    #[arg(long, requires = "frames")]
    pub skip_existing: bool,
    /// With --frames: write a JSON report of every frame (status, inputs, output, seconds,
    /// error) to FILE, atomically, also when frames fail (docs/farm.md).
    #[arg(long, value_name = "FILE.json", requires = "frames")]
    pub report: Option<PathBuf>,
    /// Print per-stage timings, megapixels per second, per-id pixel counts and the cos θ range.
    #[arg(long)]
    pub stats: bool,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutsideArg {
    Error,
    NoReflection,
    Transmission,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum KeepArg {
    All,
    None,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum UnknownArg {
    Error,
    Passthrough,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DataTypeArg {
    Half,
    Float,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum DitherArg {
    Ordered,
    None,
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
pub(crate) fn parse_mask_channels(spec: &str) -> anyhow::Result<ExrMaskChannels> {
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

/// How far (degrees) a glass pixel's Normal pass may lie from its plane's normal when planes are
/// matched from geometry (a pass is filtered at edges; panes meet at far larger angles).
const PLANE_MATCH_DEG: f64 = 10.0;

/// The Cryptomatte mask options: the layer, the glasses, cos θ from an AOV (`cos=`, default
/// `facing`) or from `normal=` and `position=` with the camera, the plane AOV (`plane=`).
fn cryptomatte_options(args: &Args, layer: &str) -> anyhow::Result<CryptomatteOptions> {
    if args.mask_glass.is_empty() {
        bail!("--mask-cryptomatte needs --mask-glass PATTERN=ID for each glass (e.g. 'Glass*=1')");
    }
    let mappings = args
        .mask_glass
        .iter()
        .map(|g| GlassMapping::parse(g))
        .collect::<Result<Vec<_>, _>>()?;
    let spec = args.mask_channels.as_deref().unwrap_or("");
    let pairs = parse_channel_spec(spec, &["cos", "plane", "normal", "position"])?;
    let planes = match (&args.planes, pairs.iter().find(|(k, _)| k == "plane")) {
        (_, Some((_, aov))) => PlaneSource::Aov(aov.clone()),
        (Some(file), None) if args.refl.len() > 1 => {
            let get = |k: &str, default: &str| {
                pairs
                    .iter()
                    .find(|(key, _)| key == k)
                    .map_or(default.to_string(), |(_, v)| v.clone())
            };
            let planes = glassdb_scene::PlanesFile::load(file)?;
            PlaneSource::Geometry {
                normal: get("normal", "Normal"),
                position: get("position", "Position"),
                equations: planes.planes.iter().map(|p| p.equation).collect(),
                max_angle_deg: PLANE_MATCH_DEG,
            }
        }
        _ => PlaneSource::Single,
    };
    let get = |k: &str| {
        pairs
            .iter()
            .find(|(key, _)| key == k)
            .map(|(_, v)| v.clone())
    };
    let cos = match (get("cos"), get("normal"), get("position")) {
        (Some(_), Some(_), _) | (Some(_), _, Some(_)) => {
            bail!("--mask-channels: give cos=AOV, or normal= and position= with --camera, not both")
        }
        (_, Some(normal), Some(position)) => {
            let camera = args.camera.as_ref().context(
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
        weighting: match args.mask_aovs {
            AovsArg::GlassOnly => AovWeighting::GlassOnly,
            AovsArg::EveryMaterial => AovWeighting::EveryMaterial,
        },
    })
}

/// `t.exr` → `t.composite.exr` (PNG passes give a PNG), beside the transmission pass.
fn default_output(trans: &Path) -> PathBuf {
    let stem = trans
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let ext = match trans
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png") => "png",
        _ => "exr",
    };
    trans.with_file_name(format!("{stem}.composite.{ext}"))
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

/// The side each plane shows: from `planes.json` (when given), then each `--side K=SIDE`.
pub(crate) fn plane_sides(
    planes: Option<&Path>,
    side_specs: &[String],
    passes: usize,
) -> anyhow::Result<std::collections::BTreeMap<usize, Side>> {
    let mut sides = match planes {
        Some(p) => glassdb_compose::sides_from_planes_json(p, passes)?,
        None => Default::default(),
    };
    for spec in side_specs {
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

/// The registry at `path`, or the bundled one, with the label outputs and messages name it by.
pub(crate) fn load_registry(path: Option<&Path>) -> anyhow::Result<(Registry, String)> {
    Ok(match path {
        Some(p) => (
            Registry::from_json_file(p).map_err(anyhow::Error::new)?,
            p.display().to_string(),
        ),
        None => (
            glassdb_registry::default_registry()?,
            "the bundled catalog".to_string(),
        ),
    })
}

fn settings_from(args: &Args) -> anyhow::Result<(ComposeSettings, RegistryLuts)> {
    let (registry, label) = load_registry(args.registry.as_deref())?;
    let luts = RegistryLuts::new(&registry);
    let registry_sha256 = registry.content_sha256()?;
    if let Some(id) = args.glass
        && registry.default_table().glass(id).is_none()
    {
        bail!("--glass {id}: {label} has no glass with id {id}");
    }
    let plane_sides = plane_sides(args.planes.as_deref(), &args.side, args.refl.len())?;
    let cryptomatte = match &args.mask_cryptomatte {
        Some(layer) => Some(cryptomatte_options(args, layer)?),
        None => None,
    };
    let mask = MaskReadOptions {
        exr_channels: match (&args.mask_channels, &cryptomatte) {
            (Some(s), None) => parse_mask_channels(s)?,
            _ => ExrMaskChannels::default(),
        },
        cryptomatte,
        binary_glass_id: args.glass,
        max_pixels: args.max_pixels,
        layer: split_layer(&args.mask)
            .1
            .or_else(|| args.mask_layer.clone()),
    };
    let layers = InputLayers {
        trans: split_layer(&args.trans)
            .1
            .or_else(|| args.trans_layer.clone()),
        refl: args
            .refl
            .iter()
            .map(|r| split_layer(r).1.or_else(|| args.refl_layer.clone()))
            .collect(),
    };
    let pass = PassReadOptions {
        layer: args.layer.clone(),
        transfer: match args.input_transfer {
            TransferArg::Srgb => InputTransfer::Srgb,
            TransferArg::Linear => InputTransfer::Linear,
        },
        max_pixels: args.max_pixels,
    };
    let output = OutputOptions {
        exr_data_type: args.data_type.map(|d| match d {
            DataTypeArg::Half => ExrDataType::Half,
            DataTypeArg::Float => ExrDataType::Float,
        }),
        exr_compression: args
            .compression
            .as_deref()
            .map(parse_exr_compression)
            .transpose()?,
        exr_zip_level: args.zip_level,
        png_bits: args.png_bits.as_deref().map(|b| {
            if b == "16" {
                PngBits::Sixteen
            } else {
                PngBits::Eight
            }
        }),
        dither: args.dither == DitherArg::Ordered,
        view: args
            .view
            .as_deref()
            .map(ViewTransform::from_arg)
            .transpose()?,
        keep_channels: args.keep_channels == KeepArg::All,
        output_layer: args.output_layer.clone(),
        provenance: vec![
            (
                "glassdb/version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
            ("glassdb/registry".to_string(), label.clone()),
            ("glassdb/registrySha256".to_string(), registry_sha256),
        ],
    };
    let settings = ComposeSettings {
        pass,
        layers,
        mask,
        outside: match args.outside_pass {
            OutsideArg::Error => OutsidePolicy::Error,
            OutsideArg::NoReflection => OutsidePolicy::NoReflection,
            OutsideArg::Transmission => OutsidePolicy::Transmission,
        },
        plane_sides,
        unknown: match args.unknown {
            UnknownArg::Error => UnknownIds::Error,
            UnknownArg::Passthrough => UnknownIds::Passthrough,
        },
        output,
        registry_label: label,
        // Every input besides the passes and the mask: no output may replace one.
        protected: args
            .registry
            .iter()
            .chain(&args.planes)
            .chain(&args.camera)
            .cloned()
            .chain(
                args.view
                    .as_deref()
                    .filter(|v| *v != "standard")
                    .map(PathBuf::from),
            )
            .collect(),
        input_space: args.input_space,
        max_memory: args.max_memory.unwrap_or_else(default_max_memory),
    };
    Ok((settings, luts))
}

fn print_stats(r: &FrameReport, luts: &RegistryLuts, limit: u64) {
    let colour = &r.colour;
    let Some(lut) = luts.get(colour.table.basis) else {
        return;
    };
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let t = &r.timings;
    outln!(
        "image        {}×{} ({:.2} Mpixel), {} reflection pass(es)",
        r.width,
        r.height,
        f64::from(r.width) * f64::from(r.height) / 1e6,
        r.planes
    );
    if r.windows.data != r.windows.display {
        outln!(
            "windows      data {} in display {}",
            r.windows.data,
            r.windows.display
        );
    }
    outln!(
        "memory       about {} at once, estimated from the headers (limit {})",
        glassdb_compose::memory::format_bytes(r.memory.total),
        glassdb_compose::memory::format_bytes(limit)
    );
    if r.output.kept_channels > 0 {
        outln!(
            "kept         {} other channel(s) of the transmission file",
            r.output.kept_channels
        );
    }
    let table_note = match colour.table.basis {
        ColourBasis::Luminous => " (grey: the same in every space)",
        ColourBasis::PaperRgb => " (the paper's CIE 1931 RGB, not a renderer's space)",
        ColourBasis::Space(_) => "",
    };
    outln!(
        "colour       passes in {}; registry table {}{table_note}",
        colour.space,
        colour.table.basis
    );
    if colour.converted_for_display {
        outln!(
            "             PNG converted from {} to linear Rec.709 (CAT02) for the standard view",
            glassdb_compose::colour::space_label(colour.space.space)
        );
    }
    outln!(
        "decode       {:9.1} ms  (all inputs, in parallel)",
        ms(t.decode)
    );
    outln!("compose      {:9.1} ms", ms(t.compose));
    outln!(
        "encode       {:9.1} ms  ({}, {} bytes)",
        ms(t.encode),
        r.output.encoding,
        r.output.bytes
    );
    outln!(
        "total        {:9.1} ms  ({:.1} Mpixel/s)",
        ms(t.total()),
        r.megapixels_per_second()
    );
    let glass: u64 = r.id_counts.values().sum();
    outln!("glass pixels {glass}");
    for (id, n) in &r.id_counts {
        let known = if lut.contains(*id) {
            ""
        } else {
            "  (not in registry: passed through)"
        };
        outln!("  id {id:5}   {n} pixels{known}");
    }
    match r.cos_range {
        Some((lo, hi)) => outln!(
            "cos θ        {lo:.4} – {hi:.4}  (θ {:.1}° – {:.1}°)",
            hi.clamp(-1.0, 1.0).acos().to_degrees(),
            lo.clamp(-1.0, 1.0).acos().to_degrees()
        ),
        None => outln!("cos θ        (no glass pixels)"),
    }
    outln!(
        "fine-table interpolation error (16-bit/float masks): {:.2e}",
        lut.fine_table_error
    );
}

fn report_nonfinite(r: &FrameReport, label: &str) {
    if r.output.half_overflow > 0 {
        eprintln!(
            "warning: {label}{} output samples exceed the half-float range (±65504) and were stored as infinite; write float (--data-type float) to keep them",
            r.output.half_overflow
        );
    }
    if r.outside_pixels > 0 {
        eprintln!(
            "warning: {label}{} glass pixels lie outside their plane's reflection pass (composited as --outside-pass says)",
            r.outside_pixels
        );
    }
    let c = &r.counts;
    if c.nonfinite_output > 0 {
        eprintln!(
            "warning: {label}{} output samples are NaN or infinite ({} from the transmission pass, {} from reflection passes); they are kept, not hidden",
            c.nonfinite_output, c.nonfinite_trans, c.nonfinite_refl
        );
    }
}

/// One `--refl FILE.exr` (no layer named) whose file holds the passes of several planes as
/// layers or parts `plane0`, `plane1`, … becomes one `--refl FILE.exr:planeK` per plane. In a
/// sequence the first frame whose file can be read decides (every frame of a shot has the same
/// planes; a frame without a layer then fails naming it).
fn expand_plane_layers(args: &mut Args) -> anyhow::Result<()> {
    let [refl] = args.refl.as_slice() else {
        return Ok(());
    };
    if split_layer(refl).1.is_some() || args.refl_layer.is_some() {
        return Ok(());
    }
    let candidates: Vec<PathBuf> = match &args.frames {
        Some(spec) if glassdb_io::is_frame_pattern(refl) => sequence::parse_frames(spec)?
            .into_iter()
            .filter_map(|f| sequence::expand(refl, f).ok())
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
    match glassdb_compose::io::plane_layers_of(first, args.max_pixels) {
        Ok(Some(layers)) => {
            let file = refl.to_string_lossy().into_owned();
            args.refl = layers
                .iter()
                .map(|l| PathBuf::from(format!("{file}:{l}")))
                .collect();
            Ok(())
        }
        Err(e @ glassdb_compose::ComposeError::PlaneLayers { .. }) => Err(e.into()),
        Ok(None) | Err(_) => Ok(()),
    }
}

pub fn run(mut args: Args) -> anyhow::Result<ExitCode> {
    expand_plane_layers(&mut args)?;
    let (settings, luts) = settings_from(&args)?;
    let trans = split_layer(&args.trans).0;
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&trans));
    let job = ComposeJob {
        refl: args.refl.iter().map(|r| split_layer(r).0).collect(),
        trans,
        mask: split_layer(&args.mask).0,
        output,
    };

    let Some(frames_spec) = &args.frames else {
        let spinner = Spinner::on_terminal("compose");
        let report = compose_frame_with_progress(&job, &settings, &luts, &spinner)?;
        spinner.finish();
        report_nonfinite(&report, "");
        if args.stats {
            print_stats(&report, &luts, settings.max_memory);
        }
        outln!(
            "wrote {} ({}×{}, {})",
            report.output.path.display(),
            report.width,
            report.height,
            report.output.encoding
        );
        return Ok(ExitCode::SUCCESS);
    };

    let frames = sequence::parse_frames(frames_spec)?;
    let bar = if std::io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(frames.len() as u64);
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{bar:40} {pos}/{len} frames, {elapsed} elapsed, ETA {eta}",
        ) {
            bar.set_style(style);
        }
        Some(bar)
    } else {
        None
    };
    let on_done = |o: &FrameOutcome| {
        let line = match &o.result {
            Ok(FrameDone::Composed { report, replaced }) => {
                report_nonfinite(report, &format!("frame {}: ", o.frame));
                replaced
                    .as_ref()
                    .map(|why| format!("frame {}: composited again: {why}", o.frame))
            }
            Ok(FrameDone::Skipped) => None,
            Err(e) => Some(format!(
                "frame {}: error: {}",
                o.frame,
                glassdb_io::ErrorChain(e)
            )),
        };
        match (&bar, line) {
            (Some(b), Some(l)) => b.println(l),
            (None, Some(l)) => eprintln!("{l}"),
            _ => {}
        }
        if let Some(b) = &bar {
            b.inc(1);
        }
    };
    if let Some(report) = &args.report {
        // The report is an output like the frames: it may not replace an input.
        glassdb_io::refuse_input_as_output(
            report,
            settings
                .protected
                .iter()
                .map(PathBuf::as_path)
                .chain(job.inputs()),
        )?;
    }
    let options = SequenceOptions {
        skip_existing: args.skip_existing,
    };
    let outcomes = sequence::compose_sequence(&job, &frames, &settings, &luts, options, &on_done)?;
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    if let Some(report) = &args.report {
        FramesReport::from_outcomes(&outcomes).write(report)?;
    }
    let failed: Vec<u32> = outcomes
        .iter()
        .filter(|o| o.result.is_err())
        .map(|o| o.frame)
        .collect();
    let done: Vec<&FrameReport> = outcomes.iter().filter_map(FrameOutcome::report).collect();
    let skipped = outcomes
        .iter()
        .filter(|o| matches!(o.result, Ok(FrameDone::Skipped)))
        .count();
    if args.stats {
        for o in &outcomes {
            if let Some(r) = o.report() {
                outln!("--- frame {}", o.frame);
                print_stats(r, &luts, settings.max_memory);
            }
        }
    }
    if let (Some(first), Some(last)) = (done.first(), done.last()) {
        outln!(
            "wrote {} frame(s): {} … {}",
            done.len(),
            first.output.path.display(),
            last.output.path.display()
        );
    }
    if skipped > 0 {
        outln!("skipped {skipped} frame(s) whose output is complete");
    }
    Ok(crate::cmd::frames_exit(&failed, frames.len()))
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
