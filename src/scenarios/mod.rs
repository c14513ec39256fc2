//! Scenario files (TOML) and `armsim run`: the top-level `kind` key picks the runner.
//!
//! - `kind = "linkage"`: a closed-chain planar mechanism ([`crate::machines::linkage`]);
//! - `kind = "torsional"`: a torsional drivetrain chain ([`crate::machines::vibration::torsional`]);
//! - `kind = "arm"` (the default): an arm scenario (planned motion, torque check,
//!   collisions, simulation; [`crate::scenarios::arm`]).
//!
//! This module is the dispatcher only: [`kind`] reads the key once for [`run_file_with`]
//! and [`check`]. Every runner returns a [`Report`] (the JSON document and a human
//! summary) or a [`ScenarioError`] naming the file, the line and the key; both live in
//! leaf modules ([`crate::io::report`], [`crate::core::diag`]) so the runners never import this one.

pub mod arm;
pub mod cam;
pub mod cam_report;
pub mod centrodes;
pub mod flexible_rotor;
pub mod flywheel;
pub mod friction;
pub mod gear_pair;
pub mod gear_pair_report;
pub mod gear_train;
pub mod gear_train_report;
pub mod isolation;
pub mod kit;
pub mod linkage;
pub mod source;
pub mod spans;
pub mod synthesis;
pub mod torsional;
use std::path::Path;

pub use crate::core::diag::{line_at, line_of_key};
pub use crate::io::report::Report;

/// An error in a scenario file (the crate's one located error).
pub type ScenarioError = crate::core::diag::LocatedError;

/// The runner a scenario file asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `kind = "arm"` or no `kind`.
    Arm,
    /// `kind = "linkage"`.
    Linkage,
    /// `kind = "torsional"`.
    Torsional,
    /// `kind = "gear_train"`.
    GearTrain,
    /// `kind = "gear_pair"`.
    GearPair,
    /// `kind = "cam"`.
    Cam,
    /// `kind = "friction"`.
    Friction,
    /// `kind = "synthesis"`.
    Synthesis,
    /// `kind = "flywheel"`.
    Flywheel,
    /// `kind = "flexible_rotor"`.
    FlexibleRotor,
    /// `kind = "isolation"`.
    Isolation,
    /// `kind = "centrodes"`.
    Centrodes,
}

/// Every `kind` name, for the messages.
const KINDS: &str = "\"arm\", \"linkage\", \"torsional\", \"gear_train\", \"gear_pair\", \"cam\", \"friction\", \"synthesis\", \"flywheel\", \"flexible_rotor\", \"isolation\" or \"centrodes\"";

/// Parses `text` as TOML (refusing an empty file) and reads its `kind`.
pub fn kind(file: &str, text: &str) -> Result<Kind, ScenarioError> {
    if text.trim().is_empty() {
        return Err(ScenarioError::new(
            file,
            Some(1),
            "file",
            "the file is empty",
        ));
    }
    let table: toml::Table =
        toml::from_str(text).map_err(|e| ScenarioError::from_toml(file, text, &e))?;
    let kind_error = |msg: String| ScenarioError::new(file, line_of_key(text, "kind"), "kind", msg);
    match table.get("kind") {
        None => Ok(Kind::Arm),
        Some(toml::Value::String(k)) => match k.as_str() {
            "arm" => Ok(Kind::Arm),
            "linkage" => Ok(Kind::Linkage),
            "torsional" => Ok(Kind::Torsional),
            "gear_train" => Ok(Kind::GearTrain),
            "gear_pair" => Ok(Kind::GearPair),
            "cam" => Ok(Kind::Cam),
            "friction" => Ok(Kind::Friction),
            "synthesis" => Ok(Kind::Synthesis),
            "flywheel" => Ok(Kind::Flywheel),
            "flexible_rotor" => Ok(Kind::FlexibleRotor),
            "isolation" => Ok(Kind::Isolation),
            "centrodes" => Ok(Kind::Centrodes),
            other => Err(kind_error(format!(
                "unknown scenario kind '{other}' (expected {KINDS})"
            ))),
        },
        Some(_) => Err(kind_error(format!("expected a string: {KINDS}"))),
    }
}

/// Reads a scenario file and runs it (arm scenarios write their files to `out/<name>`).
pub fn run_file(path: &Path) -> Result<Report, ScenarioError> {
    run_file_with(path, &crate::scenarios::arm::RunOptions::default())
}

/// Reads a scenario file and runs it with `opts` (output directory, interrupt).
pub fn run_file_with(
    path: &Path,
    opts: &crate::scenarios::arm::RunOptions,
) -> Result<Report, ScenarioError> {
    let file = path.display().to_string();
    let text = crate::core::files::read_input_string(path)
        .map_err(|e| ScenarioError::new(&file, None, "file", format!("cannot read: {e}")))?;
    match kind(&file, &text)? {
        Kind::Linkage => crate::scenarios::linkage::run(path, &text),
        Kind::Torsional => crate::scenarios::torsional::run(path, &text),
        Kind::GearTrain => crate::scenarios::gear_train::run(path, &text),
        Kind::GearPair => crate::scenarios::gear_pair::run(path, &text, opts.out_dir.as_deref()),
        Kind::Cam => crate::scenarios::cam::run(path, &text, opts.out_dir.as_deref()),
        Kind::Friction => crate::scenarios::friction::run(path, &text),
        Kind::Synthesis => crate::scenarios::synthesis::run(path, &text, opts.out_dir.as_deref()),
        Kind::Flywheel => crate::scenarios::flywheel::run(path, &text, opts.out_dir.as_deref()),
        Kind::FlexibleRotor => {
            crate::scenarios::flexible_rotor::run(path, &text, opts.out_dir.as_deref())
        }
        Kind::Isolation => crate::scenarios::isolation::run(path, &text, opts.out_dir.as_deref()),
        Kind::Centrodes => crate::scenarios::centrodes::run(path, &text, opts.out_dir.as_deref()),
        Kind::Arm => crate::scenarios::arm::run(path, &text, opts).map(|o| o.report),
    }
}

/// Parses and validates scenario text without running the analyses (the fuzz targets'
/// entry: no filesystem, no long computation); `file` names the text in messages. Same
/// `kind` dispatch and messages as [`run_file`]. Arm scenarios are validated up to the
/// planning ([`crate::scenarios::arm::load`]: model file read relative to `file`, no IK, no run).
pub fn check(file: &str, text: &str) -> Result<(), ScenarioError> {
    match kind(file, text)? {
        Kind::Linkage => crate::scenarios::linkage::parse(file, text).map(drop),
        Kind::Torsional => crate::scenarios::torsional::parse(file, text).map(drop),
        Kind::GearTrain => crate::scenarios::gear_train::parse(file, text).map(drop),
        Kind::GearPair => crate::scenarios::gear_pair::parse(file, text).map(drop),
        Kind::Cam => crate::scenarios::cam::parse(file, text).map(drop),
        Kind::Friction => crate::scenarios::friction::parse(file, text),
        Kind::Synthesis => crate::scenarios::synthesis::parse(file, text).map(drop),
        Kind::Flywheel => crate::scenarios::flywheel::parse(file, text).map(drop),
        Kind::FlexibleRotor => crate::scenarios::flexible_rotor::parse(file, text).map(drop),
        Kind::Isolation => crate::scenarios::isolation::parse(file, text).map(drop),
        Kind::Centrodes => crate::scenarios::centrodes::parse(file, text).map(drop),
        Kind::Arm => crate::scenarios::arm::load(Path::new(file), text).map(drop),
    }
}
