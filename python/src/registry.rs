//! `glassdb.Registry`: a registry loaded (`Registry.load`, the bundled one without a path) or
//! built from a catalog (`Registry.build`, the command's own build), its glasses, their r and t
//! at any angle, and the compositor's tables of it, built once per colour basis and kept for
//! every `compose` call.

use std::path::PathBuf;

use clap::Parser;
use glassdb_compose::colour::RegistryLuts;
use glassdb_registry::{ColourBasis, GlassRecord, Registry, RegistryTable};
use glassdb_side::Side;
use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyAny;

use crate::errors::{OrRaise, invalid};

/// `glassdb registry build`'s arguments, parsed as the command parses them.
#[derive(Parser)]
#[command(name = "glassdb registry build")]
struct BuildCommand {
    #[command(flatten)]
    args: glassdb::cmd::registry::BuildArgs,
}

/// A glass registry: one table of glasses per colour basis (`spaces()`), the first the default.
#[pyclass(module = "glassdb", name = "Registry", frozen)]
pub struct PyRegistry {
    pub(crate) registry: Registry,
    /// The compositor's tables, each built the first time a frame needs it.
    pub(crate) luts: RegistryLuts,
    /// How messages name it: its path, or the bundled catalog.
    pub(crate) label: String,
}

impl PyRegistry {
    pub(crate) fn new(registry: Registry, label: String) -> PyRegistry {
        let luts = RegistryLuts::new(&registry);
        PyRegistry {
            registry,
            luts,
            label,
        }
    }

    /// The table of `space` (a basis name), or the default one.
    fn table(&self, py: Python<'_>, space: Option<&str>) -> PyResult<&RegistryTable> {
        let basis = space
            .map(|s| s.parse::<ColourBasis>())
            .transpose()
            .map_err(|e| invalid(py, format!("space: {e}")))?;
        self.registry
            .table_or_error(basis, &self.label)
            .or_raise(py)
    }

    fn record(&self, py: Python<'_>, id: u16, space: Option<&str>) -> PyResult<&GlassRecord> {
        let table = self.table(py, space)?;
        table.glass(id).ok_or_else(|| {
            let ids: Vec<String> = table.glasses.iter().map(|g| g.id.to_string()).collect();
            invalid(
                py,
                format!(
                    "{} has no glass with id {id} in its {} table (ids: {})",
                    self.label,
                    table.basis(),
                    ids.join(", ")
                ),
            )
        })
    }
}

fn parse_side(py: Python<'_>, side: &str) -> PyResult<Side> {
    side.parse::<Side>()
        .map_err(|e| invalid(py, format!("side: {e}")))
}

/// A light of `Registry.build`: `"NAME=ILLUMINANT"`, or a (name, illuminant or SPD path)
/// pair, as the `--light` argument.
fn light_arg(py: Python<'_>, light: &Bound<'_, PyAny>) -> PyResult<std::ffi::OsString> {
    if let Ok(text) = light.extract::<String>() {
        return Ok(text.into());
    }
    let (name, spec): (String, PathBuf) = light.extract().map_err(|_| {
        invalid(
            py,
            "lights: each a \"NAME=ILLUMINANT\" string or a (name, illuminant or SPD path) pair"
                .into(),
        )
    })?;
    let mut arg = std::ffi::OsString::from(format!("{name}="));
    arg.push(spec.as_os_str());
    Ok(arg)
}

/// Python's `json.loads` of `text`.
fn json_loads<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

#[pymethods]
impl PyRegistry {
    /// Loads a registry JSON (`glassdb registry build`'s output), validated; without a path,
    /// the bundled registry (data/registry.json, built from data/catalog.toml).
    #[staticmethod]
    #[pyo3(signature = (path=None))]
    fn load(py: Python<'_>, path: Option<PathBuf>) -> PyResult<PyRegistry> {
        let loaded = py.detach(|| glassdb::cmd::compose::load_registry(path.as_deref()));
        let (registry, label) = loaded.or_raise(py)?;
        Ok(PyRegistry::new(registry, label))
    }

    /// Builds a registry from a catalog (catalog.toml) as `glassdb registry build` does: one
    /// table per space in `spaces` (the first the default; default `["srgb"]`), the spectral
    /// `method` (colorimetric, paper or luminous) with its observer and illuminant (default
    /// D65: a name or an SPD CSV), curves fitted within `tol` up to degree `max_degree`;
    /// `masks`: only the ids they use. `lights`: one table per (space, light), as `--light`:
    /// each a `"NAME=ILLUMINANT"` string or a (name, illuminant name or SPD path) pair, the
    /// first the default (not with `illuminant`); `white_balance` as `--white-balance`
    /// (`"light"`, or an illuminant name the camera is balanced to).
    #[staticmethod]
    #[pyo3(signature = (catalog, spaces=None, *, method="colorimetric", observer="cie1931",
        illuminant=None, lights=None, white_balance=None, extrapolate=false, tol=None,
        max_degree=12, per_channel=false, masks=None))]
    #[allow(clippy::too_many_arguments)]
    fn build(
        py: Python<'_>,
        catalog: PathBuf,
        spaces: Option<Vec<String>>,
        method: &str,
        observer: &str,
        illuminant: Option<String>,
        lights: Option<Vec<Bound<'_, PyAny>>>,
        white_balance: Option<String>,
        extrapolate: bool,
        tol: Option<f64>,
        max_degree: u32,
        per_channel: bool,
        masks: Option<Vec<PathBuf>>,
    ) -> PyResult<PyRegistry> {
        let mut argv: Vec<std::ffi::OsString> = vec!["build".into(), catalog.clone().into()];
        // The output is not written: the registry is returned.
        argv.extend(["--output".into(), "registry.json".into()]);
        for (flag, value) in [("--method", method), ("--observer", observer)] {
            argv.extend([flag.into(), value.into()]);
        }
        if let Some(illuminant) = illuminant {
            argv.extend(["--illuminant".into(), illuminant.into()]);
        }
        for light in lights.unwrap_or_default() {
            argv.extend(["--light".into(), light_arg(py, &light)?]);
        }
        if let Some(white) = white_balance {
            argv.extend(["--white-balance".into(), white.into()]);
        }
        if let Some(spaces) = spaces {
            argv.extend(["--space".into(), spaces.join(",").into()]);
        }
        if let Some(tol) = tol {
            argv.extend(["--tol".into(), tol.to_string().into()]);
        }
        argv.extend(["--max-degree".into(), max_degree.to_string().into()]);
        if extrapolate {
            argv.push("--extrapolate".into());
        }
        if per_channel {
            argv.push("--per-channel".into());
        }
        for m in masks.unwrap_or_default() {
            argv.extend(["--mask".into(), m.into()]);
        }
        let parsed = BuildCommand::try_parse_from(argv)
            .map_err(|e| invalid(py, crate::commands::clap_message(&e)))?;
        let built = py.detach(|| glassdb::cmd::registry::build_registry(&parsed.args));
        Ok(PyRegistry::new(
            built.or_raise(py)?,
            catalog.display().to_string(),
        ))
    }

    /// The colour bases of its tables (`srgb`, `acescg`, `paper-rgb`, `luminous`, …), the
    /// default first.
    fn spaces(&self) -> Vec<String> {
        self.registry
            .bases()
            .iter()
            .map(ToString::to_string)
            .collect()
    }

    /// The glass ids of a table (`space`: a basis of `spaces()`; default the first), sorted.
    #[pyo3(signature = (space=None))]
    fn ids(&self, py: Python<'_>, space: Option<&str>) -> PyResult<Vec<u16>> {
        Ok(self
            .table(py, space)?
            .glasses
            .iter()
            .map(|g| g.id)
            .collect())
    }

    /// The glass `id` as its registry JSON record (a dict: `name`, `r0`, `t0`, `r0_back`, the
    /// curves, `luminous`, `angle_model`, `provenance`, `unit`), plus `tau_v`, `rho_v` (its
    /// luminous transmittance and front reflectance, `None` without a spectrum) and `build_up`
    /// (a unit's layers and gaps, `None` for a single glass).
    #[pyo3(signature = (id, space=None))]
    fn glass<'py>(
        &self,
        py: Python<'py>,
        id: u16,
        space: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let record = self.record(py, id, space)?;
        let text = serde_json::to_string(record).or_raise(py)?;
        let dict = json_loads(py, &text)?;
        let lum = record.luminous.as_ref();
        dict.set_item("tau_v", lum.map(|l| l.transmittance))?;
        dict.set_item("rho_v", lum.map(|l| l.reflectance))?;
        let elements = record
            .unit
            .as_ref()
            .map(|u| serde_json::to_string(&u.elements))
            .transpose()
            .or_raise(py)?;
        let build_up = match elements {
            Some(text) => Some(json_loads(py, &text)?),
            None => None,
        };
        dict.set_item("build_up", build_up)?;
        Ok(dict)
    }

    /// r and t of glass `id` (per channel of the table) at `cos_theta` on its `side` (`front` or
    /// `back`), as `glassdb registry show` evaluates them: a float gives two 3-tuples, a 1-D
    /// float64 array of N values two (N, 3) float64 arrays.
    #[pyo3(signature = (id, cos_theta, side="front", space=None))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        id: u16,
        cos_theta: &Bound<'py, PyAny>,
        side: &str,
        space: Option<&str>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let side = parse_side(py, side)?;
        let record = self.record(py, id, space)?;
        if let Ok(c) = cos_theta.extract::<f64>() {
            let (r, t) = record.eval(side, c);
            return (r, t).into_pyobject(py).map(|b| b.into_any());
        }
        let cos: PyReadonlyArray1<'py, f64> = cos_theta
            .extract()
            .map_err(|_| invalid(py, "cos_theta: a float or a 1-D float64 array".to_string()))?;
        let cos = cos.as_array();
        let n = cos.len();
        let (mut r, mut t) = (Vec::with_capacity(3 * n), Vec::with_capacity(3 * n));
        for &c in cos.iter() {
            let (rc, tc) = record.eval(side, c);
            r.extend(rc);
            t.extend(tc);
        }
        let r: Bound<'py, PyArray2<f64>> = numpy::PyArray1::from_vec(py, r).reshape([n, 3])?;
        let t: Bound<'py, PyArray2<f64>> = numpy::PyArray1::from_vec(py, t).reshape([n, 3])?;
        (r, t).into_pyobject(py).map(|b| b.into_any())
    }

    /// The registry JSON, as `glassdb registry build` writes it.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        self.registry.to_json_string().or_raise(py)
    }

    /// Writes the registry JSON to `path` (validated, atomically).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| self.registry.write_json(&path)).or_raise(py)
    }

    /// SHA-256 of its JSON (what `compose` records in its outputs).
    #[getter]
    fn sha256(&self, py: Python<'_>) -> PyResult<String> {
        self.registry.content_sha256().or_raise(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "<glassdb.Registry {} ({} glasses; tables {})>",
            self.label,
            self.registry.default_table().glasses.len(),
            self.spaces().join(", ")
        )
    }
}
