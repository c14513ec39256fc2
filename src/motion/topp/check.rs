//! The dense check of a TOPP solution with the exact dynamics (friction included):
//! velocity, acceleration and torque sampled inside every interval, near-limit maxima
//! refined by golden-section search, and the excess over each limit per interval.

use crate::dynamics::{inverse_dynamics, Effects};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::motion_traits::Path;

/// Dense-check results: per interval and joint, the largest excess over each limit, and
/// the largest ratio of each kind (velocity, acceleration, torque).
pub(super) struct CheckReport {
    pub(super) excess_v: Vec<f64>,
    pub(super) excess_a: Vec<f64>,
    pub(super) excess_t: Vec<f64>,
    pub(super) ratio: [f64; 3],
}

impl CheckReport {
    /// The largest ratio of any kind.
    pub(super) fn worst(&self) -> f64 {
        self.ratio.iter().copied().fold(0.0, f64::max)
    }
}

/// Buffers of the dense check.
pub(super) struct Checker {
    data: Data,
    q: Vec<f64>,
    dq: Vec<f64>,
    ddq: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau: Vec<f64>,
    /// Sampled values of one interval: `(point, kind, joint)`.
    vals: Vec<f64>,
    /// Results of the previous check per interval.
    cache: Cache,
}

/// Per-interval results of the last check: `b` at the knots it was made with, whether it
/// included the torques, the excess per kind and joint, the largest ratio per kind.
#[derive(Default)]
struct Cache {
    b: Vec<f64>,
    torque: Vec<bool>,
    excess: Vec<f64>,
    ratio: Vec<[f64; 3]>,
}

/// Sampled maxima at or above this fraction of their limit are refined by a
/// golden-section search between the neighbouring check points.
const REFINE_FROM: f64 = 0.99;

/// Golden-section steps: the bracket shrinks to `0.618³⁰ ≈ 5e-7` of its width, so the
/// maximum found is below the true one by a relative `~1e-13` (the function is flat to
/// second order there), far inside the check's tolerance.
const GOLDEN_STEPS: usize = 30;

/// The motion on one interval: `s_i`, `Δs`, `b_i`, `a_i`.
#[derive(Clone, Copy)]
struct Interval {
    s: f64,
    ds: f64,
    b: f64,
    a: f64,
}

impl Checker {
    pub(super) fn new(model: &Model, n: usize) -> Self {
        Checker {
            data: Data::new(model),
            q: vec![0.0; n],
            dq: vec![0.0; n],
            ddq: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            tau: vec![0.0; n],
            vals: Vec::new(),
            cache: Cache::default(),
        }
    }

    /// `q̇`, `q̈` (and `τ` when `torque`) at fraction `theta` of the interval.
    #[allow(clippy::too_many_arguments)]
    fn eval_at<P: Path>(
        &mut self,
        model: &Model,
        effects: &Effects,
        path: &P,
        iv: Interval,
        theta: f64,
        torque: bool,
    ) {
        let bi = (iv.b + 2.0 * iv.a * theta * iv.ds).max(0.0);
        let sd = bi.sqrt();
        path.eval(
            iv.s + theta * iv.ds,
            &mut self.q,
            &mut self.dq,
            &mut self.ddq,
        );
        for j in 0..self.q.len() {
            self.qd[j] = self.dq[j] * sd;
            self.qdd[j] = self.dq[j] * iv.a + self.ddq[j] * bi;
        }
        if torque {
            let tau =
                inverse_dynamics(model, &mut self.data, effects, &self.q, &self.qd, &self.qdd);
            self.tau.copy_from_slice(tau);
        }
    }

    /// `|q̇_j|`, `|q̈_j|` or `|τ_j|` (kind 0, 1, 2) of the last evaluation.
    fn value(&self, kind: usize, j: usize) -> f64 {
        match kind {
            0 => self.qd[j].abs(),
            1 => self.qdd[j].abs(),
            _ => self.tau[j].abs(),
        }
    }

    /// Checks every interval at `k + 2` equally spaced points (ends included) and refines
    /// the near-active maxima by golden-section search; the torques only when `torque`
    /// (and some joint has a torque limit). An interval whose `b` at both ends is the same
    /// (to the bit) as at the previous check, checked then with the torques if they are
    /// wanted now, is not evaluated again: its motion is the same, so are its results.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn check<P: Path>(
        &mut self,
        model: &Model,
        effects: &Effects,
        path: &P,
        limits: &crate::motion::joint_limits::JointLimits,
        s: &[f64],
        b: &[f64],
        a: &[f64],
        k: usize,
        torque: bool,
    ) -> CheckReport {
        let n = self.q.len();
        let nn = a.len();
        let mut rep = CheckReport {
            excess_v: vec![0.0; nn * n],
            excess_a: vec![0.0; nn * n],
            excess_t: vec![0.0; nn * n],
            ratio: [0.0; 3],
        };
        let torque = torque && limits.effort.iter().any(|e| e.is_finite());
        let mut cache = std::mem::take(&mut self.cache);
        if cache.b.len() != b.len() {
            cache = Cache {
                b: vec![f64::NAN; nn + 1],
                torque: vec![false; nn],
                excess: vec![0.0; nn * 3 * n],
                ratio: vec![[0.0; 3]; nn],
            };
        }
        let mut vals = std::mem::take(&mut self.vals);
        vals.resize((k + 2) * 3 * n, 0.0);
        let same = |c: &Cache, x: usize| c.b[x].to_bits() == b[x].to_bits();
        for i in 0..nn {
            let unchanged = same(&cache, i) && same(&cache, i + 1);
            if !(unchanged && (cache.torque[i] || !torque)) {
                let iv = Interval {
                    s: s[i],
                    ds: s[i + 1] - s[i],
                    b: b[i],
                    a: a[i],
                };
                // Unchanged but checked without the torques: only those are missing.
                let first = if unchanged { 2 } else { 0 };
                let out = &mut cache.excess[i * 3 * n..(i + 1) * 3 * n];
                let kinds = (first, if torque { 3 } else { 2 });
                let r =
                    self.check_interval(model, effects, path, limits, iv, kinds, &mut vals, out);
                cache.ratio[i][first..].copy_from_slice(&r[first..]);
                cache.torque[i] = torque;
            }
            let ex = &cache.excess[i * 3 * n..(i + 1) * 3 * n];
            rep.excess_v[i * n..(i + 1) * n].copy_from_slice(&ex[..n]);
            rep.excess_a[i * n..(i + 1) * n].copy_from_slice(&ex[n..2 * n]);
            rep.excess_t[i * n..(i + 1) * n].copy_from_slice(&ex[2 * n..]);
            for kind in 0..3 {
                rep.ratio[kind] = rep.ratio[kind].max(cache.ratio[i][kind]);
            }
        }
        cache.b.copy_from_slice(b);
        self.cache = cache;
        self.vals = vals;
        rep
    }

    /// One interval, the kinds `first..kinds` (0 velocity, 1 acceleration, 2 torque): the
    /// excess over each limit per kind and joint into `out` (`3 n`, kind-major; 0 where
    /// within the limit), and the largest ratio per kind.
    #[allow(clippy::too_many_arguments)]
    fn check_interval<P: Path>(
        &mut self,
        model: &Model,
        effects: &Effects,
        path: &P,
        limits: &crate::motion::joint_limits::JointLimits,
        iv: Interval,
        (first, kinds): (usize, usize),
        vals: &mut [f64],
        out: &mut [f64],
    ) -> [f64; 3] {
        let n = self.q.len();
        let np = vals.len() / (3 * n);
        let theta = |p: usize| p as f64 / (np - 1) as f64;
        let mut ratio = [0.0f64; 3];
        out[first * n..].fill(0.0);
        for p in 0..np {
            self.eval_at(model, effects, path, iv, theta(p), kinds == 3);
            for kind in first..kinds {
                for j in 0..n {
                    vals[(p * 3 + kind) * n + j] = self.value(kind, j);
                }
            }
        }
        for kind in first..kinds {
            for j in 0..n {
                let lim = match kind {
                    0 => limits.velocity[j],
                    1 => limits.acceleration[j],
                    _ => limits.effort[j],
                };
                if !lim.is_finite() {
                    continue;
                }
                let (mut pbest, mut best) = (0, f64::NEG_INFINITY);
                for p in 0..np {
                    let v = vals[(p * 3 + kind) * n + j];
                    if v > best {
                        (pbest, best) = (p, v);
                    }
                }
                if best >= REFINE_FROM * lim {
                    let (lo, hi) = (
                        theta(pbest.saturating_sub(1)),
                        theta((pbest + 1).min(np - 1)),
                    );
                    best = best.max(self.golden(model, effects, path, iv, kind, j, lo, hi));
                }
                out[kind * n + j] = out[kind * n + j].max(best - lim);
                ratio[kind] = ratio[kind].max(best / lim);
            }
        }
        ratio
    }

    /// The maximum of `|x_j|` of `kind` on `[lo, hi]` (fractions of the interval) by
    /// golden-section search.
    #[allow(clippy::too_many_arguments)]
    fn golden<P: Path>(
        &mut self,
        model: &Model,
        effects: &Effects,
        path: &P,
        iv: Interval,
        kind: usize,
        j: usize,
        lo: f64,
        hi: f64,
    ) -> f64 {
        const R: f64 = 0.618_033_988_749_894_9;
        let (mut lo, mut hi) = (lo, hi);
        let mut f = |x: f64| {
            self.eval_at(model, effects, path, iv, x, kind == 2);
            self.value(kind, j)
        };
        let mut x1 = hi - R * (hi - lo);
        let mut x2 = lo + R * (hi - lo);
        let (mut f1, mut f2) = (f(x1), f(x2));
        for _ in 0..GOLDEN_STEPS {
            if f1 > f2 {
                hi = x2;
                (x2, f2) = (x1, f1);
                x1 = hi - R * (hi - lo);
                f1 = f(x1);
            } else {
                lo = x1;
                (x1, f1) = (x2, f2);
                x2 = lo + R * (hi - lo);
                f2 = f(x2);
            }
        }
        f1.max(f2)
    }
}
