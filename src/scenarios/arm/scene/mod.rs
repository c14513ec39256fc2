//! Validation of an arm scenario: from the parsed [`ArmFile`] to a [`Scene`] whose every
//! part is checked (model loaded, joints named, limits consistent with each other and with
//! the model, effects built, poses in the robot's base frame). Every error names the
//! file, the line and the key.
//!
//! [`build`] reads the sections in file order, one module each: [`model`] (name, model
//! file, base, tool), [`effects`], [`limits`] (and the initial configuration),
//! [`obstacles`] (obstacles, collision settings, contact scene), [`task`] (steps, part,
//! planner), [`simulation`] (trajectory timing and simulation settings) and [`outputs`].

mod effect_sections;
mod limits;
mod model;
mod obstacle_sections;
mod output_sections;
mod simulation;
mod task;
pub mod transmission;
use crate::collision::resolve::PackagePaths;
use crate::collision::{CollisionOptions, ObstacleSpec};
use crate::core::diag::LocatedError as ScenarioError;
use crate::core::spatial::{Inertia, Se3};
use crate::dynamics::Effects;
use crate::model::{Model, ModelSpec};
use crate::motion::JointLimits;
use crate::scenarios::arm::schema::*;
use crate::scenarios::source::Source;
use crate::sim::{Controller, Integrator};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// The effects a scenario may name, in report order: the dynamics effects of
/// [`crate::model::data::EffectSet::NAMES`] (external wrenches come from the contact scene, not
/// from a name) and `contact`.
pub const EFFECT_NAMES: [&str; 6] = {
    let d = crate::model::data::EffectSet::NAMES;
    [d[0], d[1], d[2], d[3], d[4], "contact"]
};

/// How the joint motion is timed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timing {
    /// Trapezoidal velocity profiles, stopping at every waypoint.
    Trapezoidal,
    /// Rest-to-rest quintic polynomials per segment.
    Quintic,
    /// The minimum-jerk spline through the waypoints.
    MinimumJerk,
    /// Time-optimal timing (TOPP) under the velocity, acceleration and torque limits.
    TimeOptimal,
}

impl Timing {
    /// Name as written in files.
    pub fn as_str(&self) -> &'static str {
        match self {
            Timing::Trapezoidal => "trapezoidal",
            Timing::Quintic => "quintic",
            Timing::MinimumJerk => "minimum_jerk",
            Timing::TimeOptimal => "time_optimal",
        }
    }
}

/// One step of the task, with poses in the robot's base frame.
#[derive(Clone, Debug)]
pub enum Step {
    /// Joint-space move to these values.
    Joint(Vec<f64>),
    /// Joint-space move to the IK solution of this tool pose.
    Pose(Se3),
    /// Straight tool line to this pose.
    Line(Se3),
    /// Stay still (s).
    Dwell(f64),
    /// Planned, collision-free move to joint values (`Ok`) or a tool pose through IK.
    Plan(Result<Vec<f64>, Se3>),
    /// The tool grasps the part: from here its mass and shape travel with it.
    Attach,
    /// The tool releases the part.
    Detach,
}

/// A step with where it was written (for error messages).
#[derive(Clone, Debug)]
pub struct TaskStep {
    /// The step.
    pub step: Step,
    /// The key it was read from, for messages.
    pub key: String,
    /// Its line in the file, when known.
    pub line: Option<usize>,
}

/// The contact scene (poses in scene axes).
#[derive(Clone, Debug)]
pub struct ContactScene {
    /// Table edge lengths (m).
    pub table_size: [f64; 3],
    /// Table centre (m).
    pub table_xyz: [f64; 3],
    /// Table friction coefficient.
    pub table_friction: f64,
    /// Box edge lengths (m).
    pub box_size: [f64; 3],
    /// Initial box centre (m).
    pub box_xyz: [f64; 3],
    /// Box mass (kg).
    pub box_mass: f64,
    /// Box friction coefficient.
    pub box_friction: f64,
    /// Link index carrying the pusher sphere.
    pub pusher_link: usize,
    /// Pusher sphere radius (m).
    pub pusher_radius: f64,
    /// Pusher offset in the link frame (m).
    pub pusher_offset: [f64; 3],
    /// Contact-solver step (s).
    pub dt: f64,
}

/// Simulation settings.
#[derive(Clone, Debug)]
pub struct SimSettings {
    /// The controller tracking the planned motion.
    pub controller: Controller,
    /// The integrator.
    pub integrator: Integrator,
    /// Integration step (s).
    pub dt: f64,
    /// Simulated time (s); `None`: the motion plus `settle`.
    pub duration: Option<f64>,
    /// Time simulated after the motion ends (s).
    pub settle: f64,
    /// Samples recorded per second.
    pub record_rate: f64,
}

/// Output settings.
#[derive(Clone, Debug)]
pub struct Outputs {
    /// Output directory (`None`: `out/<name>`, or the command line's).
    pub dir: Option<PathBuf>,
    /// Format of the torque and simulation plots (`None`: no plots).
    pub torque_plot: Option<crate::io::plots::torque_chart::PlotFormat>,
    /// Write `<name>.json`.
    pub report: bool,
    /// Write the planned trajectory as CSV.
    pub trajectory_csv: bool,
    /// Write the simulated samples as CSV.
    pub simulation_csv: bool,
    /// Write the MCAP recording.
    pub mcap: bool,
}

/// A validated scenario.
pub struct Scene {
    /// The scenario file, as the user named it.
    pub file: String,
    /// The scenario name (names the output files).
    pub name: String,
    /// Free text from the file.
    pub description: Option<String>,
    /// The model file, resolved against the scenario.
    pub model_path: PathBuf,
    /// The compiled model.
    pub model: Model,
    /// The model as read, its resolvable mesh URIs replaced by absolute paths.
    pub spec: ModelSpec,
    /// Where `package://` URIs were searched (command line, `model.package_path`, then
    /// the environment).
    pub package_paths: PackagePaths,
    /// The model loader's warnings.
    pub model_warnings: Vec<String>,
    /// Scene → robot base.
    pub base: Se3,
    /// The tool frame.
    pub tool: usize,
    /// The named effects, in [`EFFECT_NAMES`] order.
    pub effect_names: Vec<&'static str>,
    /// The effects for dynamics (payload: the last mass of a sweep).
    pub effects: Effects,
    /// Payload masses of a sweep (one entry without a sweep); empty without payload.
    pub payload_masses: Vec<f64>,
    /// The payload's link and inertia (the first mass of a sweep).
    pub payload_inertia: Option<(usize, Inertia)>,
    /// Joints whose rotor ratio, efficiency and added inertia come from a gear train.
    pub transmissions: Vec<transmission::JointTransmission>,
    /// The contact scene, with the `contact` effect.
    pub contact: Option<ContactScene>,
    /// The start configuration.
    pub q0: Vec<f64>,
    /// Planning limits (velocity scaled).
    pub limits: JointLimits,
    /// Position limits used by planning and checks.
    pub lower: Vec<f64>,
    /// Upper position limits the planning respects.
    pub upper: Vec<f64>,
    /// Limits the torque check judges against (model velocity, effort possibly overridden).
    pub check_velocity: Vec<f64>,
    /// Effort limits the torque check judges against.
    pub check_effort: Vec<f64>,
    /// The scene's obstacles.
    pub obstacles: Vec<ObstacleSpec>,
    /// Collision-check settings (`None`: no check).
    pub collision: Option<CollisionOptions>,
    /// Check link pairs against each other too.
    pub self_collision: bool,
    /// Where the step, settling, record rate and check step are written (budget messages).
    pub setting_lines: crate::scenarios::arm::budget::SettingLines,
    /// The task as steps, with poses in the robot's base frame.
    pub steps: Vec<TaskStep>,
    /// The task type as written.
    pub task_kind: String,
    /// IK and lines ignore the tool orientation.
    pub position_only: bool,
    /// How the joint motion is timed.
    pub timing: Timing,
    /// TOPP grid intervals per segment.
    pub topp_segments: usize,
    /// IK samples per straight-line move.
    pub line_samples: usize,
    /// Tool speed limit on straight lines (m/s).
    pub tool_speed: f64,
    /// Tool acceleration limit on straight lines (m/s²).
    pub tool_acceleration: f64,
    /// Torque-check sample step (s).
    pub check_dt: f64,
    /// Simulation settings (`None`: not simulated).
    pub simulation: Option<SimSettings>,
    /// The files to write.
    pub outputs: Outputs,
    /// Warnings found while reading the file.
    pub warnings: Vec<String>,
    /// Planner settings (when the task plans).
    pub planner: Option<crate::scenarios::arm::planner_setup::PlannerSettings>,
    /// The grasped part's shape, on the tool between attach and detach.
    pub part: Option<crate::scenarios::arm::planner_setup::Part>,
    /// `collision.disabled_pairs` and the skeleton's touching pairs, for the planner.
    pub planner_disabled: Vec<[String; 2]>,
}

/// What the sections after `[model]` read: the file, the model, its coordinate names,
/// the tool and the base pose.
struct Sections<'a> {
    cx: Source<'a>,
    /// The scenario file, as the user named it.
    file: &'a ArmFile,
    dir: &'a Path,
    /// The compiled model.
    model: &'a Model,
    names: Vec<String>,
    n: usize,
    /// The tool frame.
    tool: usize,
    /// The robot base pose in scene axes.
    base: Se3,
    base_inv: Se3,
}

/// `x` in radians when `degrees` is set and coordinate `k` turns (prismatic joints keep
/// their metres).
fn to_radians_if(model: &Model, x: f64, k: usize, degrees: bool) -> f64 {
    if degrees && model.dof_joint(k).jtype != crate::model::JointType::Prismatic {
        x.to_radians()
    } else {
        x
    }
}

use crate::core::diag::finite_positive as finite_pos;

/// Reads a per-joint value: a number for all, a list in joint order, or a table by joint
/// name over `default`.
pub fn per_joint(
    cx: &Source,
    v: &PerJoint,
    key: &str,
    names: &[String],
    default: &[f64],
) -> Result<Vec<f64>, ScenarioError> {
    let n = names.len();
    let num = |x: &toml::Value| -> Option<f64> {
        match x {
            toml::Value::Float(f) => Some(*f),
            toml::Value::Integer(i) => Some(*i as f64),
            _ => None,
        }
    };
    let out = match v.get_ref() {
        toml::Value::Array(a) => {
            if a.len() != n {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!("{} values for {n} joints ({})", a.len(), names.join(", ")),
                ));
            }
            a.iter()
                .enumerate()
                .map(|(k, x)| {
                    num(x).ok_or_else(|| {
                        cx.at(
                            v.span(),
                            key,
                            format!("value {k} (joint {}) is not a number", names[k]),
                        )
                    })
                })
                .collect::<Result<Vec<_>, _>>()?
        }
        toml::Value::Table(t) => {
            let mut out = default.to_vec();
            for (name, x) in t {
                let k = names.iter().position(|j| j == name).ok_or_else(|| {
                    let hint = closest(name, names)
                        .map(|c| format!(" (did you mean '{c}'?)"))
                        .unwrap_or_default();
                    cx.at(
                        v.span(),
                        format!("{key}.{name}"),
                        format!(
                            "unknown joint '{name}'{hint}; the joints are: {}",
                            names.join(", ")
                        ),
                    )
                })?;
                out[k] = num(x)
                    .ok_or_else(|| cx.at(v.span(), format!("{key}.{name}"), "expected a number"))?;
            }
            out
        }
        x => match num(x) {
            Some(f) => vec![f; n],
            None => {
                return Err(cx.at(
                    v.span(),
                    key,
                    format!(
                        "expected a number, a list of {n} numbers or a table by joint name, got {}",
                        x.type_str()
                    ),
                ))
            }
        },
    };
    if let Some(k) = out.iter().position(|x| !x.is_finite()) {
        return Err(cx.at(
            v.span(),
            key,
            format!("joint {}: the value is not finite", names[k]),
        ));
    }
    Ok(out)
}

/// The name in `names` closest to `name` (edit distance ≤ 3), for "did you mean".
fn closest<'a>(name: &str, names: &'a [String]) -> Option<&'a str> {
    fn dist(a: &str, b: &str) -> usize {
        let b: Vec<char> = b.chars().collect();
        let mut prev: Vec<usize> = (0..=b.len()).collect();
        for (i, ca) in a.chars().enumerate() {
            let mut cur = vec![i + 1; b.len() + 1];
            for (j, cb) in b.iter().enumerate() {
                cur[j + 1] = (prev[j] + usize::from(ca != *cb))
                    .min(prev[j + 1] + 1)
                    .min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    }
    names
        .iter()
        .map(|n| (dist(name, n), n))
        .filter(|(d, _)| *d <= 3)
        .min_by_key(|(d, _)| *d)
        .map(|(_, n)| n.as_str())
}

/// `v` read per joint ([`per_joint`], `default` where absent) and checked `> 0` (`≥ 0`
/// with `allow_zero`); `default` itself when `v` is absent.
fn per_joint_checked(
    cx: &Source,
    v: Option<&PerJoint>,
    key: &str,
    names: &[String],
    default: &[f64],
    allow_zero: bool,
) -> Result<Vec<f64>, ScenarioError> {
    let Some(v) = v else {
        return Ok(default.to_vec());
    };
    let vals = per_joint(cx, v, key, names, default)?;
    positive_all(cx, v, key, names, &vals, allow_zero)?;
    Ok(vals)
}

fn positive_all(
    cx: &Source,
    v: &PerJoint,
    key: &str,
    names: &[String],
    vals: &[f64],
    allow_zero: bool,
) -> Result<(), ScenarioError> {
    for (k, x) in vals.iter().enumerate() {
        if *x < 0.0 || (!allow_zero && *x == 0.0) {
            return Err(cx.at(
                v.span(),
                key,
                format!(
                    "joint {}: must be {} (got {x})",
                    names[k],
                    if allow_zero { ">= 0" } else { "> 0" }
                ),
            ));
        }
    }
    Ok(())
}

fn pose_of(p: &PoseSec) -> Se3 {
    Se3::from_xyz_rpy(p.xyz, p.rpy)
}

fn finite_pose(p: &PoseSec) -> bool {
    p.xyz.iter().chain(p.rpy.iter()).all(|x| x.is_finite())
}

fn get_f(
    cx: &Source,
    v: &Option<Spanned<f64>>,
    key: &str,
    default: f64,
) -> Result<f64, ScenarioError> {
    match v {
        None => Ok(default),
        Some(s) if finite_pos(*s.get_ref()) => Ok(*s.get_ref()),
        Some(s) => Err(cx.at(
            s.span(),
            key,
            format!(
                "must be finite and positive (got {})",
                crate::core::diag::fmt_num(*s.get_ref())
            ),
        )),
    }
}

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
    let plans = steps.iter().any(|s| matches!(s.step, Step::Plan(_)));
    limits::jerk_applies(&sx, traj.timing == Timing::TimeOptimal, plans)?;
    let planner = task::planner_settings(&cx, file, dir, &ms.model, plans, &mut warnings)?;
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
