//! The TOML schema of a linkage scenario (the `serde` tables the section parsers read)
//! and the small lookups they share: a link by name, a unit direction, a table's line.

use crate::core::diag::LocatedError as ScenarioError;
use crate::machines::linkage::description::{PlanarLink, GROUND};
use crate::machines::linkage::Vec2;
use crate::scenarios::source::Source;
use serde::Deserialize;
use std::collections::BTreeMap;
use toml::Spanned;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Spec {
    #[allow(dead_code)]
    pub(super) kind: String,
    pub(super) name: Option<String>,
    pub(super) description: Option<String>,
    pub(super) ground: Option<BTreeMap<String, Spanned<[f64; 2]>>>,
    pub(super) links: Option<BTreeMap<String, Spanned<LinkSpec>>>,
    #[serde(default)]
    pub(super) sliders: Vec<Spanned<SliderSpec>>,
    #[serde(default)]
    pub(super) contacts: Vec<Spanned<crate::scenarios::linkage::contacts_spec::ContactSpec>>,
    pub(super) driver: Option<Spanned<DriverSpec>>,
    pub(super) guess: Option<BTreeMap<String, Spanned<[f64; 2]>>>,
    pub(super) sweep: Option<Spanned<SweepSpec>>,
    pub(super) four_bar: Option<Spanned<Vec<String>>>,
    pub(super) coupler_curves: Option<Spanned<Vec<String>>>,
    pub(super) kinetostatics: Option<Spanned<KinetoSpec>>,
    pub(super) instant_centres: Option<Spanned<CentresSpec>>,
    #[serde(default)]
    pub(super) loads: Vec<Spanned<LoadSpec>>,
    pub(super) counterweight: Option<Spanned<CounterweightSpec>>,
    pub(super) flywheel: Option<Spanned<FlywheelSpec>>,
    pub(super) rotor_balance: Option<Spanned<RotorSpec>>,
    pub(super) machine_motion: Option<Spanned<MachineSpec>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LinkSpec {
    pub(super) ends: Option<[String; 2]>,
    pub(super) length: Option<f64>,
    pub(super) points: Option<BTreeMap<String, [f64; 2]>>,
    pub(super) mass: Option<f64>,
    pub(super) com: Option<[f64; 2]>,
    pub(super) inertia: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SliderSpec {
    pub(super) link: String,
    pub(super) point: String,
    #[serde(default = "ground_name")]
    pub(super) guide: String,
    pub(super) through: [f64; 2],
    pub(super) direction: [f64; 2],
    #[serde(rename = "type", default = "prismatic_name")]
    pub(super) kind: String,
    pub(super) angle_deg: Option<f64>,
    /// Two bearing points along the line (m): the reaction as two normal forces.
    pub(super) contacts: Option<Vec<f64>>,
    /// Where `contacts` are measured: "guide" (from `through`, default) or "link".
    pub(super) contacts_on: Option<String>,
}

fn ground_name() -> String {
    "ground".into()
}

fn prismatic_name() -> String {
    "prismatic".into()
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct DriverSpec {
    pub(super) link: String,
    #[serde(rename = "type", default = "angle_name")]
    pub(super) kind: String,
    pub(super) relative_to: Option<String>,
    pub(super) point: Option<String>,
    pub(super) through: Option<[f64; 2]>,
    pub(super) direction: Option<[f64; 2]>,
    pub(super) speed: f64,
    #[serde(default)]
    pub(super) acceleration: f64,
}

fn angle_name() -> String {
    "angle".into()
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub(super) struct SweepSpec {
    pub(super) from_deg: Option<f64>,
    pub(super) to_deg: Option<f64>,
    pub(super) step_deg: Option<f64>,
    pub(super) assemble_at_deg: Option<f64>,
    #[serde(default)]
    pub(super) report_at_deg: Vec<f64>,
    pub(super) from: Option<f64>,
    pub(super) to: Option<f64>,
    pub(super) step: Option<f64>,
    pub(super) assemble_at: Option<f64>,
    #[serde(default)]
    pub(super) report_at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KinetoSpec {
    pub(super) gravity: Option<[f64; 2]>,
    pub(super) friction_coefficient: Option<f64>,
    pub(super) pin_radius: Option<f64>,
    /// Per-joint pin radii (m) by joint name, over `pin_radius`.
    pub(super) pin_radii: Option<std::collections::BTreeMap<String, f64>>,
    #[serde(default)]
    pub(super) report_at_deg: Vec<f64>,
    #[serde(default)]
    pub(super) report_at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CentresSpec {
    #[serde(default)]
    pub(super) report_at_deg: Vec<f64>,
    #[serde(default)]
    pub(super) report_at: Vec<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LoadSpec {
    pub(super) link: String,
    pub(super) point: Option<String>,
    pub(super) force: Option<[f64; 2]>,
    pub(super) torque: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CounterweightSpec {
    pub(super) crank: String,
    pub(super) rod: String,
    pub(super) slider: String,
    pub(super) fraction: Option<f64>,
    pub(super) radius: f64,
    pub(super) rod_radius: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct FlywheelSpec {
    pub(super) speed_fluctuation: f64,
    pub(super) speed: Option<f64>,
    pub(super) load: Option<f64>,
    pub(super) torque_deg: Option<Vec<[f64; 2]>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RotorSpec {
    pub(super) masses: Vec<f64>,
    pub(super) radii: Vec<f64>,
    pub(super) angles_deg: Vec<f64>,
    pub(super) positions: Vec<f64>,
    pub(super) planes: Vec<f64>,
    pub(super) plane_radii: Vec<f64>,
    pub(super) speed_rpm: Option<f64>,
    pub(super) bearings: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct MachineSpec {
    pub(super) inertia: Option<f64>,
    pub(super) ratio: Option<f64>,
    pub(super) motor_inertia: Option<f64>,
    pub(super) inertia_deg: Option<Vec<[f64; 2]>>,
    pub(super) inertia_from_linkage: Option<bool>,
    pub(super) drive: Vec<f64>,
    pub(super) load: f64,
    #[serde(default)]
    pub(super) omega0: f64,
    pub(super) t_end: f64,
    pub(super) dt: Option<f64>,
}

/// The link named `name` (`ground` is [`GROUND`]).
pub(super) fn body_of(links: &[PlanarLink], name: &str) -> Option<usize> {
    if name == "ground" {
        Some(GROUND)
    } else {
        links.iter().position(|l| l.name == name)
    }
}

/// The line (1-based) of the `[table]` header in `text`.
pub(super) fn text_line_of_table(text: &str, table: &str) -> Option<usize> {
    text.lines()
        .position(|l| l.trim() == format!("[{table}]"))
        .map(|i| i + 1)
}

/// The moving link named `name` (not the ground), or an error at `key` of the table at
/// `span` that names it as `table.key`.
pub(super) fn moving_link(
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

/// `v` scaled to unit length, `None` for a zero or non-finite vector.
pub(super) fn unit(v: [f64; 2]) -> Option<Vec2> {
    let d = Vec2::new(v[0], v[1]);
    let n = d.norm();
    (n > 0.0 && n.is_finite()).then(|| d / n)
}
