//! The robots the studies use, embedded at build time so `armsim tradeoffs` runs without
//! the source tree: their texts and the models built from them.

/// The robots the studies use, embedded so the command runs without the source tree.
const ROBOTS: [(&str, &str); 5] = [
    (
        "ur5.urdf",
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/ur5.urdf")),
    ),
    (
        "panda.urdf",
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/panda.urdf")),
    ),
    (
        "iiwa14.urdf",
        include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/robots/iiwa14.urdf")),
    ),
    (
        "planar_2r.toml",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/planar_2r.toml"
        )),
    ),
    (
        "textbook_spherical_rrp.toml",
        include_str!(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/robots/textbook_spherical_rrp.toml"
        )),
    ),
];

/// The text of a bundled robot file (`robots/NAME`, embedded at build time).
pub(crate) fn robot_text(name: &str) -> Result<&'static str, String> {
    ROBOTS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, t)| *t)
        .ok_or_else(|| format!("robots/{name} is not embedded"))
}

/// Builds a model from the text of a URDF (`.urdf`) or DH table (`.toml`) file.
pub(crate) fn model_from_text(text: &str, file: &str) -> Result<crate::model::Model, String> {
    use crate::model::parse::{dh_table as dh, urdf};
    use crate::model::Model;
    let spec = if file.ends_with(".urdf") {
        urdf::parse(text, file)
    } else {
        dh::parse(text, file)
    }
    .map_err(|e| e.to_string())?;
    Model::build(spec)
        .map(|(m, _)| m)
        .map_err(|e| e.to_string())
}

/// A bundled robot (`robots/NAME`), from the embedded text.
pub(crate) fn bundled_robot(name: &str) -> Result<crate::model::Model, String> {
    model_from_text(robot_text(name)?, &format!("robots/{name}"))
}
