//! `kind = "linkage"` scenarios: the TOML schema, its validation (every error names the
//! file, the line and the key), and [`run`]. The analyses and their output are in
//! [`super::report`]; `docs/mechanism.md` documents the format.
//!
//! A file holds any of: a linkage (`[ground]`, `[links.*]`, `[[sliders]]`, `[driver]`,
//! `[guess]`, `[sweep]`, `four_bar`, `coupler_curves`) with optional `[kinetostatics]`,
//! `[[loads]]`, `[counterweight]`, `[flywheel]`; a `[rotor_balance]`; a
//! `[machine_motion]`. Points shared by name between links (or a link and the ground)
//! are pins.

use super::balancing::RotorMass;
use super::kinetostatics::{Loads, PointForce};
use super::linkage::{Driver, Link, Linkage, Slider, GROUND};
use super::machine_motion::Characteristic;
use super::position::{solve_position, NewtonOptions};
use super::sweep::SweepOptions;
use super::Vec2;
use crate::diag::{all_finite, line_of_key, LocatedError as ScenarioError, Source};
use crate::report::Report;
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
pub struct Scenario {
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
pub fn parse(file: &str, text: &str) -> Result<Scenario, ScenarioError> {
    let spec: Spec = toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let cx = Source::new(file, text);
    let name = spec.name.clone().unwrap_or_else(|| {
        Path::new(file)
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("linkage")
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
    Ok(Scenario {
        file: file.to_string(),
        name,
        description: spec.description.clone(),
        mechanism,
        flywheel,
        rotor,
        machine,
    })
}

fn parse_link(cx: &Source, name: &str, sp: &Spanned<LinkSpec>) -> Result<Link, ScenarioError> {
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
        if !(len.is_finite() && len > 0.0) {
            return Err(cx.err(
                cx.key_line(&sp.span(), "length"),
                format!("{key}.length"),
                format!("must be a positive length, got {len}"),
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
    Ok(Link {
        name: name.to_string(),
        points,
        mass,
        com,
        inertia,
    })
}

fn body_of(links: &[Link], name: &str) -> Option<usize> {
    if name == "ground" {
        Some(GROUND)
    } else {
        links.iter().position(|l| l.name == name)
    }
}

fn parse_mechanism(cx: &Source, spec: &Spec) -> Result<MechanismScenario, ScenarioError> {
    let links_spec = spec.links.as_ref().expect("checked by the caller");
    // File order (the map is sorted by name): by span.
    let mut order: Vec<(&String, &Spanned<LinkSpec>)> = links_spec.iter().collect();
    order.sort_by_key(|(_, s)| s.span().start);
    let mut links = Vec::new();
    let mut link_lines = Vec::new();
    for (n, s) in &order {
        if n.as_str() == "ground" {
            return Err(cx.err(
                cx.line(&s.span()),
                "links.ground",
                "`ground` is reserved: use [ground]",
            ));
        }
        links.push(parse_link(cx, n, s)?);
        link_lines.push(cx.line(&s.span()));
    }
    let mut ground = Vec::new();
    for (n, p) in spec.ground.iter().flatten() {
        if !all_finite(p.get_ref()) {
            return Err(cx.err(
                cx.line(&p.span()),
                format!("ground.{n}"),
                "non-finite coordinates",
            ));
        }
        ground.push((n.clone(), Vec2::new(p.get_ref()[0], p.get_ref()[1])));
    }
    let mut sliders = Vec::new();
    for (k, sp) in spec.sliders.iter().enumerate() {
        let s = sp.get_ref();
        let key = format!("sliders[{k}]");
        let span = sp.span();
        let link = body_of(&links, &s.link)
            .filter(|&b| b != GROUND)
            .ok_or_else(|| {
                cx.err(
                    cx.key_line(&span, "link"),
                    format!("{key}.link"),
                    format!("no link '{}'", s.link),
                )
            })?;
        let guide = body_of(&links, &s.guide).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "guide"),
                format!("{key}.guide"),
                format!("no link '{}'", s.guide),
            )
        })?;
        if guide == link {
            return Err(cx.err(
                cx.key_line(&span, "guide"),
                format!("{key}.guide"),
                "a link cannot slide on itself",
            ));
        }
        let p = links[link].point(&s.point).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "point"),
                format!("{key}.point"),
                format!("link '{}' has no point '{}'", s.link, s.point),
            )
        })?;
        let dir = unit(s.direction).ok_or_else(|| {
            cx.err(
                cx.key_line(&span, "direction"),
                format!("{key}.direction"),
                "must be a non-zero vector",
            )
        })?;
        if !all_finite(&s.through) {
            return Err(cx.err(
                cx.key_line(&span, "through"),
                format!("{key}.through"),
                "non-finite",
            ));
        }
        let prismatic = match s.kind.as_str() {
            "prismatic" => Some(s.angle_deg.unwrap_or(0.0).to_radians()),
            "pin_in_slot" => None,
            other => {
                return Err(cx.err(
                    cx.key_line(&span, "type"),
                    format!("{key}.type"),
                    format!(
                        "unknown slider type '{other}' (expected \"prismatic\" or \"pin_in_slot\")"
                    ),
                ))
            }
        };
        sliders.push(Slider {
            name: s.point.clone(),
            link,
            p,
            guide,
            through: Vec2::new(s.through[0], s.through[1]),
            dir,
            prismatic,
        });
    }
    let Some(dsp) = &spec.driver else {
        return Err(cx.err(
            link_lines[0],
            "driver",
            "missing [driver]: which link is the input",
        ));
    };
    let dspan = dsp.span();
    let d = dsp.get_ref();
    let dlink = body_of(&links, &d.link)
        .filter(|&b| b != GROUND)
        .ok_or_else(|| {
            cx.err(
                cx.key_line(&dspan, "link"),
                "driver.link",
                format!("no link '{}'", d.link),
            )
        })?;
    if !(d.speed.is_finite() && d.acceleration.is_finite()) {
        return Err(cx.err(cx.key_line(&dspan, "speed"), "driver.speed", "non-finite"));
    }
    let (driver, angle_input) = match d.kind.as_str() {
        "angle" => {
            let rel = match &d.relative_to {
                None => GROUND,
                Some(n) => body_of(&links, n).ok_or_else(|| {
                    cx.err(
                        cx.key_line(&dspan, "relative_to"),
                        "driver.relative_to",
                        format!("no link '{n}'"),
                    )
                })?,
            };
            if rel == dlink {
                return Err(cx.err(
                    cx.key_line(&dspan, "relative_to"),
                    "driver.relative_to",
                    "the driven link itself",
                ));
            }
            (
                Driver::Angle {
                    link: dlink,
                    relative_to: rel,
                },
                true,
            )
        }
        "slide" => {
            let pn = d.point.as_ref().ok_or_else(|| {
                cx.err(
                    cx.line(&dspan),
                    "driver.point",
                    "missing: a slide driver needs the driven `point`",
                )
            })?;
            let p = links[dlink].point(pn).ok_or_else(|| {
                cx.err(
                    cx.key_line(&dspan, "point"),
                    "driver.point",
                    format!("link '{}' has no point '{pn}'", d.link),
                )
            })?;
            let through = d
                .through
                .ok_or_else(|| cx.err(cx.line(&dspan), "driver.through", "missing"))?;
            let dir = d
                .direction
                .and_then(unit)
                .ok_or_else(|| cx.err(cx.line(&dspan), "driver.direction", "missing or zero"))?;
            (
                Driver::Slide {
                    link: dlink,
                    p,
                    through: Vec2::new(through[0], through[1]),
                    dir,
                },
                false,
            )
        }
        other => {
            return Err(cx.err(
                cx.key_line(&dspan, "type"),
                "driver.type",
                format!("unknown driver type '{other}' (expected \"angle\" or \"slide\")"),
            ))
        }
    };
    let lname = spec.name.clone().unwrap_or_else(|| "linkage".into());
    let linkage = Linkage::with_shared_pins(lname, ground, links, sliders, driver);
    linkage
        .validate()
        .map_err(|e| cx.err(link_lines[0], "links", e.to_string()))?;

    // Sweep.
    let default_sweep = Spanned::new(0..0, SweepSpec::default());
    let ssp = spec.sweep.as_ref().unwrap_or(&default_sweep);
    let sspan = ssp.span();
    let s = ssp.get_ref();
    let deg_keys = s.from_deg.is_some()
        || s.to_deg.is_some()
        || s.step_deg.is_some()
        || s.assemble_at_deg.is_some()
        || !s.report_at_deg.is_empty();
    let lin_keys = s.from.is_some()
        || s.to.is_some()
        || s.step.is_some()
        || s.assemble_at.is_some()
        || !s.report_at.is_empty();
    if angle_input && lin_keys {
        return Err(cx.err(
            cx.line(&sspan),
            "sweep",
            "an angle driver sweeps in degrees: use from_deg, to_deg, step_deg, assemble_at_deg, report_at_deg",
        ));
    }
    if !angle_input && deg_keys {
        return Err(cx.err(
            cx.line(&sspan),
            "sweep",
            "a slide driver sweeps in metres: use from, to, step, assemble_at, report_at",
        ));
    }
    let (from, to, step, assemble_at, report_at) = if angle_input {
        let from = s.from_deg.unwrap_or(0.0);
        (
            from.to_radians(),
            s.to_deg.unwrap_or(from + 360.0).to_radians(),
            s.step_deg.unwrap_or(1.0).to_radians(),
            s.assemble_at_deg.unwrap_or(from).to_radians(),
            s.report_at_deg
                .iter()
                .map(|x| x.to_radians())
                .collect::<Vec<_>>(),
        )
    } else {
        let from = s.from.ok_or_else(|| {
            cx.err(
                cx.line(&sspan),
                "sweep.from",
                "missing: where the slide sweep starts (m)",
            )
        })?;
        let to = s.to.ok_or_else(|| {
            cx.err(
                cx.line(&sspan),
                "sweep.to",
                "missing: where the slide sweep ends (m)",
            )
        })?;
        (
            from,
            to,
            s.step.unwrap_or((to - from).abs() / 100.0),
            s.assemble_at.unwrap_or(from),
            s.report_at.clone(),
        )
    };
    let step_key = if angle_input { "step_deg" } else { "step" };
    if !(step.is_finite()
        && step > 0.0
        && all_finite(&[from, to, assemble_at])
        && all_finite(&report_at))
    {
        return Err(cx.err(
            cx.key_line(&sspan, step_key),
            format!("sweep.{step_key}"),
            "the sweep needs finite bounds and a positive step",
        ));
    }
    if (to - from).abs() / step > 1e6 {
        return Err(cx.err(
            cx.key_line(&sspan, step_key),
            format!("sweep.{step_key}"),
            "more than a million steps",
        ));
    }
    // Guess.
    let mut guess = HashMap::new();
    for (n, p) in spec.guess.iter().flatten() {
        if linkage.find_point(n).is_none() {
            return Err(cx.err(
                cx.line(&p.span()),
                format!("guess.{n}"),
                format!("no point '{n}' on any link"),
            ));
        }
        if !all_finite(p.get_ref()) {
            return Err(cx.err(cx.line(&p.span()), format!("guess.{n}"), "non-finite"));
        }
        guess.insert(n.clone(), Vec2::new(p.get_ref()[0], p.get_ref()[1]));
    }
    let guess_line = text_line_of_table(cx.text, "guess").unwrap_or(link_lines[0]);
    let q0 = linkage.coordinates_from_points(&guess, &[]).map_err(|l| {
        cx.err(
            guess_line,
            "guess",
            format!("link '{l}' has no point in [guess] or on the ground"),
        )
    })?;
    let newton = NewtonOptions::default();
    let assembly = match solve_position(&linkage, &q0, assemble_at, &newton) {
        Ok(sol) => sol.q,
        Err(e) => {
            let n_pins = linkage.joints.len() - spec.sliders.len();
            let (line, key) = match e.joint {
                Some(k) if k >= n_pins => (
                    cx.line(&spec.sliders[k - n_pins].span()),
                    format!("sliders[{}]", k - n_pins),
                ),
                Some(k) => match &linkage.joints[k] {
                    super::Joint::Revolute { b, .. } if *b != GROUND => {
                        (link_lines[*b], format!("links.{}", linkage.links[*b].name))
                    }
                    _ => (cx.line(&dspan), "driver".to_string()),
                },
                None => (cx.line(&dspan), "driver".to_string()),
            };
            let at = if angle_input {
                format!("{}°", assemble_at.to_degrees())
            } else {
                format!("{assemble_at} m")
            };
            return Err(cx.err(
                line,
                key,
                format!(
                    "the linkage cannot be assembled at input {at}: {} is off by {:.4} (check the link lengths, the ground points and [guess])",
                    e.what, e.residual
                ),
            ));
        }
    };
    // The assembly must be a regular position (where the guess picks one branch), and the
    // sweep's start reachable from it on that branch.
    {
        let at_key = if angle_input {
            "assemble_at_deg"
        } else {
            "assemble_at"
        };
        let t = super::sweep::Tracker::assemble(&linkage, &assembly, assemble_at, newton)
            .map_err(|e| cx.err(cx.line(&sspan), "sweep", e.to_string()))?;
        // The tracker moves at most `max_step` at a time: from the assembly to `from`,
        // then over the sweep (at most `step` between samples).
        let tracking_steps =
            (from - assemble_at).abs() / t.max_step + (to - from).abs() / step.min(t.max_step);
        if tracking_steps.is_nan() || tracking_steps > 1e6 {
            let at_key = if angle_input {
                "assemble_at_deg"
            } else {
                "assemble_at"
            };
            return Err(cx.err(
                cx.line(&sspan),
                "sweep",
                format!(
                    "more than a million tracking steps from `{at_key}` to the start of the sweep and over it (a tracking step is at most {})",
                    if angle_input {
                        format!("{}°", t.max_step.to_degrees())
                    } else {
                        format!("{} m", t.max_step)
                    }
                ),
            ));
        }
        if t.state().singular {
            return Err(cx.err(
                cx.key_line(&sspan, at_key),
                format!("sweep.{at_key}"),
                "the linkage is at a singular position there (branches meet, the guess cannot pick one): assemble at a regular position",
            ));
        }
        let mut t = t;
        t.advance(from).map_err(|e| {
            let k = if angle_input { "from_deg" } else { "from" };
            cx.err(
                cx.key_line(&sspan, k),
                format!("sweep.{k}"),
                format!("the sweep start is not reachable from the assembly on its branch: {e}"),
            )
        })?;
    }
    // Four-bar and coupler curves.
    let four_bar = match &spec.four_bar {
        None => None,
        Some(fb) => {
            let v = fb.get_ref();
            if v.len() != 4 {
                return Err(cx.err(cx.line(&fb.span()), "four_bar", "give four points [O, A, B, C]: input pivot, input pin, coupler-output pin, output pivot"));
            }
            for n in v {
                if linkage.find_point(n).is_none() {
                    return Err(cx.err(cx.line(&fb.span()), "four_bar", format!("no point '{n}'")));
                }
            }
            Some([v[0].clone(), v[1].clone(), v[2].clone(), v[3].clone()])
        }
    };
    let coupler_curves = match &spec.coupler_curves {
        None => Vec::new(),
        Some(c) => {
            for n in c.get_ref() {
                if linkage.find_point(n).is_none() {
                    return Err(cx.err(
                        cx.line(&c.span()),
                        "coupler_curves",
                        format!("no point '{n}'"),
                    ));
                }
            }
            c.get_ref().clone()
        }
    };
    let kinetostatics = match &spec.kinetostatics {
        None => {
            if let Some(l) = spec.loads.first() {
                return Err(cx.err(
                    cx.line(&l.span()),
                    "loads",
                    "loads need a [kinetostatics] table",
                ));
            }
            None
        }
        Some(k) => Some(parse_kineto(
            cx,
            k,
            &spec.loads,
            &linkage,
            angle_input,
            &report_at,
        )?),
    };
    let counterweight = match &spec.counterweight {
        None => None,
        Some(c) => {
            let span = c.span();
            let cs = c.get_ref();
            let find = |key: &str, n: &str| {
                body_of(&linkage.links, n)
                    .filter(|&b| b != GROUND)
                    .ok_or_else(|| {
                        cx.err(
                            cx.key_line(&span, key),
                            format!("counterweight.{key}"),
                            format!("no link '{n}'"),
                        )
                    })
            };
            if kinetostatics.is_none() {
                return Err(cx.err(
                    cx.line(&span),
                    "counterweight",
                    "needs [kinetostatics] (the shaking force comes from it)",
                ));
            }
            if !(cs.radius.is_finite() && cs.radius > 0.0) {
                return Err(cx.err(
                    cx.key_line(&span, "radius"),
                    "counterweight.radius",
                    "must be positive",
                ));
            }
            if !(cs.fraction.is_finite() && (0.0..=1.0).contains(&cs.fraction)) {
                return Err(cx.err(
                    cx.key_line(&span, "fraction"),
                    "counterweight.fraction",
                    "must be in [0, 1]",
                ));
            }
            Some(CounterweightScenario {
                crank: find("crank", &cs.crank)?,
                rod: find("rod", &cs.rod)?,
                slider: find("slider", &cs.slider)?,
                fraction: cs.fraction,
                radius: cs.radius,
            })
        }
    };
    Ok(MechanismScenario {
        linkage,
        assembly,
        sweep: SweepOptions {
            from,
            to,
            step,
            assemble_at,
            newton,
        },
        angle_input,
        speed: d.speed,
        acceleration: d.acceleration,
        report_at,
        four_bar,
        coupler_curves,
        kinetostatics,
        counterweight,
    })
}

fn text_line_of_table(text: &str, table: &str) -> Option<usize> {
    text.lines()
        .position(|l| l.trim() == format!("[{table}]"))
        .map(|i| i + 1)
}

fn parse_kineto(
    cx: &Source,
    k: &Spanned<KinetoSpec>,
    loads: &[Spanned<LoadSpec>],
    l: &Linkage,
    angle_input: bool,
    sweep_report: &[f64],
) -> Result<KinetostaticsScenario, ScenarioError> {
    let span = k.span();
    let ks = k.get_ref();
    let g = ks.gravity.unwrap_or([0.0, -9.81]);
    if !all_finite(&g) {
        return Err(cx.err(
            cx.key_line(&span, "gravity"),
            "kinetostatics.gravity",
            "non-finite",
        ));
    }
    if angle_input && !ks.report_at.is_empty() {
        return Err(cx.err(
            cx.key_line(&span, "report_at"),
            "kinetostatics.report_at",
            "an angle driver: use report_at_deg",
        ));
    }
    if !angle_input && !ks.report_at_deg.is_empty() {
        return Err(cx.err(
            cx.key_line(&span, "report_at_deg"),
            "kinetostatics.report_at_deg",
            "a slide driver: use report_at (m)",
        ));
    }
    let mut report_at: Vec<f64> = if angle_input {
        ks.report_at_deg.iter().map(|x| x.to_radians()).collect()
    } else {
        ks.report_at.clone()
    };
    if report_at.is_empty() {
        report_at = sweep_report.to_vec();
    }
    let mut out = Loads {
        gravity: Vec2::new(g[0], g[1]),
        ..Default::default()
    };
    for (i, ls) in loads.iter().enumerate() {
        let s = ls.get_ref();
        let span = ls.span();
        let key = format!("loads[{i}]");
        let link = body_of(&l.links, &s.link)
            .filter(|&b| b != GROUND)
            .ok_or_else(|| {
                cx.err(
                    cx.key_line(&span, "link"),
                    format!("{key}.link"),
                    format!("no link '{}'", s.link),
                )
            })?;
        if s.force.is_none() && s.torque.is_none() {
            return Err(cx.err(
                cx.line(&span),
                key,
                "a load needs `force` (with `point`) or `torque`",
            ));
        }
        if let Some(f) = s.force {
            let pn = s.point.as_ref().ok_or_else(|| {
                cx.err(
                    cx.key_line(&span, "force"),
                    format!("{key}.point"),
                    "missing: where the force acts",
                )
            })?;
            let p = l.links[link].point(pn).ok_or_else(|| {
                cx.err(
                    cx.key_line(&span, "point"),
                    format!("{key}.point"),
                    format!("link '{}' has no point '{pn}'", s.link),
                )
            })?;
            if !all_finite(&f) {
                return Err(cx.err(
                    cx.key_line(&span, "force"),
                    format!("{key}.force"),
                    "non-finite",
                ));
            }
            out.forces.push(PointForce {
                link,
                p,
                force: Vec2::new(f[0], f[1]),
            });
        }
        if let Some(t) = s.torque {
            if !t.is_finite() {
                return Err(cx.err(
                    cx.key_line(&span, "torque"),
                    format!("{key}.torque"),
                    "non-finite",
                ));
            }
            out.torques.push((link, t));
        }
    }
    Ok(KinetostaticsScenario {
        loads: out,
        report_at,
    })
}

fn parse_flywheel(
    cx: &Source,
    f: &Spanned<FlywheelSpec>,
    mech: Option<&MechanismScenario>,
) -> Result<FlywheelScenario, ScenarioError> {
    let span = f.span();
    let s = f.get_ref();
    if !(s.speed_fluctuation.is_finite() && s.speed_fluctuation > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "speed_fluctuation"),
            "flywheel.speed_fluctuation",
            "must be positive",
        ));
    }
    let speed = match (s.speed, mech) {
        (Some(w), _) => w,
        (None, Some(m)) if m.angle_input => m.speed,
        _ => {
            return Err(cx.err(
                cx.line(&span),
                "flywheel.speed",
                "missing: the mean speed (rad/s)",
            ))
        }
    };
    if !(speed.is_finite() && speed != 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "speed"),
            "flywheel.speed",
            "must be non-zero",
        ));
    }
    let table = match &s.torque_deg {
        Some(t) => {
            if t.len() < 3
                || t.iter().any(|r| !all_finite(r))
                || t.windows(2).any(|w| w[1][0] <= w[0][0])
            {
                return Err(cx.err(
                    cx.key_line(&span, "torque_deg"),
                    "flywheel.torque_deg",
                    "needs at least three finite [angle_deg, torque] rows with increasing angles",
                ));
            }
            Some(t.iter().map(|r| (r[0].to_radians(), r[1])).collect())
        }
        None => {
            if mech.and_then(|m| m.kinetostatics.as_ref()).is_none()
                || !mech.is_some_and(|m| m.angle_input)
            {
                return Err(cx.err(
                    cx.line(&span),
                    "flywheel",
                    "needs `torque_deg` or a crank-driven linkage with [kinetostatics]",
                ));
            }
            None
        }
    };
    Ok(FlywheelScenario {
        delta: s.speed_fluctuation,
        speed,
        load: s.load,
        table,
    })
}

fn parse_rotor(cx: &Source, r: &Spanned<RotorSpec>) -> Result<RotorScenario, ScenarioError> {
    let span = r.span();
    let s = r.get_ref();
    let n = s.masses.len();
    for (k, v) in [
        ("radii", &s.radii),
        ("angles_deg", &s.angles_deg),
        ("positions", &s.positions),
    ] {
        if v.len() != n {
            return Err(cx.err(
                cx.key_line(&span, k),
                format!("rotor_balance.{k}"),
                format!("has {} values, `masses` has {n}", v.len()),
            ));
        }
    }
    for (k, v) in [
        ("masses", &s.masses),
        ("radii", &s.radii),
        ("angles_deg", &s.angles_deg),
        ("positions", &s.positions),
        ("planes", &s.planes),
        ("plane_radii", &s.plane_radii),
    ] {
        if !all_finite(v) {
            return Err(cx.err(
                cx.key_line(&span, k),
                format!("rotor_balance.{k}"),
                "non-finite value",
            ));
        }
    }
    if n == 0 {
        return Err(cx.err(
            cx.key_line(&span, "masses"),
            "rotor_balance.masses",
            "no masses",
        ));
    }
    if s.planes.is_empty() || s.planes.len() > 2 || s.plane_radii.len() != s.planes.len() {
        return Err(cx.err(
            cx.key_line(&span, "planes"),
            "rotor_balance.planes",
            "give one (static) or two (dynamic) correction planes and as many `plane_radii`",
        ));
    }
    if s.plane_radii.iter().any(|&x| x <= 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "plane_radii"),
            "rotor_balance.plane_radii",
            "must be positive",
        ));
    }
    if s.planes.len() == 2 && s.planes[0] == s.planes[1] {
        return Err(cx.err(
            cx.key_line(&span, "planes"),
            "rotor_balance.planes",
            "the two planes coincide",
        ));
    }
    Ok(RotorScenario {
        masses: (0..n)
            .map(|k| RotorMass {
                mass: s.masses[k],
                radius: s.radii[k],
                angle: s.angles_deg[k].to_radians(),
                position: s.positions[k],
            })
            .collect(),
        planes: s
            .planes
            .iter()
            .copied()
            .zip(s.plane_radii.iter().copied())
            .collect(),
    })
}

fn parse_machine(cx: &Source, m: &Spanned<MachineSpec>) -> Result<MachineScenario, ScenarioError> {
    let span = m.span();
    let s = m.get_ref();
    if !(s.inertia.is_finite() && s.inertia > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "inertia"),
            "machine_motion.inertia",
            "must be positive",
        ));
    }
    if s.drive.is_empty() || !all_finite(&s.drive) {
        return Err(cx.err(
            cx.key_line(&span, "drive"),
            "machine_motion.drive",
            "give the coefficients of M_d(ω) = c0 + c1 ω + …",
        ));
    }
    if !(s.t_end.is_finite() && s.t_end > 0.0) {
        return Err(cx.err(
            cx.key_line(&span, "t_end"),
            "machine_motion.t_end",
            "must be positive",
        ));
    }
    let dt = s.dt.unwrap_or(s.t_end / 1000.0);
    if !(dt.is_finite() && dt > 0.0) || s.t_end / dt > 1e7 {
        return Err(cx.err(
            cx.key_line(&span, "dt"),
            "machine_motion.dt",
            "must be positive (and at most 1e7 steps)",
        ));
    }
    if !(s.load.is_finite() && s.omega0.is_finite()) {
        return Err(cx.err(
            cx.line(&span),
            "machine_motion",
            "non-finite load or omega0",
        ));
    }
    Ok(MachineScenario {
        inertia: s.inertia,
        drive: Characteristic(s.drive.clone()),
        load: s.load,
        omega0: s.omega0,
        t_end: s.t_end,
        dt,
    })
}

/// Runs a linkage scenario: parses it and produces the report.
pub fn run(path: &Path, text: &str) -> Result<Report, ScenarioError> {
    let sc = parse(&path.display().to_string(), text)?;
    Ok(super::report::report(&sc))
}
