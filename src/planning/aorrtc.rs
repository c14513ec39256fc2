//! The improving search of AORRTC (Wilson, Thomason, Kingston, Kavraki & Gammell, RA-L
//! 2025): RRT-Connect run in the configuration space augmented by cost, so that with a
//! path of cost `c_best` known, only paths cheaper than `c_best` can be found.
//!
//! Each node keeps its cost from its tree's root, `g(v)`. An iteration of tree A (rooted
//! at `r_A`; tree B at `r_B`):
//!
//! 1. draws `x` from the informed set ([`InformedSampler`]) and a cost bound
//!    `c ~ U[ĝ, c_best − ĥ]`, with `ĝ = ‖x − r_A‖`, `ĥ = ‖x − r_B‖` (the cost of reaching
//!    `x` through any path cheaper than `c_best` lies in that range);
//! 2. takes the nearest node in the augmented metric `√(‖x − v‖² + (c − g(v))²)` among the
//!    nodes that can reach `x` within the bound, `g(v) + ‖x − v‖ ≤ c` (the root always
//!    can: it is the fallback);
//! 3. steps at most `range` towards `x`, checks the edge, and gives the new node `x'` the
//!    cost `g(v) + ‖x' − v‖`;
//! 4. *resamples the cost bound* below that cost, `c ~ U[‖x' − r_A‖, g(x')]`, for a
//!    cheaper parent, as long as each found parent is new, cheaper, and reachable by a
//!    free edge;
//! 5. connects: the node of tree B nearest `x'` within the remaining bound
//!    `c_best − g(x')`, joined in steps of at most `range`, each checked and added to A.
//!    A connection whose total cost is not below `c_best` is not tried.
//!
//! A path found this way is cheaper than `c_best` by construction. The trees are built
//! afresh for each bound. Nearest neighbours are a linear scan, as in
//! [`crate::planning::rrt`]; nothing is allocated per iteration.

use crate::planning::checker::{CheckScratch, Checker, EdgeMode};
use crate::planning::informed::{dist, InformedSampler};
use crate::planning::rrt::{
    domain_after, iteration_start, RrtOptions, SearchEnd, SearchLimit, Tree,
};
use crate::planning::sampler::Rng;

/// Most cost-bound resamples per new node (VAMP's `max_cost_bound_resamples`).
pub const COST_BOUND_RESAMPLES: usize = 1000;

/// One tree with the cost of each node from its root.
#[derive(Clone, Debug)]
struct CostTree {
    tree: Tree,
    cost: Vec<f32>,
}

impl CostTree {
    fn with_capacity(nv: usize, cap: usize) -> CostTree {
        CostTree {
            tree: Tree::with_capacity(nv, cap),
            cost: Vec::with_capacity(cap),
        }
    }

    fn reset(&mut self, root: &[f32]) {
        self.tree.clear();
        self.cost.clear();
        self.push(root, u32::MAX, 0.0);
    }

    fn len(&self) -> usize {
        self.tree.len()
    }

    fn push(&mut self, q: &[f32], parent: u32, cost: f32) -> u32 {
        self.cost.push(cost);
        self.tree.push(q, parent)
    }

    #[inline]
    fn node(&self, i: u32) -> &[f32] {
        self.tree.node(i)
    }

    /// The node nearest `(q, c)` in the cost-augmented metric among those that reach `q`
    /// within cost `c` (the root, cost 0, always counts), and its distance to `q`.
    #[inline]
    fn nearest_within(&self, q: &[f32], c: f32) -> (u32, f32) {
        let mut best = (0u32, f32::INFINITY);
        let mut best_aug = f32::INFINITY;
        for (i, node) in self.tree.nodes.chunks_exact(self.tree.stride).enumerate() {
            let mut d2 = 0.0f32;
            for (a, b) in node.iter().zip(q) {
                d2 += (a - b) * (a - b);
            }
            let g = self.cost[i];
            let aug = d2 + (c - g) * (c - g);
            if aug >= best_aug {
                continue;
            }
            let d = d2.sqrt();
            if g == 0.0 || g + d <= c {
                best = (i as u32, d);
                best_aug = aug;
            }
        }
        best
    }

    /// Appends node `i` and its ancestors (root last) to `out`, `nv` values each.
    fn chain(&self, mut i: u32, nv: usize, out: &mut Vec<f32>) {
        while i != u32::MAX {
            out.extend_from_slice(&self.node(i)[..nv]);
            i = self.tree.parent[i as usize];
        }
    }
}

/// Where one improving search runs: the checker, the informed set and the limits.
pub struct ImproveSearch<'a> {
    /// The scene's checker.
    pub checker: &'a Checker,
    /// Its scratch.
    pub scratch: &'a mut CheckScratch,
    /// The informed set of the current bound.
    pub informed: &'a InformedSampler,
    /// Samples and cost bounds.
    pub rng: &'a mut Rng,
    /// Deadline and stop flag.
    pub limit: &'a SearchLimit,
    /// Edge checks (discrete: the optimiser certifies the path found).
    pub mode: EdgeMode,
}

/// The AORRTC improving search with its buffers.
#[derive(Clone, Debug)]
pub struct Aorrtc {
    opts: RrtOptions,
    trees: [CostTree; 2],
    sample: Vec<f32>,
    step: Vec<f32>,
    next: Vec<f32>,
    /// Iterations of the last search.
    pub iterations: usize,
}

impl Aorrtc {
    /// A search for `nv` coordinates, with buffers for `opts.max_nodes` nodes per tree.
    pub fn new(nv: usize, opts: RrtOptions) -> Aorrtc {
        let tree = CostTree::with_capacity(nv, opts.max_nodes);
        let stride = tree.tree.stride;
        Aorrtc {
            opts,
            trees: [tree.clone(), tree],
            sample: vec![0.0; stride],
            step: vec![0.0; stride],
            next: vec![0.0; stride],
            iterations: 0,
        }
    }

    /// Searches for a path from `start` to `goal` cheaper than `max_cost`, in at most
    /// `max_iterations` iterations; on success writes it into `path` (flat, `nv` per
    /// point, ends included).
    pub fn solve(
        &mut self,
        s: &mut ImproveSearch<'_>,
        start: &[f32],
        goal: &[f32],
        max_cost: f32,
        max_iterations: usize,
        path: &mut Vec<f32>,
    ) -> Result<(), SearchEnd> {
        let nv = start.len();
        self.trees[0].reset(start);
        self.trees[1].reset(goal);
        self.iterations = 0;
        for it in 0..max_iterations {
            self.iterations = it + 1;
            let lens = [self.trees[0].len(), self.trees[1].len()];
            let a = iteration_start(it, 64, s.limit, lens, self.opts.max_nodes)?;
            s.informed.sample(s.rng, &mut self.sample[..nv]);
            let Some((new, cost)) = self.extend(a, s, max_cost, nv) else {
                continue;
            };
            if let Some((last, other)) = self.connect(a, s, new, cost, max_cost, nv) {
                self.trace(a, last, other, nv, path);
                return Ok(());
            }
        }
        Err(SearchEnd::Iterations)
    }

    /// Steps 1–4: one cost-bounded extension of tree `a` towards `self.sample`. Returns the
    /// new node and its cost.
    fn extend(
        &mut self,
        a: usize,
        s: &mut ImproveSearch<'_>,
        max_cost: f32,
        nv: usize,
    ) -> Option<(u32, f32)> {
        let o = self.opts;
        let tree = &self.trees[a];
        let (x, root_a, root_b) = (&self.sample[..nv], tree.node(0), self.trees[1 - a].node(0));
        let g_hat = dist(x, &root_a[..nv]);
        let c_range = (max_cost - g_hat - dist(x, &root_b[..nv])).max(0.0);
        let c_rand = s.rng.next_f64() as f32 * c_range + g_hat;
        let (mut near, d) = tree.nearest_within(&self.sample, c_rand);
        if o.dynamic_domain && d > tree.tree.radius[near as usize] {
            return None;
        }
        let reach = d <= o.range;
        let t = if reach { 1.0 } else { o.range / d };
        let from = tree.node(near);
        for ((st, f), x) in self.step.iter_mut().zip(from).zip(&self.sample) {
            *st = f + t * (x - f);
        }
        let mode = s.mode.leaving(tree.tree.is_root(near));
        let free = s
            .checker
            .edge_free(&from[..nv], &self.step[..nv], mode, s.scratch);
        let tree = &mut self.trees[a];
        domain_after(&mut tree.tree.radius[near as usize], free, &o);
        if !free {
            return None;
        }
        let mut cost = tree.cost[near as usize] + d.min(o.range);
        // Step 4: cheaper parents below the new node's cost.
        let g_new = dist(&self.step[..nv], &tree.node(0)[..nv]);
        for _ in 0..COST_BOUND_RESAMPLES {
            let c_range = (cost - g_new).max(0.0);
            if c_range == 0.0 {
                break;
            }
            let c_rand = s.rng.next_f64() as f32 * c_range + g_new;
            let (p, dp) = tree.nearest_within(&self.step, c_rand);
            if p == near || tree.cost[p as usize] + dp >= cost {
                break;
            }
            let parent = &tree.node(p)[..nv];
            let mode = s.mode.leaving(tree.tree.is_root(p));
            if !s
                .checker
                .edge_free(parent, &self.step[..nv], mode, s.scratch)
            {
                break;
            }
            near = p;
            cost = tree.cost[p as usize] + dp;
        }
        Some((tree.push(&self.step, near, cost), cost))
    }

    /// Step 5: joins node `new` (cost `cost`) of tree `a` to the other tree within the
    /// bound. Returns the last node added to `a` (at the other tree's node) and that node.
    fn connect(
        &mut self,
        a: usize,
        s: &mut ImproveSearch<'_>,
        new: u32,
        cost: f32,
        max_cost: f32,
        nv: usize,
    ) -> Option<(u32, u32)> {
        let b = 1 - a;
        let from = &self.trees[a].node(new)[..nv];
        let (other, d) = self.trees[b].nearest_within(from, max_cost - cost);
        if cost + d + self.trees[b].cost[other as usize] >= max_cost {
            return None;
        }
        let n = (d / self.opts.range).ceil().max(1.0);
        let (steps, inc) = (n as usize, d / n);
        self.step.copy_from_slice(self.trees[a].node(new));
        let (mut last, mut g) = (new, cost);
        for i in 1..=steps {
            let target = self.trees[b].node(other);
            if i == steps {
                self.next.copy_from_slice(target);
            } else {
                let t = i as f32 / n;
                for ((nx, st), g) in self.next[..nv].iter_mut().zip(&self.step).zip(target) {
                    *nx = st + t * (g - st);
                }
            }
            let prev = &self.trees[a].node(last)[..nv];
            // The last step may arrive at the other tree's root: checked leaving it.
            let free = if i == steps && self.trees[b].tree.is_root(other) {
                let mode = s.mode.leaving(true);
                s.checker.edge_free(&self.next[..nv], prev, mode, s.scratch)
            } else {
                s.checker
                    .edge_free(prev, &self.next[..nv], s.mode, s.scratch)
            };
            if !free {
                return None;
            }
            g += inc;
            last = self.trees[a].push(&self.next, last, g);
            if self.trees[a].len() >= self.opts.max_nodes {
                return None;
            }
        }
        Some((last, other))
    }

    /// Writes the path start → goal through node `last` of tree `a` and node `other` of
    /// the other tree (at the same configuration) into `path`.
    fn trace(&self, a: usize, last: u32, other: u32, nv: usize, path: &mut Vec<f32>) {
        path.clear();
        let b = 1 - a;
        let other_parent = self.trees[b].tree.parent[other as usize];
        // The start tree's part is traced goal-side first, then reversed.
        let (first, second) = if a == 0 {
            ((0, last), (1, other_parent))
        } else {
            ((0, other_parent), (1, last))
        };
        if first.1 != u32::MAX {
            self.trees[first.0].chain(first.1, nv, path);
        }
        let n = path.len() / nv;
        for p in 0..n / 2 {
            for k in 0..nv {
                path.swap(p * nv + k, (n - 1 - p) * nv + k);
            }
        }
        if second.1 != u32::MAX {
            self.trees[second.0].chain(second.1, nv, path);
        }
    }
}
