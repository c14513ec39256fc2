//! The optimising mode's outer loop (AORRTC, Wilson et al., RA-L 2025): after
//! RRT-Connect's first path is simplified, search again for a cheaper path
//! ([`crate::planning::aorrtc`]), sampling only the informed set of the best cost so far
//! ([`crate::planning::informed`]); certify each path found, simplify it, and keep it when
//! it is cheaper. It ends when the [`OptimiseBudget`] is spent, the stop flag is raised,
//! or the path is the straight line; the best path is then simplified once more with the
//! thorough settings (`Optimiser::polish`), within what is left of the deadline.
//!
//! Every kept path is certified as RRT-Connect's first path is: the improving search
//! checks its edges discretely, then every edge of the path it finds is checked
//! continuously and an edge that fails is re-planned and spliced in
//! ([`crate::planning::repair`]). Near the optimum the paths graze the obstacles: on the
//! Panda's bookshelf problems about 20 paths per query need a repair (dropping them wasted
//! the search), and checking continuously while searching made the UR5's queries 5×
//! slower. The simplifier checks each change continuously (with the clearance the query
//! asks of simplified paths, as for the first path). A repaired path may cost more than
//! the bound; it is kept only if, simplified, it is cheaper than the best. Such a path
//! is simplified in full only if a first greedy pass (shortcuts to the farthest visible
//! waypoint) brings it below the best: near the optimum most repaired paths stay dearer,
//! and their simplification was most of the time of the slowest UR5 queries (`table_pick`
//! p95 2.8 → 2.1 ms at 2000 iterations, the paths' costs the same in distribution).
//! The cost after each improvement is logged with its time ([`Improvement`]), so the
//! convergence can be plotted.

use crate::planning::aorrtc::{Aorrtc, ImproveSearch};
use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::informed::InformedSampler;
use crate::planning::plan_options::OptimiseBudget;
use crate::planning::repair::{EdgeRepair, RepairTools};
use crate::planning::rrt::{Rrt, RrtOptions, SearchEnd, SearchLimit};
use crate::planning::sampler::Sampler;
use crate::planning::simplify::{path_length, Simplifier, SimplifyOptions};
use serde::Serialize;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

/// A path cost reached, and when.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Improvement {
    /// Time from the query's start (µs).
    pub time_us: f64,
    /// Search iterations spent by then.
    pub iterations: usize,
    /// The path's cost (joint-space L2 length).
    pub cost: f64,
}

/// The scene and the tools one optimisation uses (the planner's own).
pub struct ImproveContext<'a> {
    /// The scene's checker.
    pub checker: &'a Checker,
    /// Its scratch (set up for simplification by the caller).
    pub scratch: &'a mut CheckScratch,
    /// The simplifier, or `None` not to simplify the paths found.
    pub simplifier: Option<&'a mut Simplifier>,
    /// Simplify with the clearance of [`crate::planning::checker::CheckOptions::clearance`]
    /// (the scratch's `ends` set by the caller).
    pub keep_clearance: bool,
    /// RRT-Connect, to repair the edges that fail their certification.
    pub rrt: &'a mut Rrt,
    /// The repairs' samples; its generator draws the informed samples, the cost bounds
    /// and the simplifier's choices.
    pub sampler: &'a mut Sampler,
    /// Raised to stop (Ctrl-C).
    pub stop: Option<&'a Arc<AtomicBool>>,
    /// The joint box.
    pub lo: &'a [f32],
    /// The joint box.
    pub hi: &'a [f32],
}

/// The optimising mode's state: the improving search and its buffers, sized once.
#[derive(Clone, Debug)]
pub struct Optimiser {
    search: Aorrtc,
    informed: InformedSampler,
    candidate: Vec<f32>,
    repair: EdgeRepair,
    /// The query's start, then its goal.
    ends: Vec<f32>,
    /// Search iterations of the last optimisation, the first path's included.
    pub iterations: usize,
}

impl Optimiser {
    /// An optimiser for `nv` coordinates with RRT-Connect's settings.
    pub fn new(nv: usize, opts: RrtOptions) -> Optimiser {
        Optimiser {
            search: Aorrtc::new(nv, opts),
            informed: InformedSampler::default(),
            candidate: Vec::with_capacity(nv * 1024),
            repair: EdgeRepair::with_capacity(nv, 1024),
            ends: Vec::with_capacity(2 * nv),
            iterations: 0,
        }
    }

    /// Improves `path` (start to goal, simplified, `first_iterations` spent on it) until
    /// `budget` runs out, counted from `t0`; `limit` is the query's own deadline and stop
    /// flag. Appends each cheaper path's cost to `log`.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &mut self,
        cx: ImproveContext<'_>,
        path: &mut Vec<f32>,
        nv: usize,
        budget: OptimiseBudget,
        first_iterations: usize,
        t0: Instant,
        limit: &SearchLimit,
        log: &mut Vec<Improvement>,
    ) {
        let ImproveContext {
            checker,
            scratch,
            mut simplifier,
            keep_clearance,
            rrt,
            sampler,
            stop,
            lo,
            hi,
        } = cx;
        let n = path.len() / nv;
        self.ends.clear();
        self.ends.extend_from_slice(&path[..nv]);
        self.ends.extend_from_slice(&path[(n - 1) * nv..]);
        let (start, goal) = self.ends.split_at(nv);
        self.informed.reset(start, goal, lo, hi);
        let c_min = self.informed.min_cost();
        let deadline = match (budget.time.map(|d| t0 + d), limit.deadline) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let limit = SearchLimit {
            deadline,
            stop: limit.stop.clone(),
        };
        self.iterations = first_iterations;
        let mut best = path_length(path, nv) as f32;
        while self.iterations < budget.iterations && best - c_min > 1e-6 * best.max(1.0) {
            if limit.reached().is_some() {
                break;
            }
            self.informed.set_cost_bound(best);
            let mut search = ImproveSearch {
                checker,
                scratch: &mut *scratch,
                informed: &self.informed,
                rng: sampler.rng(),
                limit: &limit,
                mode: EdgeMode::Discrete,
            };
            let left = budget.iterations - self.iterations;
            let found =
                self.search
                    .solve(&mut search, start, goal, best, left, &mut self.candidate);
            self.iterations += self.search.iterations;
            match found {
                Ok(()) => {}
                Err(SearchEnd::Nodes) => continue,
                Err(_) => break,
            }
            let mut tools = RepairTools {
                rrt: &mut *rrt,
                checker,
                scratch: &mut *scratch,
                sampler: &mut *sampler,
                limit: &limit,
            };
            match self.repair.certify(&mut tools, &mut self.candidate, nv) {
                Ok(extra) => self.iterations += extra,
                Err(_) => continue,
            }
            if let Some(simplifier) = simplifier.as_deref_mut() {
                scratch.keep_clearance = keep_clearance;
                // A repair that made the path dearer than the best: a greedy pass first,
                // and the full simplification only if that brings it below the best.
                let hopeless = path_length(&self.candidate, nv) as f32 >= best && {
                    simplifier.greedy_pass(&mut self.candidate, nv, checker, scratch, stop);
                    path_length(&self.candidate, nv) as f32 >= best
                };
                if !hopeless {
                    let rng = sampler.rng();
                    simplifier.run(&mut self.candidate, nv, checker, scratch, rng, stop);
                }
                scratch.keep_clearance = false;
                if hopeless {
                    continue;
                }
            }
            let at = (t0, self.iterations);
            keep_if_cheaper(&mut self.candidate, path, &mut best, nv, at, log);
        }
        if let Some(simplifier) = simplifier {
            scratch.keep_clearance = keep_clearance;
            self.polish(simplifier, path, checker, scratch, sampler, &limit, stop);
            scratch.keep_clearance = false;
            let at = (t0, self.iterations);
            keep_if_cheaper(&mut self.candidate, path, &mut best, nv, at, log);
        }
    }

    /// The best path, simplified once more with the thorough settings
    /// ([`SimplifyOptions::thorough`]) into the candidate, within what is left of the
    /// query's deadline. Every path found was simplified with the fast settings; this last
    /// pass straightens the one kept (on the shown MBM problems, the thorough settings
    /// reach a 0.3–2 % lower cost).
    #[allow(clippy::too_many_arguments)]
    fn polish(
        &mut self,
        simplifier: &mut Simplifier,
        path: &[f32],
        checker: &Checker,
        scratch: &mut CheckScratch,
        sampler: &mut Sampler,
        limit: &SearchLimit,
        stop: Option<&Arc<AtomicBool>>,
    ) {
        self.candidate.clear();
        self.candidate.extend_from_slice(path);
        if limit.reached().is_some() {
            return;
        }
        let left = limit
            .deadline
            .map(|d| d.saturating_duration_since(Instant::now()));
        let time_limit = match (left, simplifier.opts.time_limit) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let fast = simplifier.opts;
        simplifier.opts = SimplifyOptions::thorough(time_limit);
        let nv = self.ends.len() / 2;
        simplifier.run(
            &mut self.candidate,
            nv,
            checker,
            scratch,
            sampler.rng(),
            stop,
        );
        simplifier.opts = fast;
    }
}

/// Swaps `candidate` in as the path when it is cheaper than `best`, and logs it with `at`
/// (the query's start and the iterations spent).
fn keep_if_cheaper(
    candidate: &mut Vec<f32>,
    path: &mut Vec<f32>,
    best: &mut f32,
    nv: usize,
    at: (Instant, usize),
    log: &mut Vec<Improvement>,
) {
    let length = path_length(candidate, nv);
    let cost = length as f32;
    if cost < *best {
        *best = cost;
        std::mem::swap(path, candidate);
        log.push(Improvement {
            time_us: at.0.elapsed().as_secs_f64() * 1e6,
            iterations: at.1,
            cost: length,
        });
    }
}
