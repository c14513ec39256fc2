//! The time-optimal motion [`ToppTrajectory`]: the profile on the grid, the jerk
//! smoothing applied on top of it ([`Smoothing`], chosen in `jerk.rs`), and their sampling.

use crate::motion::motion_traits::{Path, Trajectory};
use crate::motion::topp::topp_options::ToppStats;

/// A time-optimal motion along a path: the path, the grid `s_i`, `b_i = ṡ_i²`, `a_i = s̈`
/// on each interval, and the knot times `t_i`; with a jerk limit, the smoothing of
/// `s(t)` applied on top (see `jerk.rs`).
#[derive(Clone, Debug)]
pub struct ToppTrajectory<P> {
    pub(super) path: P,
    pub(super) n: usize,
    pub(super) s: Vec<f64>,
    pub(super) b: Vec<f64>,
    pub(super) a: Vec<f64>,
    pub(super) t: Vec<f64>,
    pub(super) smooth: Option<Smoothing>,
    pub(super) stats: ToppStats,
}

impl<P> ToppTrajectory<P> {
    /// The path.
    pub fn path(&self) -> &P {
        &self.path
    }

    /// Solve figures.
    pub fn stats(&self) -> &ToppStats {
        &self.stats
    }

    /// Grid `s_i`, path speeds `ṡ_i`, and times `t_i` at the knots of the time-optimal
    /// profile (before any jerk smoothing).
    pub fn profile(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        (
            self.s.clone(),
            self.b.iter().map(|b| b.sqrt()).collect(),
            self.t.clone(),
        )
    }
}

/// The moving-average window and slow-down applied to a time-optimal profile.
#[derive(Clone, Debug)]
pub(super) struct Smoothing {
    /// Window `w` (s, in the time of the unscaled optimum).
    pub(super) w: f64,
    /// Uniform slow-down `k ≥ 1`.
    pub(super) k: f64,
    /// Duration `T` of the unsmoothed optimum.
    pub(super) t_opt: f64,
    /// `S(t_i) = ∫_0^{t_i} s dt` at the knots.
    pub(super) big_s: Vec<f64>,
}

impl Smoothing {
    /// Duration of the smoothed motion before the slow-down, `T + w`.
    pub(super) fn span(&self) -> f64 {
        self.t_opt + self.w
    }
}

impl<P> ToppTrajectory<P> {
    /// `(s, ṡ, s̈)` of the unsmoothed optimum at time `u` (rest outside `[0, T]`).
    fn base(&self, u: f64) -> [f64; 3] {
        let end = *self.t.last().expect("non-empty");
        if u <= 0.0 {
            return [self.s[0], 0.0, 0.0];
        }
        if u >= end {
            return [*self.s.last().expect("non-empty"), 0.0, 0.0];
        }
        let (i, tau) = crate::motion::waypoints::locate(&self.t, u);
        let sd0 = self.b[i].sqrt();
        let a = self.a[i];
        let s = (self.s[i] + sd0 * tau + 0.5 * a * tau * tau).clamp(self.s[i], self.s[i + 1]);
        [s, (sd0 + a * tau).max(0.0), a]
    }

    /// `∫_0^u s dt` of the unsmoothed optimum.
    fn integral(&self, big_s: &[f64], u: f64) -> f64 {
        let end = *self.t.last().expect("non-empty");
        if u <= 0.0 {
            return 0.0;
        }
        if u >= end {
            return big_s[big_s.len() - 1] + (u - end) * self.s[self.s.len() - 1];
        }
        let (i, tau) = crate::motion::waypoints::locate(&self.t, u);
        let sd0 = self.b[i].sqrt();
        big_s[i] + tau * (self.s[i] + tau * (0.5 * sd0 + tau * self.a[i] / 6.0))
    }

    /// `(σ, σ̇, σ̈, σ⃛)` of the smoothed (unscaled) time law at `u`.
    pub(super) fn smoothed(&self, sm: &Smoothing, u: f64) -> [f64; 4] {
        let w = sm.w;
        let (x1, x0) = (self.base(u), self.base(u - w));
        let sigma = (self.integral(&sm.big_s, u) - self.integral(&sm.big_s, u - w)) / w;
        [
            sigma.clamp(0.0, 1.0),
            ((x1[0] - x0[0]) / w).max(0.0),
            (x1[1] - x0[1]) / w,
            (x1[2] - x0[2]) / w,
        ]
    }

    /// `S(t_i) = ∫_0^{t_i} s dt` at the knots of the unsmoothed optimum.
    pub(super) fn knot_integrals(&self) -> Vec<f64> {
        let mut big_s = vec![0.0; self.t.len()];
        for i in 0..self.a.len() {
            let h = self.t[i + 1] - self.t[i];
            let sd0 = self.b[i].sqrt();
            big_s[i + 1] = big_s[i] + h * (self.s[i] + h * (0.5 * sd0 + h * self.a[i] / 6.0));
        }
        big_s
    }
}

impl<P: Path> ToppTrajectory<P> {
    /// `q`, `q̇`, `q̈` and the jerk `q⃛` at `t`. Without a jerk limit the time-optimal
    /// motion's `s̈` jumps at the knots: the jerk given there is the one inside the
    /// interval holding `t` (`3 q'' ṡ s̈ + q''' ṡ³`), excluding the jumps.
    pub fn sample_jerk(
        &self,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
        qdd: &mut [f64],
        qddd: &mut [f64],
    ) {
        let [sg, sd, sdd, sddd] = match &self.smooth {
            Some(sm) => {
                let [sg, sd, sdd, sddd] = self.smoothed(sm, (t / sm.k).clamp(0.0, sm.span()));
                let k = sm.k;
                [sg, sd / k, sdd / (k * k), sddd / (k * k * k)]
            }
            None => {
                let end = *self.t.last().unwrap_or(&0.0);
                if t <= 0.0 || t >= end {
                    let s = if t <= 0.0 {
                        self.s[0]
                    } else {
                        self.s[self.s.len() - 1]
                    };
                    [s, 0.0, 0.0, 0.0]
                } else {
                    let (i, tau) = crate::motion::waypoints::locate(&self.t, t);
                    let sd0 = self.b[i].sqrt();
                    let a = self.a[i];
                    let s = self.s[i] + sd0 * tau + 0.5 * a * tau * tau;
                    [
                        s.clamp(self.s[i], self.s[i + 1]),
                        (sd0 + a * tau).max(0.0),
                        a,
                        0.0,
                    ]
                }
            }
        };
        self.path.eval3(sg, q, qd, qdd, qddd);
        for j in 0..self.n {
            let (d1, d2, d3) = (qd[j], qdd[j], qddd[j]);
            qd[j] = d1 * sd;
            qdd[j] = d1 * sdd + d2 * sd * sd;
            qddd[j] = d1 * sddd + 3.0 * d2 * sd * sdd + d3 * sd * sd * sd;
        }
    }
}

impl<P: Path> Trajectory for ToppTrajectory<P> {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        match &self.smooth {
            Some(sm) => sm.k * sm.span(),
            None => *self.t.last().unwrap(),
        }
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        if let Some(sm) = &self.smooth {
            let [sg, sd, sdd, _] = self.smoothed(sm, (t / sm.k).clamp(0.0, sm.span()));
            self.path.eval(sg, q, qd, qdd);
            let (v, a) = (sd / sm.k, sdd / (sm.k * sm.k));
            for j in 0..self.n {
                qdd[j] = qd[j] * a + qdd[j] * v * v;
                qd[j] *= v;
            }
            return;
        }
        let end = *self.t.last().unwrap_or(&0.0);
        if t < 0.0 || t > end {
            // Held at an end point, at rest (the last interval's deceleration `q' s̈` is
            // one-sided: it must not persist after the end).
            self.sample(t.clamp(0.0, end), q, qd, qdd);
            qd.fill(0.0);
            qdd.fill(0.0);
            return;
        }
        let (i, tau) = crate::motion::waypoints::locate(&self.t, t);
        let sd0 = self.b[i].sqrt();
        let a = self.a[i];
        let s = (self.s[i] + sd0 * tau + 0.5 * a * tau * tau).clamp(self.s[i], self.s[i + 1]);
        let sd = (sd0 + a * tau).max(0.0);
        self.path.eval(s, q, qd, qdd);
        for j in 0..self.n {
            qdd[j] = qd[j] * a + qdd[j] * sd * sd;
            qd[j] *= sd;
        }
    }
}
