//! Queries to a goal set and under path constraints: [`Planner::plan_to`].
//!
//! 1. The start is checked (limits, collisions, then the path constraints).
//! 2. The goal becomes a set: joint values are a set of one; a tool pose becomes its
//!    inverse-kinematics solutions ([`goal_set`]). Each is checked as the start is; when
//!    a numeric set is wholly invalid (a redundant arm's solutions all in collision), up
//!    to [`EXTRA_GOAL_ROUNDS`] rounds of fresh IK draws follow ([`more_goals`]);
//!    `invalid_goal` says why none is left (unreachable, every solution in collision or
//!    violating the constraints, each with its reason).
//! 3. One search to the whole set (the goal tree rooted at every valid goal): RRT-Connect
//!    with discrete edge checks whose path is then certified continuously, a failing edge
//!    re-planned (as [`Planner::plan`] searches), then the simplifier; under path
//!    constraints the projection-based constrained RRT-Connect ([`ConstrainedRrt`]), then
//!    its constrained shortcuts (the simplifier's straight shortcuts and B-spline would
//!    leave the constraint manifold, so they are not used).
//! 4. **The best goal.** Each other goal whose straight joint distance from the start is
//!    below the best cost so far gets its own search (the same seed) and simplification;
//!    the shortest path wins (ties: the earlier goal, nearest the start first). So the
//!    answer is the shortest simplified path over the goals that could beat it, and the
//!    same seed gives the same path.
//!
//! `plan_time_us` runs to the first path; `simplify_time_us` covers the simplification
//! and the searches of step 4.

use super::{PlanResult, PlanStatus, Planner};
use crate::planning::constrained_rrt::{ConstrainedContext, ConstrainedRrt};
use crate::planning::improve::Improvement;
use crate::planning::path_constraints::{ConstraintSet, PathConstraint};
use crate::planning::plan_options::PlannerKind;
use crate::planning::pose_goal::{goal_set, more_goals, Goal};
use crate::planning::repair::RepairTools;
use crate::planning::rrt::{SearchEnd, SearchLimit};
use crate::planning::sampler::Sampler;
use crate::planning::simplify::path_length;
use std::time::Instant;

/// Further rounds of numeric IK when a redundant arm's whole goal set is invalid
/// ([`more_goals`]; they stop at the first round with a valid goal). On the Panda's
/// MotionBenchMaker `table_pick` poses 3–10 % of converged random-start solutions are
/// free, 1.3 % on the hardest seen; 24 rounds (288 starts, about 10–20 ms) miss such a
/// pose with odds of about 2 %.
pub const EXTRA_GOAL_ROUNDS: usize = 24;

/// Reasons of invalid IK solutions quoted in an `invalid_goal` message (the rest counted).
const SHOWN_REASONS: usize = 6;

/// Shortcut tries of a constrained path (after the walk between its ends).
pub const CONSTRAINED_SHORTCUT_TRIES: usize = 60;

/// The constrained search's view of the planner (model, constraints, checker, scratch,
/// joint box): a macro rather than a method, so that `self.path` stays borrowable beside
/// it (a method would borrow the whole planner).
macro_rules! constrained_context {
    ($planner:ident, $set:expr) => {
        ConstrainedContext {
            model: &$planner.robot.model,
            set: $set,
            checker: &$planner.checker,
            scratch: &mut $planner.scratch,
            lo: &$planner.lo,
            hi: &$planner.hi,
        }
    };
}

/// The answer to [`Planner::plan_to`].
#[derive(Clone, Debug)]
pub struct GoalPlanResult {
    /// The query's answer (the path ends at `goal`).
    pub result: PlanResult,
    /// The goal the path ends at (joint values, model order).
    pub goal: Option<Vec<f64>>,
    /// Goals in the set (inverse-kinematics solutions; 1 for joint values).
    pub goals_found: usize,
    /// Goals free, inside the limits and satisfying the constraints.
    pub goals_valid: usize,
    /// Searches run (one to the set, then one per goal that could give a shorter path).
    pub searches: usize,
}

fn blank(status: PlanStatus, reason: Option<String>, t0: Instant) -> PlanResult {
    PlanResult {
        status,
        reason,
        plan_time_us: t0.elapsed().as_secs_f64() * 1e6,
        simplify_time_us: 0.0,
        iterations: 0,
        cost_initial: 0.0,
        cost: 0.0,
        path: Vec::new(),
        // Goal sets and constrained paths are answered by RRT-Connect (the optimising
        // mode does not apply to them yet).
        planner: PlannerKind::RrtConnect,
        improvements: Vec::new(),
    }
}

fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f64>()
        .sqrt()
}

impl Planner {
    /// Plans from `start` to `goal` (joint values or a tool pose) keeping `constraints`
    /// along the whole path (module docs). An error is a constraint that cannot be used.
    pub fn plan_to(
        &mut self,
        start: &[f64],
        goal: &Goal,
        constraints: &[PathConstraint],
    ) -> Result<GoalPlanResult, String> {
        let t0 = Instant::now();
        let model = self.robot.clone();
        let model = &model.model;
        let mut set = ConstraintSet::new(model, constraints)?;
        let mut out = GoalPlanResult {
            result: blank(PlanStatus::Solved, None, t0),
            goal: None,
            goals_found: 0,
            goals_valid: 0,
            searches: 0,
        };
        let start_bad = self.invalid(start, "start").or_else(|| {
            set.violation(model, start)
                .map(|v| format!("start violates the path constraints: {v}"))
        });
        if let Some(why) = start_bad {
            out.result = blank(PlanStatus::InvalidStart, Some(why), t0);
            return Ok(out);
        }
        let valid = match self.valid_goals(start, goal, &mut set, &mut out) {
            Ok(v) => v,
            Err(why) => {
                out.result = blank(PlanStatus::InvalidGoal, Some(why), t0);
                return Ok(out);
            }
        };
        self.search_goals(start, &valid, &mut set, t0, &mut out);
        Ok(out)
    }

    /// The goals of the set that are valid, nearest the start first, or why none is.
    fn valid_goals(
        &mut self,
        start: &[f64],
        goal: &Goal,
        set: &mut ConstraintSet,
        out: &mut GoalPlanResult,
    ) -> Result<Vec<Vec<f64>>, String> {
        let model = self.robot.clone();
        let model = &model.model;
        let (candidates, pose) = match goal {
            Goal::Joints(g) => (vec![g.clone()], false),
            Goal::Pose(p) => (
                goal_set(model, p, start, self.opts.seed).map_err(|e| format!("goal pose: {e}"))?,
                true,
            ),
        };
        let (mut valid, mut reasons) = (Vec::new(), Vec::new());
        let mut candidates = candidates;
        // A redundant arm's set may lie wholly in collision while other points of its
        // self-motion reach the pose freely: more IK rounds (as MoveIt resamples IK).
        for round in 1..=EXTRA_GOAL_ROUNDS + 1 {
            for g in std::mem::take(&mut candidates) {
                let which = if pose {
                    format!("IK solution {}", out.goals_found)
                } else {
                    "goal".to_string()
                };
                out.goals_found += 1;
                let bad = self.invalid(&g, &which).or_else(|| {
                    set.violation(model, &g)
                        .map(|v| format!("{which} violates the path constraints: {v}"))
                });
                match bad {
                    Some(why) => reasons.push(why),
                    None => valid.push(g),
                }
            }
            let Goal::Pose(p) = goal else { break };
            if !valid.is_empty() || round > EXTRA_GOAL_ROUNDS {
                break;
            }
            candidates = more_goals(model, p, start, self.opts.seed, round);
            if candidates.is_empty() {
                break;
            }
        }
        out.goals_valid = valid.len();
        if valid.is_empty() {
            return Err(if pose {
                let collide = reasons
                    .iter()
                    .filter(|r| r.contains("in collision"))
                    .count();
                let what = if collide == reasons.len() {
                    "in collision"
                } else {
                    "invalid"
                };
                let shown = reasons.len().min(SHOWN_REASONS);
                let more = match reasons.len() - shown {
                    0 => String::new(),
                    n => format!("; and {n} more"),
                };
                format!(
                    "goal pose: all {} inverse-kinematics solutions are {what}: {}{more}",
                    reasons.len(),
                    reasons[..shown].join("; ")
                )
            } else {
                reasons.join("; ")
            });
        }
        Ok(valid)
    }

    /// Step 3 and 4 of the module docs; fills `out`.
    fn search_goals(
        &mut self,
        start: &[f64],
        goals: &[Vec<f64>],
        set: &mut ConstraintSet,
        t0: Instant,
        out: &mut GoalPlanResult,
    ) {
        let nv = start.len();
        let mut sampler = std::mem::take(&mut self.sampler);
        let limit = SearchLimit {
            deadline: self.opts.time_limit.map(|d| t0 + d),
            stop: self.opts.stop.clone(),
        };
        let mut crrt = (!set.is_empty()).then(|| ConstrainedRrt::new(nv, self.opts.rrt));
        let flat: Vec<f32> = goals.iter().flatten().map(|&x| x as f32).collect();
        for (s, &x) in self.start[..nv].iter_mut().zip(start) {
            *s = x as f32;
        }
        let first = self.solve_once(&mut sampler, set, crrt.as_mut(), &flat, &limit);
        out.searches = 1;
        let res = &mut out.result;
        res.iterations = first.1;
        res.plan_time_us = t0.elapsed().as_secs_f64() * 1e6;
        if let Err(end) = first.0 {
            self.sampler = sampler;
            res.status = PlanStatus::Failed;
            res.reason = Some(self.end_reason(end));
            return;
        }
        res.cost_initial = first.2;
        let t1 = Instant::now();
        let mut best = self.finish_path(&sampler, set, crrt.as_mut(), start, goals);
        for g in goals {
            if best.1 == *g || dist(start, g) >= best.0 - 1e-9 {
                continue;
            }
            let one: Vec<f32> = g.iter().map(|&x| x as f32).collect();
            out.searches += 1;
            let (found, iters, _) = self.solve_once(&mut sampler, set, crrt.as_mut(), &one, &limit);
            out.result.iterations += iters;
            if found.is_ok() {
                let cand = self.finish_path(&sampler, set, crrt.as_mut(), start, goals);
                if cand.0 < best.0 - 1e-9 {
                    best = cand;
                }
            }
        }
        self.sampler = sampler;
        let res = &mut out.result;
        res.simplify_time_us = t1.elapsed().as_secs_f64() * 1e6;
        res.cost = best.0;
        res.path = best.2;
        res.improvements.push(Improvement {
            time_us: t0.elapsed().as_secs_f64() * 1e6,
            iterations: res.iterations,
            cost: res.cost,
        });
        out.goal = Some(best.1.clone());
    }

    /// One search from `self.start` to the goals `flat` (sampler reset first): the
    /// outcome, its iterations and the path's length (in `self.path`).
    fn solve_once(
        &mut self,
        sampler: &mut Sampler,
        set: &mut ConstraintSet,
        crrt: Option<&mut ConstrainedRrt>,
        flat: &[f32],
        limit: &SearchLimit,
    ) -> (Result<(), SearchEnd>, usize, f64) {
        sampler.reset();
        let nv = self.start.len();
        let found = match crrt {
            Some(c) => {
                let mut cx = constrained_context!(self, set);
                let r = c.solve(&mut cx, sampler, &self.start, flat, limit, &mut self.path);
                (r, c.iterations)
            }
            None => self.search_to_set(sampler, flat, limit),
        };
        (found.0, found.1, path_length(&self.path, nv))
    }

    /// RRT-Connect to the goal set `flat` as [`Planner::plan`] searches: discrete edge
    /// checks, then every edge certified continuously and a failing edge re-planned
    /// ([`crate::planning::repair`]); if a repair fails, the search is run again with
    /// continuous checks. The outcome and the iterations of all searches.
    fn search_to_set(
        &mut self,
        sampler: &mut Sampler,
        flat: &[f32],
        limit: &SearchLimit,
    ) -> (Result<(), SearchEnd>, usize) {
        let start = &self.start;
        let mut tools = RepairTools {
            rrt: &mut self.rrt,
            checker: &self.checker,
            scratch: &mut self.scratch,
            sampler,
            limit,
        };
        self.repair
            .search_certified(&mut tools, &mut self.path, start.len(), |t, mode, path| {
                t.rrt.solve_to_set(
                    t.checker, t.scratch, t.sampler, start, flat, t.limit, mode, path,
                )
            })
    }

    /// Simplifies `self.path` (constrained shortcuts under constraints) and returns its
    /// cost, the goal it ends at and the path in f64 with the exact start and goal.
    fn finish_path(
        &mut self,
        sampler: &Sampler,
        set: &mut ConstraintSet,
        crrt: Option<&mut ConstrainedRrt>,
        start: &[f64],
        goals: &[Vec<f64>],
    ) -> (f64, Vec<f64>, Vec<Vec<f64>>) {
        let nv = start.len();
        let mut rng = sampler.clone();
        let rng = rng.rng();
        let n = self.path.len() / nv;
        let end: Vec<f64> = self.path[(n - 1) * nv..]
            .iter()
            .map(|&x| x as f64)
            .collect();
        let goal = goals
            .iter()
            .min_by(|a, b| dist(a, &end).total_cmp(&dist(b, &end)))
            .expect("a non-empty goal set")
            .clone();
        if self.opts.simplify {
            let deadline = self.simplifier.opts.time_limit.map(|d| Instant::now() + d);
            match crrt {
                Some(c) => {
                    let mut cx = constrained_context!(self, set);
                    let stop = self.opts.stop.clone();
                    c.shortcut(
                        &mut cx,
                        &mut self.path,
                        rng,
                        CONSTRAINED_SHORTCUT_TRIES,
                        deadline,
                        stop.as_ref(),
                    );
                }
                None => {
                    self.scratch.keep_clearance = self.opts.check.clearance > 0.0;
                    self.scratch.ends.clear();
                    self.scratch.ends.extend_from_slice(&self.start);
                    self.scratch.ends.extend(goal.iter().map(|&x| x as f32));
                    let stop = self.opts.stop.clone();
                    self.simplifier.run(
                        &mut self.path,
                        nv,
                        &self.checker,
                        &mut self.scratch,
                        rng,
                        stop.as_ref(),
                    );
                    self.scratch.keep_clearance = false;
                }
            }
        }
        let mut path: Vec<Vec<f64>> = self
            .path
            .chunks_exact(nv)
            .map(|p| p.iter().map(|&x| x as f64).collect())
            .collect();
        let n = path.len();
        path[0].copy_from_slice(start);
        path[n - 1].copy_from_slice(&goal);
        (path_length(&self.path, nv), goal, path)
    }

    /// The reason of a search that ended without a path.
    pub(super) fn end_reason(&self, end: SearchEnd) -> String {
        match end {
            SearchEnd::Iterations => {
                format!("no path within {} iterations", self.rrt.opts.max_iterations)
            }
            SearchEnd::Time => format!(
                "no path within the time limit of {} ms",
                self.opts.time_limit.map_or(0.0, |d| d.as_secs_f64() * 1e3)
            ),
            SearchEnd::Nodes => format!("a tree reached {} nodes", self.rrt.opts.max_nodes),
            SearchEnd::Interrupted => "interrupted".to_string(),
        }
    }
}
