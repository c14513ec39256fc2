//! The TOML schema of `[[contacts]]` (cam contacts of a linkage scenario): the two links,
//! a circle or a line on each, the side and the contact's friction; read by
//! [`crate::scenarios::linkage::contacts_section`].

use serde::Deserialize;

/// One `[[contacts]]` entry.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ContactSpec {
    pub(super) name: Option<String>,
    pub(super) links: [String; 2],
    pub(super) profiles: [ProfileSpec; 2],
    pub(super) side: Option<String>,
    pub(super) friction_coefficient: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ProfileSpec {
    pub(super) circle: Option<CircleSpec>,
    pub(super) line: Option<LineSpec>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CircleSpec {
    pub(super) centre: PointRef,
    pub(super) radius: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LineSpec {
    pub(super) through: PointRef,
    pub(super) direction: [f64; 2],
}

/// A point of a body: coordinates in its frame, or the name of one of its points.
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum PointRef {
    At([f64; 2]),
    Named(String),
}
