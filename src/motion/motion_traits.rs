//! The interfaces the motion modules share: a [`Trajectory`] sampled in time, a [`Path`]
//! sampled along its parameter, and the adapters [`TimeScaled`] (uniform slow-down) and
//! [`AsReference`] (a trajectory as the simulator's reference).

use crate::motion::trajectory_error::TrajectoryError;

/// A motion sampled in time. `t` outside `[0, duration]` is clamped (the motion holds its
/// end points).
pub trait Trajectory {
    /// Number of coordinates.
    fn dof(&self) -> usize;
    /// Duration (s).
    fn duration(&self) -> f64;
    /// Writes `q(t)`, `q̇(t)`, `q̈(t)` (each `dof()` long).
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]);
}

/// A geometric path `q(s)`, `s ∈ [0, 1]`, with its first two derivatives in `s`.
pub trait Path {
    /// Number of coordinates.
    fn dof(&self) -> usize;
    /// Writes `q(s)`, `q'(s)`, `q''(s)` (`s` is clamped to `[0, 1]`).
    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]);

    /// Writes `q(s)`, `q'(s)`, `q''(s)` and `q'''(s)` (for jerk limits). The default
    /// differentiates `q''` numerically (central difference, step `1e-5`, one-sided at the
    /// ends); the paths of this crate give it exactly.
    fn eval3(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64], dddq: &mut [f64]) {
        const H: f64 = 1e-5;
        let s = s.clamp(0.0, 1.0);
        let (lo, hi) = ((s - H).max(0.0), (s + H).min(1.0));
        self.eval(hi, q, dq, dddq);
        self.eval(lo, q, dq, ddq);
        for (d3, d2) in dddq.iter_mut().zip(ddq.iter()) {
            *d3 = (*d3 - d2) / (hi - lo);
        }
        self.eval(s, q, dq, ddq);
    }
}

/// A trajectory slowed down uniformly in time by `factor ≥ 1` (or sped up, `< 1`):
/// `q_s(t) = q(t/k)`, `q̇_s = q̇/k`, `q̈_s = q̈/k²`. Velocities scale by `1/k`, accelerations
/// and the velocity-dependent torques by `1/k²` (gravity does not scale).
pub struct TimeScaled<T> {
    inner: T,
    factor: f64,
}

impl<T: Trajectory> TimeScaled<T> {
    /// `inner` stretched by `factor` (> 0).
    pub fn new(inner: T, factor: f64) -> Result<Self, TrajectoryError> {
        if !(factor > 0.0 && factor.is_finite()) {
            return Err(TrajectoryError::Invalid(format!(
                "time scale factor must be positive (got {factor})"
            )));
        }
        Ok(TimeScaled { inner, factor })
    }

    /// The scale factor.
    pub fn factor(&self) -> f64 {
        self.factor
    }

    /// The unscaled trajectory.
    pub fn into_inner(self) -> T {
        self.inner
    }
}

impl<T: Trajectory> Trajectory for TimeScaled<T> {
    fn dof(&self) -> usize {
        self.inner.dof()
    }

    fn duration(&self) -> f64 {
        self.inner.duration() * self.factor
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let k = self.factor;
        self.inner.sample(t / k, q, qd, qdd);
        for (v, a) in qd.iter_mut().zip(qdd.iter_mut()) {
            *v /= k;
            *a /= k * k;
        }
    }
}

/// Makes any [`Trajectory`] a reference for the simulator ([`crate::sim::Reference`]).
pub struct AsReference<'a>(pub &'a dyn Trajectory);

impl crate::sim::Reference for AsReference<'_> {
    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        self.0.sample(t, q, qd, qdd);
    }
}
