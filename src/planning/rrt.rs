//! RRT-Connect (Kuffner & LaValle, ICRA 2000), balanced, with an optional dynamic domain
//! (Yershova et al., ICRA 2005), on the continuous edge checks of [`crate::planning::checker`].
//!
//! One tree grows from the start and one from the goal. Each iteration draws a sample,
//! *extends* the smaller tree one step of at most `range` towards it, then *connects* the
//! other tree: steps of at most `range` towards the new node until it is reached (a path)
//! or an edge collides. With the dynamic domain, a node whose extension collided gets a
//! radius (`dd_radius`, shrunk by `1 − α` at each further failure, grown by `1 + α` at each
//! success); samples farther than its radius from their nearest node are rejected, which
//! keeps the trees from wasting samples against walls.
//!
//! The goal tree may have several roots ([`Rrt::solve_to_set`]: a goal set, such as the
//! inverse-kinematics solutions of a tool pose); a path ends at the root it grew from.
//!
//! Trees live in buffers sized once ([`Rrt::new`]); nearest neighbours are found by a
//! linear scan over coordinates padded to a multiple of eight (vectorised). Nothing is
//! allocated per iteration.

use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::sampler::Sampler;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

/// Settings of the search.
#[derive(Clone, Copy, Debug)]
pub struct RrtOptions {
    /// Longest step of an extension (joint-space L2).
    pub range: f32,
    /// Use the dynamic domain.
    pub dynamic_domain: bool,
    /// Initial domain radius of a node whose extension failed.
    pub dd_radius: f32,
    /// Domain growth/shrink factor.
    pub dd_alpha: f32,
    /// Most iterations.
    pub max_iterations: usize,
    /// Most nodes per tree.
    pub max_nodes: usize,
}

impl Default for RrtOptions {
    fn default() -> Self {
        Self {
            range: 1.0,
            dynamic_domain: true,
            dd_radius: 4.0,
            dd_alpha: 0.0001,
            max_iterations: 1_000_000,
            max_nodes: 200_000,
        }
    }
}

/// The prologue of a bidirectional iteration `it`: every `every` iterations the limit is
/// checked, a tree at `max_nodes` ends the search, and the smaller of the two trees (sizes
/// `lens`) is the one to extend (balanced RRT-Connect). Returns that tree's index.
pub(crate) fn iteration_start(
    it: usize,
    every: usize,
    limit: &SearchLimit,
    lens: [usize; 2],
    max_nodes: usize,
) -> Result<usize, SearchEnd> {
    if it % every == every - 1 {
        if let Some(end) = limit.reached() {
            return Err(end);
        }
    }
    if lens[0] >= max_nodes || lens[1] >= max_nodes {
        return Err(SearchEnd::Nodes);
    }
    Ok(usize::from(lens[1] < lens[0]))
}

/// The dynamic domain's update of a node's radius after an extension from it: a first
/// failure gives it `dd_radius`, a further one shrinks it by `1 − α` (not below `range`), a
/// success grows a finite radius by `1 + α`.
pub(crate) fn domain_after(r: &mut f32, free: bool, o: &RrtOptions) {
    if !o.dynamic_domain {
        return;
    }
    if free {
        if r.is_finite() {
            *r *= 1.0 + o.dd_alpha;
        }
    } else {
        *r = if r.is_finite() {
            (*r * (1.0 - o.dd_alpha)).max(o.range)
        } else {
            o.dd_radius
        };
    }
}

/// Why a search ended without a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SearchEnd {
    /// The iteration limit.
    Iterations,
    /// The time limit.
    Time,
    /// A tree filled its buffer.
    Nodes,
    /// The caller's stop flag was raised (Ctrl-C).
    Interrupted,
}

/// When a search gives up besides its iteration and node limits: a wall-clock deadline
/// and a stop flag that another thread (a Ctrl-C handler) may raise. Both are polled
/// every 64 iterations.
#[derive(Clone, Debug, Default)]
pub struct SearchLimit {
    /// Wall-clock deadline.
    pub deadline: Option<Instant>,
    /// Raised to stop the search.
    pub stop: Option<Arc<AtomicBool>>,
}

impl SearchLimit {
    /// Why the search must end now, if it must.
    pub fn reached(&self) -> Option<SearchEnd> {
        if self
            .stop
            .as_ref()
            .is_some_and(|s| s.load(Ordering::Relaxed))
        {
            return Some(SearchEnd::Interrupted);
        }
        self.deadline
            .is_some_and(|d| Instant::now() >= d)
            .then_some(SearchEnd::Time)
    }
}

/// One tree: nodes (padded to a multiple of eight coordinates), parents, domain radii.
/// [`crate::planning::aorrtc`] adds the nodes' costs.
#[derive(Clone, Debug)]
pub(crate) struct Tree {
    pub(crate) stride: usize,
    pub(crate) nodes: Vec<f32>,
    pub(crate) parent: Vec<u32>,
    pub(crate) radius: Vec<f32>,
}

impl Tree {
    pub(crate) fn with_capacity(nv: usize, cap: usize) -> Tree {
        let stride = nv.div_ceil(8) * 8;
        Tree {
            stride,
            nodes: Vec::with_capacity(stride * cap),
            parent: Vec::with_capacity(cap),
            radius: Vec::with_capacity(cap),
        }
    }

    pub(crate) fn clear(&mut self) {
        self.nodes.clear();
        self.parent.clear();
        self.radius.clear();
    }

    pub(crate) fn len(&self) -> usize {
        self.parent.len()
    }

    pub(crate) fn push(&mut self, q: &[f32], parent: u32) -> u32 {
        let n = self.len();
        self.nodes.extend_from_slice(q);
        self.nodes.resize((n + 1) * self.stride, 0.0);
        self.parent.push(parent);
        self.radius.push(f32::INFINITY);
        n as u32
    }

    /// Whether node `i` is a root (a task's start or goal).
    #[inline]
    pub(crate) fn is_root(&self, i: u32) -> bool {
        self.parent[i as usize] == u32::MAX
    }

    #[inline]
    pub(crate) fn node(&self, i: u32) -> &[f32] {
        let s = i as usize * self.stride;
        &self.nodes[s..s + self.stride]
    }

    /// Index of and squared distance to the node nearest `q` (padded to the stride).
    #[inline]
    fn nearest(&self, q: &[f32]) -> (u32, f32) {
        let mut best = (0u32, f32::INFINITY);
        for (i, node) in self.nodes.chunks_exact(self.stride).enumerate() {
            let mut d = 0.0f32;
            for (a, b) in node.iter().zip(q) {
                d += (a - b) * (a - b);
            }
            if d < best.1 {
                best = (i as u32, d);
            }
        }
        best
    }
}

/// The RRT-Connect search with its buffers.
#[derive(Clone, Debug)]
pub struct Rrt {
    /// Settings.
    pub opts: RrtOptions,
    trees: [Tree; 2],
    sample: Vec<f32>,
    step: Vec<f32>,
    /// Iterations of the last search.
    pub iterations: usize,
}

/// Outcome of one step towards a target.
enum Step {
    Reached(u32),
    Advanced(u32),
    Trapped,
}

impl Rrt {
    /// A search for `nv` coordinates with buffers for `opts.max_nodes` nodes per tree.
    pub fn new(nv: usize, opts: RrtOptions) -> Rrt {
        let tree = Tree::with_capacity(nv, opts.max_nodes);
        let stride = tree.stride;
        Rrt {
            opts,
            trees: [tree.clone(), tree],
            sample: vec![0.0; stride],
            step: vec![0.0; stride],
            iterations: 0,
        }
    }

    /// Searches from `start` to `goal` (both free). On success writes the path's
    /// waypoints into `path` (flat, `nv` per point, start and goal included).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        checker: &Checker,
        scratch: &mut CheckScratch,
        sampler: &mut Sampler,
        start: &[f32],
        goal: &[f32],
        limit: &SearchLimit,
        mode: EdgeMode,
        path: &mut Vec<f32>,
    ) -> Result<(), SearchEnd> {
        self.solve_to_set(checker, scratch, sampler, start, goal, limit, mode, path)
    }

    /// [`Rrt::solve`] to a goal set: `goals` holds one or more free configurations (flat,
    /// `nv` each), all roots of the goal tree; the path ends at the one the trees meet
    /// through (the first whose straight edge from the start is free, if any is).
    #[allow(clippy::too_many_arguments)]
    pub fn solve_to_set(
        &mut self,
        checker: &Checker,
        scratch: &mut CheckScratch,
        sampler: &mut Sampler,
        start: &[f32],
        goals: &[f32],
        limit: &SearchLimit,
        mode: EdgeMode,
        path: &mut Vec<f32>,
    ) -> Result<(), SearchEnd> {
        let nv = start.len();
        self.iterations = 0;
        path.clear();
        for goal in goals.chunks_exact(nv) {
            if checker.edge_free(start, goal, mode.leaving(true), scratch) {
                path.extend_from_slice(start);
                path.extend_from_slice(goal);
                return Ok(());
            }
        }
        self.solve_around(checker, scratch, sampler, start, goals, limit, mode, path)
    }

    /// [`Rrt::solve_to_set`] where the straight edges from `start` to `goals` are known to
    /// collide (a certified path's edge that failed): the trees grow at once.
    #[allow(clippy::too_many_arguments)]
    pub fn solve_around(
        &mut self,
        checker: &Checker,
        scratch: &mut CheckScratch,
        sampler: &mut Sampler,
        start: &[f32],
        goals: &[f32],
        limit: &SearchLimit,
        mode: EdgeMode,
        path: &mut Vec<f32>,
    ) -> Result<(), SearchEnd> {
        self.iterations = 0;
        path.clear();
        let nv = start.len();
        for t in &mut self.trees {
            t.clear();
        }
        self.trees[0].push(start, u32::MAX);
        for goal in goals.chunks_exact(nv) {
            self.trees[1].push(goal, u32::MAX);
        }
        for it in 0..self.opts.max_iterations {
            self.iterations = it + 1;
            let lens = [self.trees[0].len(), self.trees[1].len()];
            let a = iteration_start(it, 64, limit, lens, self.opts.max_nodes)?;
            sampler.next(&mut self.sample[..nv]);
            let target = std::mem::take(&mut self.sample);
            let ext = self.extend(a, &target, checker, scratch, mode, true);
            self.sample = target;
            let (Step::Advanced(new) | Step::Reached(new)) = ext else {
                continue;
            };
            let mut target = std::mem::take(&mut self.sample);
            target[..self.trees[a].stride].copy_from_slice(self.trees[a].node(new));
            let b = 1 - a;
            let connected = loop {
                match self.extend(b, &target, checker, scratch, mode, false) {
                    Step::Reached(end) => break Some(end),
                    Step::Advanced(_) => continue,
                    Step::Trapped => break None,
                }
            };
            self.sample = target;
            if let Some(end_b) = connected {
                let (from_start, from_goal) = if a == 0 { (new, end_b) } else { (end_b, new) };
                self.trace(from_start, from_goal, nv, path);
                return Ok(());
            }
        }
        Err(SearchEnd::Iterations)
    }

    /// One step of tree `t` towards `target` (padded): at most `range` from the nearest
    /// node, checked. `sample` marks a fresh sample (subject to the dynamic domain).
    fn extend(
        &mut self,
        t: usize,
        target: &[f32],
        checker: &Checker,
        scratch: &mut CheckScratch,
        mode: EdgeMode,
        sample: bool,
    ) -> Step {
        let o = self.opts;
        let tree = &mut self.trees[t];
        let (near, d2) = tree.nearest(target);
        let d = d2.sqrt();
        if sample && o.dynamic_domain && d > tree.radius[near as usize] {
            return Step::Trapped;
        }
        let reach = d <= o.range;
        let s = if reach { 1.0 } else { o.range / d };
        let from = tree.node(near);
        for k in 0..tree.stride {
            self.step[k] = from[k] + s * (target[k] - from[k]);
        }
        let nv = checker.nv();
        let free = checker.edge_free(
            &tree.nodes[near as usize * tree.stride..][..nv],
            &self.step[..nv],
            mode.leaving(tree.is_root(near)),
            scratch,
        );
        domain_after(&mut tree.radius[near as usize], free, &o);
        if !free {
            return Step::Trapped;
        }
        let new = tree.push(&self.step, near);
        if reach {
            Step::Reached(new)
        } else {
            Step::Advanced(new)
        }
    }

    /// Writes start → `a` (tree 0) then `b` → goal (tree 1) into `path`.
    fn trace(&self, a: u32, b: u32, nv: usize, path: &mut Vec<f32>) {
        path.clear();
        let mut i = a;
        while i != u32::MAX {
            path.extend_from_slice(&self.trees[0].node(i)[..nv]);
            i = self.trees[0].parent[i as usize];
        }
        // Reverse point order (start first).
        let n = path.len() / nv;
        for p in 0..n / 2 {
            for k in 0..nv {
                path.swap(p * nv + k, (n - 1 - p) * nv + k);
            }
        }
        // The meeting point is in both trees: skip tree 1's copy.
        let mut i = self.trees[1].parent[b as usize];
        while i != u32::MAX {
            path.extend_from_slice(&self.trees[1].node(i)[..nv]);
            i = self.trees[1].parent[i as usize];
        }
    }
}
