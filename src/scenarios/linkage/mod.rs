//! `kind = "linkage"` scenarios: the TOML schema, its validation (every error names the
//! file, the line and the key), and [`run`]. The analyses and their output are in
//! [`crate::scenarios::linkage::report`]; `docs/mechanism.md` documents the format.
//!
//! A file holds any of: a linkage (`[ground]`, `[links.*]`, `[[sliders]]`, `[driver]`,
//! `[guess]`, `[sweep]`, `four_bar`, `coupler_curves`) with optional `[kinetostatics]`,
//! `[[loads]]`, `[counterweight]`, `[flywheel]`; a `[rotor_balance]`; a
//! `[machine_motion]`. Points shared by name between links (or a link and the ground)
//! are pins.

pub mod friction_report;
mod linkage_section;
mod loads_section;
pub mod report;
mod rotor_machine_sections;
use crate::core::diag::{all_finite, line_of_key, LocatedError as ScenarioError};
use crate::io::report::Report;
use crate::machines::balancing::RotorMass;
use crate::machines::flywheel::machine_motion::Characteristic;
use crate::machines::linkage::description::{Driver, Linkage, PlanarLink, Slider, GROUND};
use crate::machines::linkage::kinetostatics::Loads;
use crate::machines::linkage::position::{solve_position, NewtonOptions};
use crate::machines::linkage::sweep::SweepOptions;
use crate::machines::linkage::Vec2;
use crate::scenarios::linkage::linkage_section::parse_mechanism;
use crate::scenarios::linkage::loads_section::{parse_flywheel, parse_kineto};
use crate::scenarios::linkage::rotor_machine_sections::{parse_machine, parse_rotor};
use crate::scenarios::source::Source;
use nalgebra::DVector;
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    #[allow(dead_code)]
    kind: String,
    name: Option<String>,
    description: Option<String>,
    ground: Option<BTreeMap<String, Spanned<[f64; 2]>>>,
    links: Option<BTreeMap<String, Spanned<LinkSpec>>>,
    #[serde(default)]
    sliders: Vec<Spanned<SliderSpec>>,
    driver: Option<Spanned<DriverSpec>>,
    guess: Option<BTreeMap<String, Spanned<[f64; 2]>>>,
    sweep: Option<Spanned<SweepSpec>>,
    four_bar: Option<Spanned<Vec<String>>>,
    coupler_curves: Option<Spanned<Vec<String>>>,
    kinetostatics: Option<Spanned<KinetoSpec>>,
    #[serde(default)]
    loads: Vec<Spanned<LoadSpec>>,
    counterweight: Option<Spanned<CounterweightSpec>>,
    flywheel: Option<Spanned<FlywheelSpec>>,
    rotor_balance: Option<Spanned<RotorSpec>>,
    machine_motion: Option<Spanned<MachineSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LinkSpec {
    ends: Option<[String; 2]>,
    length: Option<f64>,
    points: Option<BTreeMap<String, [f64; 2]>>,
    mass: Option<f64>,
    com: Option<[f64; 2]>,
    inertia: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SliderSpec {
    link: String,
    point: String,
    #[serde(default = "ground_name")]
    guide: String,
    through: [f64; 2],
    direction: [f64; 2],
    #[serde(rename = "type", default = "prismatic_name")]
    kind: String,
    angle_deg: Option<f64>,
}

fn ground_name() -> String {
    "ground".into()
}

fn prismatic_name() -> String {
    "prismatic".into()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DriverSpec {
    link: String,
    #[serde(rename = "type", default = "angle_name")]
    kind: String,
    relative_to: Option<String>,
    point: Option<String>,
    through: Option<[f64; 2]>,
    direction: Option<[f64; 2]>,
    speed: f64,
    #[serde(default)]
    acceleration: f64,
}

fn angle_name() -> String {
    "angle".into()
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct SweepSpec {
    from_deg: Option<f64>,
    to_deg: Option<f64>,
    step_deg: Option<f64>,
    assemble_at_deg: Option<f64>,
    #[serde(default)]
    report_at_deg: Vec<f64>,
    from: Option<f64>,
    to: Option<f64>,
    step: Option<f64>,
    assemble_at: Option<f64>,
    #[serde(default)]
    report_at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct KinetoSpec {
    gravity: Option<[f64; 2]>,
    friction_coefficient: Option<f64>,
    pin_radius: Option<f64>,
    #[serde(default)]
    report_at_deg: Vec<f64>,
    #[serde(default)]
    report_at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LoadSpec {
    link: String,
    point: Option<String>,
    force: Option<[f64; 2]>,
    torque: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CounterweightSpec {
    crank: String,
    rod: String,
    slider: String,
    fraction: f64,
    radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FlywheelSpec {
    speed_fluctuation: f64,
    speed: Option<f64>,
    load: Option<f64>,
    torque_deg: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RotorSpec {
    masses: Vec<f64>,
    radii: Vec<f64>,
    angles_deg: Vec<f64>,
    positions: Vec<f64>,
    planes: Vec<f64>,
    plane_radii: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MachineSpec {
    inertia: f64,
    drive: Vec<f64>,
    load: f64,
    #[serde(default)]
    omega0: f64,
    t_end: f64,
    dt: Option<f64>,
}

/// Kinetostatics settings.
#[derive(Clone, Debug)]
pub struct KinetostaticsScenario {
    /// Loads (gravity included).
    pub loads: Loads,
    /// Joint friction `(coefficient, pin radius)` in every joint (friction circles).
    pub friction: Option<(f64, f64)>,
    /// Inputs (rad or m) at which the text report lists the joint forces.
    pub report_at: Vec<f64>,
}

/// Counterweight settings (slider-crank).
#[derive(Clone, Debug)]
pub struct CounterweightScenario {
    /// Crank link.
    pub crank: usize,
    /// Connecting rod.
    pub rod: usize,
    /// Slider link.
    pub slider: usize,
    /// Fraction of the reciprocating mass balanced.
    pub fraction: f64,
    /// Counterweight radius (m).
    pub radius: f64,
}

/// Flywheel settings.
#[derive(Clone, Debug)]
pub struct FlywheelScenario {
    /// Coefficient of speed fluctuation `δ`.
    pub delta: f64,
    /// Mean speed (rad/s).
    pub speed: f64,
    /// Constant load torque; `None`: the cycle mean of the driving torque.
    pub load: Option<f64>,
    /// A driving torque table `(φ rad, M)`; `None`: the linkage's kinetostatic torque.
    pub table: Option<Vec<(f64, f64)>>,
}

/// The linkage part of a scenario.
#[derive(Clone, Debug)]
pub struct MechanismScenario {
    /// The linkage.
    pub linkage: Linkage,
    /// Assembled coordinates at `sweep.assemble_at` (the guess closed by Newton).
    pub assembly: DVector<f64>,
    /// Sweep settings.
    pub sweep: SweepOptions,
    /// Whether the input is an angle (else a slide, in m).
    pub angle_input: bool,
    /// Input rate `ṡ`.
    pub speed: f64,
    /// Input acceleration `s̈`.
    pub acceleration: f64,
    /// Inputs the text report tabulates.
    pub report_at: Vec<f64>,
    /// Four-bar loop points `[O, A, B, C]` (Grashof, transmission angle at `B`).
    pub four_bar: Option<[String; 4]>,
    /// Points whose paths are reported.
    pub coupler_curves: Vec<String>,
    /// Kinetostatics, if asked for.
    pub kinetostatics: Option<KinetostaticsScenario>,
    /// Counterweight, if asked for.
    pub counterweight: Option<CounterweightScenario>,
}

/// Rotor balancing settings.
#[derive(Clone, Debug)]
pub struct RotorScenario {
    /// The masses.
    pub masses: Vec<RotorMass>,
    /// Correction planes `(position, radius)` (one or two).
    pub planes: Vec<(f64, f64)>,
}

/// Machine-motion settings.
#[derive(Clone, Debug)]
pub struct MachineScenario {
    /// Reduced inertia `J`.
    pub inertia: f64,
    /// Motor characteristic.
    pub drive: Characteristic,
    /// Constant load torque.
    pub load: f64,
    /// Starting speed.
    pub omega0: f64,
    /// End time.
    pub t_end: f64,
    /// Step.
    pub dt: f64,
}

/// A parsed and validated linkage scenario.
#[derive(Clone, Debug)]
pub struct LinkageScenario {
    /// The file.
    pub file: String,
    /// Name.
    pub name: String,
    /// Description.
    pub description: Option<String>,
    /// The linkage, if any.
    pub mechanism: Option<MechanismScenario>,
    /// Flywheel sizing, if asked for.
    pub flywheel: Option<FlywheelScenario>,
    /// Rotor balancing, if any.
    pub rotor: Option<RotorScenario>,
    /// Machine motion, if any.
    pub machine: Option<MachineScenario>,
}

fn unit(v: [f64; 2]) -> Option<Vec2> {
    let d = Vec2::new(v[0], v[1]);
    let n = d.norm();
    (n > 0.0 && n.is_finite()).then(|| d / n)
}

/// Parses and validates `text` (the contents of `file`); assembles the linkage once.
pub fn parse(file: &str, text: &str) -> Result<LinkageScenario, ScenarioError> {
    let spec: Spec = toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let cx = Source::new(file, text);
    let name = spec.name.clone().unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or(NAME)
            .to_string()
    });
    let mechanism = match &spec.links {
        Some(_) => Some(parse_mechanism(&cx, &spec)?),
        None => {
            for (key, present) in [
                ("driver", spec.driver.is_some()),
                ("sweep", spec.sweep.is_some()),
                ("kinetostatics", spec.kinetostatics.is_some()),
                ("counterweight", spec.counterweight.is_some()),
            ] {
                if present {
                    let line = text
                        .lines()
                        .position(|l| l.trim() == format!("[{key}]"))
                        .map(|i| i + 1)
                        .unwrap_or(1);
                    return Err(cx.err(
                        line,
                        key,
                        "needs a linkage: no [links.*] tables in the file",
                    ));
                }
            }
            None
        }
    };
    let flywheel = match &spec.flywheel {
        Some(f) => Some(parse_flywheel(&cx, f, mechanism.as_ref())?),
        None => None,
    };
    let rotor = match &spec.rotor_balance {
        Some(r) => Some(parse_rotor(&cx, r)?),
        None => None,
    };
    let machine = match &spec.machine_motion {
        Some(m) => Some(parse_machine(&cx, m)?),
        None => None,
    };
    if mechanism.is_none() && flywheel.is_none() && rotor.is_none() && machine.is_none() {
        return Err(ScenarioError::new(
            file,
            line_of_key(text, "kind"),
            "file",
            "nothing to do: give a linkage ([links.*]), [rotor_balance], [flywheel] or [machine_motion]",
        ));
    }
    Ok(LinkageScenario {
        file: file.to_string(),
        name,
        description: spec.description.clone(),
        mechanism,
        flywheel,
        rotor,
        machine,
    })
}

fn parse_link(
    cx: &Source,
    name: &str,
    sp: &Spanned<LinkSpec>,
) -> Result<PlanarLink, ScenarioError> {
    let line = cx.line(&sp.span());
    let key = format!("links.{name}");
    let s = sp.get_ref();
    let mut points: Vec<(String, Vec2)> = Vec::new();
    if let Some([a, b]) = &s.ends {
        let Some(len) = s.length else {
            return Err(cx.err(
                line,
                format!("{key}.length"),
                "missing: a link with `ends` needs its `length` (m)",
            ));
        };
        let (lo, hi) = crate::scenarios::source::LENGTHS;
        if !(len.is_finite() && len > 0.0) {
            return Err(cx.err(
                cx.key_line(&sp.span(), "length"),
                format!("{key}.length"),
                format!("must be a positive length, got {len}"),
            ));
        }
        if !(lo..=hi).contains(&len) {
            return Err(cx.err(
                cx.key_line(&sp.span(), "length"),
                format!("{key}.length"),
                format!("{len:e} is out of range: a length lies in {lo:e}..{hi:e}"),
            ));
        }
        if a == b {
            return Err(cx.err(line, format!("{key}.ends"), "the two ends must differ"));
        }
        points.push((a.clone(), Vec2::zeros()));
        points.push((b.clone(), Vec2::new(len, 0.0)));
    } else if s.length.is_some() {
        return Err(cx.err(
            cx.key_line(&sp.span(), "length"),
            format!("{key}.length"),
            "`length` needs `ends = [\"P\", \"Q\"]` (the points it separates)",
        ));
    }
    for (pn, p) in s.points.iter().flatten() {
        if !all_finite(p) {
            return Err(cx.err(line, format!("{key}.points.{pn}"), "non-finite coordinates"));
        }
        if points.iter().any(|(n, _)| n == pn) {
            return Err(cx.err(
                line,
                format!("{key}.points.{pn}"),
                "point given twice (also in `ends`)",
            ));
        }
        points.push((pn.clone(), Vec2::new(p[0], p[1])));
    }
    if points.is_empty() {
        return Err(cx.err(line, key, "a link needs `ends` and `length`, or `points`"));
    }
    let mass = s.mass.unwrap_or(0.0);
    let inertia = s.inertia.unwrap_or(0.0);
    for (k, v) in [("mass", mass), ("inertia", inertia)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(cx.err(
                cx.key_line(&sp.span(), k),
                format!("{key}.{k}"),
                format!("must be ≥ 0, got {v}"),
            ));
        }
    }
    let com = match s.com {
        Some(c) if !all_finite(&c) => {
            return Err(cx.err(
                cx.key_line(&sp.span(), "com"),
                format!("{key}.com"),
                "non-finite",
            ))
        }
        Some(c) => Vec2::new(c[0], c[1]),
        None if s.ends.is_some() => (points[0].1 + points[1].1) * 0.5,
        None => Vec2::zeros(),
    };
    Ok(PlanarLink {
        name: name.to_string(),
        points,
        mass,
        com,
        inertia,
    })
}

/// The moving link named `name` (not the ground), or an error at `key` of the table at
/// `span` that names it as `table.key`.
fn moving_link(
    cx: &Source,
    links: &[PlanarLink],
    name: &str,
    span: &std::ops::Range<usize>,
    (table, key): (&str, &str),
) -> Result<usize, ScenarioError> {
    body_of(links, name)
        .filter(|&b| b != GROUND)
        .ok_or_else(|| {
            cx.err(
                cx.key_line(span, key),
                format!("{table}.{key}"),
                format!("no link '{name}'"),
            )
        })
}

fn body_of(links: &[PlanarLink], name: &str) -> Option<usize> {
    if name == "ground" {
        Some(GROUND)
    } else {
        links.iter().position(|l| l.name == name)
    }
}

fn text_line_of_table(text: &str, table: &str) -> Option<usize> {
    text.lines()
        .position(|l| l.trim() == format!("[{table}]"))
        .map(|i| i + 1)
}

/// Runs a linkage scenario: parses it and produces the report.
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    let sc = parse(&path.display().to_string(), text)?;
    Ok(crate::scenarios::linkage::report::report(&sc, NAME))
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "linkage";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| parse(file, text).map(drop),
    run: |path, text, _opts| run(path, text),
};
