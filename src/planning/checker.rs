//! The vectorised collision checker: eight configurations at once, forward kinematics of
//! the sphere centres and sphere–obstacle and sphere–sphere tests in f32 lanes.
//!
//! **Configurations.** [`Checker::lanes_hit`] computes the body poses for eight
//! configurations (one per lane) down the tree, places each link's bounding sphere, tests it
//! against each obstacle, and only where a lane overlaps tests the link's own spheres; then
//! the enabled self-collision link pairs, bounding spheres first. The result is the mask
//! of lanes in collision.
//!
//! **Edges, continuously.** An edge `a → b` is cut into `n = ⌈‖b − a‖ · resolution⌉`
//! intervals of half-width `h = 1/(2n)` in the parameter `t`. The check at an interval's
//! centre with every sphere inflated by `e_s = v_s h − tol` covers the whole interval: by
//! the motion bound of [`super::spheres`], over the interval no centre moves further than
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
//! Intervals are visited in *rake* order (lane `ℓ` takes
//! intervals `ℓm, ℓm + 1, …`, `m = ⌈n/8⌉`), so a collision anywhere on the edge shows up in
//! the first batches. An interval whose inflated check fails is checked exactly at its
//! centre (a hit there is a real collision: the edge is invalid); otherwise it is split
//! into two halves with half the inflation, until the inflation is gone, when a hit is
//! real. Near obstacles the subdivision goes deep only where it has to.
//!
//! **Dispatch.** The entry points run an AVX2+FMA copy of the code when the CPU has them
//! (detected once at construction), an AVX-512 VL build of that copy when the CPU has those
//! too, and the baseline SSE2 copy otherwise; all are the same source, inlined into
//! `#[target_feature]` wrappers.

use super::environment::Environment;
use super::lanes::{Mask, P3m, Pose, PoseM, L, N, P3};
pub use super::simd::Isa;
#[cfg(target_arch = "x86_64")]
use super::simd::{avx512vl_detected, Avx2, Sse2};
use super::simd::{Scalar, Simd, W};
use super::spheres::{LinkSpheres, SphereModel};
use crate::model::{Model, WORLD};

/// One body of the kinematic tree in f32.
#[derive(Clone, Copy, Debug)]
struct Body {
    parent: usize,
    rot: [[f32; 3]; 3],
    rot_identity: bool,
    trans: [f32; 3],
    axis: usize,
    revolute: bool,
    q_index: usize,
    mult: f32,
    offset: f32,
}

/// How an edge is checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeMode {
    /// Continuously: nothing penetrates by more than the tolerance anywhere on the edge.
    Continuous,
    /// At points only (`search_resolution` per unit), as sampling planners usually do:
    /// fast, but the edge may graze an obstacle between two points.
    Discrete,
}

/// Joint-space distance from the path's ends over which the demanded clearance grows from
/// zero to its full value (rad).
pub const CLEARANCE_RAMP: f32 = 0.3;

/// Settings of the checker.
#[derive(Clone, Copy, Debug)]
pub struct CheckOptions {
    /// Edge intervals per unit of joint-space distance (the coarse level; finer where
    /// needed).
    pub resolution: f32,
    /// Points per unit of joint-space distance of the discrete checks
    /// ([`EdgeMode::Discrete`]). The planner searches with them and then checks the path's
    /// edges continuously, so they only need to turn away most colliding edges: 16 (half
    /// VAMP's 32) cuts the Panda and UR5 medians by 13–18 % with the same success.
    pub search_resolution: f32,
    /// Penetration the continuous check allows (m); the exact checks allow none.
    pub tolerance: f32,
    /// Distance from the obstacles that checks made with [`CheckScratch::keep_clearance`]
    /// set demand (m), ramped down near the path's ends ([`CLEARANCE_RAMP`]): the simplifier
    /// keeps it so that a smooth curve through the simplified waypoints has room to cut
    /// corners. Zero by default (MotionBenchMaker semantics).
    pub clearance: f32,
}

impl Default for CheckOptions {
    fn default() -> Self {
        Self {
            resolution: 32.0,
            search_resolution: 16.0,
            tolerance: 5e-5,
            clearance: 0.0,
        }
    }
}

/// Reusable buffers of one thread's checks (no allocation once warm).
#[derive(Clone, Debug, Default)]
pub struct CheckScratch {
    poses: Vec<PoseM>,
    centers: Vec<P3m>,
    bounds: Vec<P3m>,
    placed: Vec<bool>,
    /// Per body, its world twist `(ω, v)` per unit of the edge parameter.
    twist: Vec<[P3m; 2]>,
    /// Per sphere and per group bound, the inflation of the current batch.
    infl: Vec<L>,
    bound_infl: Vec<L>,
    /// Per body, its coordinate's change over the edge (mimic multiplier included).
    body_delta: Vec<f32>,
    /// `Σ |body_delta|`.
    l1: f32,
    /// Whether a continuous edge check is under way (twists and speeds are set).
    moving: bool,
    /// Whether the obstacle checks demand [`CheckOptions::clearance`].
    pub keep_clearance: bool,
    /// The path's start and goal (`2 nv`): the clearance demanded of a configuration grows
    /// from zero at them to the full value [`CLEARANCE_RAMP`] away (joint-space distance),
    /// since a task puts the arm close to the obstacles there on purpose (a pick, a place).
    pub ends: Vec<f32>,
    speed: Vec<f32>,
    link_speed: Vec<f32>,
    stack: Vec<(f32, f32)>,
    q: Vec<L>,
    /// Edge checks done.
    pub edges: u64,
    /// Batches of eight configurations checked.
    pub batches: u64,
}

/// The robot's spheres, the obstacles, the self-collision pairs and the f32 kinematics.
#[derive(Clone, Debug)]
pub struct Checker {
    bodies: Vec<Body>,
    /// The robot's spheres.
    pub spheres: SphereModel,
    /// The obstacles.
    pub env: Environment,
    /// Link-group pairs checked for self-collision.
    pub self_pairs: Vec<(usize, usize)>,
    /// Per link group, the obstacles its bounding sphere can ever reach.
    reachable: Vec<Vec<usize>>,
    /// Settings.
    pub opts: CheckOptions,
    #[cfg(target_arch = "x86_64")]
    avx2: Option<Avx2>,
    /// The AVX2 code runs in its AVX-512 VL instantiation (see [`super::simd`]).
    #[cfg(target_arch = "x86_64")]
    avx512vl: bool,
}

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
        Checker {
            bodies,
            spheres,
            env,
            self_pairs,
            reachable,
            opts,
            #[cfg(target_arch = "x86_64")]
            avx2: Avx2::detect(),
            #[cfg(target_arch = "x86_64")]
            avx512vl: avx512vl_detected() && Avx2::detect().is_some(),
        }
    }

    /// The instruction set the checks run on (the best the CPU has, unless limited).
    pub fn isa(&self) -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            match (self.avx2, self.avx512vl) {
                (Some(_), true) => Isa::Avx512Vl,
                (Some(_), false) => Isa::Avx2,
                (None, _) => Isa::Baseline,
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        Isa::Baseline
    }

    /// Runs the checks on at most `max` (to compare instruction sets, or to reproduce a
    /// baseline run). Every instruction set gives the same answers.
    pub fn limit_isa(&mut self, max: Isa) {
        #[cfg(target_arch = "x86_64")]
        {
            if max < Isa::Avx2 {
                self.avx2 = None;
            }
            self.avx512vl &= max >= Isa::Avx512Vl && self.avx2.is_some();
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = max;
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
            twist: vec![[P3m::default(); 2]; self.bodies.len()],
            infl: vec![L::splat(0.0); self.spheres.len()],
            bound_infl: vec![L::splat(0.0); self.spheres.links.len()],
            body_delta: vec![0.0; self.bodies.len()],
            ends: Vec::with_capacity(2 * self.nv()),
            speed: vec![0.0; self.spheres.len()],
            link_speed: vec![0.0; self.spheres.links.len()],
            stack: Vec::with_capacity(256),
            q: vec![L::splat(0.0); self.nv()],
            ..Default::default()
        };
        s.stack.clear();
        s
    }

    /// Whether configuration `q` is free (exact spheres, no inflation).
    pub fn config_free(&self, q: &[f32], s: &mut CheckScratch) -> bool {
        for (k, lane) in s.q.iter_mut().enumerate() {
            *lane = L::splat(q[k]);
        }
        let mut qs = std::mem::take(&mut s.q);
        let (hit, _) = self.dispatch_lanes(&qs, L::splat(0.0), s);
        std::mem::swap(&mut s.q, &mut qs);
        hit == 0
    }

    /// Whether the straight edge `a → b` is free, continuously (see the module docs).
    pub fn edge_free(&self, a: &[f32], b: &[f32], mode: EdgeMode, s: &mut CheckScratch) -> bool {
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

    #[inline(always)]
    fn edge_free_impl<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        mode: EdgeMode,
        s: &mut CheckScratch,
    ) -> bool {
        let continuous = mode == EdgeMode::Continuous;
        let nv = self.nv();
        let mut dist2 = 0.0f32;
        for k in 0..nv {
            dist2 += (b[k] - a[k]) * (b[k] - a[k]);
        }
        if continuous {
            self.edge_speeds(a, b, s);
        }
        s.moving = continuous;
        let res = if continuous {
            self.opts.resolution
        } else {
            self.opts.search_resolution
        };
        let n = ((dist2.sqrt() * res).ceil() as usize).max(1);
        let h0 = if continuous { 0.5 / n as f32 } else { 0.0 };
        let m = n.div_ceil(N);
        let mut qs = std::mem::take(&mut s.q);
        s.stack.clear();
        let mut ok = true;
        // Coarse pass in rake order; an exact hit ends it, inflated-only hits wait.
        for i in 0..m {
            let mut t = [0.0f32; N];
            let mut valid: Mask = 0;
            for (l, tl) in t.iter_mut().enumerate() {
                let k = l * m + i;
                valid |= Mask::from(k < n) << l;
                // Continuous: interval centres; discrete: the points k/n, k = 1..n (the end
                // included, the start being a node already checked).
                *tl = (k.min(n - 1) as f32 + if continuous { 0.5 } else { 1.0 }) / n as f32;
            }
            let (exact, inflated) = self.lerp_lanes_hit(tok, a, b, &t, &[h0; N], &mut qs, s);
            if exact & valid != 0 {
                ok = false;
                break;
            }
            for (l, &tl) in t.iter().enumerate() {
                if inflated & valid & (1 << l) != 0 {
                    s.stack.push((tl, h0));
                }
            }
        }
        ok = ok && self.refine(tok, a, b, &mut qs, s);
        std::mem::swap(&mut s.q, &mut qs);
        s.moving = false;
        ok
    }

    /// Works through the stack of intervals `(t, h)` whose inflated check failed but whose
    /// centre is free: their two halves are checked with half the inflation, eight at a
    /// time. False on a real (exact) hit.
    #[inline(always)]
    fn refine<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        qs: &mut [L],
        s: &mut CheckScratch,
    ) -> bool {
        while !s.stack.is_empty() {
            let mut t = [0.0f32; N];
            let mut h = [0.0f32; N];
            let mut lanes = 0;
            while lanes + 2 <= N && !s.stack.is_empty() {
                let (tc, hc) = s.stack.pop().unwrap_or_default();
                let hh = 0.5 * hc;
                if hh < 1e-7 {
                    // Subdivided to nothing without an exact hit: refuse, conservatively.
                    return false;
                }
                t[lanes] = tc - hh;
                t[lanes + 1] = tc + hh;
                h[lanes] = hh;
                h[lanes + 1] = hh;
                lanes += 2;
            }
            for l in lanes..N {
                t[l] = t[0];
                h[l] = h[0];
            }
            let (exact, inflated) = self.lerp_lanes_hit(tok, a, b, &t, &h, qs, s);
            if exact != 0 {
                return false;
            }
            for l in 0..lanes {
                if inflated & (1 << l) != 0 {
                    s.stack.push((t[l], h[l]));
                }
            }
        }
        true
    }

    /// Per-sphere and per-link speed bounds `v = Σ_k |b_k − a_k| ρ_k` of the edge.
    #[inline(always)]
    fn edge_speeds(&self, a: &[f32], b: &[f32], s: &mut CheckScratch) {
        let nv = self.nv();
        let sm = &self.spheres;
        for (i, v) in s.speed.iter_mut().enumerate() {
            let rho = &sm.rho[i * nv..(i + 1) * nv];
            *v = (0..nv).map(|k| (b[k] - a[k]).abs() * rho[k]).sum();
        }
        for (g, v) in s.link_speed.iter_mut().enumerate() {
            let rho = &sm.link_rho[g * nv..(g + 1) * nv];
            *v = (0..nv).map(|k| (b[k] - a[k]).abs() * rho[k]).sum();
        }
        s.l1 = 0.0;
        for (d, body) in s.body_delta.iter_mut().zip(&self.bodies) {
            *d = body.mult * (b[body.q_index] - a[body.q_index]);
            s.l1 += d.abs();
        }
    }

    /// Hits at `a + t (b − a)` per lane, spheres inflated for half-widths `h`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn lerp_lanes_hit<S: Simd>(
        &self,
        tok: S,
        a: &[f32],
        b: &[f32],
        t: &[f32; N],
        h: &[f32; N],
        qs: &mut [L],
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        for (k, lane) in qs.iter_mut().enumerate() {
            let d = b[k] - a[k];
            for (x, &tl) in lane.0.iter_mut().zip(t) {
                *x = a[k] + tl * d;
            }
        }
        s.batches += 1;
        if s.moving {
            self.lanes_hit::<S, true>(tok, qs, L(*h), s)
        } else {
            self.lanes_hit::<S, false>(tok, qs, L(*h), s)
        }
    }

    /// Collision masks `(exact, inflated)` of eight configurations `q` (one `L` per
    /// coordinate): `exact` with the spheres as they are, `inflated` with sphere `i` grown by
    /// `max(speed_i · h − tol, 0)` per lane. Returns at the first exact hit (the masks are
    /// then partial). Without `MOVING` (configurations, discrete edges) nothing is inflated
    /// and the inflation is not even computed: `inflated == exact`.
    ///
    /// Every body is placed first (base to tip), then the link groups meet the obstacles
    /// from the tip back to the base, as VAMP orders them: the hand and the distal links are
    /// the likeliest to hit, so a colliding batch ends early. Self pairs come last.
    #[inline(always)]
    pub(crate) fn lanes_hit<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        q: &[L],
        h: L,
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        let sm = &self.spheres;
        let h = tok.load(&h);
        let (mut exact, mut inflated): (Mask, Mask) = (0, 0);
        let pad = if s.keep_clearance {
            self.clearance(tok, q, s)
        } else {
            tok.splat(0.0)
        };
        for bi in 0..self.bodies.len() {
            let pose = self.body_pose(tok, bi, q, &s.poses);
            s.poses[bi] = pose.store();
            if MOVING {
                let (w, v) = self.body_twist(tok, bi, &pose, s);
                s.twist[bi] = [w.store(), v.store()];
            }
        }
        for g in (0..sm.links.len()).rev() {
            let ls = &sm.links[g];
            s.placed[g] = false;
            let pose = self.stored_pose(tok, ls.body, s);
            let bc = pose.act(tok, &ls.bound.center);
            s.bounds[g] = bc.store();
            let mut br = tok.splat(ls.bound.radius) + pad;
            if MOVING {
                let bi_g = self.bound_inflation(tok, g, &bc, h, s);
                s.bound_infl[g] = S::store(bi_g);
                br = br + bi_g;
            }
            for &o in &self.reachable[g] {
                let ob = &self.env.obstacles[o];
                if ob.near(tok, &bc, br) == 0 || ob.overlaps(tok, &bc, br) == 0 {
                    continue;
                }
                self.place_spheres::<S, MOVING>(tok, g, &pose, h, s);
                for i in ls.first..ls.end {
                    let r = tok.splat(sm.spheres[i].radius) + pad;
                    let c = P3::load(tok, &s.centers[i]);
                    if MOVING {
                        let m = ob.overlaps(tok, &c, r + tok.load(&s.infl[i]));
                        if m != 0 {
                            inflated |= m;
                            exact |= ob.overlaps(tok, &c, r);
                        }
                    } else {
                        exact |= ob.overlaps(tok, &c, r);
                    }
                }
                if exact != 0 {
                    return (exact, if MOVING { inflated } else { exact });
                }
            }
        }
        for &(ga, gb) in &self.self_pairs {
            let (e, i) = self.pair_hit::<S, MOVING>(tok, ga, gb, h, s);
            exact |= e;
            inflated |= i;
            if exact != 0 {
                break;
            }
        }
        (exact, if MOVING { inflated } else { exact })
    }

    /// The clearance demanded of each lane: the full [`CheckOptions::clearance`] farther
    /// than [`CLEARANCE_RAMP`] from both ends of the path, less in proportion nearer.
    #[inline(always)]
    fn clearance<S: Simd>(&self, tok: S, q: &[L], s: &CheckScratch) -> W<S> {
        let nv = self.nv();
        let full = tok.splat(self.opts.clearance);
        if s.ends.len() != 2 * nv {
            return full;
        }
        let (mut ds, mut dg) = (tok.splat(0.0), tok.splat(0.0));
        for (k, qk) in q.iter().enumerate().take(nv) {
            let x = tok.load(qk);
            let a = x - tok.splat(s.ends[k]);
            let b = x - tok.splat(s.ends[nv + k]);
            ds = a.mul_add(a, ds);
            dg = b.mul_add(b, dg);
        }
        let near = ds.min(dg).sqrt() * tok.splat(1.0 / CLEARANCE_RAMP);
        full * near.min(tok.splat(1.0))
    }

    /// Computes the world centres of group `g`'s spheres (once per batch).
    #[inline(always)]
    fn place_spheres<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        g: usize,
        pose: &Pose<S>,
        h: W<S>,
        s: &mut CheckScratch,
    ) {
        if s.placed[g] {
            return;
        }
        let ls = &self.spheres.links[g];
        if !MOVING {
            for i in ls.first..ls.end {
                s.centers[i] = pose.act(tok, &self.spheres.spheres[i].center).store();
            }
            s.placed[g] = true;
            return;
        }
        // No closures here: they would not inherit the caller's target features.
        let tw = if ls.body != WORLD {
            let t = &s.twist[ls.body];
            Some((P3::load(tok, &t[0]), P3::load(tok, &t[1])))
        } else {
            None
        };
        for i in ls.first..ls.end {
            let c = pose.act(tok, &self.spheres.spheres[i].center);
            s.centers[i] = c.store();
            let speed = match &tw {
                Some((w, v)) => Some(point_speed(w, v, &pose.t, &c)),
                None => None,
            };
            s.infl[i] = S::store(self.inflation(tok, s.speed[i], speed, h, s.l1));
        }
        s.placed[g] = true;
    }

    /// The inflation `max(speed · h − tol, 0)` of a point whose speed bound over the edge is
    /// `v` (per unit of the edge parameter) and whose speed at the check point is `now`:
    /// within `h` of it the speed is at most `now + ½ M h` with `M = 3 ‖Δ‖₁ v` (see the
    /// module docs), and never more than `v`.
    #[inline(always)]
    fn inflation<S: Simd>(&self, tok: S, v: f32, now: Option<W<S>>, h: W<S>, l1: f32) -> W<S> {
        let bound = tok.splat(v);
        let speed = match now {
            Some(now) => bound.min(now + tok.splat(1.5 * l1 * v) * h),
            None => bound,
        };
        (speed * h - tok.splat(self.opts.tolerance)).max(tok.splat(0.0))
    }

    /// Inflation of group `g`'s bounding sphere centred at `bc`: its points move at most at
    /// `|v_bc| + |ω| R`.
    #[inline(always)]
    fn bound_inflation<S: Simd>(
        &self,
        tok: S,
        g: usize,
        bc: &P3<S>,
        h: W<S>,
        s: &CheckScratch,
    ) -> W<S> {
        // No closures here: they would not inherit the caller's target features.
        let ls = &self.spheres.links[g];
        let now = if ls.body != WORLD {
            let t = &s.twist[ls.body];
            let (w, v) = (P3::load(tok, &t[0]), P3::load(tok, &t[1]));
            let o = P3::load(tok, &s.poses[ls.body].t);
            Some(
                point_speed(&w, &v, &o, bc)
                    + W::norm2(w.x, w.y, w.z).sqrt() * tok.splat(ls.bound.radius),
            )
        } else {
            None
        };
        self.inflation(tok, s.link_speed[g], now, h, s.l1)
    }

    /// World twist `(ω, v)` of body `i` per unit of the edge parameter: `ω = ω_p + Δ_i z_i`
    /// (revolute), `v = v_p + ω_p × (o_i − o_p)` (`+ Δ_i z_i` if prismatic).
    #[inline(always)]
    fn body_twist<S: Simd>(
        &self,
        tok: S,
        i: usize,
        pose: &Pose<S>,
        s: &CheckScratch,
    ) -> (P3<S>, P3<S>) {
        let b = &self.bodies[i];
        let zero = P3::splat(tok, &[0.0; 3]);
        let (wp, vp, op) = if b.parent == WORLD {
            (zero, zero, zero)
        } else {
            let t = &s.twist[b.parent];
            (
                P3::load(tok, &t[0]),
                P3::load(tok, &t[1]),
                P3::load(tok, &s.poses[b.parent].t),
            )
        };
        let d = tok.splat(s.body_delta[i]);
        let k = b.axis;
        let z = P3 {
            x: pose.r[0][k] * d,
            y: pose.r[1][k] * d,
            z: pose.r[2][k] * d,
        };
        let c = cross(&wp, &sub(&pose.t, &op));
        let mut v = P3 {
            x: vp.x + c.x,
            y: vp.y + c.y,
            z: vp.z + c.z,
        };
        let w = if b.revolute {
            P3 {
                x: wp.x + z.x,
                y: wp.y + z.y,
                z: wp.z + z.z,
            }
        } else {
            v = P3 {
                x: v.x + z.x,
                y: v.y + z.y,
                z: v.z + z.z,
            };
            wp
        };
        (w, v)
    }

    /// The pose of body `b` (or the world) stored by this batch.
    #[inline(always)]
    fn stored_pose<S: Simd>(&self, tok: S, b: usize, s: &CheckScratch) -> Pose<S> {
        if b == WORLD {
            let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
            Pose::splat(tok, &identity, &[0.0; 3])
        } else {
            Pose::load(tok, &s.poses[b])
        }
    }

    /// Masks `(exact, inflated)` where link groups `ga` and `gb` overlap (bounding spheres
    /// first).
    #[inline(always)]
    fn pair_hit<S: Simd, const MOVING: bool>(
        &self,
        tok: S,
        ga: usize,
        gb: usize,
        h: W<S>,
        s: &mut CheckScratch,
    ) -> (Mask, Mask) {
        let sm = &self.spheres;
        let (la, lb) = (&sm.links[ga], &sm.links[gb]);
        let ca = P3::load(tok, &s.bounds[ga]);
        let cb = P3::load(tok, &s.bounds[gb]);
        let mut rr = tok.splat(la.bound.radius + lb.bound.radius);
        if MOVING {
            rr = rr + tok.load(&s.bound_infl[ga]) + tok.load(&s.bound_infl[gb]);
        }
        if ca.dist2(&cb).lt(rr * rr) == 0 {
            return (0, 0);
        }
        for (g, body) in [(ga, la.body), (gb, lb.body)] {
            if !s.placed[g] {
                let pose = self.stored_pose(tok, body, s);
                self.place_spheres::<S, MOVING>(tok, g, &pose, h, s);
            }
        }
        if !MOVING {
            return (self.pair_spheres_hit(tok, la, lb, ca, cb, s), 0);
        }
        let (mut exact, mut inflated) = (0, 0);
        // Each sphere of the group with more spheres against the other group's bound first.
        let (la, lb, cb, gb) = if la.end - la.first >= lb.end - lb.first {
            (la, lb, cb, gb)
        } else {
            (lb, la, ca, ga)
        };
        let rb = tok.splat(lb.bound.radius) + tok.load(&s.bound_infl[gb]);
        for i in la.first..la.end {
            let ri = tok.splat(sm.spheres[i].radius);
            let ei = tok.load(&s.infl[i]);
            let ci = P3::load(tok, &s.centers[i]);
            let reach = ri + ei + rb;
            if ci.dist2(&cb).lt(reach * reach) == 0 {
                continue;
            }
            for j in lb.first..lb.end {
                let cj = P3::load(tok, &s.centers[j]);
                let r = ri + tok.splat(sm.spheres[j].radius);
                let d2 = ci.dist2(&cj);
                let rinf = r + ei + tok.load(&s.infl[j]);
                let m = d2.lt(rinf * rinf);
                if m != 0 {
                    inflated |= m;
                    exact |= d2.lt(r * r);
                }
            }
        }
        (exact, inflated)
    }

    /// Mask of the lanes where a sphere of `la` touches one of `lb` (no inflation): each
    /// sphere of the group with more spheres against the other group's bound first.
    #[inline(always)]
    fn pair_spheres_hit<S: Simd>(
        &self,
        tok: S,
        la: &LinkSpheres,
        lb: &LinkSpheres,
        ca: P3<S>,
        cb: P3<S>,
        s: &CheckScratch,
    ) -> Mask {
        let sm = &self.spheres;
        let (la, lb, cb) = if la.end - la.first >= lb.end - lb.first {
            (la, lb, cb)
        } else {
            (lb, la, ca)
        };
        let rb = tok.splat(lb.bound.radius);
        let mut hit = 0;
        for i in la.first..la.end {
            let ri = tok.splat(sm.spheres[i].radius);
            let ci = P3::load(tok, &s.centers[i]);
            let reach = ri + rb;
            if ci.dist2(&cb).lt(reach * reach) == 0 {
                continue;
            }
            for j in lb.first..lb.end {
                let r = ri + tok.splat(sm.spheres[j].radius);
                hit |= ci.dist2(&P3::load(tok, &s.centers[j])).lt(r * r);
            }
        }
        hit
    }

    /// `oM_parent · placement · J(q)` of body `i` in every lane.
    #[inline(always)]
    fn body_pose<S: Simd>(&self, tok: S, i: usize, q: &[L], poses: &[PoseM]) -> Pose<S> {
        let b = &self.bodies[i];
        let qi = tok
            .load(&q[b.q_index])
            .mul_add(tok.splat(b.mult), tok.splat(b.offset));
        let mut out = if b.parent == WORLD {
            Pose::splat(tok, &b.rot, &b.trans)
        } else {
            let p = Pose::load(tok, &poses[b.parent]);
            let t = p.act(tok, &b.trans);
            let r = if b.rot_identity {
                p.r
            } else {
                let mut r = p.r;
                for (row, rr) in r.iter_mut().enumerate() {
                    for (col, x) in rr.iter_mut().enumerate() {
                        *x = p.r[row][0].mul_add(
                            tok.splat(b.rot[0][col]),
                            p.r[row][1].mul_add(
                                tok.splat(b.rot[1][col]),
                                p.r[row][2] * tok.splat(b.rot[2][col]),
                            ),
                        );
                    }
                }
                r
            };
            Pose { r, t }
        };
        if b.revolute {
            let (sn, cs) = qi.sin_cos();
            let (ci, cj) = match b.axis {
                0 => (1, 2),
                1 => (2, 0),
                _ => (0, 1),
            };
            for row in 0..3 {
                let (x, y) = (out.r[row][ci], out.r[row][cj]);
                out.r[row][ci] = cs.mul_add(x, sn * y);
                out.r[row][cj] = cs.mul_add(y, -(sn * x));
            }
        } else {
            let k = b.axis;
            out.t.x = out.r[0][k].mul_add(qi, out.t.x);
            out.t.y = out.r[1][k].mul_add(qi, out.t.y);
            out.t.z = out.r[2][k].mul_add(qi, out.t.z);
        }
        out
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn edge_free_avx2(
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
#[target_feature(enable = "avx2,fma")]
unsafe fn lanes_hit_avx2(
    c: &Checker,
    tok: Avx2,
    q: &[L],
    h: L,
    s: &mut CheckScratch,
) -> (Mask, Mask) {
    c.lanes_hit::<_, false>(tok, q, h, s)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
unsafe fn edge_free_avx512vl(
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
#[target_feature(enable = "avx2,fma,avx512f,avx512vl")]
unsafe fn lanes_hit_avx512vl(
    c: &Checker,
    tok: Avx2,
    q: &[L],
    h: L,
    s: &mut CheckScratch,
) -> (Mask, Mask) {
    c.lanes_hit::<_, false>(tok, q, h, s)
}

/// Per link group, the obstacles within reach of its bounding sphere in any configuration:
/// the group's bound swept about the first movable body's origin (a sphere of radius
/// `|o − c| + r` around the chain root). Groups on the world are tested statically.
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
                    if ls.body != WORLD {
                        return true;
                    }
                    // A fixed link: does any of its spheres touch the obstacle at all?
                    let ob = &env.obstacles[o];
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

/// `a − b`.
#[inline(always)]
fn sub<S: Simd>(a: &P3<S>, b: &P3<S>) -> P3<S> {
    P3 {
        x: a.x - b.x,
        y: a.y - b.y,
        z: a.z - b.z,
    }
}

/// `a × b`.
#[inline(always)]
fn cross<S: Simd>(a: &P3<S>, b: &P3<S>) -> P3<S> {
    P3 {
        x: a.y * b.z - a.z * b.y,
        y: a.z * b.x - a.x * b.z,
        z: a.x * b.y - a.y * b.x,
    }
}

/// `|v + ω × (c − o)|`: the speed of point `c` on a body with twist `(ω, v)` at origin `o`.
#[inline(always)]
fn point_speed<S: Simd>(w: &P3<S>, v: &P3<S>, o: &P3<S>, c: &P3<S>) -> W<S> {
    let r = cross(w, &sub(c, o));
    W::norm2(v.x + r.x, v.y + r.y, v.z + r.z).sqrt()
}
