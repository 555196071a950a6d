//! Frames: `compose` over arrays (the compositor's `compose_in_memory`, the kernel `compose`
//! runs), `read_passes` (glassdb-pass, as `compose` reads its passes) and `cryptomatte_mask`
//! (glassdb-mask's Cryptomatte reader, as `compose --mask-cryptomatte` builds its mask).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glassdb_colour::RgbSpace;
use glassdb_compose::colour::SpaceSource;
use glassdb_compose::{
    ComposeError, ComposeSettings, LightGroup, MemoryFrame, MemoryGroup, MemoryLabels,
    OutsidePolicy, UnknownIds, compose_in_memory, compose_light_groups_in_memory,
};
use glassdb_image::PixelWindow;
use glassdb_mask::{
    AovWeighting, CosSource, CryptomatteOptions, ExrMaskChannels, FloatMaskChannels, GlassMapping,
    GlassNames, MaskImage, MaskReadOptions, PlaneSource,
};
use glassdb_pass::PassReadOptions;
use glassdb_side::Side;
use numpy::{
    PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2, PyReadonlyArray3,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{OrRaise, choose, invalid};
use crate::registry::PyRegistry;

/// `compose(unknown=…)`: what mask ids without a registry entry do.
const UNKNOWN_IDS: [(&str, UnknownIds); 2] = [
    ("error", UnknownIds::Error),
    ("passthrough", UnknownIds::Passthrough),
];

/// `cryptomatte_mask(aovs=…)`: how the cos θ and plane AOVs were written.
const AOV_WEIGHTINGS: [(&str, AovWeighting); 2] = [
    ("glass-only", AovWeighting::GlassOnly),
    ("every-material", AovWeighting::EveryMaterial),
];

/// A pass as `compose` reads it: linear, premultiplied RGB (and alpha) over its data window.
#[pyclass(module = "glassdb", name = "Pass", frozen)]
pub struct PyPass {
    /// float32 (H, W, 3), or (H, W, 4) with alpha.
    #[pyo3(get)]
    pixels: Py<PyArray3<f32>>,
    /// The EXR layer read (`""`: bare R, G, B; `None` for a PNG).
    #[pyo3(get)]
    layer: Option<String>,
    /// The linear RGB space its header names (`srgb`, `acescg`, …); `None` when untagged
    /// (`compose` then takes linear Rec.709).
    #[pyo3(get)]
    space: Option<String>,
    /// Its data window: (x, y, width, height).
    #[pyo3(get)]
    data_window: (i32, i32, usize, usize),
    /// Its display window: (x, y, width, height).
    #[pyo3(get)]
    display_window: (i32, i32, usize, usize),
}

#[pymethods]
impl PyPass {
    fn __repr__(&self) -> String {
        let (_, _, w, h) = self.data_window;
        format!(
            "<glassdb.Pass {w}×{h} layer {:?} space {}>",
            self.layer.as_deref().unwrap_or(""),
            self.space.as_deref().unwrap_or("untagged")
        )
    }
}

fn window(w: PixelWindow) -> (i32, i32, usize, usize) {
    (w.x, w.y, w.width, w.height)
}

/// One pass decoded: its interleaved pixels, layer, space and windows.
struct ReadPass {
    samples: Vec<f32>,
    channels: usize,
    layer: Option<String>,
    space: Option<String>,
    windows: glassdb_image::ImageWindows,
}

/// The passes of `path`: the one `layer`, else its plane layers (`plane0`, `plane1`, …), else
/// its default RGB layer, each as `compose` reads it.
fn read_file_passes(path: &Path, layer: Option<String>) -> anyhow::Result<Vec<ReadPass>> {
    let defaults = PassReadOptions::default();
    let layers: Vec<Option<String>> = match layer {
        Some(l) => vec![Some(l)],
        None => match glassdb_pass::plane_layers_of(path, defaults.max_pixels)? {
            Some(planes) => planes.into_iter().map(Some).collect(),
            None => vec![None],
        },
    };
    let mut out = Vec::with_capacity(layers.len());
    for layer in layers {
        let opts = PassReadOptions {
            layer,
            ..PassReadOptions::default()
        };
        let header = glassdb_pass::read_pass_header(path, &opts)?;
        let space = glassdb_compose::colour::pass_space(path, &header.colour, None)?;
        let pass = glassdb_pass::read_pass(path, &opts)?;
        let image = &pass.image;
        let samples = glassdb_compose::interleave(&image.rgb, image.alpha.as_deref());
        out.push(ReadPass {
            channels: if image.alpha.is_some() { 4 } else { 3 },
            samples,
            layer: match &pass.source {
                glassdb_pass::PassSource::Exr { layer, .. } => Some(layer.clone()),
                glassdb_pass::PassSource::Png { .. } => None,
            },
            space: (space.source != SpaceSource::Untagged).then(|| space.space.name().to_string()),
            windows: pass.windows,
        });
    }
    Ok(out)
}

/// Reads the passes of an EXR or PNG file as `compose` reads them: with `layer`, that RGB
/// layer; without, each plane layer (`plane0`, `plane1`, …: one per reflection plane, in
/// order) of a file that has them, else its default RGB layer (the only one, bare R, G, B, or
/// the one named `…Combined`). Returns a list of `Pass`.
#[pyfunction]
#[pyo3(signature = (path, layer=None))]
pub fn read_passes<'py>(
    py: Python<'py>,
    path: PathBuf,
    layer: Option<String>,
) -> PyResult<Vec<PyPass>> {
    let read = py.detach(|| read_file_passes(&path, layer)).or_raise(py)?;
    read.into_iter()
        .map(|p| {
            let (w, h) = (p.windows.data.width, p.windows.data.height);
            let pixels = PyArray1::from_vec(py, p.samples).reshape([h, w, p.channels])?;
            Ok(PyPass {
                pixels: pixels.unbind(),
                layer: p.layer,
                space: p.space,
                data_window: window(p.windows.data),
                display_window: window(p.windows.display),
            })
        })
        .collect()
}

/// A mask argument: the packed 8-bit mask or float channels.
enum MaskArg<'py> {
    Packed(PyReadonlyArray3<'py, u8>),
    Channels(Bound<'py, PyDict>),
}

fn mask_arg<'py>(py: Python<'py>, mask: &Bound<'py, PyAny>) -> PyResult<MaskArg<'py>> {
    if let Ok(dict) = mask.cast::<PyDict>() {
        return Ok(MaskArg::Channels(dict.clone()));
    }
    mask.extract::<PyReadonlyArray3<'py, u8>>()
        .map(MaskArg::Packed)
        .map_err(|_| {
            invalid(
                py,
                "mask: a uint8 (H, W, 3) packed mask (R plane, G id, B cos θ code) or a dict of float32 (H, W) arrays `id`, `cos` and optionally `plane`, `coverage`".into(),
            )
        })
}

/// A float32 (H, W) array of a mask dict, as a contiguous slice copy-free when it is one.
fn mask_channel<'py>(
    py: Python<'py>,
    dict: &Bound<'py, PyDict>,
    key: &str,
) -> PyResult<Option<PyReadonlyArray2<'py, f32>>> {
    match dict.get_item(key)? {
        None => Ok(None),
        Some(v) => v
            .extract::<PyReadonlyArray2<'py, f32>>()
            .map(Some)
            .map_err(|_| {
                invalid(
                    py,
                    format!("mask[{key:?}]: a float32 array of shape (H, W)"),
                )
            }),
    }
}

/// The samples of an array, borrowed when it is C-contiguous, else copied in row-major order.
fn samples<'a, T: numpy::Element + Copy, D: numpy::ndarray::Dimension>(
    view: &'a numpy::PyReadonlyArray<'_, T, D>,
) -> std::borrow::Cow<'a, [T]> {
    match view.as_slice() {
        Ok(s) => std::borrow::Cow::Borrowed(s),
        Err(_) => std::borrow::Cow::Owned(view.as_array().iter().copied().collect()),
    }
}

/// The mask of a `compose` call, checked against the frame's (height, width).
fn decode_mask(py: Python<'_>, arg: &MaskArg<'_>, hw: (usize, usize)) -> PyResult<MaskImage> {
    let (h, w) = hw;
    let shape_err = |shape: &[usize]| {
        invalid(
            py,
            format!("mask: shape {shape:?}, but the transmission pass is {h} × {w} pixels"),
        )
    };
    match arg {
        MaskArg::Packed(a) => {
            let shape = a.shape().to_vec();
            if shape[0] != h || shape[1] != w || !(3..=4).contains(&shape[2]) {
                return Err(shape_err(&shape));
            }
            let s = samples(a);
            Ok(py.detach(|| MaskImage::from_packed8(w as u32, h as u32, shape[2], &s)))
        }
        MaskArg::Channels(d) => {
            let id = mask_channel(py, d, "id")?
                .ok_or_else(|| invalid(py, "mask: the dict has no `id` array".into()))?;
            let cos = mask_channel(py, d, "cos")?
                .ok_or_else(|| invalid(py, "mask: the dict has no `cos` array".into()))?;
            let plane = mask_channel(py, d, "plane")?;
            let coverage = mask_channel(py, d, "coverage")?;
            for a in [Some(&id), Some(&cos), plane.as_ref(), coverage.as_ref()]
                .into_iter()
                .flatten()
            {
                if a.shape() != [h, w] {
                    return Err(shape_err(a.shape()));
                }
            }
            let (id, cos) = (samples(&id), samples(&cos).into_owned());
            let plane = plane.as_ref().map(samples);
            let coverage = coverage.as_ref().map(|c| samples(c).into_owned());
            let names = ExrMaskChannels {
                id: "id".into(),
                cos_theta: "cos".into(),
                plane: "plane".into(),
                coverage: "coverage".into(),
            };
            let channels = FloatMaskChannels {
                id: &id,
                cos_theta: cos,
                plane: plane.as_deref(),
                coverage,
            };
            py.detach(|| {
                glassdb_mask::mask_from_floats(Path::new("mask"), &names, (w, h), channels)
            })
            .or_raise(py)
        }
    }
}

/// A pass array's interleaved samples (borrowed when C-contiguous), channels and size.
struct PassSamples<'a> {
    samples: std::borrow::Cow<'a, [f32]>,
    channels: usize,
    /// (height, width).
    hw: (usize, usize),
}

/// A pass array's samples, checked to be (H, W, 3|4) of the frame's size.
fn pass_samples<'a>(
    py: Python<'_>,
    what: &str,
    a: &'a PyReadonlyArray3<'_, f32>,
    hw: Option<(usize, usize)>,
) -> PyResult<PassSamples<'a>> {
    let shape = a.shape();
    let (h, w, c) = (shape[0], shape[1], shape[2]);
    if !(3..=4).contains(&c) || hw.is_some_and(|hw| hw != (h, w)) {
        let frame = hw.map_or(String::new(), |(fh, fw)| {
            format!(" for a {fh} × {fw} transmission pass")
        });
        return Err(invalid(
            py,
            format!("{what}: shape {shape:?}; expected float32 (H, W, 3) or (H, W, 4){frame}"),
        ));
    }
    Ok(PassSamples {
        samples: samples(a),
        channels: c,
        hw: (h, w),
    })
}

/// The bundled registry, loaded once per process.
fn bundled(py: Python<'_>) -> PyResult<&'static PyRegistry> {
    static BUNDLED: std::sync::OnceLock<PyRegistry> = std::sync::OnceLock::new();
    if let Some(r) = BUNDLED.get() {
        return Ok(r);
    }
    let (registry, label) = glassdb::cmd::compose::load_registry(None).or_raise(py)?;
    Ok(BUNDLED.get_or_init(|| PyRegistry::new(registry, label)))
}

/// Each plane's side: planes.json's, then `sides` over them.
fn plane_sides(
    py: Python<'_>,
    planes: Option<PathBuf>,
    sides: Option<BTreeMap<usize, String>>,
    passes: usize,
) -> PyResult<BTreeMap<usize, Side>> {
    let mut out = match planes {
        Some(p) => glassdb_scene::sides_from_planes_json(&p, passes).or_raise(py)?,
        None => BTreeMap::new(),
    };
    for (k, side) in sides.unwrap_or_default() {
        let side = side
            .parse::<Side>()
            .map_err(|e| invalid(py, format!("sides[{k}]: {e}")))?;
        if k >= passes {
            return Err(invalid(
                py,
                format!(
                    "sides[{k}]: plane {k} has no reflection pass ({passes} given; planes count from 0)"
                ),
            ));
        }
        out.insert(k, side);
    }
    Ok(out)
}

/// The reflection passes of a `compose` call: one array or a list of them.
fn refl_arrays<'py>(
    py: Python<'py>,
    refl: &Bound<'py, PyAny>,
) -> PyResult<Vec<PyReadonlyArray3<'py, f32>>> {
    if refl.is_instance_of::<PyList>() {
        return refl.extract();
    }
    Ok(vec![refl.extract().map_err(|_| {
        invalid(
            py,
            "refl: a float32 (H, W, 3) array or a list of them".into(),
        )
    })?])
}

/// The light groups named: a list of names or one comma-separated string (`"sun,warm"`).
fn group_names(py: Python<'_>, groups: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(text) = groups.extract::<String>() {
        return Ok(text.split(',').map(|g| g.trim().to_string()).collect());
    }
    groups.extract().map_err(|_| {
        invalid(
            py,
            "light_groups: a list of group names or a comma-separated string (\"sun,warm\")".into(),
        )
    })
}

/// One group's arrays of each dict `{group: array}` (`what` names the pass in messages), in
/// the order of `names`, refused as `compose --light-groups` refuses a pass's layers: a group
/// of the dict not composited, or a group without an array.
fn group_arrays<'py>(
    py: Python<'py>,
    what: &str,
    dict: &Bound<'py, PyAny>,
    names: &[String],
) -> PyResult<Vec<PyReadonlyArray3<'py, f32>>> {
    let dict = dict.cast::<PyDict>().map_err(|_| {
        invalid(
            py,
            format!("{what}: with light_groups, a dict {{group: float32 (H, W, 3) array}}"),
        )
    })?;
    let found: Vec<String> = dict.keys().extract()?;
    let extra: Vec<String> = found
        .iter()
        .filter(|g| !names.contains(g))
        .cloned()
        .collect();
    if !extra.is_empty() {
        return Err(ComposeError::GroupWithoutTable {
            path: what.into(),
            groups: extra,
            composited: names.to_vec(),
        })
        .or_raise(py);
    }
    names
        .iter()
        .map(|group| match dict.get_item(group)? {
            Some(a) => a.extract().map_err(|_| {
                invalid(
                    py,
                    format!("{what}[{group:?}]: a float32 (H, W, 3) or (H, W, 4) array"),
                )
            }),
            None => Err(ComposeError::GroupWithoutLayer {
                path: what.into(),
                group: group.clone(),
                found: found.clone(),
            })
            .or_raise(py),
        })
        .collect()
}

/// Composites a frame from arrays, bit for bit as `compose` writes it to a float EXR from the
/// same passes and mask: `trans` float32 (H, W, 3) or (H, W, 4) (alpha kept), linear and
/// premultiplied; `refl` one such array or a list, one per glass plane; `mask` the packed
/// uint8 (H, W, 3) mask or a dict of float32 (H, W) arrays `id`, `cos`, and optionally `plane`,
/// `coverage` (as `cryptomatte_mask` returns); `registry` a `Registry` (default: the bundled
/// one); `planes` a planes.json giving each plane's side, `sides` {plane: "front"|"back"} over
/// it; `space` the passes' linear RGB space (default: untagged, linear Rec.709), which chooses
/// the registry's table; `unknown` "error" or "passthrough" for ids the registry lacks.
/// `surfaces` (`compose --surfaces N`): the pane groups of a unit given their own reflection
/// pass; arrays carry no pane-group passes, so a unit (an insulated glass id of the registry)
/// in the mask is refused, naming its plane and first missing group, unless `surfaces=1`
/// composites its plane's pass with every pane group's share (no double image).
/// `light_groups` (a list of names, or "sun,warm"): the passes split by light, as
/// `compose --light-groups`: `trans` a dict {group: array}, `refl` one such dict or a list, one
/// per plane; each group composited with the table of the registry's light of its name and the
/// groups summed in the order named, Σ_g (trans_g·t_g + refl_g·r_g); the alpha is the first
/// group's (when its array has one).
/// Returns a new float32 (H, W, C) array; the GIL is released while it composites.
#[pyfunction]
#[pyo3(signature = (trans, refl, mask, registry=None, planes=None, space=None, sides=None,
    unknown="error", light_groups=None, surfaces=None))]
#[allow(clippy::too_many_arguments)]
pub fn compose<'py>(
    py: Python<'py>,
    trans: &Bound<'py, PyAny>,
    refl: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
    registry: Option<Bound<'py, PyRegistry>>,
    planes: Option<PathBuf>,
    space: Option<&str>,
    sides: Option<BTreeMap<usize, String>>,
    unknown: &str,
    light_groups: Option<&Bound<'py, PyAny>>,
    surfaces: Option<usize>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let names = light_groups.map(|g| group_names(py, g)).transpose()?;
    let registry: &PyRegistry = match &registry {
        Some(r) => r.get(),
        None => bundled(py)?,
    };
    // Each light group's tables (the registry's light of its name), refused as the command
    // refuses them, before its passes.
    let groups = names
        .as_ref()
        .map(|n| LightGroup::from_registry(&registry.registry, n, &registry.label))
        .transpose()
        .or_raise(py)?;
    // Each group's transmission pass and reflection passes (one group: the frame's own).
    let (trans, refl): (
        Vec<PyReadonlyArray3<'py, f32>>,
        Vec<Vec<PyReadonlyArray3<'py, f32>>>,
    ) = match &names {
        None => (
            vec![trans.extract().map_err(|_| {
                invalid(py, "trans: a float32 (H, W, 3) or (H, W, 4) array".into())
            })?],
            vec![refl_arrays(py, refl)?],
        ),
        Some(names) => {
            // the transmission pass first, as the command checks its passes
            let trans = group_arrays(py, "trans", trans, names)?;
            let dicts: Vec<Bound<'py, PyAny>> = if refl.is_instance_of::<PyList>() {
                refl.extract()?
            } else {
                vec![refl.clone()]
            };
            let mut per_plane = Vec::with_capacity(dicts.len());
            for (k, d) in dicts.iter().enumerate() {
                per_plane.push(group_arrays(py, &format!("refl[{k}]"), d, names)?);
            }
            // per group, its pass of each plane
            let refl = (0..names.len())
                .map(|g| per_plane.iter().map(|p| p[g].clone()).collect())
                .collect();
            (trans, refl)
        }
    };
    // how messages name a group's pass: `trans`, `refl[0]`; `trans["sun"]` with groups
    let of_group = |what: String, g: usize| match &names {
        Some(names) => format!("{what}[{:?}]", names[g]),
        None => what,
    };
    let first = pass_samples(py, &of_group("trans".into(), 0), &trans[0], None)?;
    let (channels, hw) = (first.channels, first.hw);
    let mut trans_samples = vec![first];
    for (g, t) in trans.iter().enumerate().skip(1) {
        trans_samples.push(pass_samples(py, &of_group("trans".into(), g), t, Some(hw))?);
    }
    let mut refl_samples: Vec<Vec<PassSamples<'_>>> = Vec::with_capacity(refl.len());
    for (g, group) in refl.iter().enumerate() {
        let mut planes = Vec::with_capacity(group.len());
        for (k, r) in group.iter().enumerate() {
            let what = of_group(format!("refl[{k}]"), g);
            planes.push(pass_samples(py, &what, r, Some(hw))?);
        }
        refl_samples.push(planes);
    }
    let mask = decode_mask(py, &mask_arg(py, mask)?, hw)?;
    let space = space
        .map(|s| s.parse::<RgbSpace>())
        .transpose()
        .map_err(|e| invalid(py, format!("space: {e}")))?;
    let unknown = choose(py, "unknown", unknown, &UNKNOWN_IDS)?;
    let mut settings = ComposeSettings::default();
    settings.decode.unknown = unknown;
    settings.decode.outside = OutsidePolicy::Error;
    settings.decode.registry_label = registry.label.clone();
    settings.decode.max_groups = surfaces
        .map(|n| {
            std::num::NonZeroUsize::new(n)
                .ok_or_else(|| invalid(py, "surfaces: at least 1 (the unit's front group)".into()))
        })
        .transpose()?;
    let passes = refl_samples.first().map_or(0, Vec::len);
    settings.plane_sides = plane_sides(py, planes, sides, passes)?;
    let labels = MemoryLabels {
        trans: "trans".into(),
        mask: "mask".into(),
    };
    let composite = py.detach(|| {
        let deinterleave =
            |p: &PassSamples<'_>| glassdb_compose::planes_from_interleaved(&p.samples, p.channels);
        // the first group's alpha (the frame's, without groups) is the composite's
        let mut alpha = None;
        let composited = match &groups {
            None => {
                let (trans, a) = deinterleave(&trans_samples[0]);
                alpha = a;
                let frame = MemoryFrame {
                    trans,
                    refl: refl_samples[0].iter().map(|p| deinterleave(p).0).collect(),
                    mask,
                    space,
                };
                compose_in_memory(frame, &settings, &registry.luts, &labels)
            }
            Some(groups) => {
                // each group's planes made when its turn comes
                let each = groups
                    .iter()
                    .zip(trans_samples.iter().zip(&refl_samples))
                    .enumerate()
                    .map(|(g, (group, (trans, refl)))| {
                        let (trans, a) = deinterleave(trans);
                        if g == 0 {
                            alpha = a;
                        }
                        MemoryGroup {
                            luts: &group.luts,
                            trans,
                            refl: refl.iter().map(|p| deinterleave(p).0).collect(),
                        }
                    });
                compose_light_groups_in_memory(each, &mask, space, &settings, &labels)
            }
        };
        composited.map(|c| glassdb_compose::interleave(&c.rgb, alpha.as_deref()))
    });
    let out = composite.or_raise(py)?;
    PyArray1::from_vec(py, out).reshape([hw.0, hw.1, channels])
}

/// The mask `compose --mask-cryptomatte` builds from a render's Cryptomatte: `glass` maps name
/// patterns (globs over the manifest's material or object names) to registry ids, the first
/// match winning; cos θ from the AOV `cos` (default `facing`); planes from the AOV `plane`
/// (default: every glass pixel on plane 0); `layer` the Cryptomatte layer (default the only
/// one, or `…CryptoMaterial`); `aovs` "glass-only" or "every-material". Returns a dict of
/// float32 (H, W) arrays `id`, `cos`, `plane` (and `coverage` where the mask has it), which
/// `compose` takes as its `mask`.
#[pyfunction]
#[pyo3(signature = (path, glass, cos="facing", plane=None, layer=None, aovs="glass-only"))]
pub fn cryptomatte_mask<'py>(
    py: Python<'py>,
    path: PathBuf,
    glass: Vec<(String, u16)>,
    cos: &str,
    plane: Option<String>,
    layer: Option<String>,
    aovs: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let mappings = glass
        .iter()
        .map(|(pattern, id)| GlassMapping::parse(&format!("{pattern}={id}")))
        .collect::<Result<Vec<_>, _>>()
        .or_raise(py)?;
    let weighting = choose(py, "aovs", aovs, &AOV_WEIGHTINGS)?;
    let opts = MaskReadOptions {
        cryptomatte: Some(CryptomatteOptions {
            layer,
            glass: GlassNames::new(&mappings).or_raise(py)?,
            cos: CosSource::Aov {
                channel: cos.to_string(),
            },
            planes: plane.map_or(PlaneSource::Single, PlaneSource::Aov),
            weighting,
        }),
        ..MaskReadOptions::default()
    };
    let mask = py
        .detach(|| glassdb_mask::read_mask(&path, &opts))
        .or_raise(py)?;
    mask_dict(py, &mask)
}

/// A mask as the dict of float32 (H, W) arrays `compose` takes.
fn mask_dict<'py>(py: Python<'py>, mask: &MaskImage) -> PyResult<Bound<'py, PyDict>> {
    let (h, w) = (mask.height as usize, mask.width as usize);
    let plane2 = |v: Vec<f32>| -> PyResult<Bound<'py, PyArray2<f32>>> {
        PyArray1::from_vec(py, v).reshape([h, w])
    };
    let dict = PyDict::new(py);
    dict.set_item(
        "id",
        plane2(mask.id.iter().map(|&v| f32::from(v)).collect())?,
    )?;
    let cos = (0..mask.pixel_count())
        .map(|i| mask.cos_theta_at(i) as f32)
        .collect();
    dict.set_item("cos", plane2(cos)?)?;
    dict.set_item(
        "plane",
        plane2(mask.plane.iter().map(|&v| f32::from(v)).collect())?,
    )?;
    if let Some(c) = &mask.coverage {
        dict.set_item("coverage", plane2(c.clone())?)?;
    }
    Ok(dict)
}
