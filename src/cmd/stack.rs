//! `glassdb stack LAYER... [--gap MM[:GAS]]... [--angles …] [--json]`: the optics of a unit
//! given on the command line (docs/stack.md). The stack engine (`glassdb_stack`) does the
//! work; this module reads the layers' files, maps errors to the argument at fault and prints.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, bail};
use glassdb_spectral::{IntegrationSettings, Integrator, Method, WindowMethod, read_spectral_file};
use glassdb_stack::{
    Application, Combination, Element, EvalOptions, Evaluation, Gap, Gas, Layer, LayerOptions,
    ModelChoice, Optics, Stack,
};
use serde_json::{Value, json};

use crate::cmd::spectral::SpaceArg;
use crate::cmd::table::{Column, TextTable};

/// The gap used between layers when no `--gap` is given (WINDOW's default air gap).
pub const DEFAULT_GAP_MM: f64 = 12.7;

/// The build-up on the command line, shared by `glassdb stack` and `glassdb plot stack`.
#[derive(Debug, clap::Args)]
pub struct StackArgs {
    /// The layers, outside first: a glazing file (Optics, IGSDB JSON v1/v2, CSV), with options
    /// after colons: `:flip` (coating faces the other way), `:model=M` (auto, uncoated,
    /// coated, coated-clear, coated-bronze, opaque), `:thickness=MM`. E.g.
    /// `SB.json:flip:model=coated-bronze`.
    #[arg(required = true, value_name = "LAYER")]
    pub layers: Vec<String>,
    /// The gaps between layers, `MM[:GAS]` (gas air, argon, krypton, xenon): one for every
    /// gap, or one per gap in order [default: 12.7 mm air]. Gaps do not change the optics;
    /// they place the panes.
    #[arg(long = "gap", value_name = "MM[:GAS]", allow_hyphen_values = true)]
    pub gaps: Vec<String>,
    /// Apply each layer's angle model to its integrated channels instead of per wavelength.
    #[arg(long)]
    pub per_channel: bool,
    /// Where the layers are combined: per-wavelength (WINDOW, ISO 9050) or per-band (each layer
    /// integrated first: the "RGB shortcut", for comparison).
    #[arg(long, value_enum, default_value = "per-wavelength")]
    pub combine: CombineArg,
}

/// `--combine`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum CombineArg {
    /// Wavelength by wavelength, then integrated.
    PerWavelength,
    /// Each layer integrated to the output's channels first.
    PerBand,
}

/// `glassdb stack`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub stack: StackArgs,
    /// Angles of incidence: START:END:STEP or a comma list (degrees).
    #[arg(long, default_value = "0:80:10")]
    pub angles: String,
    /// The linear RGB space of the colours shown.
    #[arg(long, value_enum, default_value = "srgb")]
    pub space: SpaceArg,
    /// The light of the colours shown: a CIE illuminant (D65, A, FL2, LED-B3, …) or an SPD
    /// CSV file (wavelength_nm,power) [default: D65].
    #[arg(long, value_name = "NAME|FILE.csv")]
    pub illuminant: Option<String>,
    /// The white the camera is balanced to: `light` (the illuminant's own) or a CIE
    /// illuminant [default: light].
    #[arg(long, value_name = "light|NAME")]
    pub white_balance: Option<glassdb_spectral::WhiteBalance>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
    /// With --json: also the system's spectra (T, Rf, Rb per wavelength at each angle).
    #[arg(long, requires = "json")]
    pub spectra: bool,
}

/// One layer argument: `FILE[:flip][:model=M][:thickness=MM]`.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerArg {
    /// The glazing file.
    pub file: PathBuf,
    /// The layer's options.
    pub opts: LayerOptions,
}

/// Parses one LAYER argument (`n`: its 1-based place among the layers, for messages).
pub fn parse_layer(arg: &str, n: usize) -> anyhow::Result<LayerArg> {
    let whole = PathBuf::from(arg);
    if whole.is_file() {
        return Ok(LayerArg {
            file: whole,
            opts: LayerOptions::default(),
        });
    }
    let mut parts = arg.split(':');
    let file = PathBuf::from(parts.next().unwrap_or_default());
    let mut opts = LayerOptions::default();
    for opt in parts {
        let bad = |why: String| anyhow::anyhow!("LAYER {n} `{arg}`: {why}");
        match opt.split_once('=') {
            None if opt == "flip" => opts.flipped = true,
            Some(("model", m)) => opts.model = m.parse::<ModelChoice>().map_err(bad)?,
            Some(("thickness", mm)) => {
                let v: f64 = mm
                    .trim()
                    .parse()
                    .map_err(|_| bad(format!("thickness `{mm}` is not a number")))?;
                if !(v.is_finite() && v > 0.0) {
                    return Err(bad(format!(
                        "thickness {v} mm is not a positive number of millimetres"
                    )));
                }
                opts.thickness_mm = Some(v);
            }
            _ => {
                return Err(bad(format!(
                    "unknown option `{opt}` (expected flip, model=M or thickness=MM)"
                )));
            }
        }
    }
    Ok(LayerArg { file, opts })
}

/// Parses one `--gap MM[:GAS]`.
pub fn parse_gap(arg: &str) -> anyhow::Result<Gap> {
    if arg.split(':').any(|p| p.trim() == "flip") {
        bail!("--gap {arg}: a flip on a gap: only a layer can face the other way");
    }
    let (mm, gas) = match arg.split_once(':') {
        Some((mm, gas)) => (
            mm,
            gas.parse::<Gas>()
                .map_err(|e| anyhow::anyhow!("--gap {arg}: {e}"))?,
        ),
        None => (arg, Gas::Air),
    };
    let thickness_mm: f64 = mm
        .trim()
        .parse()
        .with_context(|| format!("--gap {arg}: `{mm}` is not a thickness in mm"))?;
    if !(thickness_mm.is_finite() && thickness_mm > 0.0) {
        bail!("--gap {arg}: {thickness_mm} mm is not a positive number of millimetres");
    }
    Ok(Gap { thickness_mm, gas })
}

/// The stack the arguments describe, and what each element is on the command line.
pub struct CommandStack {
    /// The validated build-up.
    pub stack: Stack,
    /// Per element, how the command line gave it (for messages and labels).
    pub origins: Vec<String>,
    /// The evaluation options the flags choose.
    pub eval: EvalOptions,
}

impl StackArgs {
    /// Reads the layers' files and assembles the stack; errors name the argument.
    pub fn build(&self) -> anyhow::Result<CommandStack> {
        let n_gaps = self.layers.len() - 1;
        let gaps: Vec<Gap> = self
            .gaps
            .iter()
            .map(|g| parse_gap(g))
            .collect::<anyhow::Result<_>>()?;
        let gaps = match gaps.len() {
            0 => vec![
                Gap {
                    thickness_mm: DEFAULT_GAP_MM,
                    gas: Gas::Air
                };
                n_gaps
            ],
            1 => vec![gaps[0]; n_gaps],
            k if k == n_gaps => gaps,
            k => bail!(
                "{k} --gap values for {} layers: give one for every gap, or {n_gaps} (one per gap, in order)",
                self.layers.len()
            ),
        };
        let mut elements = Vec::new();
        let mut origins = Vec::new();
        for (i, arg) in self.layers.iter().enumerate() {
            if i > 0 {
                let g = gaps[i - 1];
                elements.push(Element::Gap(g));
                origins.push(format!("gap {} ({} mm {})", i, g.thickness_mm, g.gas));
            }
            let la = parse_layer(arg, i + 1)?;
            let data = read_spectral_file(&la.file, &Default::default())
                .with_context(|| format!("LAYER {} `{arg}`", i + 1))?;
            let layer = Layer::from_spectral_data(data, &la.opts, arg)
                .with_context(|| format!("LAYER {} `{arg}`", i + 1))?;
            elements.push(Element::Layer(Box::new(layer)));
            origins.push(format!("LAYER {} `{arg}`", i + 1));
        }
        let stack = Stack::new(elements).map_err(|e| {
            let at = e
                .position()
                .and_then(|p| origins.get(p - 1))
                .map(|o| format!("{o}: "))
                .unwrap_or_default();
            anyhow::Error::new(e).context(format!("{at}the build-up {}", self.layers.join(" | ")))
        })?;
        let eval = EvalOptions {
            application: if self.per_channel {
                Application::PerChannel
            } else {
                Application::PerWavelength
            },
            combination: match self.combine {
                CombineArg::PerWavelength => Combination::PerWavelength,
                CombineArg::PerBand => Combination::PerBand,
            },
        };
        Ok(CommandStack {
            stack,
            origins,
            eval,
        })
    }
}

/// The colorimetric integrator of the colours shown (CIE 1931; D65 unless `--illuminant`).
fn colour_settings(args: &Args) -> anyhow::Result<IntegrationSettings> {
    let illuminant = match &args.illuminant {
        Some(text) => glassdb_spectral::Illuminant::from_name_or_file(text)
            .map_err(anyhow::Error::new)
            .context("--illuminant")?,
        None => Default::default(),
    };
    let mut settings = IntegrationSettings::colorimetric(args.space.space(), illuminant);
    if let (Some(wb), Method::Colorimetric(c)) = (args.white_balance, &mut settings.method) {
        c.white_balance = wb;
    }
    Ok(settings)
}

pub fn run(args: Args) -> anyhow::Result<ExitCode> {
    let text = if args.json {
        let mut s = serde_json::to_string_pretty(&report_json(&args)?)?;
        s.push('\n');
        s
    } else {
        let u = evaluate(&args)?;
        to_text(&u.built, &u.eval, &u.settings)
    };
    out!("{text}");
    Ok(ExitCode::SUCCESS)
}

/// A unit built from the command line and evaluated at its angles.
struct EvaluatedUnit {
    built: CommandStack,
    eval: Evaluation,
    /// Each layer's own photopic T, Rf, Rb per angle.
    layers: Vec<Option<Vec<[f64; 3]>>>,
    settings: IntegrationSettings,
}

/// The unit of `args` built and evaluated at its angles, with each layer's own photopic values.
fn evaluate(args: &Args) -> anyhow::Result<EvaluatedUnit> {
    let angles = crate::cmd::fit::parse_angles(&args.angles)?;
    let built = args.stack.build()?;
    let settings = colour_settings(args)?;
    let integrator = Integrator::new(&settings)?;
    let eval = built
        .stack
        .evaluate(&angles, std::slice::from_ref(&integrator), true, built.eval)
        .context("evaluating the unit")?;
    let layers = built
        .stack
        .layer_averages(&angles, WindowMethod::Photopic)?;
    Ok(EvaluatedUnit {
        built,
        eval,
        layers,
        settings,
    })
}

/// What `glassdb stack --json` prints (with `--spectra`, the system's spectra too), for the
/// command and the Python package alike.
pub fn report_json(args: &Args) -> anyhow::Result<Value> {
    let u = evaluate(args)?;
    let mut v = to_json(&u.built, &u.eval, &u.layers, &u.settings);
    if args.spectra {
        let angles = crate::cmd::fit::parse_angles(&args.angles)?;
        v["spectra"] = spectra_json(&u.built.stack, &angles)?;
    }
    Ok(v)
}

fn column<V, U>(per_angle: &[Optics<V>], f: impl Fn(&Optics<V>) -> U) -> Vec<U> {
    per_angle.iter().map(f).collect()
}

/// T, Rf, Rb and the pane groups' shares per angle (and the layers' absorptances, with
/// `absorptance`).
fn optics_json<V: serde::Serialize + Clone>(per_angle: &[Optics<V>], absorptance: bool) -> Value {
    let mut v = json!({
        "T": column(per_angle, |o| o.t.clone()),
        "Rf": column(per_angle, |o| o.rf.clone()),
        "Rb": column(per_angle, |o| o.rb.clone()),
        "group_shares": {
            "front": column(per_angle, |o| o.share.front.clone()),
            "back": column(per_angle, |o| o.share.back.clone()),
        },
    });
    if absorptance {
        v["absorptance"] = json!({
            "front": column(per_angle, |o| o.absorptance.front.clone()),
            "back": column(per_angle, |o| o.absorptance.back.clone()),
        });
    }
    v
}

fn to_json(
    built: &CommandStack,
    eval: &Evaluation,
    layer_photopic: &[Option<Vec<[f64; 3]>>],
    settings: &IntegrationSettings,
) -> Value {
    let mut rgb = optics_json(&eval.colour[0], false);
    if let Method::Colorimetric(c) = &settings.method {
        rgb["space"] = json!(c.space.name());
        rgb["illuminant"] = json!(c.illuminant.name());
        rgb["white_balance"] = json!(c.white_balance.name());
    }
    let mut layers = Vec::new();
    for ((l, origin), own) in built
        .stack
        .layers()
        .zip(
            built
                .stack
                .layer_positions()
                .iter()
                .map(|&p| &built.origins[p - 1]),
        )
        .zip(layer_photopic)
    {
        let product = l.product.as_ref();
        layers.push(json!({
            "argument": origin,
            "name": product.and_then(|p| p.name.clone()),
            "product_type": product.and_then(|p| p.product_type.clone()),
            "flipped": l.flipped,
            "thickness_mm": l.thickness_mm,
            "model": l.model.name(),
            "model_chosen_by": l.model_reason,
            "photopic": own.as_ref().map(|rows| json!({
                "T": rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
                "Rf": rows.iter().map(|r| r[1]).collect::<Vec<_>>(),
                "Rb": rows.iter().map(|r| r[2]).collect::<Vec<_>>(),
            })),
        }));
    }
    let gaps: Vec<Value> = built
        .stack
        .elements()
        .iter()
        .filter_map(|e| match e {
            Element::Gap(g) => Some(json!({"thickness_mm": g.thickness_mm, "gas": g.gas})),
            Element::Layer(_) => None,
        })
        .collect();
    json!({
        "angles_deg": eval.angles_deg,
        "combination": eval.combination.name(),
        "photopic": eval.photopic.as_ref().map_or(Value::Null, |p| optics_json(p, true)),
        "solar": eval.solar.as_ref().map_or(Value::Null, |p| optics_json(p, true)),
        "rgb": rgb,
        "layers": layers,
        "gaps": gaps,
        "groups": built.stack.groups().iter().map(|g| json!({
            "layers": g.layers.clone().collect::<Vec<_>>(),
            "thickness_mm": g.thickness_mm,
            "depth_mm": g.depth_mm,
            "depth_back_mm": g.depth_back_mm,
        })).collect::<Vec<_>>(),
        "thickness_mm": built.stack.thickness_mm(),
    })
}

/// The per-wavelength optics at each angle (none when combined per band).
fn spectra_json(stack: &Stack, angles: &[f64]) -> anyhow::Result<Value> {
    let mut wavelength_nm = Vec::new();
    let (mut t, mut rf, mut rb) = (Vec::new(), Vec::new(), Vec::new());
    for &a in angles {
        let Some(s) = stack.spectra_at(a)? else {
            return Ok(Value::Null);
        };
        wavelength_nm = s.wavelength_nm;
        t.push(s.optics.t);
        rf.push(s.optics.rf);
        rb.push(s.optics.rb);
    }
    Ok(json!({"wavelength_nm": wavelength_nm, "T": t, "Rf": rf, "Rb": rb}))
}

/// The readable report's table: per angle WINDOW's photopic and solar values, then the
/// colour table's T, R out and R in.
const ANGLE_TABLE: TextTable<10> = TextTable {
    columns: [
        Column::right("", 5),
        Column::right("  ", 6),
        Column::right(" ", 7),
        Column::right(" ", 6),
        Column::right("  ", 6),
        Column::right(" ", 8),
        Column::right(" ", 7),
        Column::left("   ", 22),
        Column::left(" ", 22),
        Column::left(" ", 22),
    ],
};

fn rgb_text(v: [f64; 3]) -> String {
    format!("{:.4} {:.4} {:.4}", v[0], v[1], v[2])
}

fn to_text(built: &CommandStack, eval: &Evaluation, settings: &IntegrationSettings) -> String {
    let mut s = String::new();
    let stack = &built.stack;
    let _ = writeln!(
        s,
        "unit of {} layer(s){}, combined {}",
        stack.layers().len(),
        stack
            .thickness_mm()
            .map(|t| format!(", {t:.2} mm"))
            .unwrap_or_default(),
        eval.combination.name()
    );
    let mut layer_no = 0;
    for (e, origin) in stack.elements().iter().zip(&built.origins) {
        match e {
            Element::Gap(_) => {
                let _ = writeln!(s, "  {origin}");
            }
            Element::Layer(l) => {
                layer_no += 1;
                let name = l
                    .product
                    .as_ref()
                    .and_then(|p| p.name.clone())
                    .unwrap_or_default();
                let _ = writeln!(
                    s,
                    "  layer {layer_no}: {origin} {name}{}{}, model {} ({})",
                    if l.flipped { ", flipped" } else { "" },
                    l.thickness_mm
                        .map(|t| format!(", {t:.3} mm"))
                        .unwrap_or_default(),
                    l.model.name(),
                    l.model_reason
                );
            }
        }
    }
    for (k, g) in stack.groups().iter().enumerate() {
        let _ = writeln!(
            s,
            "  pane group {}: layers {}–{}{}",
            k + 1,
            g.layers.start + 1,
            g.layers.end,
            g.depth_mm
                .map(|d| format!(", mid-plane {d:.2} mm behind surface #1"))
                .unwrap_or_default()
        );
    }
    let _ = writeln!(s, "colours: {}", settings.method);
    let titles = [
        "θ(°)",
        "Tv",
        "Rv out",
        "Rv in",
        "Tsol",
        "Rsol out",
        "Rsol in",
        "T rgb",
        "R out rgb",
        "R in rgb",
    ];
    let _ = writeln!(s, "{}", ANGLE_TABLE.line(titles));
    for (i, &a) in eval.angles_deg.iter().enumerate() {
        let c = &eval.colour[0][i];
        // WINDOW's T, R out and R in, or dashes where the unit has none.
        let window = |o: Option<&Vec<Optics<f64>>>| match o {
            Some(v) => [v[i].t, v[i].rf, v[i].rb].map(|x| format!("{x:.4}")),
            None => ["–", "–", "–"].map(String::from),
        };
        let ([tv, rv_out, rv_in], [tsol, rsol_out, rsol_in]) =
            (window(eval.photopic.as_ref()), window(eval.solar.as_ref()));
        let row = [
            a.to_string(),
            tv,
            rv_out,
            rv_in,
            tsol,
            rsol_out,
            rsol_in,
            rgb_text(c.t),
            rgb_text(c.rf),
            rgb_text(c.rb),
        ];
        let _ = writeln!(s, "{}", ANGLE_TABLE.line(row));
    }
    s
}
