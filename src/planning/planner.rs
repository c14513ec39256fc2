//! The planner: a [`Checker`] for one scene plus the RRT-Connect search and the
//! simplifier, with their buffers, answering start → goal queries.
//!
//! A query checks the start and goal (joint limits, then collisions, exactly), tries the
//! straight edge, searches, and simplifies. `plan_time_us` runs from the query to the first
//! path (the scene is built once, in [`Planner::new`]); `simplify_time_us` is the rest.

use super::checker::{CheckOptions, CheckScratch, Checker, EdgeMode};
use super::environment::Environment;
use super::rrt::{Rrt, RrtOptions, SearchEnd};
use super::sampler::{bounds, Sampler, SamplerKind};
use super::self_pairs::{self, PairSource};
use super::simplify::{path_length, Simplifier, SimplifyOptions};
use super::spheres::{SphereModel, SphereOptions};
use crate::collision::Obstacle;
use crate::model::Model;
use serde::Serialize;
use std::time::{Duration, Instant};

/// Everything a query can be told.
#[derive(Clone, Debug)]
pub struct PlanOptions {
    /// Seed of the sampler and of the simplifier's random choices.
    pub seed: u64,
    /// Wall-clock limit of the search (simplification is not counted).
    pub time_limit: Option<Duration>,
    /// Simplify the path.
    pub simplify: bool,
    /// Sample sequence.
    pub sampler: SamplerKind,
    /// Search settings.
    pub rrt: RrtOptions,
    /// Collision-check settings.
    pub check: CheckOptions,
    /// Simplification settings.
    pub simplifier: SimplifyOptions,
    /// Sphere generation settings.
    pub spheres: SphereOptions,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            time_limit: None,
            simplify: true,
            sampler: SamplerKind::Halton,
            rrt: RrtOptions::default(),
            check: CheckOptions::default(),
            simplifier: SimplifyOptions::default(),
            spheres: SphereOptions::default(),
        }
    }
}

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
    /// Query start to first path (µs).
    pub plan_time_us: f64,
    /// Simplification (µs).
    pub simplify_time_us: f64,
    /// Search iterations.
    pub iterations: usize,
    /// Length of the first path (joint-space L2).
    pub cost_initial: f64,
    /// Length after simplification.
    pub cost: f64,
    /// Waypoints, start and goal included.
    pub path: Vec<Vec<f64>>,
}

/// A planner for one robot in one scene.
#[derive(Debug)]
pub struct Planner {
    /// The collision checker of the scene.
    pub checker: Checker,
    /// How the self-collision pairs were chosen.
    pub pair_source: PairSource,
    opts: PlanOptions,
    sampler: Sampler,
    rrt: Rrt,
    simplifier: Simplifier,
    scratch: CheckScratch,
    lo: Vec<f32>,
    hi: Vec<f32>,
    start: Vec<f32>,
    goal: Vec<f32>,
    path: Vec<f32>,
    sub: Vec<f32>,
    spliced: Vec<f32>,
}

impl Planner {
    /// A planner for `model` among `obstacles`. `disabled` lists the SRDF's disabled link
    /// pairs; `None` chooses the self pairs by sampling (see [`self_pairs`]).
    pub fn new(
        model: &Model,
        obstacles: &[Obstacle],
        disabled: Option<&[(String, String)]>,
        opts: PlanOptions,
    ) -> Result<Planner, String> {
        let spheres = SphereModel::new(model, &opts.spheres);
        if spheres.is_empty() {
            return Err(format!(
                "model '{}' has no collision geometry the planner can use",
                model.name
            ));
        }
        let (pairs, pair_source) = match disabled {
            Some(d) => (
                self_pairs::from_disabled(model, &spheres, d),
                PairSource::Srdf,
            ),
            None => {
                let n = 10_000;
                (
                    self_pairs::sampled(model, &spheres, n, opts.seed).0,
                    PairSource::Sampled(n),
                )
            }
        };
        let env = Environment::new(obstacles)?;
        let checker = Checker::new(model, spheres, env, pairs, opts.check);
        let nv = model.nv;
        let (lo, hi): (Vec<f32>, Vec<f32>) = (0..nv)
            .map(|k| {
                let (l, h) = bounds(model, k);
                (l as f32, h as f32)
            })
            .unzip();
        Ok(Planner {
            sampler: Sampler::new(opts.sampler, &lo, &hi, opts.seed),
            scratch: checker.scratch(),
            rrt: Rrt::new(nv, opts.rrt),
            simplifier: Simplifier::new(opts.simplifier),
            checker,
            pair_source,
            lo,
            hi,
            start: vec![0.0; nv],
            goal: vec![0.0; nv],
            path: Vec::with_capacity(nv * 1024),
            sub: Vec::with_capacity(nv * 1024),
            spliced: Vec::with_capacity(nv * 1024),
            opts,
        })
    }

    /// Why `q` is not a valid start or goal, if it is not.
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
                    "{which}: coordinate {k} = {} is outside its limits [{}, {}]",
                    q[k], self.lo[k], self.hi[k]
                ));
            }
        }
        let qf: Vec<f32> = q.iter().map(|&x| x as f32).collect();
        (!self.checker.config_free(&qf, &mut self.scratch))
            .then(|| format!("{which} is in collision"))
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
        };
        for (q, which, status) in [
            (start, "start", PlanStatus::InvalidStart),
            (goal, "goal", PlanStatus::InvalidGoal),
        ] {
            if let Some(why) = self.invalid(q, which) {
                res.status = status;
                res.reason = Some(why);
                res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
                return res;
            }
        }
        let nv = self.lo.len();
        for k in 0..nv {
            self.start[k] = start[k] as f32;
            self.goal[k] = goal[k] as f32;
        }
        // The sampler lives in the planner (no allocation per query); each query starts
        // its sequence afresh, so the same query gives the same path.
        let mut sampler = std::mem::take(&mut self.sampler);
        sampler.reset();
        let deadline = self.opts.time_limit.map(|d| t0 + d);
        let found = self.search(&mut sampler, deadline);
        res.iterations = self.rrt.iterations;
        res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
        if let Err(end) = found {
            self.sampler = sampler;
            res.status = PlanStatus::Failed;
            res.reason = Some(match end {
                SearchEnd::Iterations => {
                    format!("no path within {} iterations", self.rrt.opts.max_iterations)
                }
                SearchEnd::Time => format!(
                    "no path within the time limit of {} ms",
                    self.opts.time_limit.map_or(0.0, |d| d.as_secs_f64() * 1e3)
                ),
                SearchEnd::Nodes => format!("a tree reached {} nodes", self.rrt.opts.max_nodes),
            });
            return res;
        }
        res.cost_initial = path_length(&self.path, nv);
        let t1 = Instant::now();
        if self.opts.simplify {
            self.scratch.keep_clearance = self.opts.check.clearance > 0.0;
            self.scratch.ends.clear();
            self.scratch.ends.extend_from_slice(&self.start);
            self.scratch.ends.extend_from_slice(&self.goal);
            self.simplifier.run(
                &mut self.path,
                nv,
                &self.checker,
                &mut self.scratch,
                sampler.rng(),
            );
            self.scratch.keep_clearance = false;
        }
        self.sampler = sampler;
        res.simplify_time_us = t1.elapsed().as_secs_f64() * 1e6;
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
    fn search(
        &mut self,
        sampler: &mut Sampler,
        deadline: Option<Instant>,
    ) -> Result<(), SearchEnd> {
        let (c, s) = (&self.checker, &mut self.scratch);
        let (start, goal) = (&self.start, &self.goal);
        self.rrt.solve(
            c,
            s,
            sampler,
            start,
            goal,
            deadline,
            EdgeMode::Discrete,
            &mut self.path,
        )?;
        let iterations = self.rrt.iterations;
        let nv = start.len();
        self.spliced.clear();
        self.spliced.extend_from_slice(&self.path[..nv]);
        let n = self.path.len() / nv;
        for i in 0..n - 1 {
            let (a, b) = (&self.path[i * nv..][..nv], &self.path[(i + 1) * nv..][..nv]);
            if !c.edge_free(a, b, EdgeMode::Continuous, s) {
                let repaired = self.rrt.solve(
                    c,
                    s,
                    sampler,
                    a,
                    b,
                    deadline,
                    EdgeMode::Continuous,
                    &mut self.sub,
                );
                if repaired.is_err() {
                    let r = self.rrt.solve(
                        c,
                        s,
                        sampler,
                        start,
                        goal,
                        deadline,
                        EdgeMode::Continuous,
                        &mut self.path,
                    );
                    self.rrt.iterations += iterations;
                    return r;
                }
                // The sub-path's first point is `a`, already in.
                self.spliced.extend_from_slice(&self.sub[nv..]);
                self.rrt.iterations += iterations;
            } else {
                self.spliced.extend_from_slice(b);
            }
        }
        std::mem::swap(&mut self.path, &mut self.spliced);
        self.rrt.iterations = self.rrt.iterations.max(iterations);
        Ok(())
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
            super::checker::EdgeMode::Continuous,
            &mut self.scratch,
        )
    }

    /// The check counters (edges, batches of eight) since the planner was built.
    pub fn counters(&self) -> (u64, u64) {
        (self.scratch.edges, self.scratch.batches)
    }
}
