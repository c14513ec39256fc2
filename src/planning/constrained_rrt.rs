//! Constrained RRT-Connect (CBiRRT2: Berenson, Srinivasa, Ferguson & Kuffner, "Manipulation
//! planning on constraint manifolds", ICRA 2009), projection-based, with a goal tree that
//! may have several roots (a goal set).
//!
//! A tree grows from a node towards a target in steps of [`ConstrainedRrt::step`]: each
//! step moves towards the target, is projected onto the constraints
//! ([`crate::planning::projection`]), and is kept only when it got closer to the target,
//! the edge from the previous node is certified for the constraints
//! ([`ConstraintSet::edge_certified`]: they hold at every point of the edge, not only at
//! its ends) and is collision-free under the continuous edge check. Each iteration draws a
//! sample, grows the smaller tree towards it (at most `range` of steps), then grows the
//! other tree towards the new node until it is reached or the walk stalls.
//!
//! The step is the nominal step of the constraint set (the longest whose Lipschitz bound
//! stays below the functions' interior margins), at most `range`; a step whose edge is not
//! certified is halved up to three times.
//!
//! [`ConstrainedRrt::shortcut`] shortens a path by the same walks between two of its
//! points (CBiRRT2's shortcut): a walk that reaches the later point and is shorter than
//! the path between replaces it, so every edge of the result is certified as well.
//!
//! Trees live in buffers sized once; nothing allocates per iteration.

use crate::model::Model;
use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::path_constraints::{ConstraintSet, MAX_FUNCTIONS};
use crate::planning::projection::Projector;
use crate::planning::rrt::{iteration_start, RrtOptions, SearchEnd, SearchLimit};
use crate::planning::sampler::{Rng, Sampler};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// What a constrained search works on: the model, its constraints, the collision checker
/// and the joint bounds.
pub struct ConstrainedContext<'a> {
    /// The model (for forward kinematics).
    pub model: &'a Model,
    /// The path constraints.
    pub set: &'a mut ConstraintSet,
    /// The scene's checker.
    pub checker: &'a Checker,
    /// Its scratch.
    pub scratch: &'a mut CheckScratch,
    /// Lower joint bounds.
    pub lo: &'a [f32],
    /// Upper joint bounds.
    pub hi: &'a [f32],
}

/// One tree: nodes, parents, constraint values.
#[derive(Clone, Debug)]
struct CTree {
    nv: usize,
    nodes: Vec<f32>,
    parent: Vec<u32>,
    h: Vec<f64>,
}

impl CTree {
    fn new(nv: usize, cap: usize) -> CTree {
        CTree {
            nv,
            nodes: Vec::with_capacity(nv * cap),
            parent: Vec::with_capacity(cap),
            h: Vec::with_capacity(MAX_FUNCTIONS * cap),
        }
    }

    fn clear(&mut self) {
        self.nodes.clear();
        self.parent.clear();
        self.h.clear();
    }

    fn len(&self) -> usize {
        self.parent.len()
    }

    fn push(&mut self, q: &[f32], h: &[f64], parent: u32) -> u32 {
        self.nodes.extend_from_slice(&q[..self.nv]);
        self.h.extend_from_slice(&h[..MAX_FUNCTIONS]);
        self.parent.push(parent);
        (self.len() - 1) as u32
    }

    fn node(&self, i: u32) -> &[f32] {
        &self.nodes[i as usize * self.nv..][..self.nv]
    }

    fn values(&self, i: u32) -> &[f64] {
        &self.h[i as usize * MAX_FUNCTIONS..][..MAX_FUNCTIONS]
    }

    fn nearest(&self, q: &[f32]) -> u32 {
        let mut best = (0u32, f32::INFINITY);
        for (i, node) in self.nodes.chunks_exact(self.nv).enumerate() {
            let d = dist2(node, q);
            if d < best.1 {
                best = (i as u32, d);
            }
        }
        best.0
    }
}

fn dist2(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Outcome of a walk.
enum Grow {
    Reached(u32),
    Advanced(u32),
    Trapped,
}

/// The constrained search with its buffers.
#[derive(Clone, Debug)]
pub struct ConstrainedRrt {
    /// Settings (range, iteration and node limits; the dynamic domain is not used).
    pub opts: RrtOptions,
    /// The walk's step (joint-space L2), set per query from the constraints.
    pub step: f64,
    /// Iterations of the last search.
    pub iterations: usize,
    trees: [CTree; 2],
    projector: Projector,
    q64: Vec<f64>,
    cand: Vec<f32>,
    sample: Vec<f32>,
    target: Vec<f32>,
    target_h: [f64; MAX_FUNCTIONS],
    hc: [f64; MAX_FUNCTIONS],
    tmp: Vec<f32>,
    tail: Vec<f32>,
}

impl ConstrainedRrt {
    /// A search for `nv` coordinates with buffers for `opts.max_nodes` nodes per tree.
    pub fn new(nv: usize, opts: RrtOptions) -> ConstrainedRrt {
        let t = CTree::new(nv, opts.max_nodes.min(1 << 16));
        ConstrainedRrt {
            opts,
            step: 0.05,
            iterations: 0,
            trees: [t.clone(), t],
            projector: Projector::new(nv),
            q64: vec![0.0; nv],
            cand: vec![0.0; nv],
            sample: vec![0.0; nv],
            target: vec![0.0; nv],
            target_h: [0.0; MAX_FUNCTIONS],
            hc: [0.0; MAX_FUNCTIONS],
            tmp: Vec::with_capacity(nv * 4096),
            tail: Vec::with_capacity(nv * 4096),
        }
    }

    /// The constraint values of `q` (f32 values, evaluated in f64) into `out`.
    pub fn values_of(
        cx: &mut ConstrainedContext,
        q: &[f32],
        q64: &mut [f64],
        out: &mut [f64; MAX_FUNCTIONS],
    ) {
        for (d, s) in q64.iter_mut().zip(q) {
            *d = *s as f64;
        }
        out.fill(0.0);
        cx.set.eval(cx.model, q64, out, None);
    }

    /// Searches from `start` to any of `goals` (flat, `nv` each; all free and satisfying
    /// the constraints). On success writes the path into `path` (start and the goal
    /// reached included).
    pub fn solve(
        &mut self,
        cx: &mut ConstrainedContext,
        sampler: &mut Sampler,
        start: &[f32],
        goals: &[f32],
        limit: &SearchLimit,
        path: &mut Vec<f32>,
    ) -> Result<(), SearchEnd> {
        let nv = start.len();
        self.step = cx.set.nominal_step().min(self.opts.range as f64).max(1e-4);
        for t in &mut self.trees {
            t.clear();
        }
        self.iterations = 0;
        let mut h = [0.0; MAX_FUNCTIONS];
        Self::values_of(cx, start, &mut self.q64, &mut h);
        self.trees[0].push(start, &h, u32::MAX);
        for g in goals.chunks_exact(nv) {
            Self::values_of(cx, g, &mut self.q64, &mut h);
            self.trees[1].push(g, &h, u32::MAX);
        }
        // The direct walk from the start to each goal first.
        for gi in 0..self.trees[1].len() as u32 {
            if let Some(end) = self.connect(cx, 0, 1, gi) {
                self.trace(end, gi, path);
                return Ok(());
            }
        }
        let extend_steps = ((self.opts.range as f64 / self.step).ceil() as usize).max(1);
        for it in 0..self.opts.max_iterations {
            self.iterations = it + 1;
            let lens = [self.trees[0].len(), self.trees[1].len()];
            let a = iteration_start(it, 16, limit, lens, self.opts.max_nodes)?;
            sampler.next(&mut self.sample[..nv]);
            self.target.copy_from_slice(&self.sample);
            let near = self.trees[a].nearest(&self.target);
            let new = match self.grow(cx, a, near, None, extend_steps) {
                Grow::Advanced(n) | Grow::Reached(n) => n,
                Grow::Trapped => continue,
            };
            if let Some(end_b) = self.connect(cx, 1 - a, a, new) {
                let (s, g) = if a == 0 { (new, end_b) } else { (end_b, new) };
                self.trace(s, g, path);
                return Ok(());
            }
        }
        Err(SearchEnd::Iterations)
    }

    /// Grows tree `b` from its node nearest to node `n` of tree `a` towards it; the node
    /// of `b` that reached it, if it did.
    fn connect(&mut self, cx: &mut ConstrainedContext, b: usize, a: usize, n: u32) -> Option<u32> {
        self.target.copy_from_slice(self.trees[a].node(n));
        self.target_h.copy_from_slice(self.trees[a].values(n));
        let near = self.trees[b].nearest(&self.target);
        match self.grow(cx, b, near, Some(()), usize::MAX) {
            Grow::Reached(end) => Some(end),
            _ => None,
        }
    }

    /// Walks tree `t` from node `near` towards `self.target` (a node of the other tree,
    /// with values `self.target_h`, when `on_manifold`), at most `max_steps` steps.
    fn grow(
        &mut self,
        cx: &mut ConstrainedContext,
        t: usize,
        near: u32,
        on_manifold: Option<()>,
        max_steps: usize,
    ) -> Grow {
        let mut cur = near;
        let mut steps = 0;
        loop {
            let from = self.trees[t].node(cur);
            let d = dist2(from, &self.target).sqrt() as f64;
            if on_manifold.is_some() && d <= self.step {
                let ok =
                    cx.set.edge_certified(
                        self.trees[t].values(cur),
                        &self.target_h,
                        from,
                        &self.target,
                    ) && cx
                        .checker
                        .edge_free(from, &self.target, EdgeMode::Continuous, cx.scratch);
                if ok {
                    return Grow::Reached(self.trees[t].push(&self.target, &self.target_h, cur));
                }
            }
            if steps >= max_steps || d < 1e-6 {
                break;
            }
            if !self.step_towards(cx, t, cur, d) {
                break;
            }
            cur = self.trees[t].push(&self.cand, &self.hc, cur);
            steps += 1;
        }
        if cur == near {
            Grow::Trapped
        } else {
            Grow::Advanced(cur)
        }
    }

    /// One projected step from node `cur` of tree `t` (at distance `d` from the target)
    /// into `self.cand` / `self.hc`; false when none is kept.
    fn step_towards(&mut self, cx: &mut ConstrainedContext, t: usize, cur: u32, d: f64) -> bool {
        let from = self.trees[t].node(cur);
        let mut s = self.step.min(d) / d;
        for _ in 0..4 {
            for ((q, &a), &b) in self.q64.iter_mut().zip(from).zip(&self.target) {
                let (a, b) = (a as f64, b as f64);
                *q = a + s * (b - a);
            }
            if !self
                .projector
                .project(cx.model, cx.set, cx.lo, cx.hi, &mut self.q64)
            {
                return false;
            }
            for k in 0..from.len() {
                self.cand[k] = self.q64[k] as f32;
            }
            let d_new = dist2(&self.cand, &self.target).sqrt() as f64;
            let moved = dist2(&self.cand, from).sqrt() as f64;
            if d_new >= d - 1e-7 || moved > 2.0 * self.step {
                return false;
            }
            Self::values_of(cx, &self.cand, &mut self.q64, &mut self.hc);
            if cx
                .set
                .edge_certified(self.trees[t].values(cur), &self.hc, from, &self.cand)
            {
                return cx
                    .checker
                    .edge_free(from, &self.cand, EdgeMode::Continuous, cx.scratch);
            }
            s *= 0.5;
        }
        false
    }

    /// Writes start → node `a` of tree 0, then node `b` of tree 1 → its root, into `path`
    /// (the meeting point once).
    fn trace(&self, a: u32, b: u32, path: &mut Vec<f32>) {
        let nv = self.q64.len();
        path.clear();
        let mut i = a;
        while i != u32::MAX {
            path.extend_from_slice(self.trees[0].node(i));
            i = self.trees[0].parent[i as usize];
        }
        let n = path.len() / nv;
        for p in 0..n / 2 {
            for k in 0..nv {
                path.swap(p * nv + k, (n - 1 - p) * nv + k);
            }
        }
        // `b` is a copy of tree 0's last node (or a root tree 0 reached): skip it.
        let mut i = self.trees[1].parent[b as usize];
        while i != u32::MAX {
            path.extend_from_slice(self.trees[1].node(i));
            i = self.trees[1].parent[i as usize];
        }
    }

    /// Shortens `path` (whose edges are certified) by walks between two of its points:
    /// first its ends, then `tries` random pairs. A walk that reaches the later point and
    /// is shorter than the path between replaces that part. Stops at `deadline` or when
    /// `stop` is raised; returns the number of shortcuts taken.
    #[allow(clippy::too_many_arguments)]
    pub fn shortcut(
        &mut self,
        cx: &mut ConstrainedContext,
        path: &mut Vec<f32>,
        rng: &mut Rng,
        tries: usize,
        deadline: Option<Instant>,
        stop: Option<&Arc<AtomicBool>>,
    ) -> usize {
        let nv = self.q64.len();
        let mut taken = 0;
        for attempt in 0..=tries {
            let late = deadline.is_some_and(|d| Instant::now() >= d);
            if late || stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
                break;
            }
            let n = path.len() / nv;
            if n < 3 {
                break;
            }
            let (i, j) = if attempt == 0 {
                (0, n - 1)
            } else {
                let i = rng.below(n - 2);
                (i, i + 2 + rng.below(n - i - 2))
            };
            let old: f64 = (i..j)
                .map(|p| dist2(&path[p * nv..][..nv], &path[(p + 1) * nv..][..nv]).sqrt() as f64)
                .sum();
            let direct = dist2(&path[i * nv..][..nv], &path[j * nv..][..nv]).sqrt() as f64;
            if direct >= old - 1e-6 {
                continue;
            }
            self.trees[0].clear();
            let mut h = [0.0; MAX_FUNCTIONS];
            Self::values_of(cx, &path[i * nv..][..nv], &mut self.q64, &mut h);
            self.trees[0].push(&path[i * nv..][..nv], &h, u32::MAX);
            self.target.copy_from_slice(&path[j * nv..][..nv]);
            Self::values_of(cx, &path[j * nv..][..nv], &mut self.q64, &mut self.target_h);
            let Grow::Reached(end) = self.grow(cx, 0, 0, Some(()), usize::MAX) else {
                continue;
            };
            self.chain(end);
            let new: f64 = self
                .tmp
                .chunks_exact(nv)
                .zip(self.tmp.chunks_exact(nv).skip(1))
                .map(|(a, b)| dist2(a, b).sqrt() as f64)
                .sum();
            if new < old - 1e-6 {
                self.tail.clear();
                self.tail.extend_from_slice(&path[(j + 1) * nv..]);
                path.truncate(i * nv);
                path.extend_from_slice(&self.tmp);
                path.extend_from_slice(&self.tail);
                taken += 1;
            }
        }
        taken
    }

    /// Tree 0's root → `end` into `self.tmp`.
    fn chain(&mut self, end: u32) {
        let nv = self.q64.len();
        self.tmp.clear();
        let mut i = end;
        while i != u32::MAX {
            self.tmp.extend_from_slice(self.trees[0].node(i));
            i = self.trees[0].parent[i as usize];
        }
        let n = self.tmp.len() / nv;
        for p in 0..n / 2 {
            for k in 0..nv {
                self.tmp.swap(p * nv + k, (n - 1 - p) * nv + k);
            }
        }
    }
}
