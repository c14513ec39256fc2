//! Planning an arm scenario's task: the [`Step`]s become joint waypoints (tool poses
//! through IK, seeded from the previous configuration so the arm stays on its branch),
//! straight tool lines ([`cartesian_line`]) and dwells, timed by the chosen profile and
//! joined into one [`Sequence`].
//!
//! - Consecutive joint-space steps form one group through its waypoints, timed as a whole
//!   (trapezoidal and quintic stop at each waypoint; the minimum-jerk spline passes
//!   through them); time-optimal timing runs TOPP on each straight joint segment, with
//!   the scene's torque limits and effects.
//! - A planned step ([`Step::Plan`]) runs RRT-Connect ([`crate::scenarios::arm::planner_setup`])
//!   from the current configuration (with the grasped part on the tool between [`Step::Attach`] and
//!   [`Step::Detach`]) and times the path as one smooth motion through its via points by
//!   TOPP with the effects of that interval (the payload only while the part is held).
//! - A straight line keeps its tool-speed timing, or is re-timed by TOPP along its IK
//!   path when the timing is time-optimal.

use crate::core::diag::LocatedError as ScenarioError;
use crate::dynamics::Effects;
use crate::kinematics::ik::{IkOptions, IkSolver, IkStatus};
use crate::model::Model;
use crate::motion::topp;
use crate::motion::{
    cartesian_line, CartesianOptions, LinearPath, MinJerk, Quintic, ToppOptions, ToppTrajectory,
    Trajectory, Trapezoidal,
};
use crate::planning::Planner;
use crate::scenarios::arm::planner_setup::{smooth_path, ScenePlanners};
use crate::scenarios::arm::scene::arm_scene::{
    PlanQuery, QueryGoal, Scene, Step, TaskStep, Timing,
};
use std::time::Duration;

/// A motion made of pieces played one after the other.
pub struct Sequence {
    n: usize,
    /// Start time of each piece (and the end time last).
    knots: Vec<f64>,
    pieces: Vec<Box<dyn Trajectory + Send + Sync>>,
}

impl Sequence {
    /// Start times of the pieces, then the end.
    pub fn knots(&self) -> &[f64] {
        &self.knots
    }
}

impl Trajectory for Sequence {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        *self.knots.last().unwrap_or(&0.0)
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let k = self
            .knots
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .min(self.pieces.len() - 1);
        self.pieces[k].sample(t - self.knots[k], q, qd, qdd);
    }
}

/// Holds a configuration for a time.
struct Dwell {
    q: Vec<f64>,
    duration: f64,
}

impl Trajectory for Dwell {
    fn dof(&self) -> usize {
        self.q.len()
    }
    fn duration(&self) -> f64 {
        self.duration
    }
    fn sample(&self, _t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        q.copy_from_slice(&self.q);
        qd.fill(0.0);
        qdd.fill(0.0);
    }
}

/// One planned piece, for the report.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PieceInfo {
    /// `joint`, `planned`, `line` or `dwell`.
    pub kind: &'static str,
    /// Where it comes from in the file.
    pub from: String,
    /// Start time (s).
    pub start_s: f64,
    /// Duration (s).
    pub duration_s: f64,
    /// Joint values at its end, by joint name.
    pub end_q: serde_json::Map<String, serde_json::Value>,
}

/// The planned motion.
pub struct Plan {
    /// The timed joint trajectory.
    pub trajectory: Sequence,
    /// The pieces of the motion, in order.
    pub pieces: Vec<PieceInfo>,
    /// The configurations the task passes through (start, each step end).
    pub waypoints: Vec<Vec<f64>>,
    /// IK solves the planning used.
    pub ik_solves: usize,
    /// Wall time of the planning (s).
    pub planning_time_s: f64,
    /// When the task grasps a part: the attach and detach times (s); `None` when the
    /// payload (if any) is carried throughout.
    pub carry: Option<(f64, f64)>,
    /// The planned paths' via points (one list per planned segment).
    pub planned_paths: Vec<Vec<Vec<f64>>>,
    /// The planner's figures and notes, when the task plans.
    pub planner: Option<serde_json::Value>,
    /// Each planned segment's result, in order.
    pub planned_segments: Vec<crate::scenarios::arm::planner_setup::SegmentResult>,
    /// Time per planning stage (s): `setup_s` (sphere models, allowed-collision matrices),
    /// `search_s` (RRT-Connect), `simplify_s`, `smoothing_s` (the spline through the via
    /// points), `topp_s` (time-optimal timing of every piece), `ik_s` and the rest
    /// (`other_s`).
    pub stages: serde_json::Map<String, serde_json::Value>,
    /// Each planned piece as timed, so that another tool can re-time it: its via points,
    /// the spline through them (knot times and quintic coefficients per segment and joint,
    /// in local time, increasing degree) and the TOPP profile (`s`, `ṡ`, `t` at the grid
    /// points, `s` the spline's time over its duration).
    pub timed_paths: Vec<serde_json::Value>,
}

fn named(model: &Model, q: &[f64]) -> serde_json::Map<String, serde_json::Value> {
    model
        .dof_names()
        .into_iter()
        .zip(q)
        .map(|(n, v)| (n, serde_json::json!(v)))
        .collect()
}

enum Group {
    Joint(Vec<Vec<f64>>, Vec<String>),
    /// A planned path's via points, whether the part is on the tool, the step key.
    Planned(Vec<Vec<f64>>, bool, String),
    /// Grasp (true) or release.
    Grip(bool),
    Line(Box<crate::motion::CartesianMove>, String),
    Dwell(Vec<f64>, f64, String),
}

/// Plans the scene's task from `scene.q0`: the steps become motion groups (IK, planned
/// paths, straight lines, dwells), then the groups are timed one after the other.
pub fn plan(scene: &Scene) -> Result<Plan, ScenarioError> {
    let start = std::time::Instant::now();
    let model = &scene.model;
    let mut grouper = Grouper::new(scene);
    for ts in &scene.steps {
        grouper.step(ts)?;
    }
    let Grouper {
        groups,
        waypoints,
        ik_solves,
        mut planners,
        ..
    } = grouper.finish()?;
    let ik_s = start.elapsed().as_secs_f64();
    let mut clock = StageClock::default();
    let timed = time_groups(scene, groups, &mut planners, &mut clock)?;
    let tl = timed.timeline;
    let end = *tl.knots.last().expect("non-empty");
    let carry = timed.attach_t.map(|a| (a, timed.detach_t.unwrap_or(end)));
    let planned_segments = planners
        .as_mut()
        .map_or_else(Vec::new, |p| std::mem::take(&mut p.results));
    let mut stages = serde_json::Map::new();
    if let Some(p) = &planners {
        stages.insert("setup_s".into(), serde_json::json!(p.setup_s));
        stages.insert("search_s".into(), serde_json::json!(p.plan_time_us / 1e6));
        stages.insert(
            "simplify_s".into(),
            serde_json::json!(p.simplify_time_us / 1e6),
        );
    }
    stages.insert("smoothing_s".into(), serde_json::json!(clock.smoothing_s));
    stages.insert("topp_s".into(), serde_json::json!(clock.topp_s));
    let total = start.elapsed().as_secs_f64();
    let known: f64 = stages.values().filter_map(|v| v.as_f64()).sum();
    // IK and grouping run before the timing; the planners are built and queried then too.
    let setup_search = planners.as_ref().map_or(0.0, |p| {
        p.setup_s + (p.plan_time_us + p.simplify_time_us) / 1e6
    });
    stages.insert(
        "ik_s".into(),
        serde_json::json!((ik_s - setup_search).max(0.0)),
    );
    stages.insert(
        "other_s".into(),
        serde_json::json!((total - known - (ik_s - setup_search).max(0.0)).max(0.0)),
    );
    let planner = planners.map(|p| {
        serde_json::json!({
            "algorithm": "rrt-connect",
            "segments": p.segments,
            "iterations": p.iterations,
            "plan_time_us": p.plan_time_us,
            "notes": p.notes,
        })
    });
    Ok(Plan {
        trajectory: Sequence {
            n: model.nv,
            knots: tl.knots,
            pieces: tl.pieces,
        },
        pieces: tl.infos,
        waypoints,
        ik_solves,
        planning_time_s: start.elapsed().as_secs_f64(),
        carry,
        planned_paths: timed.planned_paths,
        planner,
        planned_segments,
        stages,
        timed_paths: timed.timed_paths,
    })
}

/// An error at a step (`key`, `line`) of the scene's file.
fn step_err(scene: &Scene, key: &str, line: Option<usize>, msg: String) -> ScenarioError {
    match line {
        Some(_) => ScenarioError::new(&scene.file, line, key, msg),
        None => scene.error_at(key, msg),
    }
}

/// Turns the task's steps into motion groups, in order: consecutive joint-space steps
/// (joint targets and tool poses through IK) collect into one group; a planned path, a
/// grip change, a straight line and a dwell each close it and stand alone.
struct Grouper<'s> {
    scene: &'s Scene,
    ik: IkSolver,
    ik_opts: IkOptions,
    /// Whether the part is on the tool (between attach and detach).
    carrying: bool,
    /// Built at the first planned step.
    planners: Option<ScenePlanners>,
    groups: Vec<Group>,
    /// The configuration so far.
    q: Vec<f64>,
    waypoints: Vec<Vec<f64>>,
    ik_solves: usize,
    /// The open joint-space group: its waypoints (from the configuration it starts at)
    /// and the keys of the steps that added them.
    pending: Vec<Vec<f64>>,
    pending_keys: Vec<String>,
}

impl<'s> Grouper<'s> {
    fn new(scene: &'s Scene) -> Self {
        let q = scene.q0.clone();
        Self {
            scene,
            ik: IkSolver::new(&scene.model),
            ik_opts: IkOptions {
                tol_position: 1e-7,
                tol_rotation: 1e-7,
                max_restarts: 20,
                time_budget: Duration::from_millis(500),
                respect_limits: true,
                position_only: scene.position_only,
                ..Default::default()
            },
            carrying: false,
            planners: None,
            groups: Vec::new(),
            waypoints: vec![q.clone()],
            ik_solves: 0,
            pending: vec![q.clone()],
            pending_keys: Vec::new(),
            q,
        }
    }

    /// Adds one step; the configuration it ends at must be within the joint limits.
    fn step(&mut self, ts: &TaskStep) -> Result<(), ScenarioError> {
        let scene = self.scene;
        let err = |m: String| step_err(scene, &ts.key, ts.line, m);
        match &ts.step {
            Step::Joint(target) => {
                self.q = target.clone();
                if self.pending.last() != Some(&self.q) {
                    self.pending.push(self.q.clone());
                    self.pending_keys.push(ts.key.clone());
                }
            }
            Step::Pose(target) => {
                self.q = self.solve_ik(target).map_err(err)?;
                self.pending.push(self.q.clone());
                self.pending_keys.push(ts.key.clone());
            }
            Step::Plan(target) => self.plan_to(ts, target)?,
            Step::PlanTo(query) => self.plan_query(ts, query)?,
            Step::Attach | Step::Detach => {
                self.flush();
                self.carrying = matches!(ts.step, Step::Attach);
                self.groups.push(Group::Grip(self.carrying));
            }
            Step::Line(goal) => self.line_to(ts, goal)?,
            Step::Dwell(d) => {
                self.flush();
                self.groups
                    .push(Group::Dwell(self.q.clone(), *d, ts.key.clone()));
            }
        }
        self.check_limits(ts)?;
        self.waypoints.push(self.q.clone());
        Ok(())
    }

    /// The configuration that puts the tool at `target`, seeded from the current one.
    fn solve_ik(&mut self, target: &crate::core::spatial::Se3) -> Result<Vec<f64>, String> {
        self.ik_solves += 1;
        let scene = self.scene;
        let r = self.ik.solve(
            &scene.model,
            scene.tool,
            target,
            Some(&self.q),
            &self.ik_opts,
        );
        if r.status != IkStatus::Converged {
            return Err(format!(
                "the tool pose is out of reach: IK {} (position error {:.3e} m, rotation error {:.3e} rad)",
                r.status.as_str(),
                r.position_error,
                r.rotation_error
            ));
        }
        Ok(r.q)
    }

    /// Closes the open joint-space group (when it moves) and opens the next at `q`.
    fn flush(&mut self) {
        if self.pending.len() > 1 {
            self.groups.push(Group::Joint(
                std::mem::take(&mut self.pending),
                std::mem::take(&mut self.pending_keys),
            ));
        }
        self.pending = vec![self.q.clone()];
        self.pending_keys.clear();
    }

    /// A planned path to a joint goal or a tool pose (through IK), with the part on the
    /// tool when it is carried.
    fn plan_to(
        &mut self,
        ts: &TaskStep,
        target: &Result<Vec<f64>, crate::core::spatial::Se3>,
    ) -> Result<(), ScenarioError> {
        let scene = self.scene;
        let err = |m: String| step_err(scene, &ts.key, ts.line, m);
        let goal = match target {
            Ok(g) => g.clone(),
            Err(pose) => self.solve_ik(pose).map_err(err)?,
        };
        self.flush();
        let (carrying, start) = (self.carrying, self.q.clone());
        let p = self.planners(ts)?;
        let path = p.plan(&ts.key, carrying, &start, &goal).map_err(err)?;
        self.q = goal;
        self.groups
            .push(Group::Planned(path, self.carrying, ts.key.clone()));
        self.pending = vec![self.q.clone()];
        Ok(())
    }

    /// The scene's planners, built at the first planned step.
    fn planners(&mut self, ts: &TaskStep) -> Result<&mut ScenePlanners, ScenarioError> {
        let scene = self.scene;
        if self.planners.is_none() {
            let settings = scene
                .planner
                .as_ref()
                .ok_or_else(|| step_err(scene, &ts.key, ts.line, "no planner settings".into()))?;
            self.planners = Some(
                ScenePlanners::new(scene, settings)
                    .map_err(|m| step_err(scene, "planner", None, m))?,
            );
        }
        Ok(self.planners.as_mut().expect("built"))
    }

    /// A planned path to a goal set (`task.goal_pose`) or under path constraints. A
    /// constrained path is played as straight joint segments through its via points (the
    /// edges the constraints are certified on), stopping at each; the minimum-jerk and
    /// trapezoidal timings, which leave those edges, are refused.
    fn plan_query(&mut self, ts: &TaskStep, q: &PlanQuery) -> Result<(), ScenarioError> {
        use crate::planning::pose_goal::{Goal, PoseGoal};
        let scene = self.scene;
        let err = |m: String| step_err(scene, &ts.key, ts.line, m);
        let constrained = !q.constraints.is_empty();
        if constrained && matches!(scene.timing, Timing::MinimumJerk | Timing::Trapezoidal) {
            return Err(err(format!(
                "task.path_constraints: the {} timing leaves the straight joint edges the constraints are kept on (its joints blend apart); use quintic or time_optimal",
                scene.timing.as_str()
            )));
        }
        let goal = match &q.goal {
            QueryGoal::Joints(g) => Goal::Joints(g.clone()),
            QueryGoal::IkPose(p) => Goal::Joints(self.solve_ik(p).map_err(err)?),
            QueryGoal::Pose(p) => Goal::Pose(PoseGoal {
                link: scene.tool,
                target: *p,
                position_only: scene.position_only,
            }),
        };
        self.flush();
        let (carrying, start) = (self.carrying, self.q.clone());
        let p = self.planners(ts)?;
        let path = p
            .plan_query(&ts.key, carrying, &start, &goal, &q.constraints)
            .map_err(err)?;
        self.q = path.last().expect("a solved path has its ends").clone();
        if constrained {
            self.pending = path;
            self.pending_keys = vec![ts.key.clone(); self.pending.len() - 1];
            self.flush();
        } else {
            self.groups
                .push(Group::Planned(path, self.carrying, ts.key.clone()));
            self.pending = vec![self.q.clone()];
        }
        Ok(())
    }

    /// A straight tool line to `goal` at the scene's tool speed; the arm ends where the
    /// line ends.
    fn line_to(
        &mut self,
        ts: &TaskStep,
        goal: &crate::core::spatial::Se3,
    ) -> Result<(), ScenarioError> {
        let scene = self.scene;
        let model = &scene.model;
        self.flush();
        let mut opts = CartesianOptions {
            samples: scene.line_samples,
            max_linear_speed: scene.tool_speed,
            max_linear_acceleration: scene.tool_acceleration,
            joint_limits: Some(scene.limits.clone()),
            ..Default::default()
        };
        opts.ik.position_only = scene.position_only;
        let mv = cartesian_line(model, scene.tool, &self.q, goal, &opts)
            .map_err(|e| step_err(scene, &ts.key, ts.line, format!("straight line: {e}")))?;
        self.ik_solves += scene.line_samples;
        let mut qd = vec![0.0; model.nv];
        let mut qdd = vec![0.0; model.nv];
        mv.sample(mv.duration(), &mut self.q, &mut qd, &mut qdd);
        self.groups.push(Group::Line(Box::new(mv), ts.key.clone()));
        self.pending = vec![self.q.clone()];
        Ok(())
    }

    /// The configuration a step ends at must lie within the joint limits.
    fn check_limits(&self, ts: &TaskStep) -> Result<(), ScenarioError> {
        let (scene, q) = (self.scene, &self.q);
        let outside = (0..scene.model.nv)
            .find(|&k| q[k] < scene.lower[k] - 1e-9 || q[k] > scene.upper[k] + 1e-9);
        match outside {
            Some(k) => Err(step_err(
                scene,
                &ts.key,
                ts.line,
                format!(
                    "the step ends with joint {} at {:.6}, outside its limits [{}, {}]",
                    scene.model.dof_names()[k],
                    q[k],
                    scene.lower[k],
                    scene.upper[k]
                ),
            )),
            None => Ok(()),
        }
    }

    /// Closes the last group; a task that does not move the arm is an error.
    fn finish(mut self) -> Result<Self, ScenarioError> {
        self.flush();
        if self.groups.is_empty() {
            return Err(step_err(
                self.scene,
                "task",
                None,
                "the task does not move the arm (every step ends where the arm already is)".into(),
            ));
        }
        Ok(self)
    }
}

/// The timed groups: the timeline, the planned paths' via points, and when the part was
/// grasped and released.
struct Timed {
    timeline: Timeline,
    planned_paths: Vec<Vec<Vec<f64>>>,
    timed_paths: Vec<serde_json::Value>,
    attach_t: Option<f64>,
    detach_t: Option<f64>,
}

/// Times the groups one after the other, each with the effects of its interval (the
/// payload only while the part is held, or throughout when the task never grasps).
fn time_groups(
    scene: &Scene,
    groups: Vec<Group>,
    planners: &mut Option<ScenePlanners>,
    clock: &mut StageClock,
) -> Result<Timed, ScenarioError> {
    let model = &scene.model;
    let grips = scene.steps.iter().any(|s| matches!(s.step, Step::Attach));
    let topp_opts = ToppOptions {
        segments: scene.topp_segments,
        ..Default::default()
    };
    let loaded = &scene.effects;
    let free = Effects {
        payload: None,
        ..scene.effects.clone()
    };
    let mut tl = Timeline {
        n: model.nv,
        knots: vec![0.0],
        pieces: Vec::new(),
        infos: Vec::new(),
    };
    let mut carrying = !grips;
    let (mut attach_t, mut detach_t) = (None, None);
    let mut planned_paths = Vec::new();
    let mut timed_paths = Vec::new();
    let lim = &scene.limits;
    let t_all = std::time::Instant::now();
    for g in groups {
        let fx = if carrying { loaded } else { &free };
        match g {
            Group::Joint(wps, keys) => {
                time_joint_group(scene, &mut tl, &wps, &keys, fx, &topp_opts)?
            }
            Group::Planned(path, with_part, key) => {
                let planner = planners.as_mut().expect("built").planner(with_part);
                let t = time_planned(scene, planner, &path, fx, &topp_opts, &key, clock)?;
                timed_paths.push(timed_path_json(model, &key, &path, &t));
                tl.push(model, Box::new(t), "planned", key);
                planned_paths.push(path);
            }
            Group::Grip(on) => {
                carrying = on;
                let t = *tl.knots.last().expect("non-empty");
                if on {
                    attach_t = Some(t);
                } else {
                    detach_t = Some(t);
                }
            }
            Group::Line(mv, key) => {
                if scene.timing == Timing::TimeOptimal {
                    let path = mv.path().clone();
                    let t = topp(model, path, lim, fx, &topp_opts)
                        .map_err(|x| step_err(scene, &key, None, format!("straight line: {x}")))?;
                    tl.push(model, Box::new(t), "line", key);
                } else {
                    tl.push(model, mv, "line", key);
                }
            }
            Group::Dwell(q, d, key) => {
                tl.push(model, Box::new(Dwell { q, duration: d }), "dwell", key)
            }
        }
    }
    // Everything here but the smoothing is timing (TOPP, or the chosen profile).
    clock.topp_s = (t_all.elapsed().as_secs_f64() - clock.smoothing_s).max(0.0);
    Ok(Timed {
        timeline: tl,
        planned_paths,
        timed_paths,
        attach_t,
        detach_t,
    })
}

/// A joint-space group through its waypoints, timed by the scene's profile as a whole,
/// or by TOPP segment by segment when time-optimal.
fn time_joint_group(
    scene: &Scene,
    tl: &mut Timeline,
    wps: &[Vec<f64>],
    keys: &[String],
    fx: &Effects,
    topp_opts: &ToppOptions,
) -> Result<(), ScenarioError> {
    let (model, lim) = (&scene.model, &scene.limits);
    let from = keys.join(", ");
    let e = |x: crate::motion::TrajectoryError| {
        step_err(
            scene,
            keys.first().map_or("task", |s| s.as_str()),
            None,
            format!("joint motion: {x}"),
        )
    };
    match scene.timing {
        Timing::Trapezoidal => tl.push(
            model,
            Box::new(Trapezoidal::new(wps, lim).map_err(e)?),
            "joint",
            from,
        ),
        Timing::Quintic => tl.push(
            model,
            Box::new(Quintic::new(wps, lim).map_err(e)?),
            "joint",
            from,
        ),
        Timing::MinimumJerk => tl.push(
            model,
            Box::new(MinJerk::new(wps, lim).map_err(e)?),
            "joint",
            from,
        ),
        Timing::TimeOptimal => {
            for (i, w) in wps.windows(2).enumerate() {
                let path = LinearPath::new(w[0].clone(), w[1].clone()).map_err(e)?;
                let t = topp(model, path, lim, fx, topp_opts).map_err(e)?;
                let key = keys.get(i).cloned().unwrap_or_default();
                tl.push(model, Box::new(t), "joint", key);
            }
        }
    }
    Ok(())
}

/// Time spent in the planning stages that [`time_groups`] runs (s).
#[derive(Default)]
struct StageClock {
    smoothing_s: f64,
    topp_s: f64,
}

/// A planned piece as timed (see [`Plan::timed_paths`]).
fn timed_path_json(
    model: &Model,
    key: &str,
    via: &[Vec<f64>],
    t: &ToppTrajectory<MinJerk>,
) -> serde_json::Value {
    let spline = t.path();
    let knots = spline.knot_times();
    let coefficients: Vec<Vec<[f64; 6]>> = (0..knots.len().saturating_sub(1))
        .map(|k| (0..model.nv).map(|j| spline.coefficients(k, j)).collect())
        .collect();
    let (s, sdot, times) = t.profile();
    serde_json::json!({
        "step": key,
        "joints": model.dof_names(),
        "via_points": via,
        "spline": {
            "type": "piecewise_quintic",
            "knot_times": knots,
            "coefficients": coefficients,
        },
        "topp": {
            "s": s,
            "sdot": sdot,
            "t": times,
            "duration_s": t.duration(),
        },
    })
}

/// A planned path smoothed through its via points and timed by TOPP as one motion.
fn time_planned(
    scene: &Scene,
    planner: &mut Planner,
    path: &[Vec<f64>],
    fx: &Effects,
    topp_opts: &ToppOptions,
    key: &str,
    clock: &mut StageClock,
) -> Result<ToppTrajectory<MinJerk>, ScenarioError> {
    let t0 = std::time::Instant::now();
    let spline = smooth_path(planner, path)
        .map_err(|m| step_err(scene, key, None, format!("planned motion: {m}")))?;
    clock.smoothing_s += t0.elapsed().as_secs_f64();
    // A curved path's dense check may need more refinements: first to the strict
    // tolerance, then accepting a 1e-6 relative excess, then on a finer grid, once.
    let mut opts = ToppOptions {
        max_refinements: 30,
        ..topp_opts.clone()
    };
    loop {
        match topp(&scene.model, spline.clone(), &scene.limits, fx, &opts) {
            Ok(t) => {
                crate::scenarios::arm::topp_bench::record(
                    &scene.model,
                    &spline,
                    &scene.limits,
                    fx,
                    &opts,
                    &t,
                );
                return Ok(t);
            }
            Err(_) if opts.tolerance < 1e-6 => opts.tolerance = 1e-6,
            Err(_) if opts.segments < 2 * topp_opts.segments => opts.segments *= 2,
            Err(x) => return Err(step_err(scene, key, None, format!("planned motion: {x}"))),
        }
    }
}

/// The pieces being joined, with their start times and report entries.
struct Timeline {
    n: usize,
    knots: Vec<f64>,
    pieces: Vec<Box<dyn Trajectory + Send + Sync>>,
    infos: Vec<PieceInfo>,
}

impl Timeline {
    fn push(
        &mut self,
        model: &Model,
        p: Box<dyn Trajectory + Send + Sync>,
        kind: &'static str,
        from: String,
    ) {
        let t0 = *self.knots.last().expect("non-empty");
        let d = p.duration();
        let mut qe = vec![0.0; self.n];
        let (mut a, mut b) = (vec![0.0; self.n], vec![0.0; self.n]);
        p.sample(d, &mut qe, &mut a, &mut b);
        self.infos.push(PieceInfo {
            kind,
            from,
            start_s: t0,
            duration_s: d,
            end_q: named(model, &qe),
        });
        self.knots.push(t0 + d);
        self.pieces.push(p);
    }
}
