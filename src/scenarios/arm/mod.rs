//! Arm scenarios (`kind = "arm"`, the default): one TOML file names a model, the effects
//! the scene calls for, obstacles, a task and how to time it, and the simulation; `armsim
//! run` plans the motion, checks the joint torques it needs against the limits, checks
//! collisions along it, simulates it with exactly the named effects and writes the
//! outputs. `scenarios/README.md` documents the format.
//!
//! - [`schema`]: the file's serde structures (unknown keys refused);
//! - [`scene`]: validation into a [`scene::Scene`] (errors name the file, line and key);
//! - [`plan`]: the task as one timed trajectory;
//! - [`budget`]: the work budgets of a run (steps and samples), checked before the work;
//! - [`planned`]: the RRT-Connect planners of a scene and smooth planned paths;
//! - [`planner_settings`]: the validated `[planner]` settings and the grasped part;
//! - [`checks`]: the collision check with the grasped part, the planned tool path;
//! - [`contact`]: the rapier3d contact scene, built only for the `contact` effect;
//! - [`run`]: the end-to-end run and its report;
//! - [`plots`]: the simulation plot;
//! - `topp_bench`: the hidden `ARMSIM_TOPP_DUMP` hook of `tools/bench_topp.py`.

pub mod budget;
pub mod checks;
pub mod contact;
pub mod planner_settings;
pub mod planner_setup;
pub mod run;
pub mod scene;
pub mod schema;
pub mod sim_plots;
pub mod task_motion;
pub mod task_prescan;
mod topp_bench;
pub use crate::scenarios::arm::run::{run_scene, Outcome, RunOptions, SimSample};

use crate::core::diag::LocatedError as ScenarioError;
use std::path::{Path, PathBuf};

/// Parses and validates an arm scenario without running it.
pub fn load(path: &Path, text: &str) -> Result<scene::Scene, ScenarioError> {
    load_with(path, text, &[])
}

/// [`load`] with package paths from the command line (searched first for `package://`
/// mesh URIs).
pub fn load_with(
    path: &Path,
    text: &str,
    package_path: &[PathBuf],
) -> Result<scene::Scene, ScenarioError> {
    let file = path.display().to_string();
    let parsed: schema::ArmFile =
        toml::from_str(text).map_err(|e| ScenarioError::from_toml(&file, text, &e))?;
    scene::build_with(path, text, &parsed, package_path)
}

/// Parses, validates and runs an arm scenario.
pub fn run(path: &Path, text: &str, opts: &RunOptions) -> Result<Outcome, ScenarioError> {
    run_scene(load_with(path, text, &opts.package_path)?, opts)
}

/// The `kind` value of these scenario files.
pub const NAME: &str = "arm";

/// The registry entry of these files ([`crate::scenarios::KINDS`]).
pub const KIND: crate::scenarios::kind::ScenarioKind = crate::scenarios::kind::ScenarioKind {
    name: NAME,
    check: |file, text| load(std::path::Path::new(file), text).map(drop),
    run: |path, text, opts| run(path, text, opts).map(|o| o.report),
};
