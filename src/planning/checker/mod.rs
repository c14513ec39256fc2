//! The vectorised collision checker: eight configurations at once, forward kinematics of
//! the sphere centres and sphere–obstacle and sphere–sphere tests in f32 lanes.
//!
//! **Configurations.** [`Checker::lanes_hit`] computes the body poses for eight
//! configurations (one per lane) down the tree, places each link's bounding sphere, tests it
//! against each obstacle, and only where a lane overlaps tests the link's own spheres; then
//! the enabled self-collision link pairs, bounding spheres first. The groups one body
//! carries (a hand with its fingers) share one more sphere, tested first ([`clusters`]).
//! The result is the mask of lanes in collision.
//!
//! **Edges, discretely.** The search checks its edges at `search_resolution` points per
//! unit ([`EdgeMode::Discrete`]); the path it returns is then checked continuously. The
//! lanes the points leave idle in the last batch check more points at no cost: interval
//! centres, or, on an edge out of a task's start or goal
//! ([`EdgeMode::DiscreteLeavingEnd`]), points in its first step, where a hand leaving a
//! grasp sweeps past the grasped object (the UR5's `table_pick` paths then fail their
//! certification in 8 % of the queries, not 46 %).
//!
//! **Edges, continuously.** An edge `a → b` is cut into `n = ⌈‖b − a‖ · resolution⌉`
//! intervals, rounded up to a multiple of eight (the lanes of a batch), of half-width
//! `h = 1/(2n)` in the parameter `t`. The check at an interval's
//! centre with every sphere inflated by `e_s = v_s h − tol` covers the whole interval: by
//! the motion bound of [`crate::planning::spheres`], over the interval no centre moves further than
//! `v_s h` from where it was checked, with `v_s = Σ_k |b_k − a_k| ρ_{s,k}`; so nothing
//! penetrates by more than `tol`.
//!
//! **Tighter, at the check point.** Along the edge (`q = a + tΔ`) a centre moves with
//! `c' = Σ_k Δ_k ω̂_k × (c − o_k)`, and `|c''| ≤ 3 ‖Δ‖₁ v_s`: differentiating, `|ω̂_k'| ≤ ‖Δ‖₁`,
//! `|c − o_k| ≤ ρ_{s,k}`, `|c'| ≤ v_s` and `|o_k'| ≤ v_s`. So within `h` of the check point
//! the centre moves at most `(|c'(t_c)| + ½ · 3 ‖Δ‖₁ v_s h) h`; the checker takes the smaller
//! of this and `v_s h`. `c'(t_c)` comes from the bodies' twists per unit `t`, propagated
//! with the poses (`ω_i = ω_p + Δ_i z_i`, `v_i = v_p + ω_p × (o_i − o_p)`); a link's bound
//! moves at most at `|v_bc| + |ω| R`. On the Panda problems this cuts the batches of the
//! continuous checks by 2.4× (median 181 → 76 per query).
//!
//! **Self pairs, relatively.** A rigid motion of both groups of a self pair changes no
//! distance between them, so the joints below their deepest common ancestor do not count:
//! a sphere pair is inflated by the smaller of its two spheres' inflations summed and the
//! pair's relative bound `v_rel h − tol`, `v_rel = Σ_k |Δ_k| ρ^rel_k` over the joints from
//! the common ancestor to each group ([`crate::planning::spheres::pair_rho`]). A hand
//! against the forearm then moves only with the wrist joints, not the shoulder's long
//! lever arms.
//!
//! **By the rate of the distance.** A sphere whose inflated test fails (against an
//! obstacle or in a self pair) is tested once more by how fast its distance `D` can shrink:
//! `D' = ĝ·c'` at the check point from the bodies' twists, and `D''` bounded below (for a
//! convex obstacle `D'' ≥ −|c''|`, the distance to a convex solid being convex; for a
//! sphere pair `D'' ≥ −|x''| − V²/(r − tol)`). Spheres sliding past a surface or each other
//! pass with a second-order inflation
//! ([`crate::planning::environment::EnvObstacle::rate_overlaps`], `Checker::distance_rate_hit`).
//! With both, 8 intervals per unit (was 32) check the Panda and UR5 paths, and their plan-time
//! medians fall by a fifth (UR5) to a third (Panda).
//!
//! Intervals are visited in *rake* order (lane `ℓ` takes
//! intervals `ℓm, ℓm + 1, …`, `m = ⌈n/8⌉`), so a collision anywhere on the edge shows up in
//! the first batches. An interval whose inflated check fails is checked exactly at its
//! centre (a hit there is a real collision: the edge is invalid); otherwise it is split
//! into pieces with a piece's inflation (as many as fill the eight lanes: halves of four
//! intervals, eighths of one), until the inflation is gone, when a hit is real. Near
//! obstacles the subdivision goes deep only where it has to. A piece is checked only
//! against what failed on its interval (the link groups against the obstacles, the self
//! pairs): what passed there covers every piece of it. On the UR5's `bookshelf_small` this
//! cuts the groups checked in continuous edge checks by a quarter.
//!
//! **Dispatch.** The entry points run an AVX2+FMA copy of the code when the CPU has them
//! (detected once at construction), an AVX-512 VL build of that copy when the CPU has those
//! too, and the baseline SSE2 copy otherwise; all are the same source, inlined into
//! `#[target_feature]` wrappers.

mod batch;
mod checker_state;
mod clusters;
mod edge;
mod exact;
mod motion;

use checker_state::Body;
pub use checker_state::{
    CheckOptions, CheckScratch, Checker, EdgeMode, ExactPairs, ExactScratch, CLEARANCE_RAMP,
};

use crate::model::{Model, WORLD};
use crate::planning::environment::Environment;
use crate::planning::lanes::{Mask, P3m, PoseM, L, N, P3};
pub use crate::planning::simd::CheckerIsa;
#[cfg(target_arch = "x86_64")]
use crate::planning::simd::{avx512vl_detected, Avx2, Sse2};
use crate::planning::simd::{Scalar, Simd};
use crate::planning::spheres::{pair_rho, reach_to, SphereModel};

impl Checker {
    /// A checker for `model` with its sphere model, obstacles and self pairs.
    pub fn new(
        model: &Model,
        spheres: SphereModel,
        env: Environment,
        self_pairs: Vec<(usize, usize)>,
        opts: CheckOptions,
    ) -> Checker {
        let f = |x: f64| x as f32;
        let bodies = (0..model.nbodies())
            .map(|i| {
                let p = &model.placement[i];
                Body {
                    parent: model.parent[i],
                    rot: [0, 1, 2].map(|r| [0, 1, 2].map(|c| f(p.rot[(r, c)]))),
                    rot_identity: model.placement_identity[i],
                    trans: [f(p.trans.x), f(p.trans.y), f(p.trans.z)],
                    axis: model.kind[i].axis_index(),
                    revolute: model.kind[i].is_revolute(),
                    q_index: model.q_index[i],
                    mult: f(model.q_mult[i]),
                    offset: f(model.q_offset[i]),
                }
            })
            .collect();
        let reachable = reachable_obstacles(model, &spheres, &env, opts.clearance);
        // Ordered by group, so that a group's pairs with the groups of one body (a cluster)
        // are consecutive. The verdicts do not depend on the order.
        let mut self_pairs: Vec<(usize, usize)> = self_pairs
            .iter()
            .map(|&(a, b)| (a.min(b), a.max(b)))
            .collect();
        self_pairs.sort_unstable();
        self_pairs.dedup();
        let pair_rho: Vec<f32> = self_pairs
            .iter()
            .flat_map(|&(a, b)| pair_rho(model, &spheres, a, b))
            .collect();
        let clusters = clusters::Clusters::new(&spheres, &reachable, &self_pairs);
        let cluster_rho: Vec<f32> = clusters.list.iter().flat_map(|c| c.rho.clone()).collect();
        let speed_tables = checker_state::SpeedTables::new(
            model.nv,
            [&spheres.rho, &spheres.link_rho, &pair_rho, &cluster_rho],
        );
        Checker {
            speed_tables,
            bodies,
            spheres,
            env,
            clusters,
            self_pairs,
            reachable,
            opts,
            #[cfg(target_arch = "x86_64")]
            avx2: Avx2::detect(),
            #[cfg(target_arch = "x86_64")]
            avx512vl: avx512vl_detected() && Avx2::detect().is_some(),
            exact: None,
            selective: true,
        }
    }

    /// The instruction set the checks run on (the best the CPU has, unless limited).
    pub fn isa(&self) -> CheckerIsa {
        #[cfg(target_arch = "x86_64")]
        {
            match (self.avx2, self.avx512vl) {
                (Some(_), true) => CheckerIsa::Avx512Vl,
                (Some(_), false) => CheckerIsa::Avx2,
                (None, _) => CheckerIsa::Baseline,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        CheckerIsa::Baseline
    }

    /// Runs the checks on at most `max` (to compare instruction sets, or to reproduce a
    /// baseline run). Every instruction set gives the same answers.
    pub fn limit_isa(&mut self, max: CheckerIsa) {
        #[cfg(target_arch = "x86_64")]
        {
            if max < CheckerIsa::Avx2 {
                self.avx2 = None;
            }
            self.avx512vl &= max >= CheckerIsa::Avx512Vl && self.avx2.is_some();
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = max;
    }

    /// Checks every link group and self pair on its own, without the body clusters'
    /// early outs (see [`clusters`]): slower, with the same verdicts (to compare them).
    pub fn without_clusters(&mut self) {
        self.clusters = clusters::Clusters::none(self.spheres.links.len(), &self.self_pairs);
    }

    /// Refines a failed interval's pieces against every obstacle and self pair, not only
    /// against what failed on the interval: more work, the same verdicts (to compare them).
    pub fn refine_every_check(&mut self) {
        self.selective = false;
    }

    /// The body clusters' groups (index ranges into the sphere model's groups).
    pub fn clusters(&self) -> Vec<std::ops::Range<usize>> {
        self.clusters
            .list
            .iter()
            .map(|c| c.groups.clone())
            .collect()
    }

    /// Number of coordinates.
    pub fn nv(&self) -> usize {
        self.spheres.nv
    }

    /// Fresh scratch buffers sized for this checker.
    pub fn scratch(&self) -> CheckScratch {
        let mut s = CheckScratch {
            poses: vec![PoseM::default(); self.bodies.len()],
            centers: vec![P3m::default(); self.spheres.len()],
            bounds: vec![P3m::default(); self.spheres.links.len()],
            placed: vec![false; self.spheres.links.len()],
            need: vec![crate::planning::lanes::ALL; self.spheres.links.len()],
            need_pairs: crate::planning::lanes::ALL,
            group_fail: vec![0; self.spheres.links.len()],
            twist: vec![[P3m::default(); 2]; self.bodies.len()],
            infl: vec![L::splat(0.0); self.spheres.len()],
            bound_infl: vec![L::splat(0.0); self.spheres.links.len()],
            body_delta: vec![0.0; self.bodies.len()],
            abs_delta: vec![0.0; self.nv()],
            ends: Vec::with_capacity(2 * self.nv()),
            speed: vec![0.0; self.spheres.len()],
            link_speed: vec![0.0; self.spheres.links.len()],
            pair_speed: vec![0.0; self.self_pairs.len()],
            cluster_bounds: vec![P3m::default(); self.clusters.list.len()],
            cluster_infl: vec![L::splat(0.0); self.clusters.list.len()],
            cluster_speed: vec![0.0; self.clusters.list.len()],
            near: vec![false; self.env.len()],
            stack: Vec::with_capacity(256),
            q: vec![L::splat(0.0); self.nv()],
            exact: self.exact.as_ref().map(|e| Box::new(e.scratch())),
            ..Default::default()
        };
        s.stack.clear();
        s
    }

    /// Whether configuration `q` is free (exact spheres, no inflation).
    pub fn config_free(&self, q: &[f32], s: &mut CheckScratch) -> bool {
        self.spheres_free(q, q, s)
            && match (&self.exact, s.exact.as_deref_mut()) {
                (Some(e), Some(es)) => e.config_free(q, es),
                _ => true,
            }
    }

    /// Whether configurations `a` and `b` are both free, in one batch (half the lanes
    /// each; a query's start and goal). False when either collides.
    pub fn both_free(&self, a: &[f32], b: &[f32], s: &mut CheckScratch) -> bool {
        self.spheres_free(a, b, s)
            && match (&self.exact, s.exact.as_deref_mut()) {
                (Some(e), Some(es)) => e.config_free(a, es) && e.config_free(b, es),
                _ => true,
            }
    }

    /// Whether `a` (the first half of the lanes) and `b` (the second) are both free on the
    /// spheres, in one batch.
    fn spheres_free(&self, a: &[f32], b: &[f32], s: &mut CheckScratch) -> bool {
        for (k, lane) in s.q.iter_mut().enumerate() {
            let (la, lb) = lane.0.split_at_mut(N / 2);
            la.fill(a[k]);
            lb.fill(b[k]);
        }
        let mut qs = std::mem::take(&mut s.q);
        let (hit, _) = self.dispatch_lanes(&qs, L::splat(0.0), s);
        std::mem::swap(&mut s.q, &mut qs);
        hit == 0
    }

    /// Whether the straight edge `a → b` is free (see the module docs), the exact stage
    /// included.
    pub fn edge_free(&self, a: &[f32], b: &[f32], mode: EdgeMode, s: &mut CheckScratch) -> bool {
        self.spheres_edge_free(a, b, mode, s)
            && match (&self.exact, s.exact.as_deref_mut()) {
                (Some(e), Some(es)) => e.edge_free(a, b, mode, es),
                _ => true,
            }
    }

    /// Whether the straight edge `a → b` is free on the spheres (see the module docs).
    fn spheres_edge_free(
        &self,
        a: &[f32],
        b: &[f32],
        mode: EdgeMode,
        s: &mut CheckScratch,
    ) -> bool {
        s.edges += 1;
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(tok) = self.avx2 {
                // SAFETY: the token proves the CPU has AVX2 and FMA; `avx512vl` was
                // detected at construction.
                return unsafe {
                    if self.avx512vl {
                        edge_free_avx512vl(self, tok, a, b, mode, s)
                    } else {
                        edge_free_avx2(self, tok, a, b, mode, s)
                    }
                };
            }
            self.edge_free_impl(Sse2::new(), a, b, mode, s)
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.edge_free_impl(Scalar, a, b, mode, s)
    }

    fn dispatch_lanes(&self, q: &[L], h: L, s: &mut CheckScratch) -> (Mask, Mask) {
        #[cfg(target_arch = "x86_64")]
        {
            if let Some(tok) = self.avx2 {
                // SAFETY: as in `edge_free`.
                return unsafe {
                    if self.avx512vl {
                        lanes_hit_avx512vl(self, tok, q, h, s)
                    } else {
                        lanes_hit_avx2(self, tok, q, h, s)
                    }
                };
            }
            self.lanes_hit::<_, false>(Sse2::new(), q, h, s)
        }
        #[cfg(not(target_arch = "x86_64"))]
        self.lanes_hit::<_, false>(Scalar, q, h, s)
    }
}

/// The entry points compiled for one instruction set: the shared generic code inlined into
/// `#[target_feature]` wrappers (callers prove the features with the token and detection).
macro_rules! isa_entry_points {
    ($features:literal, $edge:ident, $lanes:ident) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        unsafe fn $edge(
            c: &Checker,
            tok: Avx2,
            a: &[f32],
            b: &[f32],
            mode: EdgeMode,
            s: &mut CheckScratch,
        ) -> bool {
            c.edge_free_impl(tok, a, b, mode, s)
        }

        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $features)]
        unsafe fn $lanes(
            c: &Checker,
            tok: Avx2,
            q: &[L],
            h: L,
            s: &mut CheckScratch,
        ) -> (Mask, Mask) {
            c.lanes_hit::<_, false>(tok, q, h, s)
        }
    };
}

isa_entry_points!("avx2,fma", edge_free_avx2, lanes_hit_avx2);
isa_entry_points!(
    "avx2,fma,avx512f,avx512vl",
    edge_free_avx512vl,
    lanes_hit_avx512vl
);

/// Per link group, the obstacles within reach of its bounding sphere in any configuration:
/// the group's bound swept about the origin `o` of its chain's root body, fixed in the
/// world (a sphere of radius `R + r` around it, `R` bounding `|c − o|` by the placements
/// and slides down the chain, [`crate::planning::spheres::reach_to`]): the shoulder of an
/// arm never meets the far end of a table. Groups on the world are tested statically.
fn reachable_obstacles(
    model: &Model,
    sm: &SphereModel,
    env: &Environment,
    clearance: f32,
) -> Vec<Vec<usize>> {
    let centers = sm.world_centers(model, &vec![0.0; model.nv]);
    sm.links
        .iter()
        .map(|ls| {
            (0..env.len())
                .filter(|&o| {
                    let ob = &env.obstacles[o];
                    if ls.body != WORLD {
                        let root = model.support(ls.body).last().unwrap_or(ls.body);
                        let t = model.placement[root].trans;
                        let reach = reach_to(model, ls.bound.center, ls.body, root)
                            + f64::from(ls.bound.radius + clearance);
                        let p = P3::splat(Scalar, &[t.x as f32, t.y as f32, t.z as f32]);
                        // A millimetre of margin for the f32 tests.
                        return ob.overlaps(Scalar, &p, Scalar.splat((reach + 1e-3) as f32)) != 0;
                    }
                    // A fixed link: does any of its spheres touch the obstacle at all?
                    (ls.first..ls.end).any(|i| {
                        let c = centers[i];
                        let p = P3::splat(Scalar, &[c.x as f32, c.y as f32, c.z as f32]);
                        ob.overlaps(Scalar, &p, Scalar.splat(sm.spheres[i].radius + clearance)) != 0
                    })
                })
                .collect()
        })
        .collect()
}
