//! Trajectories through joint waypoints, time-optimal path parameterisation, and the
//! torque-requirement check. One file per algorithm, each citing its equations:
//!
//! - [`Trapezoidal`] (`trapezoidal.rs`): trapezoidal velocity per segment, stop at every
//!   waypoint, joints synchronised on the slowest one;
//! - [`Quintic`] (`quintic.rs`): the rest-to-rest quintic `10u³ − 15u⁴ + 6u⁵` per segment;
//! - [`MinJerk`] (`min_jerk.rs`): the minimum-jerk quintic spline through via points (C⁴
//!   at interior knots), segment times scaled to the limits;
//! - [`CartesianMove`] (`cartesian.rs`): a straight tool line (linear position, slerp
//!   rotation) solved by IK sample by sample;
//! - [`topp`] (`topp/`): time-optimal path parameterisation under joint velocity,
//!   acceleration and torque limits, by reachability analysis (TOPP-RA, Pham & Pham 2018;
//!   `reachability.rs`, its two-variable LPs in `lp2.rs`) or, as [`ToppMethod::Conic`],
//!   the second-order-cone program of Verscheure et al. (2009) with clarabel (`socp.rs`);
//!   verified by a dense check with repairs (`check.rs`); optional jerk limits by
//!   smoothing and slowing down (`jerk.rs`);
//! - [`check_torques`] (`torque_check.rs`): peak / RMS torque, peak speed and power, margins
//!   and the first violation time of every limit along any trajectory, with a text table,
//!   JSON rows and a PNG/SVG plot (`plot.rs`), whose axis labels come from [`ticks`]
//!   (nice tick positions, labels with a common power of ten);
//! - [`panels`] (`panels.rs`): line panels and bar charts shared by the trade-offs report
//!   and the machine scenarios' pictures.
//!
//! Also [`TimeScaled`] (uniform slow-down of any trajectory), [`LinearPath`] and
//! [`SplinePath`] (paths for TOPP), and [`AsReference`] (any trajectory as the simulator's
//! reference).
//!
//! A [`Trajectory`] is sampled in time, `t ↦ (q, q̇, q̈)`, clamped to `[0, duration]`; a
//! [`Path`] is a geometric curve `s ↦ (q, q', q'')` for `s ∈ [0, 1]` (what TOPP times).
//! Sampling allocates nothing.

mod cartesian;
mod min_jerk;
mod quintic;
mod topp;
pub mod torque_check;
mod trapezoidal;
pub use crate::motion::cartesian::{
    cartesian_line, CartesianMove, CartesianOptions, CartesianReport, SplinePath,
};
pub use crate::motion::min_jerk::MinJerk;
pub use crate::motion::quintic::Quintic;
pub use crate::motion::topp::{
    topp, LinearPath, ToppMethod, ToppOptions, ToppStats, ToppTrajectory,
};
pub use crate::motion::torque_check::{
    check_torques, check_torques_switched, JointCheck, TorqueCheckOptions, TorqueReport,
};
pub use crate::motion::trapezoidal::Trapezoidal;

use crate::model::Model;

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

/// Why a trajectory could not be built or checked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrajectoryError {
    /// Bad input (waypoints, limits, options).
    #[error("{0}")]
    Invalid(String),
    /// A Cartesian sample the IK could not reach.
    #[error(
        "Cartesian move: sample {index} of {samples} (s = {s:.4}) is unreachable: IK {status}, \
         position error {position_error:.3e} m, rotation error {rotation_error:.3e} rad"
    )]
    Unreachable {
        /// Sample index along the line.
        index: usize,
        /// Number of samples.
        samples: usize,
        /// Path parameter of the sample.
        s: f64,
        /// IK status (`unreachable` or `best_effort`).
        status: &'static str,
        /// Position residual (m).
        position_error: f64,
        /// Rotation residual (rad).
        rotation_error: f64,
    },
    /// Two consecutive Cartesian samples on different IK branches.
    #[error(
        "Cartesian move: joint {joint} jumps by {step:.3} rad between samples {index} and {} \
         (more than {max:.3}): the IK changed branch (near a singularity or a limit); use more \
         samples or another start configuration",
        index + 1
    )]
    BranchJump {
        /// Sample index before the jump.
        index: usize,
        /// Joint name.
        joint: String,
        /// Step size (rad or m).
        step: f64,
        /// Allowed step.
        max: f64,
    },
    /// The time-optimal problem could not be solved.
    #[error("TOPP: {0}")]
    Topp(String),
    /// Output could not be written.
    #[error("{0}")]
    Output(String),
}

/// Joint velocity, acceleration and effort limits, one value per coordinate. An effort of
/// `+∞` means "no torque limit" (TOPP then leaves that joint's torque free).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct JointLimits {
    /// Velocity limit (rad/s or m/s), > 0.
    pub velocity: Vec<f64>,
    /// Acceleration limit (rad/s² or m/s²), > 0.
    pub acceleration: Vec<f64>,
    /// Effort limit (N m or N), > 0 or `+∞`.
    pub effort: Vec<f64>,
    /// Jerk limit (rad/s³ or m/s³), > 0 (`+∞`: none for that joint), one value per
    /// coordinate; `None` (the default) for no jerk limit. Only [`topp`] applies it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jerk: Option<Vec<f64>>,
}

impl JointLimits {
    /// Velocity and effort limits from the model, the given accelerations (the model file
    /// has none).
    pub fn from_model(model: &Model, acceleration: Vec<f64>) -> Self {
        JointLimits {
            velocity: model.velocity_limit.clone(),
            acceleration,
            effort: model.effort_limit.clone(),
            jerk: None,
        }
    }

    /// The same limits for every one of `n` coordinates.
    pub fn uniform(n: usize, velocity: f64, acceleration: f64, effort: f64) -> Self {
        JointLimits {
            velocity: vec![velocity; n],
            acceleration: vec![acceleration; n],
            effort: vec![effort; n],
            jerk: None,
        }
    }

    /// Checks lengths and values: velocity and acceleration finite and positive, effort
    /// and jerk (if any) positive (infinite allowed). `names` label the joints in messages.
    pub fn validate(&self, names: &[String]) -> Result<(), TrajectoryError> {
        let n = names.len();
        if let Some(jerk) = &self.jerk {
            if jerk.len() != n {
                return Err(TrajectoryError::Invalid(format!(
                    "jerk limits: {} values for {n} joints",
                    jerk.len()
                )));
            }
            if let Some(k) = jerk.iter().position(|x| x.is_nan() || *x <= 0.0) {
                return Err(TrajectoryError::Invalid(format!(
                    "joint {}: the jerk limit must be positive or inf (got {})",
                    names[k], jerk[k]
                )));
            }
        }
        for (what, v) in [
            ("velocity", &self.velocity),
            ("acceleration", &self.acceleration),
            ("effort", &self.effort),
        ] {
            if v.len() != n {
                return Err(TrajectoryError::Invalid(format!(
                    "{what} limits: {} values for {n} joints",
                    v.len()
                )));
            }
        }
        for (k, name) in names.iter().enumerate() {
            for (what, x, inf_ok) in [
                ("velocity", self.velocity[k], false),
                ("acceleration", self.acceleration[k], false),
                ("effort", self.effort[k], true),
            ] {
                let good = x > 0.0 && (x.is_finite() || (inf_ok && x == f64::INFINITY));
                if !good {
                    return Err(TrajectoryError::Invalid(format!(
                        "joint {name}: the {what} limit must be {} (got {x})",
                        if inf_ok {
                            "positive or inf"
                        } else {
                            "finite and positive (the model gives none: set one)"
                        }
                    )));
                }
            }
        }
        Ok(())
    }
}

/// Names `joint0`, `joint1`, … for `n` coordinates (when no model is at hand).
pub(crate) fn default_names(n: usize) -> Vec<String> {
    (0..n).map(|k| format!("joint{k}")).collect()
}

/// Checks a waypoint list: at least two, all `n` long, all finite.
pub(crate) fn validate_waypoints(waypoints: &[Vec<f64>]) -> Result<usize, TrajectoryError> {
    if waypoints.len() < 2 {
        return Err(TrajectoryError::Invalid(format!(
            "need at least two waypoints (got {})",
            waypoints.len()
        )));
    }
    let n = waypoints[0].len();
    if n == 0 {
        return Err(TrajectoryError::Invalid(
            "waypoints have no coordinates".into(),
        ));
    }
    for (i, w) in waypoints.iter().enumerate() {
        if w.len() != n {
            return Err(TrajectoryError::Invalid(format!(
                "waypoint {i} has {} values, waypoint 0 has {n}",
                w.len()
            )));
        }
        if let Some(k) = w.iter().position(|x| !x.is_finite()) {
            return Err(TrajectoryError::Invalid(format!(
                "waypoint {i}: coordinate {k} is not finite"
            )));
        }
    }
    Ok(n)
}

/// Segment of a piecewise motion with knot times `knots` (sorted, `knots[0] = 0`) holding
/// `t` (clamped), and the local time in it.
#[inline]
pub(crate) fn locate(knots: &[f64], t: f64) -> (usize, f64) {
    let nseg = knots.len() - 1;
    let t = t.clamp(0.0, knots[nseg]);
    // First knot strictly greater than t, minus one: the segment [knots[k], knots[k+1]).
    let k = knots
        .partition_point(|&x| x <= t)
        .saturating_sub(1)
        .min(nseg - 1);
    (k, t - knots[k])
}

/// A uniform time grid over `[0, duration]` with step at most `dt`: `(intervals, step)`.
/// A zero duration gives one interval of zero length.
pub(crate) fn time_grid(duration: f64, dt: f64) -> (usize, f64) {
    if duration <= 0.0 {
        return (1, 0.0);
    }
    let n = ((duration / dt).ceil() as usize).max(1);
    (n, duration / n as f64)
}
