//! Validation of an arm scenario: from the parsed [`ArmFile`] to a [`Scene`] whose every
//! part is checked (model loaded, joints named, limits consistent with each other and with
//! the model, effects built, poses in the robot's base frame). Every error names the
//! file, the line and the key.
//!
//! [`build`] reads the sections in file order, one module each: [`model`] (name, model
//! file, base, tool), [`effects`], [`limits`] (and the initial configuration),
//! [`obstacles`] (obstacles, collision settings, contact scene), [`task`] (steps, part,
//! planner), [`simulation`] (trajectory timing and simulation settings) and [`outputs`].

pub(crate) mod arm_scene;
mod constraint_sections;
mod effect_sections;
mod limits;
mod model;
mod obstacle_sections;
mod output_sections;
mod section_reader;
mod simulation;
mod task;
pub mod transmission;

pub use arm_scene::{
    ContactScene, Outputs, Scene, SettingLines, SimSettings, Step, TaskStep, Timing, EFFECT_NAMES,
};
pub use section_reader::per_joint;
pub use task::MAX_TASK_STEPS;

use crate::core::diag::LocatedError as ScenarioError;
use crate::scenarios::arm::schema::ArmFile;
use crate::scenarios::source::Source;
use section_reader::Sections;
use std::path::{Path, PathBuf};

/// Validates `file` (read from `path`) into a [`Scene`].
pub fn build(path: &Path, text: &str, file: &ArmFile) -> Result<Scene, ScenarioError> {
    build_with(path, text, file, &[])
}

/// [`build`] with package paths from the command line, searched before the file's
/// `model.package_path` and the environment.
pub fn build_with(
    path: &Path,
    text: &str,
    file: &ArmFile,
    package_path: &[PathBuf],
) -> Result<Scene, ScenarioError> {
    let fname = path.display().to_string();
    let cx = Source { file: &fname, text };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut warnings = Vec::new();
    let name = model::scene_name(&cx, path, file)?;
    let named = effect_sections::named(&cx, file, &mut warnings)?;
    let ms = model::load(&cx, file, dir, package_path, &mut warnings)?;
    let sx = Sections {
        cx,
        file,
        dir,
        model: &ms.model,
        names: ms.model.dof_names(),
        n: ms.model.nv,
        tool: ms.tool,
        base: ms.base,
        base_inv: ms.base.inverse(),
    };
    let (effects, payload_masses, payload_inertia, transmissions) =
        effect_sections::build(&sx, &named)?;
    let (lower, upper) = limits::position_limits(&sx)?;
    let rate = limits::rate_limits(&sx)?;
    let q0 = limits::initial(&sx, &lower, &upper)?;
    let obstacles = obstacle_sections::obstacles(&sx)?;
    let coll = obstacle_sections::collision(&sx, ms.touching.clone(), &obstacles)?;
    let contact = obstacle_sections::contact(&sx, &named)?;
    let steps = task::steps(&sx, &q0, &lower, &upper)?;
    let traj = simulation::trajectory(&sx)?;
    let simulation = simulation::simulation(&sx, &effects)?;
    if contact.is_some() && simulation.is_none() {
        return Err(cx.at(
            file.effects.span(),
            "effects",
            "effect 'contact' needs the simulation (simulation.enabled = false contradicts it)",
        ));
    }
    let torque_plot = output_sections::torque_plot(&sx)?;
    let plans = steps
        .iter()
        .any(|s| matches!(s.step, Step::Plan(_) | Step::PlanTo(_)));
    limits::jerk_applies(&sx, traj.timing == Timing::TimeOptimal, plans)?;
    let planner = task::planner_settings(&cx, file, dir, &ms.model, plans, &mut warnings)?;
    let queries = steps.iter().any(|s| matches!(s.step, Step::PlanTo(_)));
    task::optimiser_applies(&cx, file, queries)?;
    let part = task::part(&sx)?;
    let outputs = output_sections::outputs(&sx, torque_plot);
    let tsec = file.task.get_ref();
    let n = sx.n;
    let setting_lines = simulation::setting_lines(&sx);
    Ok(Scene {
        file: fname.clone(),
        name,
        description: file.description.clone(),
        model_path: ms.model_path,
        package_paths: ms.package_paths,
        model: ms.model,
        spec: ms.spec,
        model_warnings: ms.model_warnings,
        base: ms.base,
        tool: ms.tool,
        effect_names: named,
        effects,
        payload_masses,
        payload_inertia,
        transmissions,
        contact,
        q0,
        limits: rate.limits,
        lower,
        upper,
        check_velocity: rate.check_velocity,
        check_effort: rate.effort,
        obstacles,
        collision: coll.collision,
        self_collision: coll.self_collision,
        setting_lines,
        steps,
        task_kind: tsec.kind.get_ref().clone(),
        position_only: tsec.position_only.unwrap_or(n < 6),
        timing: traj.timing,
        topp_segments: traj.topp_segments,
        line_samples: traj.line_samples,
        tool_speed: traj.tool_speed,
        tool_acceleration: traj.tool_acceleration,
        check_dt: traj.check_dt,
        simulation,
        outputs,
        warnings,
        planner,
        part,
        planner_disabled: coll.planner_disabled,
    })
}
