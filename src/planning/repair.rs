//! Certifying a path found with discrete edge checks: every edge is checked continuously,
//! and an edge that fails is re-planned by RRT-Connect with continuous checks between its
//! two ends (both free) and spliced in. The planner's first search and the optimiser's
//! improving searches both search discretely (fast) and certify this way.

use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::rrt::{Rrt, SearchEnd, SearchLimit};
use crate::planning::sampler::Sampler;

/// The search tools a repair uses (the planner's own).
pub struct RepairTools<'a> {
    /// RRT-Connect, for the sub-searches.
    pub rrt: &'a mut Rrt,
    /// The scene's checker.
    pub checker: &'a Checker,
    /// Its scratch.
    pub scratch: &'a mut CheckScratch,
    /// The sub-searches' samples.
    pub sampler: &'a mut Sampler,
    /// Deadline and stop flag.
    pub limit: &'a SearchLimit,
}

/// The buffers of a repair, sized once.
#[derive(Clone, Debug, Default)]
pub struct EdgeRepair {
    sub: Vec<f32>,
    spliced: Vec<f32>,
}

impl EdgeRepair {
    /// Buffers for paths of about `points` waypoints of `nv` coordinates.
    pub fn with_capacity(nv: usize, points: usize) -> EdgeRepair {
        EdgeRepair {
            sub: Vec::with_capacity(nv * points),
            spliced: Vec::with_capacity(nv * points),
        }
    }

    /// `search` (RRT-Connect to one goal or to a goal set, into `path`) with discrete edge
    /// checks (fast), then the path certified ([`EdgeRepair::certify`]); if a repair
    /// fails, `search` again with continuous checks. The outcome and the iterations of
    /// the searches that count (the failed repair's are dropped).
    pub fn search_certified(
        &mut self,
        t: &mut RepairTools<'_>,
        path: &mut Vec<f32>,
        nv: usize,
        mut search: impl FnMut(&mut RepairTools<'_>, EdgeMode, &mut Vec<f32>) -> Result<(), SearchEnd>,
    ) -> (Result<(), SearchEnd>, usize) {
        let found = search(t, EdgeMode::Discrete, path);
        let iterations = t.rrt.iterations;
        if found.is_err() {
            return (found, iterations);
        }
        if let Ok(extra) = self.certify(t, path, nv) {
            return (Ok(()), iterations + extra);
        }
        let found = search(t, EdgeMode::Continuous, path);
        (found, iterations + t.rrt.iterations)
    }

    /// Makes every edge of `path` (flat, `nv` per point) pass the continuous check,
    /// re-planning the edges that fail. Returns the sub-searches' iterations; an error
    /// when a sub-search fails (the path is then left as it was).
    pub fn certify(
        &mut self,
        t: &mut RepairTools<'_>,
        path: &mut Vec<f32>,
        nv: usize,
    ) -> Result<usize, SearchEnd> {
        let mut iterations = 0;
        self.spliced.clear();
        self.spliced.extend_from_slice(&path[..nv]);
        let n = path.len() / nv;
        for i in 0..n - 1 {
            let (a, b) = (&path[i * nv..][..nv], &path[(i + 1) * nv..][..nv]);
            if t.checker.edge_free(a, b, EdgeMode::Continuous, t.scratch) {
                self.spliced.extend_from_slice(b);
                continue;
            }
            let mode = EdgeMode::Continuous;
            let (c, s) = (t.checker, &mut *t.scratch);
            let found = t
                .rrt
                .solve(c, s, t.sampler, a, b, t.limit, mode, &mut self.sub);
            iterations += t.rrt.iterations;
            found?;
            // The sub-path's first point is `a`, already in.
            self.spliced.extend_from_slice(&self.sub[nv..]);
        }
        std::mem::swap(path, &mut self.spliced);
        Ok(iterations)
    }
}
