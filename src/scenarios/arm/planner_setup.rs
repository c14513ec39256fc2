//! Planned motions in arm scenarios: the `[planner]` settings, the grasped part, the
//! RRT-Connect planners of the scene (one for the bare arm, one with the part on the
//! tool), and the smooth path through a planned path's via points that TOPP re-times as
//! one motion (no stop at the via points).
//!
//! - **Collision model.** The planner sees the model's collision geometry as spheres
//!   ([`crate::planning::spheres`]) and the scenario's obstacles exactly. Links that the
//!   scenario disables against an obstacle (a base resting on the table) are left out of
//!   the planner's model; the parry check of the whole motion still covers them.
//! - **Self pairs.** From the `[planner] srdf`, or from the allowed-collision matrix
//!   computed as MoveIt's Setup Assistant computes one ([`crate::planning::acm`]: adjacent,
//!   default, always and never-colliding pairs dropped); the scenario's link–link
//!   `collision.disabled_pairs` are dropped as well. The report says which. The planner
//!   with the grasped part keeps the bare arm's matrix for every pair without the tool
//!   link and checks every pair of the tool link (its geometry is what changed).
//! - **Smooth path.** A minimum-jerk spline through the via points ([`MinJerk`], which
//!   passes through them without stopping; segment durations by chord length). Its chords
//!   at 48 points per via interval are checked with the planner's continuous edge check;
//!   where one collides, the planned (collision-free) polyline gets extra via points in
//!   that interval and its neighbours, which pulls the spline onto it, and the check
//!   repeats. The planner's shortcuts keep [`SMOOTHING_ROOM`] from the obstacles, so the
//!   spline has room to round the corners of the simplified path.

use crate::collision::Obstacle;
use crate::core::spatial::Se3;
use crate::model::{Geometry, Model, Shape};
use crate::motion::{MinJerk, Trajectory};
use crate::planning::{PairSource, PlanOptions, PlanStatus, Planner, PlanningRobot};
pub use crate::scenarios::arm::planner_settings::{Part, PlannerSettings};
use crate::scenarios::arm::scene::arm_scene::Scene;

/// `model` with the part as a collision box on link `tool`.
pub fn with_part(model: &Model, tool: usize, part: &Part) -> Model {
    let mut m = model.clone();
    m.links[tool].collisions.push(Geometry {
        origin: Se3::from_xyz_rpy(part.xyz, [0.0; 3]),
        shape: Shape::Box { size: part.size },
        rgba: None,
    });
    m
}

/// The planners of one scene.
pub struct ScenePlanners {
    free: Planner,
    carrying: Option<Planner>,
    /// How the self pairs were chosen, and what the planner leaves out.
    pub notes: Vec<String>,
    /// Planned segments so far.
    pub segments: usize,
    /// Search iterations and planning time over the segments.
    pub iterations: usize,
    /// Planning time over the segments (µs).
    pub plan_time_us: f64,
    /// Simplification time over the segments (µs).
    pub simplify_time_us: f64,
    /// Building the planners: sphere models and allowed-collision matrices (s).
    pub setup_s: f64,
    /// Each planned segment's result, in order (path in the `results` form of
    /// `armsim plan --json`).
    pub results: Vec<SegmentResult>,
}

/// One planned segment of a scenario's task.
#[derive(Clone, Debug)]
pub struct SegmentResult {
    /// The task step's key (`task.steps[2]`, ...).
    pub step: String,
    /// Whether the part was on the tool.
    pub carrying: bool,
    /// The planner's answer (status, reason, times, costs, via points).
    pub result: crate::planning::PlanResult,
}

impl ScenePlanners {
    /// Builds the planners of `scene` (the carrying one when the task grasps a part).
    pub fn new(scene: &Scene, settings: &PlannerSettings) -> Result<ScenePlanners, String> {
        let t0 = std::time::Instant::now();
        let obstacles = scene
            .obstacles
            .iter()
            .map(|o| o.to_obstacle().map_err(|e| e.to_string()))
            .collect::<Result<Vec<Obstacle>, _>>()?;
        let names: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
        let disabled = &scene.planner_disabled;
        let mut base = scene.model.clone();
        let mut notes = Vec::new();
        for pair in disabled {
            for (a, b) in [(&pair[0], &pair[1]), (&pair[1], &pair[0])] {
                if let (Some(l), true) = (base.link_id(a), names.contains(&b.as_str())) {
                    if !base.links[l].collisions.is_empty() {
                        base.links[l].collisions.clear();
                        notes.push(format!(
                            "planner: link '{a}' left out (disabled against obstacle '{b}')"
                        ));
                    }
                }
            }
        }
        let link_pairs: Vec<(String, String)> = disabled
            .iter()
            .filter(|p| base.link_id(&p[0]).is_some() && base.link_id(&p[1]).is_some())
            .map(|p| (p[0].clone(), p[1].clone()))
            .collect();
        let mut opts = PlanOptions {
            seed: settings.seed,
            time_limit: Some(settings.time_limit),
            simplify: settings.simplify,
            planner: settings.algorithm,
            budget: settings.budget,
            ..Default::default()
        };
        opts.spheres.package_path = scene.package_paths.explicit.clone();
        opts.spheres.max_overshoot = settings.max_overshoot;
        opts.rrt.range = settings.range as f32;
        opts.check.clearance = SMOOTHING_ROOM;
        let build = |m: &Model,
                     srdf: Option<&[(String, String)]>,
                     opts: &PlanOptions|
         -> Result<Planner, String> {
            let robot = PlanningRobot::with_extra_disabled(m, srdf, &link_pairs, opts)
                .map_err(|e| e.to_string())?;
            let mut p = Planner::for_robot(std::sync::Arc::new(robot), opts.clone());
            p.set_obstacles(&obstacles).map_err(|e| e.to_string())?;
            Ok(p)
        };
        let srdf = settings.srdf.as_ref().map(|(_, pairs)| pairs.as_slice());
        let free = build(&base, srdf, &opts)?;
        notes.push(match (&settings.srdf, &free.robot.pair_source) {
            (Some((path, _)), _) => format!("planner: self pairs from the SRDF {path}"),
            (None, PairSource::Computed(acm)) => format!(
                "planner: no SRDF; self pairs from the allowed-collision matrix computed as MoveIt's \
                 Setup Assistant does ({}), {} pairs checked",
                acm.counts()
                    .iter()
                    .map(|(r, n)| format!("{n} {}", r.as_str().to_lowercase()))
                    .collect::<Vec<_>>()
                    .join(", "),
                acm.checked.len()
            ),
            (None, PairSource::Srdf) => String::new(),
        });
        notes.extend(
            free.checker
                .spheres
                .warnings
                .iter()
                .map(|w| format!("planner: {w}")),
        );
        // With the part, only the tool link's geometry changes: the free planner's disabled
        // pairs stand for the other links, and every pair of the tool link is checked.
        let tool = &base.links[scene.tool].name;
        let carried_off: Option<Vec<(String, String)>> = match (&free.robot.pair_source, srdf) {
            (PairSource::Computed(acm), None) => Some(
                acm.disabled_names()
                    .into_iter()
                    .filter(|(a, b)| a != tool && b != tool)
                    .collect(),
            ),
            _ => srdf.map(<[_]>::to_vec),
        };
        let carrying = match &scene.part {
            Some(p) => {
                // The links the bare arm's cover refined start refined.
                let mut copts = opts.clone();
                copts.spheres = free.robot.sphere_options.clone();
                let m = with_part(&base, scene.tool, p);
                Some(build(&m, carried_off.as_deref(), &copts)?)
            }
            None => None,
        };
        Ok(ScenePlanners {
            free,
            carrying,
            notes,
            segments: 0,
            iterations: 0,
            plan_time_us: 0.0,
            simplify_time_us: 0.0,
            setup_s: t0.elapsed().as_secs_f64(),
            results: Vec::new(),
        })
    }

    /// The planner for the bare arm, or for the arm with the part.
    pub fn planner(&mut self, carrying: bool) -> &mut Planner {
        match (&mut self.carrying, carrying) {
            (Some(p), true) => p,
            _ => &mut self.free,
        }
    }

    /// A collision-free path from `a` to `b` (via points, ends included).
    pub fn plan(
        &mut self,
        step: &str,
        carrying: bool,
        a: &[f64],
        b: &[f64],
    ) -> Result<Vec<Vec<f64>>, String> {
        let r = self.planner(carrying).plan(a, b);
        self.record(step, carrying, r)
    }

    /// A collision-free path from `a` to `goal` (joint values or a tool pose: any of its
    /// IK solutions) keeping `constraints` along every straight edge
    /// ([`Planner::plan_to`]); the path ends at the goal reached.
    pub fn plan_query(
        &mut self,
        step: &str,
        carrying: bool,
        a: &[f64],
        goal: &crate::planning::pose_goal::Goal,
        constraints: &[crate::planning::path_constraints::PathConstraint],
    ) -> Result<Vec<Vec<f64>>, String> {
        let g = self
            .planner(carrying)
            .plan_to(a, goal, constraints)
            .map_err(|e| format!("path constraints: {e}"))?;
        self.record(step, carrying, g.result)
    }

    /// Counts a query's answer, keeps it for the report; its path, or why there is none.
    fn record(
        &mut self,
        step: &str,
        carrying: bool,
        r: crate::planning::PlanResult,
    ) -> Result<Vec<Vec<f64>>, String> {
        self.segments += 1;
        self.iterations += r.iterations;
        self.plan_time_us += r.plan_time_us;
        self.simplify_time_us += r.simplify_time_us;
        self.results.push(SegmentResult {
            step: step.to_string(),
            carrying,
            result: r.clone(),
        });
        match r.status {
            PlanStatus::Solved => Ok(r.path),
            s => Err(format!(
                "planner: {} ({})",
                match s {
                    PlanStatus::InvalidStart => "invalid start",
                    PlanStatus::InvalidGoal => "invalid goal",
                    _ => "failed",
                },
                r.reason.unwrap_or_default()
            )),
        }
    }
}

/// Chord checks per via interval of the smooth path.
const CHORDS: usize = 48;

/// Via points closer than this to the previous one are dropped (rad).
const MIN_GAP: f64 = 1e-4;

/// Refinement rounds of [`smooth_path`].
const ROUNDS: usize = 16;

/// Distance from the obstacles that the planner's shortcuts keep (m), so that the smooth
/// path through the via points has room to round the corners: a taut path would touch the
/// obstacles it wraps, and any spline through it would cut into them.
const SMOOTHING_ROOM: f32 = 0.01;

/// Most via points the refinement may reach, per planned via point.
const MAX_GROWTH: usize = 16;

/// A smooth path through the via points of the collision-free polyline `path`, whose
/// chords pass `planner`'s continuous check (see the module docs). The spline's segment
/// durations are proportional to the via intervals' joint-space lengths (chord-length
/// parameterisation: no wiggle where via points crowd), the end ones doubled (the spline
/// starts and ends at rest).
pub fn smooth_path(planner: &mut Planner, path: &[Vec<f64>]) -> Result<MinJerk, String> {
    let len = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let last = path.len() - 1;
    let mut wps: Vec<Vec<f64>> = vec![path[0].clone()];
    for (i, w) in path.iter().enumerate().skip(1) {
        if i == last || len(w, wps.last().expect("non-empty")) > MIN_GAP {
            wps.push(w.clone());
        }
    }
    if wps.len() > 2 && len(&wps[wps.len() - 2], &wps[wps.len() - 1]) <= MIN_GAP {
        wps.remove(wps.len() - 2);
    }
    let n = path[0].len();
    let cap = MAX_GROWTH * wps.len();
    for _ in 0..ROUNDS {
        if wps.len() > cap {
            break;
        }
        let m = wps.len() - 1;
        let h: Vec<f64> = (0..m)
            .map(|k| {
                let end = if k == 0 || k + 1 == m { 2.0 } else { 1.0 };
                end * len(&wps[k], &wps[k + 1]).max(MIN_GAP)
            })
            .collect();
        let spline = MinJerk::with_durations(&wps, &h).map_err(|e| e.to_string())?;
        let knots = spline.knot_times().to_vec();
        let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut prev = wps[0].clone();
        let mut split = vec![false; m];
        let mut clean = true;
        for k in 0..m {
            for i in 1..=CHORDS {
                let t = knots[k] + (knots[k + 1] - knots[k]) * i as f64 / CHORDS as f64;
                spline.sample(t, &mut q, &mut qd, &mut qdd);
                if !planner.edge_free(&prev, &q) {
                    clean = false;
                    split[k.saturating_sub(1)..(k + 2).min(m)].fill(true);
                }
                prev.copy_from_slice(&q);
            }
        }
        if clean {
            return Ok(spline);
        }
        // Midpoints in the offending intervals and their neighbours.
        let mut out = vec![wps[0].clone()];
        for (k, w) in wps.windows(2).enumerate() {
            if split[k] {
                out.push(w[0].iter().zip(&w[1]).map(|(a, b)| 0.5 * (a + b)).collect());
            }
            out.push(w[1].clone());
        }
        wps = out;
    }
    Err(format!(
        "the smooth path through the planned via points still collides after refining them to {} points", wps.len()
    ))
}
