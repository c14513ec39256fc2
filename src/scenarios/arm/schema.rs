//! The TOML schema of `kind = "arm"` scenario files, as serde structures. Every table
//! refuses unknown keys, and every value keeps its span so that errors found after
//! parsing (a misspelt joint, contradictory limits) still name the line.
//!
//! `scenarios/README.md` documents the format; [`crate::scenarios::arm::scene`] turns these
//! structures into a validated [`crate::scenarios::arm::scene::Scene`].

use crate::collision::ObstacleSpec;
use serde::Deserialize;
use toml::Spanned;

/// A per-joint value as written: one number for every joint, a list in joint order, or a
/// table by joint name (the joints left out keep their default).
pub type PerJoint = Spanned<toml::Value>;

/// The whole file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArmFile {
    /// `kind = "arm"` or absent.
    pub kind: Option<String>,
    /// The scenario name (default: the file stem); names the output files.
    pub name: Option<Spanned<String>>,
    /// Free text, shown in the report.
    pub description: Option<String>,
    /// `[model]`: the robot file, base pose and tool.
    pub model: Spanned<ModelSec>,
    /// The effects the scene calls for (required; `[]` for rigid bodies only).
    pub effects: Spanned<Vec<Spanned<String>>>,
    /// `[gravity]` (only with the `gravity` effect).
    pub gravity: Option<Spanned<GravitySec>>,
    /// `[friction]` (only with the `friction` effect).
    pub friction: Option<Spanned<FrictionSec>>,
    /// `[rotor_inertia]` (only with the `rotor_inertia` effect).
    pub rotor_inertia: Option<Spanned<RotorSec>>,
    /// `[joint_elasticity]` (only with the `joint_elasticity` effect).
    pub joint_elasticity: Option<Spanned<ElasticSec>>,
    /// `[payload]` (only with the `payload` effect).
    pub payload: Option<Spanned<PayloadSec>>,
    /// `[contact]` (only with the `contact` effect).
    pub contact: Option<Spanned<ContactSec>>,
    /// `[initial]`: the start configuration.
    pub initial: Option<Spanned<InitialSec>>,
    /// `[limits]`: planning limits.
    pub limits: Option<Spanned<LimitsSec>>,
    /// `[[obstacles]]`: fixed shapes in scene axes.
    #[serde(default)]
    pub obstacles: Vec<Spanned<ObstacleSpec>>,
    /// `[collision]`: the collision check of the motion.
    pub collision: Option<Spanned<CollisionSec>>,
    /// Settings of the motion planner (task `plan`, or `planner = "rrt-connect"`).
    pub planner: Option<Spanned<PlannerSec>>,
    /// `[task]`: what the arm does.
    pub task: Spanned<TaskSec>,
    /// `[trajectory]`: the timing profile and its settings.
    pub trajectory: Option<Spanned<TrajectorySec>>,
    /// `[simulation]`: controller, integrator and step.
    pub simulation: Option<Spanned<SimulationSec>>,
    /// `[outputs]`: the files written.
    pub outputs: Option<Spanned<OutputsSec>>,
}

/// `[model]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSec {
    /// URDF or DH table, relative to the scenario file.
    pub file: Spanned<String>,
    /// Base position in the scene (m).
    #[serde(default)]
    pub base_xyz: [f64; 3],
    /// Base orientation, URDF roll-pitch-yaw (rad).
    #[serde(default)]
    pub base_rpy: [f64; 3],
    /// Tool link (default: the last link of the tree).
    pub tool: Option<Spanned<String>>,
    /// Directories searched first for `package://` mesh URIs, relative to the scenario
    /// file (after the command line's `--package-path`, before `ROS_PACKAGE_PATH`).
    #[serde(default)]
    pub package_path: Vec<Spanned<String>>,
}

/// `[gravity]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravitySec {
    /// Gravity in scene axes (m/s²); default `(0, 0, −9.81)`.
    pub vector: Option<Spanned<[f64; 3]>>,
}

/// `[friction]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrictionSec {
    /// Viscous coefficient per joint (N·m·s/rad or N·s/m).
    pub viscous: Option<PerJoint>,
    /// Coulomb friction per joint (N·m or N).
    pub coulomb: Option<PerJoint>,
    /// Static friction per joint, at least the Coulomb value (N·m or N).
    pub stiction: Option<PerJoint>,
    /// Stribeck velocity per joint (rad/s or m/s).
    pub stribeck_velocity: Option<PerJoint>,
    /// Velocity scale of the smooth sign function (rad/s or m/s).
    pub smoothing: Option<Spanned<f64>>,
}

/// `[rotor_inertia]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSec {
    /// Motor-side rotor inertia per joint (kg·m²).
    pub inertia: Option<PerJoint>,
    /// Gear ratio motor : joint per joint.
    pub gear_ratio: Option<PerJoint>,
    /// Gear efficiency per joint, in (0, 1].
    pub efficiency: Option<PerJoint>,
    /// Joint name → `kind = "gear_train"` file (relative to the scenario): the joint's
    /// ratio, efficiency and added inertia come from the train.
    pub gear_train: Option<Spanned<std::collections::BTreeMap<String, Spanned<String>>>>,
}

/// `[joint_elasticity]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ElasticSec {
    /// Joint stiffness per joint (N·m/rad or N/m); required.
    pub stiffness: PerJoint,
    /// Joint damping per joint (N·m·s/rad or N·s/m); default 0.
    pub damping: Option<PerJoint>,
    /// Reflected motor inertia `I_m N²` per joint (kg·m²); default from the rotor data.
    pub motor_inertia: Option<PerJoint>,
}

/// `[payload]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PayloadSec {
    /// Link carrying it (default: the tool).
    pub link: Option<Spanned<String>>,
    /// Mass (kg), or a list of masses for a payload sweep.
    pub mass: Spanned<toml::Value>,
    /// Centre of mass in the link frame (m).
    #[serde(default)]
    pub com: [f64; 3],
    /// Principal moments about the centre of mass `[Ixx, Iyy, Izz]` (kg m²), or the six
    /// `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`; default a point mass.
    pub inertia: Option<Spanned<Vec<f64>>>,
}

/// `[contact]`: a table, a box on it and the arm's pusher (rapier3d-f64).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSec {
    /// The fixed table.
    pub table: Spanned<ContactBox>,
    /// The box the arm pushes (`box` in the file).
    #[serde(rename = "box")]
    pub object: Spanned<ContactBody>,
    /// Link whose origin carries the pusher sphere (default: the tool).
    pub pusher_link: Option<Spanned<String>>,
    /// Pusher sphere radius (m).
    pub pusher_radius: Option<Spanned<f64>>,
    /// Pusher offset in the link frame (m).
    #[serde(default)]
    pub pusher_offset: [f64; 3],
    /// Contact-solver step (s); default the simulation step.
    pub dt: Option<Spanned<f64>>,
}

/// A fixed box in the contact scene.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactBox {
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Centre in scene axes (m).
    pub xyz: [f64; 3],
    /// Friction coefficient (default 0.5).
    #[serde(default = "default_mu")]
    pub friction: f64,
}

/// The moving box of the contact scene.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactBody {
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Initial centre in scene axes (m).
    pub xyz: [f64; 3],
    /// Mass (kg).
    pub mass: f64,
    /// Friction coefficient (default 0.5).
    #[serde(default = "default_mu")]
    pub friction: f64,
}

fn default_mu() -> f64 {
    0.5
}

/// `[initial]`: the configuration the arm starts in, at rest.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSec {
    /// Joint values per joint (rad or m; degrees with `degrees`).
    pub q: PerJoint,
    /// Angles in degrees instead of radians (revolute joints).
    #[serde(default)]
    pub degrees: bool,
}

/// `[limits]`: planning limits (each at most the model's).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LimitsSec {
    /// Velocity limits per joint (rad/s or m/s); default the model's.
    pub velocity: Option<PerJoint>,
    /// Acceleration limits per joint (rad/s² or m/s²); default 4 × the velocity limit
    /// per second.
    pub acceleration: Option<PerJoint>,
    /// Effort limits per joint (N·m or N) the torque check judges against; default the model's.
    pub effort: Option<PerJoint>,
    /// Lower position limits per joint, inside the model's.
    pub lower: Option<PerJoint>,
    /// Upper position limits per joint, inside the model's.
    pub upper: Option<PerJoint>,
    /// Fraction of the velocity limits the planner may use, in (0, 1].
    pub velocity_scale: Option<Spanned<f64>>,
    /// Joint jerk limits (rad/s³ or m/s³) for the time-optimal timing; none by default.
    pub jerk: Option<PerJoint>,
}

/// `[collision]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CollisionSec {
    /// Check the motion for collisions (default true).
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Check link pairs against each other too (default true).
    #[serde(default = "yes")]
    pub self_collision: bool,
    /// Link–link or link–obstacle pairs never checked.
    #[serde(default)]
    pub disabled_pairs: Vec<Spanned<Vec<String>>>,
    /// In collision when the signed distance is at most this (m; default 0).
    #[serde(default)]
    pub margin: f64,
    /// Replace meshes by their convex hulls (conservative, faster).
    #[serde(default)]
    pub convex_hulls: bool,
    /// Give links whose meshes are missing capsules of this radius along their bones.
    pub skeleton_radius: Option<Spanned<f64>>,
    /// No longer used (the certificate replaced the stepped check): refused with a message.
    pub max_step: Option<Spanned<f64>>,
}

fn yes() -> bool {
    true
}

/// A pose in scene axes.
#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct PoseSec {
    /// Position (m).
    pub xyz: [f64; 3],
    /// Orientation, URDF roll-pitch-yaw (rad).
    #[serde(default)]
    pub rpy: [f64; 3],
}

/// One `[[task.path_constraints]]` entry: `type` "axis" (`axis`, `direction`,
/// `tolerance`), "orientation" (`rpy`, `tolerance`) or "position" (`offset`, `shape` with
/// `size`, `radius` or `radius` and `length`, `xyz`, `rpy`); `link` optional (the tool).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstraintSec {
    /// "axis", "orientation" or "position".
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    /// The constrained link (default: the tool).
    pub link: Option<Spanned<String>>,
    /// `axis`: the link's axis (link frame).
    pub axis: Option<Spanned<[f64; 3]>>,
    /// `axis`: the world direction it stays near.
    pub direction: Option<Spanned<[f64; 3]>>,
    /// `axis` and `orientation`: the largest angle (rad).
    pub tolerance: Option<Spanned<f64>>,
    /// `orientation`: the orientation kept (scene axes); `position`: the region's.
    pub rpy: Option<Spanned<[f64; 3]>>,
    /// `position`: the region's centre (scene axes).
    pub xyz: Option<Spanned<[f64; 3]>>,
    /// `position`: the point of the link (link frame, default its origin).
    pub offset: Option<Spanned<[f64; 3]>>,
    /// `position`: "box", "sphere" or "cylinder".
    pub shape: Option<Spanned<String>>,
    /// `position`, box: full extents (m).
    pub size: Option<Spanned<[f64; 3]>>,
    /// `position`, sphere and cylinder: radius (m).
    pub radius: Option<Spanned<f64>>,
    /// `position`, cylinder: full length along its z axis (m).
    pub length: Option<Spanned<f64>>,
}

/// One step of a `sequence` task (exactly one key).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSec {
    /// Joint-space move to these joint values.
    pub joint: Option<PerJoint>,
    /// Joint-space move to the IK solution of this tool pose.
    pub pose: Option<PoseSec>,
    /// Straight tool line to this pose.
    pub line: Option<PoseSec>,
    /// Stay still this long (s).
    pub dwell: Option<f64>,
}

/// `[task]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskSec {
    /// The task type (`type` in the file): `joint_waypoints`, `cartesian_waypoints`,
    /// `line`, `pick_and_place`, `plan` or `sequence`.
    #[serde(rename = "type")]
    pub kind: Spanned<String>,
    /// `joint_waypoints`: joint values (each row in joint order).
    pub waypoints: Option<Spanned<Vec<PerJoint>>>,
    /// `cartesian_waypoints`: tool poses.
    pub poses: Option<Spanned<Vec<PoseSec>>>,
    /// `line` and `plan`: the goal pose.
    pub goal: Option<Spanned<PoseSec>>,
    /// `plan`: the goal as joint values (instead of `goal`).
    pub goal_q: Option<PerJoint>,
    /// `plan`: the goal as a tool pose the planner reaches through any of its IK
    /// solutions (MoveIt's pose goal; instead of `goal` or `goal_q`).
    pub goal_pose: Option<Spanned<PoseSec>>,
    /// `plan`: constraints on a link kept along the whole planned path.
    pub path_constraints: Option<Spanned<Vec<Spanned<ConstraintSec>>>>,
    /// `pick_and_place`: `"rrt-connect"` plans the transfers around the obstacles
    /// (default `"none"`: joint-space moves to the IK solutions).
    pub planner: Option<Spanned<String>>,
    /// `pick_and_place`: the grasped part as a box in the tool frame; it joins the
    /// collision checks from the pick to the place.
    pub part: Option<Spanned<PartSec>>,
    /// `pick_and_place`.
    pub pick: Option<Spanned<PoseSec>>,
    /// `pick_and_place`: the place pose.
    pub place: Option<Spanned<PoseSec>>,
    /// Approach height above pick and place (m, scene z).
    pub approach: Option<Spanned<f64>>,
    /// Time at the pick and the place (s).
    pub dwell: Option<Spanned<f64>>,
    /// `sequence`: the steps.
    pub steps: Option<Spanned<Vec<Spanned<StepSec>>>>,
    /// Joint values in degrees (waypoints and joint steps).
    #[serde(default)]
    pub degrees: bool,
    /// Tool poses constrain the position only (default: for arms with fewer than six
    /// joints).
    pub position_only: Option<bool>,
}

/// `[planner]`: RRT-Connect (or AORRTC) settings.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlannerSec {
    /// Sampler and simplifier seed (default 0).
    pub seed: Option<u64>,
    /// Search time limit per planned segment (ms; default 1000).
    pub time_limit_ms: Option<Spanned<f64>>,
    /// Shortcut and smooth the path (default true).
    pub simplify: Option<bool>,
    /// Longest RRT-Connect step in joint space (rad; default 1).
    pub range: Option<Spanned<f64>>,
    /// Largest overshoot of the spheres covering the robot's collision primitives and
    /// meshes (m; default 0.01). Mesh covers need about `area / δ²` spheres: a coarser
    /// cover plans faster (the parry check of the motion still uses the exact meshes).
    pub max_overshoot: Option<Spanned<f64>>,
    /// MoveIt SRDF with the disabled self-collision pairs, relative to the scenario
    /// (default: adjacent and never-touching pairs found by sampling).
    pub srdf: Option<Spanned<String>>,
    /// `"rrt-connect"` (default: the first path, simplified) or `"aorrtc"` (keeps
    /// searching for cheaper paths until the budget is spent).
    pub algorithm: Option<Spanned<String>>,
    /// `aorrtc`: search iterations per planned segment, the first path's included
    /// (default 2000).
    pub budget_iterations: Option<Spanned<i64>>,
    /// `aorrtc`: wall-clock budget per planned segment (ms; default none).
    pub budget_ms: Option<Spanned<f64>>,
}

/// The grasped part: a box in the tool link's frame.
#[derive(Deserialize, Clone, Copy)]
#[serde(deny_unknown_fields)]
pub struct PartSec {
    /// Edge lengths (m).
    pub size: [f64; 3],
    /// Centre in the tool frame (m).
    #[serde(default)]
    pub xyz: [f64; 3],
}

/// `[trajectory]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectorySec {
    /// The timing profile (`trapezoidal`, `quintic`, `minimum_jerk` or `time_optimal`).
    #[serde(rename = "type")]
    pub kind: Option<Spanned<String>>,
    /// TOPP grid intervals per segment.
    pub segments: Option<Spanned<usize>>,
    /// IK samples per straight-line move.
    pub line_samples: Option<Spanned<usize>>,
    /// Tool speed limit on straight lines (m/s).
    pub tool_speed: Option<Spanned<f64>>,
    /// Tool acceleration limit on straight lines (m/s²).
    pub tool_acceleration: Option<Spanned<f64>>,
    /// Torque-check sample step (s).
    pub check_dt: Option<Spanned<f64>>,
}

/// `[simulation]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSec {
    /// Simulate the motion (default true).
    #[serde(default = "yes")]
    pub enabled: bool,
    /// `computed_torque`, `pd_gravity` or `none`.
    pub controller: Option<Spanned<String>>,
    /// `semi_implicit_euler`, `rk4` or `implicit` (the default with elastic joints).
    pub integrator: Option<Spanned<String>>,
    /// Integration step (s).
    pub dt: Option<Spanned<f64>>,
    /// Simulated time (s); default the motion plus `settle`.
    pub duration: Option<Spanned<f64>>,
    /// Time simulated after the motion ends (s).
    pub settle: Option<Spanned<f64>>,
    /// Proportional gain per joint (computed torque 1/s²; PD + gravity N·m/rad).
    pub kp: Option<PerJoint>,
    /// Derivative gain per joint (computed torque 1/s; PD + gravity N·m·s/rad).
    pub kd: Option<PerJoint>,
    /// Samples recorded per second.
    pub record_rate: Option<Spanned<f64>>,
}

/// `[outputs]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputsSec {
    /// Output directory (relative to the current one); `--out` overrides.
    pub dir: Option<String>,
    /// Torque plot format, `png`, `svg` or `none`.
    pub torque_plot: Option<Spanned<String>>,
    /// Write `<name>.json` (the report).
    pub report: Option<bool>,
    /// Write `<name>_trajectory.csv` (the planned motion).
    pub trajectory_csv: Option<bool>,
    /// Write `<name>_simulation.csv` (the simulated motion).
    pub simulation_csv: Option<bool>,
    /// Write `<name>.mcap` (ROS 2 messages: joint states, tf, robot description, torque
    /// check, collisions); default true.
    pub mcap: Option<bool>,
}
