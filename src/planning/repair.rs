//! Certifying a path found with discrete edge checks: every edge is checked continuously,
//! and an edge that fails is re-planned by RRT-Connect with continuous checks between its
//! two ends (both free) and spliced in, searching around at once (the straight edge is
//! known to fail). Collinear waypoints (RRT-Connect's connecting steps) are merged first:
//! fewer, longer edges fill the continuous checks' batches better. The planner's first
//! search and the optimiser's improving searches both search discretely (fast) and certify
//! this way.

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
        drop_collinear(path, nv);
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
                .solve_around(c, s, t.sampler, a, b, t.limit, mode, &mut self.sub);
            iterations += t.rrt.iterations;
            found?;
            // The sub-path's first point is `a`, already in.
            self.spliced.extend_from_slice(&self.sub[nv..]);
        }
        std::mem::swap(path, &mut self.spliced);
        Ok(iterations)
    }
}

/// Removes the waypoints of `path` (flat, `nv` per point) that lie on the straight line
/// between their neighbours, in the same direction (an RRT-Connect's connecting steps): the
/// path then has fewer, longer edges, whose continuous checks fill their batches' lanes
/// better (an edge's intervals are rounded up to a multiple of eight). The merged edge is
/// what is checked and returned, so the rounding of the dropped point does not matter.
pub fn drop_collinear(path: &mut Vec<f32>, nv: usize) {
    let n = path.len() / nv;
    if n < 3 {
        return;
    }
    // `w` points kept so far; `path[(w-1)·nv..]` is the last kept one.
    let mut w = 1;
    for i in 1..n - 1 {
        let (mut uu, mut vv, mut uv) = (0.0f32, 0.0f32, 0.0f32);
        for k in 0..nv {
            let u = path[i * nv + k] - path[(w - 1) * nv + k];
            let v = path[(i + 1) * nv + k] - path[i * nv + k];
            uu += u * u;
            vv += v * v;
            uv += u * v;
        }
        let collinear = uv > 0.0 && uv * uv >= (1.0 - COLLINEAR_TOLERANCE) * uu * vv;
        if !collinear {
            path.copy_within(i * nv..(i + 1) * nv, w * nv);
            w += 1;
        }
    }
    path.copy_within((n - 1) * nv..n * nv, w * nv);
    path.truncate((w + 1) * nv);
}

/// `1 − cos²` of the angle below which two edges count as one straight line.
const COLLINEAR_TOLERANCE: f32 = 1e-6;

#[cfg(test)]
mod tests {
    use super::drop_collinear;

    #[test]
    fn drop_collinear_keeps_the_corners_and_the_ends_only() {
        // 0 → 1 → 2 along x, a corner at 2, then 3 steps along y, and a reversal.
        let pts: [[f32; 2]; 7] = [
            [0., 0.],
            [1., 0.],
            [2., 0.],
            [2., 1.],
            [2., 2.],
            [2., 3.],
            [2., 1.],
        ];
        let mut path: Vec<f32> = pts.iter().flatten().copied().collect();
        drop_collinear(&mut path, 2);
        assert_eq!(path, vec![0., 0., 2., 0., 2., 3., 2., 1.]);
        let mut two = vec![0., 0., 1., 1.];
        drop_collinear(&mut two, 2);
        assert_eq!(two, vec![0., 0., 1., 1.]);
    }
}
