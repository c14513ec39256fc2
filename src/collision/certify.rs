//! Continuous certification of a timed trajectory: every tested pair is proven apart at
//! every instant of `[t_0, t_N]`, not only at the samples `t_k`, and the exact closest
//! approaches at the samples are found without measuring every pair at every sample.
//!
//! **Curve bound.** On an interval `[t_k, t_k+1]` of length `h`, let `A_j` bound `|q̈_j|`
//! along the motion ([`CertifiedMotion::accel_bound`]) and `v_j = |q̇_j(t_k)|`, `w_j =
//! |q̇_j(t_k+1)|`. Then `|q̇_j(t_k + s)| ≤ v_j + A_j s` and `≤ w_j + A_j (h − s)`, so the joint's path length
//! over the first half is at most `v_j h/2 + A_j h²/8` and over the second half at most
//! `w_j h/2 + A_j h²/8` — along the actual (smoothed, timed) curve, whatever its shape
//! between the samples. With the pair's motion coefficients `ρ` ([`crate::collision::bounds`]), a
//! pair's distance changes over a half-interval by at most `Σ_j ρ_j · (that length)`. A
//! half-interval is *proven* when a lower bound of the distance at its sample end exceeds
//! the margin plus that change (distances of lower-bound quality at the sample suffice).
//!
//! **Per pair, conservative advancement.** At a sample, a lower bound of the pair's
//! distance is worked up ([`crate::collision::bounds::Level`]: bounding spheres and boxes, convex
//! hulls, exact shapes) until it covers the half-intervals still open on both sides; it
//! then proves every following half-interval whose cumulative change stays below it, and
//! the pair jumps to the first sample past them. Where even the exact distance at the
//! samples cannot prove an interval, it is bisected in time (the curve sampled at the
//! midpoint, its velocity there) down to [`CertifyOptions::min_interval`]; a
//! configuration found at or below the margin is a collision (its first contact is
//! bisected to [`CertifyOptions::time_tolerance`] with the exact check of every pair); an
//! interval still unproven at the smallest size is reported as uncertified.
//!
//! **Closest approaches** ([`crate::collision::closest`]): the smallest exact distance over the
//! samples, environment and self separately, by branch and bound over (sample, pair), and
//! the certified lower bound of the clearance along the whole curve.

use crate::collision::bounds::{half_path_bound, Certifier, Evaluations, Level};
use crate::collision::collision_error::CollisionError;
use crate::collision::collision_scene::{Body, CollisionData, CollisionModel, PairDistance};
use crate::collision::shape::{to_pose, Scratch};
use crate::collision::trajectory::TrajectoryCollision;
use crate::model::{Model, WORLD};
use parry3d_f64::math::{Pose, Vector};
use serde::Serialize;

/// `q(t)` and `q̇(t)` of a motion, written into the two slices.
pub type SampleFn<'a> = dyn Fn(f64, &mut [f64], &mut [f64]) + 'a;

/// The motion to certify.
pub struct CertifiedMotion<'a> {
    /// Sample times, strictly increasing.
    pub times: &'a [f64],
    /// Writes `q(t)` and `q̇(t)` for any `t` in `[times[0], times[last]]`.
    pub sample: &'a SampleFn<'a>,
    /// Per joint, a bound of `|q̈|` along the whole motion.
    pub accel_bound: &'a [f64],
}

/// Certification settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CertifyOptions {
    /// Shortest interval bisection goes down to before an interval is left uncertified (s).
    pub min_interval: f64,
    /// First-contact bisection stops below this bracket (s).
    pub time_tolerance: f64,
}

impl Default for CertifyOptions {
    fn default() -> Self {
        Self {
            min_interval: 1e-7,
            time_tolerance: 1e-6,
        }
    }
}

/// The exact minimum distance over the samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SampleMin {
    /// Sample time (s).
    pub time: f64,
    /// The pair, its signed distance and witness points.
    pub pair: PairDistance,
    /// The configuration there.
    pub q: Vec<f64>,
}

/// A certified lower bound of a pair's distance over a span of the curve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ClearanceBound {
    /// The bound (m).
    pub distance: f64,
    /// The span (s): the half-intervals around the sample it comes from.
    pub from: f64,
    /// End of the span (s).
    pub to: f64,
    /// The pair: the first body.
    pub a: Body,
    /// The second body.
    pub b: Body,
}

/// What [`Certifier::certify`] proved.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Certificate {
    /// Every pair proven apart (distance above the margin) at every instant.
    pub collision_free: bool,
    /// The first collision, bisected to the time tolerance.
    pub first_collision: Option<TrajectoryCollision>,
    /// An interval `(from, to)` that could not be proven at the smallest size, and its pair.
    pub uncertified: Option<(f64, f64, Body, Body)>,
    /// Sample intervals covered.
    pub intervals: usize,
    /// Midpoints added by bisection.
    pub subdivisions: usize,
    /// Configurations placed (samples, midpoints, first-contact bisection).
    pub configurations: usize,
    /// Pair distance evaluations per level.
    pub evaluations: Evaluations,
    /// Exact smallest environment distance over the samples.
    pub min_environment: Option<SampleMin>,
    /// Exact smallest self distance over the samples.
    pub min_self: Option<SampleMin>,
    /// Certified lower bound of the environment clearance along the curve.
    pub clearance_environment: Option<ClearanceBound>,
    /// Certified lower bound of the self clearance along the curve.
    pub clearance_self: Option<ClearanceBound>,
}

/// The sampled motion and its per-half-interval path-length bounds.
pub(super) struct Work<'m> {
    pub(super) motion: &'m CertifiedMotion<'m>,
    pub(super) n: usize,
    pub(super) nv: usize,
    pub(super) nobj: usize,
    /// `n × nv` joint velocities at the samples.
    pub(super) qds: Vec<f64>,
    /// `n × nv` configurations.
    pub(super) qs: Vec<f64>,
    /// `(2n − 1) × nv`: cumulative path-length bounds at the half-points (samples at even
    /// indices, interval midpoints at odd ones).
    pub(super) cum: Vec<f64>,
    /// `n × nobj` shape poses at the samples.
    pub(super) poses: Vec<Pose>,
    /// Per bisection depth, `q` and `q̇` (2 nv each).
    pub(super) pool: Vec<f64>,
    pub(super) scratch: Scratch,
    /// Per pair, the last separating direction of its hulls (GJK's warm start).
    pub(super) hints: Vec<Vector>,
    pub(super) ev: Evaluations,
    pub(super) configurations: usize,
    pub(super) subdivisions: usize,
}

/// The best known lower bound of a (sample, pair) distance, the level it was worked to,
/// and whether it is the exact distance.
#[derive(Clone, Copy)]
pub(super) struct Known {
    pub(super) value: f64,
    pub(super) level: Level,
    pub(super) exact: bool,
}

/// One pair's outcome.
enum Outcome {
    Proven,
    /// Proven free before `.0`, in collision at `.1`.
    Hit(f64, f64),
    /// Not provable on `(.0, .1)`.
    Open(f64, f64),
}

const MAX_DEPTH: usize = 64;

impl Work<'_> {
    pub(super) fn half_time(&self, x: usize) -> f64 {
        let t = self.motion.times;
        if x.is_multiple_of(2) {
            t[x / 2]
        } else {
            0.5 * (t[x / 2] + t[x / 2 + 1])
        }
    }

    /// The motion of pair `p` between half-points `a ≤ b`.
    pub(super) fn span(&self, c: &Certifier, p: usize, a: usize, b: usize) -> f64 {
        let (ca, cb) = (
            &self.cum[a * self.nv..(a + 1) * self.nv],
            &self.cum[b * self.nv..(b + 1) * self.nv],
        );
        c.motion(p, ca.iter().zip(cb).map(|(x, y)| y - x))
    }

    pub(super) fn pose(&self, k: usize, o: u32) -> &Pose {
        &self.poses[k * self.nobj + o as usize]
    }
}

impl Certifier {
    /// Certifies `motion` (see the module docs) with the scene `cm` this certifier was
    /// built from.
    pub fn certify(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        motion: &CertifiedMotion,
        opts: &CertifyOptions,
    ) -> Result<Certificate, CollisionError> {
        let (mut w, mut known) = self.start(cm, model, cd, motion, opts)?;
        let mut hit: Option<(f64, f64)> = None;
        let mut open = None;
        for p in 0..self.pairs.len() {
            match self.march(cm, model, cd, &mut w, &mut known, p, opts) {
                Outcome::Proven => {}
                Outcome::Hit(free, t) => {
                    let (f0, t0) = hit.unwrap_or((free, t));
                    hit = Some((f0.min(free), t0.min(t)));
                }
                Outcome::Open(a, b) => {
                    if open.is_none() {
                        let [i, j] = self.pairs[p].map(|k| cm.objects[k as usize].owner);
                        open = Some((a, b, i, j));
                    }
                }
            }
        }
        let first_collision =
            hit.map(|(free, t)| self.locate(cm, model, cd, &mut w, free, t, opts));
        let (min_self, clearance_self) = self.minima(cm, &mut w, &mut known, true);
        let (min_environment, clearance_environment) = self.minima(cm, &mut w, &mut known, false);
        Ok(Certificate {
            collision_free: first_collision.is_none() && open.is_none(),
            first_collision,
            uncertified: open,
            intervals: w.n - 1,
            subdivisions: w.subdivisions,
            configurations: w.configurations,
            evaluations: w.ev,
            min_environment,
            min_self,
            clearance_environment,
            clearance_self,
        })
    }

    /// The motion checked and sampled, and the bounding-ball bounds at its samples.
    fn start<'m>(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        motion: &'m CertifiedMotion<'m>,
        opts: &CertifyOptions,
    ) -> Result<(Work<'m>, Vec<Known>), CollisionError> {
        check(model, motion, opts)?;
        let mut w = sample_motion(cm, model, cd, motion);
        w.hints = vec![Vector::ZERO; self.pairs.len()];
        let known = self.ball_bounds(cm, &mut w);
        Ok((w, known))
    }

    /// Conservative advancement of pair `p` over the samples (see the module docs).
    #[allow(clippy::too_many_arguments)]
    fn march(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        w: &mut Work,
        known: &mut [Known],
        p: usize,
        opts: &CertifyOptions,
    ) -> Outcome {
        let margin = cm.margin;
        let [i, j] = self.pairs[p];
        let last = 2 * (w.n - 1);
        let (mut covered, mut k) = (0usize, 0usize);
        loop {
            let hk = 2 * k;
            let back = w.span(self, p, covered, hk);
            let fwd = if hk < last {
                w.span(self, p, hk, hk + 1)
            } else {
                0.0
            };
            let need = margin + back.max(fwd);
            let (pa, pb) = (*w.pose(k, i), *w.pose(k, j));
            let (lb, level, exact) = self.lower_bound(
                cm,
                p,
                &pa,
                &pb,
                need,
                Level::Exact,
                &mut w.hints[p],
                &mut w.scratch,
                &mut w.ev,
            );
            let slot = &mut known[k * self.pairs.len() + p];
            if exact || (level > slot.level && lb >= slot.value) {
                *slot = Known {
                    value: lb,
                    level,
                    exact,
                };
            }
            if exact && lb <= margin {
                return Outcome::Hit(w.half_time(covered), w.half_time(hk));
            }
            if lb > need {
                if hk == last {
                    return Outcome::Proven;
                }
                let budget = lb - margin;
                let mut x = hk + 1;
                while x < last && w.span(self, p, hk, x + 1) < budget {
                    x += 1;
                }
                if x >= last {
                    return Outcome::Proven;
                }
                covered = x;
                k = x.div_ceil(2);
                continue;
            }
            // The exact distances at the samples do not reach: bisect the open intervals.
            let m1 = if hk < last { k } else { k - 1 };
            for m in covered / 2..=m1 {
                match self.prove_interval(cm, model, cd, w, p, m, opts) {
                    Outcome::Proven => {}
                    other => return other,
                }
            }
            covered = 2 * (m1 + 1);
            if covered >= last {
                return Outcome::Proven;
            }
            k = m1 + 1;
        }
    }

    /// Proves sample interval `m` of pair `p` by bisection.
    #[allow(clippy::too_many_arguments)]
    fn prove_interval(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        w: &mut Work,
        p: usize,
        m: usize,
        opts: &CertifyOptions,
    ) -> Outcome {
        let nv = w.nv;
        let [i, j] = self.pairs[p];
        let t = w.motion.times;
        let mut ends = [(0.0, false); 2];
        for (e, k) in ends.iter_mut().zip([m, m + 1]) {
            let (pa, pb) = (*w.pose(k, i), *w.pose(k, j));
            let (d, _, exact) = self.lower_bound(
                cm,
                p,
                &pa,
                &pb,
                f64::INFINITY,
                Level::Exact,
                &mut w.hints[p],
                &mut w.scratch,
                &mut w.ev,
            );
            *e = (d, exact);
        }
        // Pool slots 0 and 1 (q, then q̇, nv each) hold the ends' velocities.
        w.pool[nv..2 * nv].copy_from_slice(&w.qds[m * nv..(m + 1) * nv]);
        w.pool[3 * nv..4 * nv].copy_from_slice(&w.qds[(m + 1) * nv..(m + 2) * nv]);
        let mut proven = t[m];
        self.bisect(
            cm,
            model,
            cd,
            w,
            p,
            (t[m], ends[0], 0),
            (t[m + 1], ends[1], 1),
            &mut proven,
            opts,
        )
    }

    /// Bisection of `[a, b]` for pair `p`: `a`, `b` are `(time, (bound, exact), pool slot
    /// of q̇)`; `proven` is the time up to which everything is proven.
    #[allow(clippy::too_many_arguments)]
    fn bisect(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        w: &mut Work,
        p: usize,
        a: (f64, (f64, bool), usize),
        b: (f64, (f64, bool), usize),
        proven: &mut f64,
        opts: &CertifyOptions,
    ) -> Outcome {
        let (nv, margin) = (w.nv, cm.margin);
        let (ta, (da, ea), sa) = a;
        let (tb, (db, eb), sb) = b;
        if ea && da <= margin {
            return Outcome::Hit(*proven, ta);
        }
        let h = tb - ta;
        let half = |s: usize, w: &Work| {
            let qd = &w.pool[(2 * s + 1) * nv..(2 * s + 2) * nv];
            self.motion(
                p,
                qd.iter()
                    .zip(w.motion.accel_bound)
                    .map(|(v, acc)| half_path_bound(*v, *acc, h)),
            )
        };
        let (wa, wb) = (half(sa, w), half(sb, w));
        if da - wa > margin && db - wb > margin {
            *proven = tb;
            return Outcome::Proven;
        }
        if eb && db <= margin && h <= opts.time_tolerance {
            return Outcome::Hit(*proven, tb);
        }
        let slot = sa.max(sb) + 1;
        if h < opts.min_interval || slot >= MAX_DEPTH {
            return Outcome::Open(ta, tb);
        }
        let tm = 0.5 * (ta + tb);
        let dm = {
            let (q, qd) = w.pool[2 * slot * nv..(2 * slot + 2) * nv].split_at_mut(nv);
            (w.motion.sample)(tm, q, qd);
            let [i, j] = self.pairs[p];
            crate::kinematics::forward_kinematics(model, &mut cd.kin, q);
            let pose = |k: u32| {
                let o = &cm.objects[k as usize];
                if o.body == WORLD {
                    cd.poses[k as usize]
                } else {
                    to_pose(&cd.kin.o_m_i[o.body].mul(&o.local))
                }
            };
            let (pa, pb) = (pose(i), pose(j));
            w.configurations += 1;
            w.subdivisions += 1;
            let need = margin + wa.max(wb) / 2.0;
            let (d, _, exact) = self.lower_bound(
                cm,
                p,
                &pa,
                &pb,
                need,
                Level::Exact,
                &mut w.hints[p],
                &mut w.scratch,
                &mut w.ev,
            );
            (d, exact)
        };
        match self.bisect(cm, model, cd, w, p, a, (tm, dm, slot), proven, opts) {
            Outcome::Proven => {}
            other => return other,
        }
        self.bisect(cm, model, cd, w, p, (tm, dm, slot), b, proven, opts)
    }

    /// The first contact in `(free, hit]`, bisected with the exact check of every pair.
    #[allow(clippy::too_many_arguments)]
    fn locate(
        &self,
        cm: &CollisionModel,
        model: &Model,
        cd: &mut CollisionData,
        w: &mut Work,
        free: f64,
        hit: f64,
        opts: &CertifyOptions,
    ) -> TrajectoryCollision {
        let nv = w.nv;
        let mut q = vec![0.0; nv];
        let mut qd = vec![0.0; nv];
        let (mut lo, mut hi) = (free, hit);
        let first = free <= w.motion.times[0];
        (w.motion.sample)(lo, &mut q, &mut qd);
        let lo_hits = cm.in_collision(model, cd, &q, self.scope);
        w.configurations += 1;
        if lo_hits {
            hi = lo;
        }
        while hi - lo > opts.time_tolerance {
            let mid = 0.5 * (lo + hi);
            (w.motion.sample)(mid, &mut q, &mut qd);
            w.configurations += 1;
            if cm.in_collision(model, cd, &q, self.scope) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        (w.motion.sample)(hi, &mut q, &mut qd);
        cm.update(model, cd, &q);
        let mut pairs = Vec::new();
        cm.collisions(cd, self.scope, &mut pairs);
        let names = pairs.first().map_or((String::new(), String::new()), |p| {
            (cm.body_name(p.a).to_string(), cm.body_name(p.b).to_string())
        });
        let times = w.motion.times;
        TrajectoryCollision {
            time: hi,
            last_free: (!(first && lo_hits)).then_some(lo),
            sample: times.partition_point(|&t| t < hi),
            names,
            pairs,
            q,
        }
    }
}

/// Samples the motion: configurations, velocities, shape poses and the cumulative
/// half-interval path-length bounds of the module docs.
fn sample_motion<'m>(
    cm: &CollisionModel,
    model: &Model,
    cd: &mut CollisionData,
    motion: &'m CertifiedMotion<'m>,
) -> Work<'m> {
    let (n, nv, nobj) = (motion.times.len(), model.nv, cm.objects.len());
    let mut qs = vec![0.0; n * nv];
    let mut qds = vec![0.0; n * nv];
    let mut poses = Vec::with_capacity(n * nobj);
    for k in 0..n {
        let (q, qd) = (
            &mut qs[k * nv..(k + 1) * nv],
            &mut qds[k * nv..(k + 1) * nv],
        );
        (motion.sample)(motion.times[k], q, qd);
        cm.update(model, cd, q);
        poses.extend_from_slice(&cd.poses);
    }
    let mut cum = vec![0.0; (2 * n - 1) * nv];
    for k in 0..n - 1 {
        let h = motion.times[k + 1] - motion.times[k];
        for j in 0..nv {
            let acc = motion.accel_bound[j];
            let x = 2 * k * nv + j;
            cum[x + nv] = cum[x] + half_path_bound(qds[k * nv + j], acc, h);
            cum[x + 2 * nv] = cum[x + nv] + half_path_bound(qds[(k + 1) * nv + j], acc, h);
        }
    }
    Work {
        motion,
        n,
        nv,
        nobj,
        qds,
        qs,
        cum,
        poses,
        pool: vec![0.0; 2 * MAX_DEPTH * nv],
        scratch: Scratch::default(),
        hints: Vec::new(),
        ev: Evaluations::default(),
        configurations: n,
        subdivisions: 0,
    }
}

/// Times strictly increasing and finite, bounds of the model's size, valid options.
fn check(model: &Model, m: &CertifiedMotion, opts: &CertifyOptions) -> Result<(), CollisionError> {
    let bad = |m: String| Err(CollisionError::Trajectory(m));
    if m.times.is_empty() {
        return bad("no sample times".into());
    }
    if m.times.iter().any(|t| !t.is_finite()) || m.times.windows(2).any(|w| w[1] <= w[0]) {
        return bad("sample times must be finite and strictly increasing".into());
    }
    if m.accel_bound.len() != model.nv
        || m.accel_bound.iter().any(|a| !(a.is_finite() && *a >= 0.0))
    {
        return bad(format!(
            "the acceleration bound needs {} finite values >= 0",
            model.nv
        ));
    }
    if !(opts.min_interval > 0.0 && opts.time_tolerance > 0.0) {
        return bad("min_interval and time_tolerance must be positive".into());
    }
    Ok(())
}
