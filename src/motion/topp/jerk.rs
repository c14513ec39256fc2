//! Jerk limits on top of the time-optimal motion: smooth `s(t)` by a moving average in
//! time, then slow down uniformly until a dense check of every limit passes.
//!
//! The optimum of the discretised problem has `s̈` constant per interval, so `q⃛` is
//! unbounded at the knots. With `s(t)` that optimum (extended by `s = 0` before the start
//! and `s = 1` after the end) and a window `w`, the smoothed time law is the moving
//! average
//!
//! `σ(u) = (1/w) ∫_{u−w}^{u} s(τ) dτ`,  `u ∈ [0, T + w]`,
//!
//! so that `σ̇(u) = (s(u) − s(u−w))/w`, `σ̈(u) = (ṡ(u) − ṡ(u−w))/w` and
//! `σ⃛(u) = (s̈(u) − s̈(u−w))/w`: `σ` is `C²` with a bounded, piecewise constant `σ⃛`
//! (jumps at the knots `t_i` and at `t_i + w`), goes from 0 to 1 monotonically, and starts
//! and ends at rest (`σ̇ = σ̈ = 0`). Along the path,
//!
//! `q̇ = q' σ̇`, `q̈ = q' σ̈ + q'' σ̇²`, `q⃛ = q' σ⃛ + 3 q'' σ̇ σ̈ + q''' σ̇³`.
//!
//! Then a uniform slow-down `t = k u` divides `q̇`, `q̈`, `q⃛` by `k`, `k²`, `k³` exactly, so
//! with `r_v`, `r_a`, `r_j` the largest ratios of the smoothed motion to the limits,
//! `k = max(1, r_v, √r_a, ∛r_j)` meets the velocity, acceleration and jerk limits (the
//! torque limits are checked and `k` raised until they hold too). The duration is
//! `k (T + w)`; the window `w` is chosen to minimise it (a scan over `log w`, then a
//! golden-section search). As the jerk limit grows the best window shrinks and the
//! duration tends to the time-optimal `T`.
//!
//! Guarantees. The returned motion is checked with the exact dynamics (friction
//! included) on every piece between consecutive breakpoints (`t_i` and `t_i + w`, where
//! `σ⃛` jumps; in between everything is smooth) at `K + 2` points, with near-active maxima
//! (within 1 % of their limit) refined by golden-section search: the same standard as
//! the check of the time-optimal motion. It is **not** time-optimal under the jerk limit:
//! the slow-down is uniform, so one sharp corner of the path slows the whole motion down.
//! A local slow-down (or a third-order TOPP) would be faster.

use crate::dynamics::{inverse_dynamics, Effects};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::joint_limits::JointLimits;
use crate::motion::motion_traits::Path;
use crate::motion::topp::topp_options::ToppOptions;
use crate::motion::topp::topp_trajectory::{Smoothing, ToppTrajectory};
use crate::motion::trajectory_error::TrajectoryError;

/// Windows scanned (log-spaced, as fractions of the duration) before the refinement.
const SCAN: usize = 12;
/// Golden-section steps on `log w` after the scan.
const GOLDEN_STEPS: usize = 14;
/// Rounds of raising `k` after a failed final check.
const MAX_RAISE: usize = 30;

/// Buffers of the dense check of a smoothed motion.
struct Eval {
    data: Data,
    q: Vec<f64>,
    dq: Vec<f64>,
    ddq: Vec<f64>,
    dddq: Vec<f64>,
    /// Unscaled `q̇`, `q̈`, `q⃛` (kinds 0–2), then the torque at the scaled motion (kind 3).
    val: [Vec<f64>; 4],
    /// Sampled ratios of one piece: `(point, kind, joint)`.
    piece: Vec<f64>,
}

/// The limits of one check: per kind, the limit and the power of `k` it scales with.
struct Limits<'a> {
    lim: [&'a [f64]; 4],
    k: f64,
    torque: bool,
}

impl Limits<'_> {
    fn ratio(&self, ev: &Eval, kind: usize, j: usize) -> f64 {
        let scale = match kind {
            0 => self.k,
            1 => self.k * self.k,
            2 => self.k * self.k * self.k,
            _ => 1.0,
        };
        ev.val[kind][j].abs() / scale / self.lim[kind][j]
    }
}

impl Eval {
    fn new(model: &Model, n: usize) -> Self {
        Eval {
            data: Data::new(model),
            q: vec![0.0; n],
            dq: vec![0.0; n],
            ddq: vec![0.0; n],
            dddq: vec![0.0; n],
            val: std::array::from_fn(|_| vec![0.0; n]),
            piece: Vec::new(),
        }
    }

    /// The motion at smoothed time `u`; the torque of the motion slowed down by `k`.
    fn at<P: Path>(
        &mut self,
        tr: &ToppTrajectory<P>,
        sm: &Smoothing,
        u: f64,
        dynamics: Option<(&Model, &Effects, f64)>,
    ) {
        let [sg, sd, sdd, sddd] = tr.smoothed(sm, u);
        tr.path
            .eval3(sg, &mut self.q, &mut self.dq, &mut self.ddq, &mut self.dddq);
        let [v, a, j, t] = &mut self.val;
        for k in 0..self.q.len() {
            let (d1, d2, d3) = (self.dq[k], self.ddq[k], self.dddq[k]);
            v[k] = d1 * sd;
            a[k] = d1 * sdd + d2 * sd * sd;
            j[k] = d1 * sddd + 3.0 * d2 * sd * sdd + d3 * sd * sd * sd;
        }
        if let Some((model, effects, k)) = dynamics {
            for x in v.iter_mut() {
                *x /= k;
            }
            for x in a.iter_mut() {
                *x /= k * k;
            }
            let tau = inverse_dynamics(model, &mut self.data, effects, &self.q, &v[..], &a[..]);
            t.copy_from_slice(tau);
            for x in v.iter_mut() {
                *x *= k;
            }
            for x in a.iter_mut() {
                *x *= k * k;
            }
        }
    }
}

/// Largest ratio of each kind (velocity, acceleration, jerk, torque) over the smoothed
/// motion slowed down by `lims.k`: `pts` points on every piece between breakpoints, and,
/// with `refine`, golden-section search at the near-active maxima.
fn scan<P: Path>(
    tr: &ToppTrajectory<P>,
    sm: &Smoothing,
    ev: &mut Eval,
    lims: &Limits,
    dynamics: (&Model, &Effects),
    pts: usize,
    refine: bool,
) -> [f64; 4] {
    let n = tr.n;
    let kinds = if lims.torque { 4 } else { 3 };
    let dyn_k = lims.torque.then_some((dynamics.0, dynamics.1, lims.k));
    let mut ratio = [0.0f64; 4];
    let mut piece = std::mem::take(&mut ev.piece);
    piece.resize(pts * 4 * n, 0.0);
    let end = sm.span();
    // Breakpoints: the knots t_i and t_i + w, merged.
    let (mut i0, mut i1) = (0, 0);
    let mut u0 = 0.0;
    while u0 < end {
        let next0 = tr.t.get(i0).copied().unwrap_or(f64::INFINITY);
        let next1 = tr.t.get(i1).map_or(f64::INFINITY, |t| t + sm.w);
        let u1 = next0.min(next1).min(end);
        if next0 <= u1 {
            i0 += 1;
        }
        if next1 <= u1 {
            i1 += 1;
        }
        if u1 <= u0 {
            continue;
        }
        let at = |p: usize| {
            let th = (p as f64 / (pts - 1) as f64).clamp(1e-9, 1.0 - 1e-9);
            u0 + th * (u1 - u0)
        };
        for p in 0..pts {
            ev.at(tr, sm, at(p), dyn_k);
            for kind in 0..kinds {
                for j in 0..n {
                    piece[(p * 4 + kind) * n + j] = lims.ratio(ev, kind, j);
                }
            }
        }
        for kind in 0..kinds {
            for j in 0..n {
                let (mut pb, mut best) = (0, f64::NEG_INFINITY);
                for p in 0..pts {
                    let r = piece[(p * 4 + kind) * n + j];
                    if r > best {
                        (pb, best) = (p, r);
                    }
                }
                if refine && best >= 0.99 {
                    let (lo, hi) = (at(pb.saturating_sub(1)), at((pb + 1).min(pts - 1)));
                    let dk = (kind == 3).then_some(dyn_k).flatten();
                    let f = |ev: &mut Eval, u: f64| {
                        ev.at(tr, sm, u, dk);
                        lims.ratio(ev, kind, j)
                    };
                    best = best.max(golden_max(ev, f, lo, hi));
                }
                ratio[kind] = ratio[kind].max(best);
            }
        }
        u0 = u1;
    }
    ev.piece = piece;
    ratio
}

/// The maximum of `f` on `[lo, hi]` by golden-section search (30 steps, as in `check.rs`).
fn golden_max(ev: &mut Eval, f: impl Fn(&mut Eval, f64) -> f64, lo: f64, hi: f64) -> f64 {
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut lo, mut hi) = (lo, hi);
    let (mut x1, mut x2) = (hi - R * (hi - lo), lo + R * (hi - lo));
    let (mut f1, mut f2) = (f(ev, x1), f(ev, x2));
    for _ in 0..30 {
        if f1 > f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - R * (hi - lo);
            f1 = f(ev, x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + R * (hi - lo);
            f2 = f(ev, x2);
        }
    }
    f1.max(f2)
}

/// Smooths and slows down `tr` until it meets `jerk` and all the other limits (see the
/// module docs); records the figures in its stats.
pub(super) fn limit_jerk<P: Path>(
    model: &Model,
    effects: &Effects,
    limits: &JointLimits,
    jerk: &[f64],
    opts: &ToppOptions,
    tr: &mut ToppTrajectory<P>,
) -> Result<(), TrajectoryError> {
    let big_t = tr.t[tr.t.len() - 1];
    let mut sm = Smoothing {
        w: big_t,
        k: 1.0,
        t_opt: big_t,
        big_s: tr.knot_integrals(),
    };
    let mut ev = Eval::new(model, tr.n);
    let pts = opts.check_points + 2;
    let unit = Limits {
        lim: [
            &limits.velocity[..],
            &limits.acceleration[..],
            jerk,
            &limits.effort[..],
        ],
        k: 1.0,
        torque: false,
    };
    // The slow-down that the kinematic limits need with window `w`, and the duration.
    let mut cost = |w: f64| {
        sm.w = w;
        let r = scan(tr, &sm, &mut ev, &unit, (model, effects), pts, false);
        let k = 1f64.max(r[0]).max(r[1].sqrt()).max(r[2].cbrt());
        (k * (big_t + w), k)
    };
    // Scan log w over [1e-4 T, T], then golden-section around the best.
    let lw = |x: usize| (big_t * 1e-4).ln() + (x as f64 / (SCAN - 1) as f64) * 1e4f64.ln();
    let (mut best_x, mut best_d) = (0, f64::INFINITY);
    for x in 0..SCAN {
        let (d, _) = cost(lw(x).exp());
        if d < best_d {
            (best_x, best_d) = (x, d);
        }
    }
    let (mut lo, mut hi) = (lw(best_x.saturating_sub(1)), lw((best_x + 1).min(SCAN - 1)));
    const R: f64 = 0.618_033_988_749_894_9;
    for _ in 0..GOLDEN_STEPS {
        let (x1, x2) = (hi - R * (hi - lo), lo + R * (hi - lo));
        if cost(x1.exp()).0 < cost(x2.exp()).0 {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    let w = (0.5 * (lo + hi)).exp();
    let (_, k) = cost(w);
    sm.w = w;
    sm.k = k * (1.0 + 1e-9);
    verify_raise(model, effects, limits, jerk, opts, tr, sm, &mut ev)
}

/// The final dense check with the exact dynamics; raises `k` until it passes.
#[allow(clippy::too_many_arguments)]
fn verify_raise<P: Path>(
    model: &Model,
    effects: &Effects,
    limits: &JointLimits,
    jerk: &[f64],
    opts: &ToppOptions,
    tr: &mut ToppTrajectory<P>,
    mut sm: Smoothing,
    ev: &mut Eval,
) -> Result<(), TrajectoryError> {
    let torque = limits.effort.iter().any(|e| e.is_finite());
    let pts = opts.check_points + 2;
    for _ in 0..MAX_RAISE {
        let lims = Limits {
            lim: [
                &limits.velocity[..],
                &limits.acceleration[..],
                jerk,
                &limits.effort[..],
            ],
            k: sm.k,
            torque,
        };
        let r = scan(tr, &sm, ev, &lims, (model, effects), pts, true);
        let worst = r.iter().copied().fold(0.0, f64::max);
        if worst <= 1.0 + opts.tolerance {
            let st = &mut tr.stats;
            st.max_velocity_ratio = r[0];
            st.max_acceleration_ratio = r[1];
            st.max_jerk_ratio = r[2];
            st.max_torque_ratio = r[3];
            st.jerk_window_s = sm.w;
            st.jerk_slowdown = sm.k;
            st.duration = sm.k * sm.span();
            tr.smooth = Some(sm);
            return Ok(());
        }
        // Velocity, acceleration, jerk scale by k, k², k³; torque roughly like k².
        let raise = r[0]
            .max(r[1].sqrt())
            .max(r[2].cbrt())
            .max(r[3].sqrt())
            .max(1.0 + 1e-6);
        sm.k *= raise * (1.0 + 1e-9);
    }
    Err(TrajectoryError::Topp(format!(
        "the jerk-limited motion still exceeds a limit after slowing it down {:.3} times",
        sm.k
    )))
}
