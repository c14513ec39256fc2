//! The validated arm scenario ([`Scene`]) and its parts: the task steps, their timing, the
//! contact scene, the simulation and output settings, the effect names a file may use,
//! and where the budgeted settings were written ([`SettingLines`]).

use crate::collision::resolve::PackagePaths;
use crate::collision::{CollisionOptions, ObstacleSpec};
use crate::core::spatial::{Inertia, Se3};
use crate::dynamics::Effects;
use crate::model::{Model, ModelSpec};
use crate::motion::JointLimits;
use crate::scenarios::arm::planner_settings::{Part, PlannerSettings};
use crate::scenarios::arm::scene::transmission::JointTransmission;
use crate::sim::{Controller, Integrator};
use std::path::PathBuf;

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
    /// Planned move to a goal set or under path constraints ([`PlanQuery`]).
    PlanTo(Box<PlanQuery>),
    /// The tool grasps the part: from here its mass and shape travel with it.
    Attach,
    /// The tool releases the part.
    Detach,
}

/// What a `type = "plan"` task with `goal_pose` or `path_constraints` plans to.
#[derive(Clone, Debug)]
pub struct PlanQuery {
    /// The goal (base frame).
    pub goal: QueryGoal,
    /// Kept along the whole path (base frame).
    pub constraints: Vec<crate::planning::path_constraints::PathConstraint>,
}

/// The goal of a [`PlanQuery`].
#[derive(Clone, Debug)]
pub enum QueryGoal {
    /// Joint values (`task.goal_q`).
    Joints(Vec<f64>),
    /// A tool pose reached through IK from the current configuration (`task.goal`).
    IkPose(Se3),
    /// A tool pose the planner reaches through any of its IK solutions
    /// (`task.goal_pose`, [`crate::planning::pose_goal`]).
    Pose(Se3),
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
    pub transmissions: Vec<JointTransmission>,
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
    pub setting_lines: SettingLines,
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
    pub planner: Option<PlannerSettings>,
    /// The grasped part's shape, on the tool between attach and detach.
    pub part: Option<Part>,
    /// `collision.disabled_pairs` and the skeleton's touching pairs, for the planner.
    pub planner_disabled: Vec<[String; 2]>,
}

/// Where a setting was written (1-based line), for the budget messages.
#[derive(Clone, Copy, Debug, Default)]
pub struct SettingLines {
    /// Line of `simulation.dt`.
    pub dt: Option<usize>,
    /// Line of `simulation.settle`.
    pub settle: Option<usize>,
    /// Line of `simulation.record_rate`.
    pub record_rate: Option<usize>,
    /// Line of `trajectory.check_dt`.
    pub check_dt: Option<usize>,
    /// Header line of each table of [`SECTIONS`] the file writes.
    pub sections: [Option<usize>; SECTIONS.len()],
}

/// The tables whose header line a run-time error names (the error's key starts with one).
pub const SECTIONS: [&str; 12] = [
    "model",
    "limits",
    "payload",
    "collision",
    "planner",
    "task",
    "trajectory",
    "simulation",
    "contact",
    "outputs",
    "friction",
    "obstacles",
];

impl SettingLines {
    /// The header line of the table `key` belongs to (`planner.seed` → `[planner]`).
    pub fn section(&self, key: &str) -> Option<usize> {
        let head = key.split(['.', '[', ' ']).next().unwrap_or(key);
        SECTIONS
            .iter()
            .position(|s| *s == head)
            .and_then(|i| self.sections[i])
    }
}

impl Scene {
    /// An error of the run at `key`, located at its table's header when the file writes
    /// one (the run-time errors have no key of their own).
    pub fn error_at(&self, key: &str, msg: impl Into<String>) -> crate::scenarios::ScenarioError {
        crate::scenarios::ScenarioError::new(&self.file, self.setting_lines.section(key), key, msg)
    }
}
