//! The planner: the robot half built once ([`PlanningRobot`]: spheres and self pairs), a
//! [`Checker`] for the current scene, the RRT-Connect search and the simplifier, with their
//! buffers, answering start → goal queries.
//!
//! A query checks the start and goal (joint limits, then collisions, exactly; a rejected
//! one names the joint, or the pair it touches and by how much), tries the straight edge,
//! searches, and simplifies; in the optimising mode ([`PlannerKind::Aorrtc`]) it then
//! searches for cheaper paths until its budget is spent ([`crate::planning::improve`]).
//! `plan_time_us` runs from the query to the first path (the robot half is built once,
//! [`PlanningRobot::new`], the scene once per [`Planner::set_obstacles`]);
//! `simplify_time_us` is the rest. In the optimising mode `plan_time_us` is the whole
//! query, the simplification of every path found included (as VAMP's AORRTC reports it),
//! and `simplify_time_us` is 0. The search polls the stop flag of [`PlanOptions::stop`]
//! (Ctrl-C) with its time limit.

use crate::collision::Obstacle;
use crate::model::Model;
use crate::planning::checker::{CheckScratch, Checker};
use crate::planning::environment::Environment;
use crate::planning::improve::{ImproveContext, Improvement, Optimiser};
use crate::planning::plan_error::PlanSetupError;
pub use crate::planning::plan_options::PlanOptions;
use crate::planning::plan_options::PlannerKind;
use crate::planning::repair::{EdgeRepair, RepairTools};
use crate::planning::rrt::{Rrt, SearchEnd, SearchLimit};
use crate::planning::sampler::{bounds, Sampler};
use crate::planning::setup::PlanningRobot;
use crate::planning::simplify::{path_length, Simplifier};
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// How a query ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanStatus {
    /// A collision-free path.
    Solved,
    /// No path within the limits.
    Failed,
    /// The start is outside the joint limits or in collision.
    InvalidStart,
    /// The goal is outside the joint limits or in collision.
    InvalidGoal,
}

/// The answer to a query.
#[derive(Clone, Debug, Serialize)]
pub struct PlanResult {
    /// How it ended.
    pub status: PlanStatus,
    /// Why it did not solve.
    pub reason: Option<String>,
    /// Query start to first path (µs); in the optimising mode, the whole query.
    pub plan_time_us: f64,
    /// Simplification (µs); 0 in the optimising mode (counted in `plan_time_us`).
    pub simplify_time_us: f64,
    /// Search iterations.
    pub iterations: usize,
    /// Length of the first path (joint-space L2).
    pub cost_initial: f64,
    /// Length after simplification.
    pub cost: f64,
    /// Waypoints, start and goal included.
    pub path: Vec<Vec<f64>>,
    /// The search that answered.
    pub planner: PlannerKind,
    /// The cost after each improvement, with its time from the query's start: the
    /// simplified first path, then (optimising mode) each cheaper one.
    pub improvements: Vec<Improvement>,
}

/// A planner for one robot, one scene at a time.
#[derive(Debug)]
pub struct Planner {
    /// The collision checker of the scene.
    pub checker: Checker,
    /// The robot half, shared.
    pub robot: Arc<PlanningRobot>,
    opts: PlanOptions,
    sampler: Sampler,
    rrt: Rrt,
    optimiser: Option<Optimiser>,
    simplifier: Simplifier,
    scratch: CheckScratch,
    lo: Vec<f32>,
    hi: Vec<f32>,
    start: Vec<f32>,
    goal: Vec<f32>,
    path: Vec<f32>,
    repair: EdgeRepair,
}

impl Planner {
    /// A planner for `model` among `obstacles`. `disabled` lists the SRDF's disabled link
    /// pairs; `None` computes the allowed-collision matrix ([`crate::planning::acm`]). Builds the
    /// robot half; to plan many scenes, build it once ([`PlanningRobot::new`]) and use
    /// [`Planner::for_robot`].
    pub fn new(
        model: &Model,
        obstacles: &[Obstacle],
        disabled: Option<&[(String, String)]>,
        opts: PlanOptions,
    ) -> Result<Planner, PlanSetupError> {
        let robot = Arc::new(PlanningRobot::new(model, disabled, &opts)?);
        Ok(Planner::in_scene(robot, Environment::new(obstacles)?, opts))
    }

    /// A planner for a robot half built before, in an empty scene.
    pub fn for_robot(robot: Arc<PlanningRobot>, opts: PlanOptions) -> Planner {
        Planner::in_scene(robot, Environment::default(), opts)
    }

    /// A planner for a robot half in the scene `env`.
    fn in_scene(robot: Arc<PlanningRobot>, env: Environment, opts: PlanOptions) -> Planner {
        let checker = robot.checker(env, opts.check);
        let nv = robot.model.nv;
        let (lo, hi): (Vec<f32>, Vec<f32>) = (0..nv)
            .map(|k| {
                let (l, h) = bounds(&robot.model, k);
                (l as f32, h as f32)
            })
            .unzip();
        Planner {
            sampler: Sampler::new(opts.sampler, &lo, &hi, opts.seed),
            scratch: checker.scratch(),
            rrt: Rrt::new(nv, opts.rrt),
            optimiser: (opts.planner == PlannerKind::Aorrtc).then(|| Optimiser::new(nv, opts.rrt)),
            simplifier: Simplifier::new(opts.simplifier),
            checker,
            robot,
            lo,
            hi,
            start: vec![0.0; nv],
            goal: vec![0.0; nv],
            path: Vec::with_capacity(nv * 1024),
            repair: EdgeRepair::with_capacity(nv, 1024),
            opts,
        }
    }

    /// Sets the scene: the obstacles the next queries plan among (meshes are refused with
    /// the obstacle's name).
    pub fn set_obstacles(&mut self, obstacles: &[Obstacle]) -> Result<(), PlanSetupError> {
        let env = Environment::new(obstacles)?;
        self.checker = self.robot.checker(env, self.opts.check);
        self.scratch = self.checker.scratch();
        Ok(())
    }

    /// Sets (or clears) the flag that stops the next searches (see [`PlanOptions::stop`]).
    pub fn set_stop(&mut self, stop: Option<Arc<AtomicBool>>) {
        self.opts.stop = stop;
    }

    /// Plans from `start` to `goal` among `obstacles` (sets the scene, then plans).
    pub fn plan_among(
        &mut self,
        obstacles: &[Obstacle],
        start: &[f64],
        goal: &[f64],
    ) -> Result<PlanResult, PlanSetupError> {
        self.set_obstacles(obstacles)?;
        Ok(self.plan(start, goal))
    }

    /// Why `q` is not a valid start or goal, if it is not: a value outside its joint's
    /// limits (named), or what it touches (the deepest pair and by how much).
    fn invalid(&mut self, q: &[f64], which: &str) -> Option<String> {
        let nv = self.lo.len();
        if q.len() != nv {
            return Some(format!(
                "{which} has {} values, the model has {nv} coordinates",
                q.len()
            ));
        }
        for (k, &qk) in q.iter().enumerate() {
            let x = qk as f32;
            if !(x >= self.lo[k] && x <= self.hi[k]) {
                return Some(format!(
                    "{which}: joint '{}' = {} is outside its limits [{}, {}]",
                    self.robot.model.dof_joint(k).name,
                    q[k],
                    self.lo[k],
                    self.hi[k]
                ));
            }
        }
        let qf: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        if self.checker.config_free(&qf, &mut self.scratch) {
            return None;
        }
        let contacts = self.robot.contacts(&self.checker.env, q);
        Some(match contacts.first() {
            Some(c) if contacts.len() > 1 => format!(
                "{which} is in collision: {c} (and {} more pair{})",
                contacts.len() - 1,
                if contacts.len() > 2 { "s" } else { "" }
            ),
            Some(c) => format!("{which} is in collision: {c}"),
            None => format!("{which} is in collision"),
        })
    }

    /// Checks a query's ends and stores them in f32: both within the limits and free, in
    /// one batch; otherwise the reason, one end at a time (the start's first).
    fn take_ends(&mut self, start: &[f64], goal: &[f64]) -> Result<(), (PlanStatus, String)> {
        let nv = self.lo.len();
        if start.len() == nv && goal.len() == nv {
            for k in 0..nv {
                self.start[k] = start[k] as f32;
                self.goal[k] = goal[k] as f32;
            }
            let (lo, hi) = (&self.lo, &self.hi);
            let inside = |q: &[f32]| (0..nv).all(|k| q[k] >= lo[k] && q[k] <= hi[k]);
            if inside(&self.start)
                && inside(&self.goal)
                && self
                    .checker
                    .both_free(&self.start, &self.goal, &mut self.scratch)
            {
                return Ok(());
            }
        }
        for (q, which, status) in [
            (start, "start", PlanStatus::InvalidStart),
            (goal, "goal", PlanStatus::InvalidGoal),
        ] {
            if let Some(why) = self.invalid(q, which) {
                return Err((status, why));
            }
        }
        // Both valid (the lengths too): stored above.
        Ok(())
    }

    /// Plans from `start` to `goal`.
    pub fn plan(&mut self, start: &[f64], goal: &[f64]) -> PlanResult {
        let t0 = Instant::now();
        let mut res = PlanResult {
            status: PlanStatus::Solved,
            reason: None,
            plan_time_us: 0.0,
            simplify_time_us: 0.0,
            iterations: 0,
            cost_initial: 0.0,
            cost: 0.0,
            path: Vec::new(),
            planner: self.opts.planner,
            improvements: Vec::new(),
        };
        if let Err((status, why)) = self.take_ends(start, goal) {
            res.status = status;
            res.reason = Some(why);
            res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
            return res;
        }
        let nv = self.lo.len();
        // The sampler lives in the planner (no allocation per query); each query starts
        // its sequence afresh, so the same query gives the same path.
        let mut sampler = std::mem::take(&mut self.sampler);
        sampler.reset();
        let limit = SearchLimit {
            deadline: self.opts.time_limit.map(|d| t0 + d),
            stop: self.opts.stop.clone(),
        };
        let found = self.search(&mut sampler, &limit);
        res.iterations = self.rrt.iterations;
        res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
        if let Err(end) = found {
            self.sampler = sampler;
            res.status = PlanStatus::Failed;
            res.reason = Some(self.end_reason(end));
            if end != SearchEnd::Interrupted {
                self.explain_failure(start, goal, &mut res);
            }
            return res;
        }
        res.cost_initial = path_length(&self.path, nv);
        let t1 = Instant::now();
        let keep_clearance = self.opts.check.clearance > 0.0;
        self.scratch.ends.clear();
        self.scratch.ends.extend_from_slice(&self.start);
        self.scratch.ends.extend_from_slice(&self.goal);
        if self.opts.simplify {
            self.scratch.keep_clearance = keep_clearance;
            self.simplifier.run(
                &mut self.path,
                nv,
                &self.checker,
                &mut self.scratch,
                sampler.rng(),
                self.opts.stop.as_ref(),
            );
            self.scratch.keep_clearance = false;
        }
        res.improvements.push(Improvement {
            time_us: t0.elapsed().as_secs_f64() * 1e6,
            iterations: res.iterations,
            cost: path_length(&self.path, nv),
        });
        if let Some(optimiser) = self.optimiser.as_mut() {
            let cx = ImproveContext {
                checker: &self.checker,
                scratch: &mut self.scratch,
                simplifier: self.opts.simplify.then_some(&mut self.simplifier),
                keep_clearance,
                rrt: &mut self.rrt,
                sampler: &mut sampler,
                stop: self.opts.stop.as_ref(),
                lo: &self.lo,
                hi: &self.hi,
            };
            let (budget, first) = (self.opts.budget, res.iterations);
            optimiser.run(
                cx,
                &mut self.path,
                nv,
                budget,
                first,
                t0,
                &limit,
                &mut res.improvements,
            );
            res.iterations = optimiser.iterations;
        }
        self.sampler = sampler;
        if self.optimiser.is_some() {
            // The optimisation is the search: its time includes the paths' simplification.
            res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
        } else {
            res.simplify_time_us = t1.elapsed().as_secs_f64() * 1e6;
        }
        res.cost = path_length(&self.path, nv);
        res.path = self
            .path
            .chunks_exact(nv)
            .map(|p| p.iter().map(|&x| x as f64).collect())
            .collect();
        // The ends are the exact f64 queries (the f32 ones were checked, 1e-7 rad away).
        let n = res.path.len();
        res.path[0].copy_from_slice(start);
        res.path[n - 1].copy_from_slice(goal);
        res
    }

    /// RRT-Connect with discrete edge checks (fast), then every edge of the path checked
    /// continuously; an edge that fails is re-planned with continuous checks and spliced
    /// in. If a repair fails, the whole search is run again with continuous checks.
    fn search(&mut self, sampler: &mut Sampler, limit: &SearchLimit) -> Result<(), SearchEnd> {
        let (start, goal) = (&self.start, &self.goal);
        let mut tools = RepairTools {
            rrt: &mut self.rrt,
            checker: &self.checker,
            scratch: &mut self.scratch,
            sampler,
            limit,
        };
        let (found, iterations) = self.repair.search_certified(
            &mut tools,
            &mut self.path,
            start.len(),
            |t, mode, path| {
                t.rrt.solve(
                    t.checker, t.scratch, t.sampler, start, goal, t.limit, mode, path,
                )
            },
        );
        self.rrt.iterations = iterations;
        found
    }

    /// Adds to a failed query's reason a blocked band of a joint between start and goal,
    /// if one is found ([`crate::planning::walls`]).
    fn explain_failure(&mut self, start: &[f64], goal: &[f64], res: &mut PlanResult) {
        let model = &self.robot.model;
        let wall = crate::planning::walls::wall_between(
            model,
            &self.checker,
            &mut self.scratch,
            start,
            goal,
            self.opts.seed,
        );
        if let (Some(w), Some(reason)) = (wall, res.reason.as_mut()) {
            reason.push_str(&format!(
                "; joint '{}' must pass through [{:.2}, {:.2}] on the way, where none of {} \
                 random configurations per {} slice is free: probably no path exists",
                model.dof_joint(w.coordinate).name,
                w.from,
                w.to,
                crate::planning::walls::SAMPLES,
                crate::planning::walls::STEP
            ));
        }
    }

    /// Checks one configuration exactly (true when free).
    pub fn is_free(&mut self, q: &[f64]) -> bool {
        let qf: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        self.checker.config_free(&qf, &mut self.scratch)
    }

    /// Checks the straight edge `a → b` continuously (true when free; not the hot path:
    /// it converts to f32 through two small vectors).
    pub fn edge_free(&mut self, a: &[f64], b: &[f64]) -> bool {
        let af: Vec<f32> = a.iter().map(|&x| x as f32).collect();
        let bf: Vec<f32> = b.iter().map(|&x| x as f32).collect();
        self.checker.edge_free(
            &af,
            &bf,
            crate::planning::checker::EdgeMode::Continuous,
            &mut self.scratch,
        )
    }

    /// Configurations and edges of this planner's own thread that the spheres could not
    /// clear and the exact geometry decided ([`crate::planning::checker::ExactPairs`]).
    pub fn exact_checks(&self) -> u64 {
        self.scratch.exact.as_ref().map_or(0, |e| e.exact_checks)
    }

    /// The check counters (edges, batches of eight) since the planner was built.
    pub fn counters(&self) -> (u64, u64) {
        (self.scratch.edges, self.scratch.batches)
    }
}

pub mod goal_query;
