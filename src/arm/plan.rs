//! Planning an arm scenario's task: the [`Step`]s become joint waypoints (tool poses
//! through IK, seeded from the previous configuration so the arm stays on its branch),
//! straight tool lines ([`cartesian_line`]) and dwells, timed by the chosen profile and
//! joined into one [`Sequence`].
//!
//! - Consecutive joint-space steps form one group through its waypoints, timed as a whole
//!   (trapezoidal and quintic stop at each waypoint; the minimum-jerk spline passes
//!   through them); time-optimal timing runs TOPP on each straight joint segment, with
//!   the scene's torque limits and effects.
//! - A planned step ([`Step::Plan`]) runs RRT-Connect ([`super::planned`]) from the current
//!   configuration (with the grasped part on the tool between [`Step::Attach`] and
//!   [`Step::Detach`]) and times the path as one smooth motion through its via points by
//!   TOPP with the effects of that interval (the payload only while the part is held).
//! - A straight line keeps its tool-speed timing, or is re-timed by TOPP along its IK
//!   path when the timing is time-optimal.

use super::planned::{smooth_path, ScenePlanners};
use super::scene::{Scene, Step, Timing};
use crate::diag::LocatedError as ScenarioError;
use crate::dynamics::Effects;
use crate::kinematics::ik::{IkOptions, IkSolver, IkStatus};
use crate::model::Model;
use crate::trajectory::{
    cartesian_line, topp, CartesianOptions, LinearPath, MinJerk, Quintic, ToppOptions, Trajectory,
    Trapezoidal,
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
    pub start_s: f64,
    pub duration_s: f64,
    /// Joint values at its end, by joint name.
    pub end_q: serde_json::Map<String, serde_json::Value>,
}

/// The planned motion.
pub struct Plan {
    pub trajectory: Sequence,
    pub pieces: Vec<PieceInfo>,
    /// The configurations the task passes through (start, each step end).
    pub waypoints: Vec<Vec<f64>>,
    pub ik_solves: usize,
    pub planning_time_s: f64,
    /// When the task grasps a part: the attach and detach times (s); `None` when the
    /// payload (if any) is carried throughout.
    pub carry: Option<(f64, f64)>,
    /// The planned paths' via points (one list per planned segment).
    pub planned_paths: Vec<Vec<Vec<f64>>>,
    /// The planner's figures and notes, when the task plans.
    pub planner: Option<serde_json::Value>,
    /// Each planned segment's result, in order.
    pub planned_segments: Vec<super::planned::SegmentResult>,
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
    Line(Box<crate::trajectory::CartesianMove>, String),
    Dwell(Vec<f64>, f64, String),
}

/// Plans the scene's task from `scene.q0`.
pub fn plan(scene: &Scene) -> Result<Plan, ScenarioError> {
    let start = std::time::Instant::now();
    let model = &scene.model;
    let err = |key: &str, line: Option<usize>, msg: String| {
        ScenarioError::new(&scene.file, line, key, msg)
    };
    let mut ik = IkSolver::new(model);
    let ik_opts = IkOptions {
        tol_position: 1e-7,
        tol_rotation: 1e-7,
        max_restarts: 20,
        time_budget: Duration::from_millis(500),
        respect_limits: true,
        position_only: scene.position_only,
        ..Default::default()
    };
    let solve_ik = |ik: &mut IkSolver, target: &crate::spatial::Se3, seed: &[f64]| {
        let r = ik.solve(model, scene.tool, target, Some(seed), &ik_opts);
        if r.status != IkStatus::Converged {
            return Err(format!(
                "the tool pose is out of reach: IK {} (position error {:.3e} m, rotation error {:.3e} rad)",
                r.status.as_str(),
                r.position_error,
                r.rotation_error
            ));
        }
        Ok(r.q)
    };
    let grips = scene.steps.iter().any(|s| matches!(s.step, Step::Attach));
    let mut carrying = false;
    let mut planners: Option<ScenePlanners> = None;
    let mut groups: Vec<Group> = Vec::new();
    let mut q = scene.q0.clone();
    let mut waypoints = vec![q.clone()];
    let mut ik_solves = 0;
    let mut pending: Vec<Vec<f64>> = vec![q.clone()];
    let mut pending_keys: Vec<String> = Vec::new();
    let flush = |groups: &mut Vec<Group>,
                 pending: &mut Vec<Vec<f64>>,
                 keys: &mut Vec<String>,
                 q: &[f64]| {
        if pending.len() > 1 {
            groups.push(Group::Joint(std::mem::take(pending), std::mem::take(keys)));
        }
        *pending = vec![q.to_vec()];
        keys.clear();
    };
    for ts in &scene.steps {
        match &ts.step {
            Step::Joint(target) => {
                q = target.clone();
                if pending.last() != Some(&q) {
                    pending.push(q.clone());
                    pending_keys.push(ts.key.clone());
                }
            }
            Step::Pose(target) => {
                ik_solves += 1;
                q = solve_ik(&mut ik, target, &q).map_err(|m| err(&ts.key, ts.line, m))?;
                pending.push(q.clone());
                pending_keys.push(ts.key.clone());
            }
            Step::Plan(target) => {
                let goal = match target {
                    Ok(g) => g.clone(),
                    Err(pose) => {
                        ik_solves += 1;
                        solve_ik(&mut ik, pose, &q).map_err(|m| err(&ts.key, ts.line, m))?
                    }
                };
                flush(&mut groups, &mut pending, &mut pending_keys, &q);
                if planners.is_none() {
                    let settings = scene
                        .planner
                        .as_ref()
                        .ok_or_else(|| err(&ts.key, ts.line, "no planner settings".into()))?;
                    planners = Some(
                        ScenePlanners::new(scene, settings).map_err(|m| err("planner", None, m))?,
                    );
                }
                let p = planners.as_mut().expect("built");
                let path = p
                    .plan(&ts.key, carrying, &q, &goal)
                    .map_err(|m| err(&ts.key, ts.line, m))?;
                q = goal;
                groups.push(Group::Planned(path, carrying, ts.key.clone()));
                pending = vec![q.clone()];
            }
            Step::Attach | Step::Detach => {
                flush(&mut groups, &mut pending, &mut pending_keys, &q);
                carrying = matches!(ts.step, Step::Attach);
                groups.push(Group::Grip(carrying));
            }
            Step::Line(goal) => {
                flush(&mut groups, &mut pending, &mut pending_keys, &q);
                let mut opts = CartesianOptions {
                    samples: scene.line_samples,
                    max_linear_speed: scene.tool_speed,
                    max_linear_acceleration: scene.tool_acceleration,
                    joint_limits: Some(scene.limits.clone()),
                    ..Default::default()
                };
                opts.ik.position_only = scene.position_only;
                let mv = cartesian_line(model, scene.tool, &q, goal, &opts)
                    .map_err(|e| err(&ts.key, ts.line, format!("straight line: {e}")))?;
                ik_solves += scene.line_samples;
                let mut qd = vec![0.0; model.nv];
                let mut qdd = vec![0.0; model.nv];
                mv.sample(mv.duration(), &mut q, &mut qd, &mut qdd);
                groups.push(Group::Line(Box::new(mv), ts.key.clone()));
                pending = vec![q.clone()];
            }
            Step::Dwell(d) => {
                flush(&mut groups, &mut pending, &mut pending_keys, &q);
                groups.push(Group::Dwell(q.clone(), *d, ts.key.clone()));
            }
        }
        if let Some(k) =
            (0..model.nv).find(|&k| q[k] < scene.lower[k] - 1e-9 || q[k] > scene.upper[k] + 1e-9)
        {
            return Err(err(
                &ts.key,
                ts.line,
                format!(
                    "the step ends with joint {} at {:.6}, outside its limits [{}, {}]",
                    model.dof_names()[k],
                    q[k],
                    scene.lower[k],
                    scene.upper[k]
                ),
            ));
        }
        waypoints.push(q.clone());
    }
    flush(&mut groups, &mut pending, &mut pending_keys, &q);
    if groups.is_empty() {
        return Err(err(
            "task",
            None,
            "the task does not move the arm (every step ends where the arm already is)".into(),
        ));
    }

    // Timing.
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
    let lim = &scene.limits;
    for g in groups {
        let fx = if carrying { loaded } else { &free };
        match g {
            Group::Joint(wps, keys) => {
                let from = keys.join(", ");
                let e = |x: crate::trajectory::TrajectoryError| {
                    err(
                        keys.first().map_or("task", |s| s.as_str()),
                        None,
                        format!("joint motion: {x}"),
                    )
                };
                match scene.timing {
                    Timing::Trapezoidal => tl.push(
                        model,
                        Box::new(Trapezoidal::new(&wps, lim).map_err(e)?),
                        "joint",
                        from,
                    ),
                    Timing::Quintic => tl.push(
                        model,
                        Box::new(Quintic::new(&wps, lim).map_err(e)?),
                        "joint",
                        from,
                    ),
                    Timing::MinimumJerk => tl.push(
                        model,
                        Box::new(MinJerk::new(&wps, lim).map_err(e)?),
                        "joint",
                        from,
                    ),
                    Timing::TimeOptimal => {
                        for (i, w) in wps.windows(2).enumerate() {
                            let path = LinearPath::new(w[0].clone(), w[1].clone()).map_err(e)?;
                            let t = topp(model, path, lim, fx, &topp_opts).map_err(e)?;
                            let key = keys.get(i).cloned().unwrap_or_default();
                            tl.push(model, Box::new(t), "joint", key);
                        }
                    }
                }
            }
            Group::Planned(path, with_part, key) => {
                let planner = planners.as_mut().expect("built").planner(with_part);
                let spline = smooth_path(planner, &path)
                    .map_err(|m| err(&key, None, format!("planned motion: {m}")))?;
                // A curved path's dense check may need more refinements (and accepts a
                // 1e-6 relative excess); then a finer grid, once.
                let mut opts = ToppOptions {
                    max_refinements: 30,
                    tolerance: 1e-6,
                    ..topp_opts.clone()
                };
                let t = loop {
                    match topp(model, spline.clone(), lim, fx, &opts) {
                        Ok(t) => break t,
                        Err(_) if opts.segments < 2 * topp_opts.segments => opts.segments *= 2,
                        Err(x) => return Err(err(&key, None, format!("planned motion: {x}"))),
                    }
                };
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
                        .map_err(|x| err(&key, None, format!("straight line: {x}")))?;
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
    let end = *tl.knots.last().expect("non-empty");
    let carry = attach_t.map(|a| (a, detach_t.unwrap_or(end)));
    let planned_segments = planners
        .as_mut()
        .map_or_else(Vec::new, |p| std::mem::take(&mut p.results));
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
        planned_paths,
        planner,
        planned_segments,
    })
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
