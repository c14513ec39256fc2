//! Path simplification, every change re-checked with the continuous edge check, in rounds
//! until a round shortens the path by less than 0.1 %:
//!
//! 1. **Greedy shortcut to the farthest visible waypoint** (from each kept waypoint, the
//!    last one reachable by a free straight edge).
//! 2. **Random vertex reduction** (OMPL's `reduceVertices`): a random pair of waypoints
//!    a few apart is joined directly when the edge is free.
//! 3. **Partial shortcuts** (OMPL's `shortcutPath`): two random points anywhere along the
//!    path, joined when the edge is free and shorter than the path between them.
//! 4. **B-spline smoothing** (OMPL's `smoothBSpline`): midpoints are inserted, then every
//!    other waypoint moves to the midpoint of its neighbours' midpoints where both new edges
//!    are free; this rounds the corners that shortcuts leave.
//!
//! A time limit ([`SimplifyOptions::time_limit`]) and the stop flag end it early with the
//! path as it stands (every change was checked): where the exact stage of the checker
//! must decide many edges ([`crate::planning::checker::ExactPairs`]), shortcuts can cost
//! milliseconds each.
//!
//! The cost is the joint-space L2 length. Buffers live in [`Simplifier`]: nothing is
//! allocated once it has seen a path as long.

use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::rrt::SearchLimit;
use crate::planning::sampler::Rng;
use std::time::Duration;

/// Settings of the simplification.
#[derive(Clone, Copy, Debug)]
pub struct SimplifyOptions {
    /// Most rounds.
    pub rounds: usize,
    /// Tries of random reduction and shortcuts per round, per waypoint.
    pub tries_per_point: usize,
    /// B-spline passes per round.
    pub bspline_passes: usize,
    /// Wall-clock limit of the whole simplification.
    pub time_limit: Option<Duration>,
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self {
            // Measured on the shown MBM problems (Panda and UR5, 600): against 8 rounds, 4
            // tries and 4 passes, the median cost is 0.3–2 % higher and the simplification
            // 3–10× faster (BENCHMARKS.md, "Motion planning").
            rounds: 2,
            tries_per_point: 2,
            bspline_passes: 2,
            time_limit: Some(Duration::from_secs(1)),
        }
    }
}

impl SimplifyOptions {
    /// The thorough settings: 8 rounds, 4 tries per waypoint and 4 B-spline passes. On the
    /// shown MBM problems they reach a 0.3–2 % lower median cost than the defaults, 3–10×
    /// slower; the optimising mode polishes its best path with them once, at the end.
    pub fn thorough(time_limit: Option<Duration>) -> SimplifyOptions {
        SimplifyOptions {
            rounds: 8,
            tries_per_point: 4,
            bspline_passes: 4,
            time_limit,
        }
    }
}

/// The simplifier and its buffers.
#[derive(Clone, Debug, Default)]
pub struct Simplifier {
    /// Settings.
    pub opts: SimplifyOptions,
    tmp: Vec<f32>,
    cum: Vec<f32>,
    a: Vec<f32>,
    b: Vec<f32>,
    /// Per waypoint of a B-spline pass, whether it moved.
    moved: Vec<bool>,
}

/// Joint-space L2 length of a flat path of `nv`-vectors.
pub fn path_length(path: &[f32], nv: usize) -> f64 {
    path.chunks_exact(nv)
        .zip(path.chunks_exact(nv).skip(1))
        .map(|(p, q)| dist(p, q) as f64)
        .sum()
}

#[inline]
fn dist(p: &[f32], q: &[f32]) -> f32 {
    p.iter()
        .zip(q)
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f32>()
        .sqrt()
}

impl Simplifier {
    /// A simplifier with these settings.
    pub fn new(opts: SimplifyOptions) -> Simplifier {
        Simplifier {
            opts,
            ..Default::default()
        }
    }

    /// Simplifies `path` (flat, `nv` per waypoint) in place; its ends never move.
    pub fn run(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
        rng: &mut Rng,
        stop: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) {
        let limit = self.limit(stop);
        let mut len = path_length(path, nv);
        for _ in 0..self.opts.rounds {
            self.greedy(path, nv, c, s, &limit);
            self.reduce(path, nv, c, s, rng, &limit);
            self.shortcut(path, nv, c, s, rng, &limit);
            for _ in 0..self.opts.bspline_passes {
                if limit.reached().is_some() || !self.bspline(path, nv, c, s) {
                    break;
                }
            }
            self.greedy(path, nv, c, s, &limit);
            let new = path_length(path, nv);
            let done = new > len * (1.0 - 1e-3);
            len = new;
            if done {
                break;
            }
        }
    }

    /// One greedy pass ([`Simplifier::run`]'s first step) alone: from each kept waypoint,
    /// the farthest one reachable by a free edge.
    pub fn greedy_pass(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
        stop: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>,
    ) {
        let limit = self.limit(stop);
        self.greedy(path, nv, c, s, &limit);
    }

    /// The limit of one call: [`SimplifyOptions::time_limit`] from now, and the stop flag.
    fn limit(&self, stop: Option<&std::sync::Arc<std::sync::atomic::AtomicBool>>) -> SearchLimit {
        SearchLimit {
            deadline: self.opts.time_limit.map(|d| std::time::Instant::now() + d),
            stop: stop.cloned(),
        }
    }

    /// From each kept waypoint, jump to the farthest one reachable by a free edge.
    fn greedy(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
        limit: &SearchLimit,
    ) {
        let n = path.len() / nv;
        if n <= 2 {
            return;
        }
        self.tmp.clear();
        self.tmp.extend_from_slice(&path[..nv]);
        let mut i = 0;
        while i < n - 1 {
            let mut j = n - 1;
            while j > i + 1 {
                if limit.reached().is_some() {
                    // The path's own next edge, checked already.
                    j = i + 1;
                    break;
                }
                let (a, b) = (&path[i * nv..][..nv], &path[j * nv..][..nv]);
                if c.edge_free(a, b, EdgeMode::Continuous, s) {
                    break;
                }
                j -= 1;
            }
            self.tmp.extend_from_slice(&path[j * nv..][..nv]);
            i = j;
        }
        std::mem::swap(path, &mut self.tmp);
    }

    /// Runs `attempt` (given the path and its waypoint count) until it has failed
    /// `tries_per_point` times per waypoint in a row (a success resets the count), the
    /// limit is reached, or only the two ends are left.
    fn until_stuck(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        limit: &SearchLimit,
        mut attempt: impl FnMut(&mut Self, &mut Vec<f32>, usize) -> bool,
    ) {
        let mut fails = 0;
        while fails < self.opts.tries_per_point * (path.len() / nv) {
            let n = path.len() / nv;
            if limit.reached().is_some() || n <= 2 {
                return;
            }
            if attempt(self, path, n) {
                fails = 0;
            } else {
                fails += 1;
            }
        }
    }

    /// Random pairs of waypoints joined directly where free.
    fn reduce(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
        rng: &mut Rng,
        limit: &SearchLimit,
    ) {
        self.until_stuck(path, nv, limit, |_, path, n| {
            let i = rng.below(n - 2);
            let j = i + 2 + rng.below((n - i - 2).min(1 + n / 3));
            let (a, b) = (&path[i * nv..][..nv], &path[j.min(n - 1) * nv..][..nv]);
            if j >= n || !c.edge_free(a, b, EdgeMode::Continuous, s) {
                return false;
            }
            path.drain((i + 1) * nv..j * nv);
            true
        });
    }

    /// Random points along the path joined where free and shorter.
    fn shortcut(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
        rng: &mut Rng,
        limit: &SearchLimit,
    ) {
        self.until_stuck(path, nv, limit, |me, path, n| {
            me.cum.clear();
            me.cum.push(0.0);
            for k in 1..n {
                let d = dist(&path[(k - 1) * nv..][..nv], &path[k * nv..][..nv]);
                me.cum.push(me.cum[k - 1] + d);
            }
            let total = me.cum[n - 1];
            let (mut u, mut v) = (rng.next_f64() as f32 * total, rng.next_f64() as f32 * total);
            if u > v {
                std::mem::swap(&mut u, &mut v);
            }
            // Segments holding u and v: waypoints si..si+1 and sj..sj+1.
            let si = me.cum.partition_point(|&x| x <= u).clamp(1, n - 1) - 1;
            let sj = me.cum.partition_point(|&x| x <= v).clamp(1, n - 1) - 1;
            if sj <= si {
                return false;
            }
            me.point_at(path, nv, si, u, true);
            me.point_at(path, nv, sj, v, false);
            let direct = dist(&me.a, &me.b);
            if direct >= (v - u) * (1.0 - 1e-4)
                || !c.edge_free(&me.a, &me.b, EdgeMode::Continuous, s)
            {
                return false;
            }
            // Waypoints si+1..=sj are replaced by a, b.
            me.tmp.clear();
            me.tmp.extend_from_slice(&path[..(si + 1) * nv]);
            me.tmp.extend_from_slice(&me.a);
            me.tmp.extend_from_slice(&me.b);
            me.tmp.extend_from_slice(&path[(sj + 1) * nv..]);
            std::mem::swap(path, &mut me.tmp);
            true
        });
    }

    /// The point at arc length `x` on segment `seg`, into `a` (or `b`).
    fn point_at(&mut self, path: &[f32], nv: usize, seg: usize, x: f32, into_a: bool) {
        let len = (self.cum[seg + 1] - self.cum[seg]).max(1e-12);
        let t = ((x - self.cum[seg]) / len).clamp(0.0, 1.0);
        let out = if into_a { &mut self.a } else { &mut self.b };
        out.clear();
        let (p, q) = (&path[seg * nv..][..nv], &path[(seg + 1) * nv..][..nv]);
        out.extend(p.iter().zip(q).map(|(x0, x1)| x0 + t * (x1 - x0)));
    }

    /// One B-spline pass; whether any waypoint moved.
    fn bspline(
        &mut self,
        path: &mut Vec<f32>,
        nv: usize,
        c: &Checker,
        s: &mut CheckScratch,
    ) -> bool {
        let n = path.len() / nv;
        if n <= 2 {
            return false;
        }
        // Subdivide: insert the midpoint of every segment.
        self.tmp.clear();
        for k in 0..n {
            self.tmp.extend_from_slice(&path[k * nv..][..nv]);
            if k + 1 < n {
                for d in 0..nv {
                    self.tmp
                        .push(0.5 * (path[k * nv + d] + path[(k + 1) * nv + d]));
                }
            }
        }
        std::mem::swap(path, &mut self.tmp);
        let n = path.len() / nv;
        let mut moved = false;
        self.moved.clear();
        self.moved.resize(n, false);
        let mut i = 2;
        while i + 1 < n {
            self.a.clear();
            for d in 0..nv {
                let (p, q, r) = (
                    path[(i - 1) * nv + d],
                    path[i * nv + d],
                    path[(i + 1) * nv + d],
                );
                self.a.push(0.25 * p + 0.5 * q + 0.25 * r);
            }
            let shift = dist(&self.a, &path[i * nv..][..nv]);
            if shift > 1e-5
                && c.edge_free(
                    &path[(i - 1) * nv..][..nv],
                    &self.a,
                    EdgeMode::Continuous,
                    s,
                )
                && c.edge_free(
                    &self.a,
                    &path[(i + 1) * nv..][..nv],
                    EdgeMode::Continuous,
                    s,
                )
            {
                path[i * nv..(i + 1) * nv].copy_from_slice(&self.a);
                moved = true;
                self.moved[i] = true;
            }
            i += 2;
        }
        self.drop_straight_midpoints(path, nv);
        moved
    }

    /// Removes the inserted midpoints whose neighbours both stayed: they lie on the
    /// segment they were inserted on, so the path is the same without them (no check
    /// needed), and a path that cannot move does not double at every pass.
    fn drop_straight_midpoints(&mut self, path: &mut Vec<f32>, nv: usize) {
        let n = path.len() / nv;
        let mut w = 0;
        for k in 0..n {
            let straight = k % 2 == 1 && !self.moved[k - 1] && !self.moved[k + 1];
            if !straight {
                path.copy_within(k * nv..(k + 1) * nv, w * nv);
                w += 1;
            }
        }
        path.truncate(w * nv);
    }
}
