//! Scenario files (TOML) and `armsim run`: the top-level `kind` key picks the kind from
//! one registry, [`KINDS`]. Every kind is one module here that parses its file into
//! typed sections, runs the algorithms of the layers below (arms, linkages, gears, cams,
//! friction, vibration) and builds a [`Report`] (the JSON document and a human summary);
//! errors are [`ScenarioError`]s naming the file, the line and the key.
//!
//! Adding a kind: write its module (with a `pub const KIND:` [`ScenarioKind`]: the name, a
//! check and a run), then add `pub mod` and one entry of [`KINDS`] below. Nothing else
//! names it.

pub mod arm;
pub mod cam;
pub mod cam_motion;
pub mod cam_profile_section;
pub mod cam_report;
pub mod centrodes;
pub mod flexible_rotor;
pub mod flywheel;
pub mod friction;
pub mod friction_bodies;
pub mod gear_pair;
pub mod gear_pair_profiles;
pub mod gear_pair_query;
pub mod gear_pair_report;
pub mod gear_train;
pub mod gear_train_report;
pub mod gear_train_selection;
pub mod isolation;
pub mod kind;
pub mod kit;
pub mod linkage;
pub mod source;
pub mod synthesis;
pub mod synthesis_crank_rocker;
pub mod synthesis_two_position;
pub mod torsional;

use std::path::Path;

pub use crate::core::diag::{line_at, line_of_key};
pub use crate::io::report::Report;
pub use crate::scenarios::kind::{OnStop, RunOptions, ScenarioError, ScenarioKind};

/// Every scenario kind. The first is the one a file without a `kind` key gets.
pub static KINDS: &[&ScenarioKind] = &[
    &arm::KIND,
    &linkage::KIND,
    &torsional::KIND,
    &gear_train::KIND,
    &gear_pair::KIND,
    &cam::KIND,
    &friction::KIND,
    &synthesis::KIND,
    &flywheel::KIND,
    &flexible_rotor::KIND,
    &isolation::KIND,
    &centrodes::KIND,
];

/// Every `kind` name, for the messages: `"arm", "linkage", … or "centrodes"`.
fn kind_names() -> String {
    let names: Vec<String> = KINDS.iter().map(|k| format!("\"{}\"", k.name)).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    }
}

/// Parses `text` as TOML (refusing an empty file) and finds the kind its `kind` key
/// names (the first of [`KINDS`] when there is none).
pub fn kind(file: &str, text: &str) -> Result<&'static ScenarioKind, ScenarioError> {
    if text.trim().is_empty() {
        return Err(ScenarioError::new(
            file,
            Some(1),
            "file",
            "the file is empty",
        ));
    }
    // A model or a MoveIt file handed to `run` by mistake: say what it is, not a TOML error.
    let first = text.trim_start().trim_start_matches('\u{feff}');
    if first.starts_with('<') {
        return Err(ScenarioError::new(
            file,
            Some(1),
            "file",
            "this is an XML file (a URDF, SRDF or mesh?), not a scenario: a scenario is a TOML \
             file (`kind = \"arm\"`, `[model] file = \"robot.urdf\"`, … see scenarios/README.md)",
        ));
    }
    // The task lists' length, before the whole file is parsed (a 10⁶-entry list took
    // seconds to parse before its count was checked).
    crate::scenarios::arm::task_prescan::check(file, text)?;
    let table: toml::Table =
        toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let kind_error = |msg: String| ScenarioError::new(file, line_of_key(text, "kind"), "kind", msg);
    match table.get("kind") {
        None => Ok(KINDS[0]),
        Some(toml::Value::String(k)) => KINDS
            .iter()
            .copied()
            .find(|kind| kind.name == k.as_str())
            .ok_or_else(|| {
                kind_error(format!(
                    "unknown scenario kind '{k}' (expected {})",
                    kind_names()
                ))
            }),
        Some(_) => Err(kind_error(format!("expected a string: {}", kind_names()))),
    }
}

/// Reads a scenario file and runs it (arm scenarios write their files to `out/<name>`).
pub fn run_file(path: &Path) -> Result<Report, ScenarioError> {
    run_file_with(path, &RunOptions::default())
}

/// Reads a scenario file and runs it with `opts` (output directory, interrupt). A report
/// whose summary would show a non-finite number (`NaN`, `inf`) is refused with that line:
/// never a printed NaN with exit 0.
pub fn run_file_with(path: &Path, opts: &RunOptions) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| ScenarioError::new(&file, None, "file", format!("cannot read: {e}")))?;
    let report = (kind(&file, &text)?.run)(path, &text, opts)?;
    match report.non_finite_line() {
        Some(line) => Err(ScenarioError::new(
            &file,
            None,
            "result",
            format!(
                "a result is not finite ({line}): an input lies outside the range where this \
                 analysis means something; check the magnitudes of the values it depends on"
            ),
        )),
        None => Ok(report),
    }
}

/// Parses and validates scenario text without running the analyses (the fuzz targets'
/// entry: no filesystem, no long computation); `file` names the text in messages. Same
/// `kind` dispatch and messages as [`run_file`]. Arm scenarios are validated up to the
/// planning ([`crate::scenarios::arm::load`]: model file read relative to `file`, no IK,
/// no run).
pub fn check(file: &str, text: &str) -> Result<(), ScenarioError> {
    (kind(file, text)?.check)(file, text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_has_its_own_name_and_the_message_lists_them_all() {
        let mut names: Vec<&str> = KINDS.iter().map(|k| k.name).collect();
        assert_eq!(names.len(), 12);
        names.sort();
        names.dedup();
        assert_eq!(names.len(), 12, "two kinds share a name");
        let msg = kind_names();
        assert!(
            msg.starts_with("\"arm\", \"linkage\", ") && msg.ends_with(" or \"centrodes\""),
            "{msg}"
        );
        assert_eq!(
            kind("f", "kind = \"cam\"\n").map(|k| k.name).ok(),
            Some("cam")
        );
        assert_eq!(kind("f", "x = 1\n").map(|k| k.name).ok(), Some("arm"));
        let urdf = kind("r.urdf", "<?xml version=\"1.0\"?>\n<robot name=\"r\"/>\n")
            .map(|k| k.name)
            .unwrap_err();
        assert!(
            urdf.message.contains("XML file") && urdf.line == Some(1),
            "{urdf}"
        );
    }
}
