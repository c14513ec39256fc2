//! Torque-requirement check along a trajectory: the joint torques the motion needs with a
//! chosen set of [`Effects`], compared with the model's effort and velocity limits.
//!
//! On the uniform grid `t_k = k T / K` (`T/K ≤ dt`) the trajectory gives `q, q̇, q̈` and
//! [`inverse_dynamics`] gives `τ_k` with exactly the selected effects. Per joint:
//!
//! - peak torque `max_k |τ_k|`, RMS torque `√(∫ τ² dt / T)` (trapezoidal rule), peak speed
//!   `max_k |q̇_k|`, peak power `max_k |τ_k q̇_k|`;
//! - torque margin `100 (1 − peak / limit)` % (negative when exceeded), the same for the
//!   speed;
//! - the first violation of each limit: the first sample with `|x_k| > L`; the crossing
//!   time is interpolated linearly between that sample and the previous one,
//!   `t* = t_{k−1} + (±L − x_{k−1}) / (x_k − x_{k−1}) · Δt` (the sign of the limit crossed),
//!   or `t_0` when the first sample already violates. `first_violation_s` is the earlier
//!   of the torque and speed crossings.
//!
//! Limits of `+∞` (none in the model file) never fail; they serialise as `null`.
//! [`check_torques_switched`] uses a second effect set inside a time window (a grasped
//! part's payload).

use crate::dynamics::{inverse_dynamics, Effects};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::motion_traits::Trajectory;
use crate::motion::trajectory_error::TrajectoryError;
use crate::motion::waypoints::time_grid;
use std::fmt::Write as _;

/// Options of [`check_torques`].
#[derive(Clone, Debug)]
pub struct TorqueCheckOptions {
    /// Largest sample step (s).
    pub dt: f64,
    /// Effort limits replacing the model's (one per coordinate).
    pub effort_limit: Option<Vec<f64>>,
    /// Velocity limits replacing the model's.
    pub velocity_limit: Option<Vec<f64>>,
    /// Keep the sampled torques and speeds in the report (needed for the plot; costs
    /// `16 × samples × nv` bytes). The figures are computed streaming either way.
    pub keep_series: bool,
}

impl Default for TorqueCheckOptions {
    fn default() -> Self {
        TorqueCheckOptions {
            dt: 1e-3,
            effort_limit: None,
            velocity_limit: None,
            keep_series: true,
        }
    }
}

/// One joint's row of the report (the JSON row).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JointCheck {
    /// Joint name.
    pub joint: String,
    /// `max |τ|` (N m or N).
    pub peak_torque: f64,
    /// RMS torque over the motion.
    pub rms_torque: f64,
    /// `max |q̇|` (rad/s or m/s).
    pub peak_speed: f64,
    /// `max |τ q̇|` (W).
    pub peak_power: f64,
    /// Effort limit (`null` when none).
    pub limit: f64,
    /// Velocity limit (`null` when none).
    pub velocity_limit: f64,
    /// Torque margin `100 (1 − peak/limit)` (%).
    pub margin: f64,
    /// Neither limit exceeded.
    pub ok: bool,
    /// First time either limit is exceeded (s), `null` if never.
    pub first_violation_s: Option<f64>,
    /// Speed margin `100 (1 − peak speed / velocity limit)` (%).
    pub velocity_margin: f64,
    /// First time the effort limit is exceeded (s).
    pub first_torque_violation_s: Option<f64>,
    /// First time the velocity limit is exceeded (s).
    pub first_speed_violation_s: Option<f64>,
    /// Time of the peak torque (s).
    pub peak_torque_time_s: f64,
}

/// The result of [`check_torques`]: one row per joint, plus the sampled torques and
/// speeds (for plots and further analysis).
#[derive(Clone, Debug, serde::Serialize)]
pub struct TorqueReport {
    /// Per-joint rows.
    pub joints: Vec<JointCheck>,
    /// The effects the torques include.
    pub effects: Vec<&'static str>,
    /// Duration checked (s).
    pub duration: f64,
    /// Sample step used (s).
    pub dt: f64,
    /// Number of samples checked.
    pub samples: usize,
    /// Whether every joint is within both limits.
    pub ok: bool,
    /// Sample times (empty unless `keep_series`).
    #[serde(skip)]
    pub t: Vec<f64>,
    /// Torques, sample-major (`t.len() × nv`).
    #[serde(skip)]
    pub tau: Vec<f64>,
    /// Joint speeds, sample-major.
    #[serde(skip)]
    pub qd: Vec<f64>,
}

/// The crossing time of `|x| > lim` between `(t0, x0)` (within the limit) and `(t1, x1)`
/// (beyond it), by linear interpolation of `x` to the limit crossed.
fn crossing(t0: f64, x0: f64, t1: f64, x1: f64, lim: f64) -> f64 {
    let bound = if x1 > lim { lim } else { -lim };
    let frac = ((bound - x0) / (x1 - x0)).clamp(0.0, 1.0);
    t0 + frac * (t1 - t0)
}

/// Running per-joint figures (the check streams over the samples).
#[derive(Clone, Copy, Default)]
struct Acc {
    peak: f64,
    peak_t: f64,
    speed: f64,
    power: f64,
    sq: f64,
    first_torque: Option<f64>,
    first_speed: Option<f64>,
    prev_tau: f64,
    prev_qd: f64,
}

/// Samples `traj` every `opts.dt` (at most) and checks the torques needed with `effects`
/// against the model's limits (or those of `opts`). See the module docs.
pub fn check_torques(
    model: &Model,
    traj: &dyn Trajectory,
    effects: &Effects,
    opts: &TorqueCheckOptions,
) -> Result<TorqueReport, TrajectoryError> {
    check_torques_switched(model, traj, effects, effects, (f64::NAN, f64::NAN), opts)
}

/// The effort and velocity limits (the options', else the model's), checked positive.
fn limits(
    model: &Model,
    opts: &TorqueCheckOptions,
) -> Result<(Vec<f64>, Vec<f64>), TrajectoryError> {
    let n = model.nv;
    let effort = opts
        .effort_limit
        .clone()
        .unwrap_or_else(|| model.effort_limit.clone());
    let velocity = opts
        .velocity_limit
        .clone()
        .unwrap_or_else(|| model.velocity_limit.clone());
    for (what, v) in [("effort", &effort), ("velocity", &velocity)] {
        if v.len() != n || v.iter().any(|x| x.is_nan() || *x <= 0.0) {
            return Err(TrajectoryError::Invalid(format!(
                "torque check: {what} limits must be {n} positive values"
            )));
        }
    }
    Ok((effort, velocity))
}

/// One joint's row from its accumulated samples.
fn joint_check(
    name: &str,
    a: &Acc,
    (effort, velocity): (f64, f64),
    duration: f64,
    step: f64,
) -> JointCheck {
    let rms = if duration > 0.0 {
        (a.sq * step / duration).sqrt()
    } else {
        a.prev_tau.abs()
    };
    let first = match (a.first_torque, a.first_speed) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, y) => x.or(y),
    };
    JointCheck {
        joint: name.to_string(),
        peak_torque: a.peak,
        rms_torque: rms,
        peak_speed: a.speed,
        peak_power: a.power,
        limit: effort,
        velocity_limit: velocity,
        margin: 100.0 * (1.0 - a.peak / effort),
        ok: first.is_none(),
        first_violation_s: first,
        velocity_margin: 100.0 * (1.0 - a.speed / velocity),
        first_torque_violation_s: a.first_torque,
        first_speed_violation_s: a.first_speed,
        peak_torque_time_s: a.peak_t,
    }
}

/// [`check_torques`] with `inside` at the samples with `window.0 ≤ t ≤ window.1` and
/// `outside` elsewhere (a part grasped between two instants).
pub fn check_torques_switched(
    model: &Model,
    traj: &dyn Trajectory,
    outside: &Effects,
    inside: &Effects,
    window: (f64, f64),
    opts: &TorqueCheckOptions,
) -> Result<TorqueReport, TrajectoryError> {
    inside
        .validate(model)
        .map_err(|e| TrajectoryError::Invalid(e.to_string()))?;
    let effects = outside;
    let n = model.nv;
    if traj.dof() != n {
        return Err(TrajectoryError::Invalid(format!(
            "torque check: the trajectory has {} coordinates, the model {n}",
            traj.dof()
        )));
    }
    if !(opts.dt > 0.0 && opts.dt.is_finite()) {
        return Err(TrajectoryError::Invalid(format!(
            "torque check: dt must be positive (got {})",
            opts.dt
        )));
    }
    effects
        .validate(model)
        .map_err(|e| TrajectoryError::Invalid(e.to_string()))?;
    let (effort, velocity) = limits(model, opts)?;
    let duration = traj.duration();
    let (intervals, step) = time_grid(duration, opts.dt);
    let ns = intervals + 1;
    let keep = if opts.keep_series { ns } else { 0 };
    let mut t = Vec::with_capacity(keep);
    let mut tau_all = Vec::with_capacity(keep * n);
    let mut qd_all = Vec::with_capacity(keep * n);
    let mut acc = vec![Acc::default(); n];
    let mut data = Data::new(model);
    let (mut q, mut qd, mut qdd) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut t_prev = 0.0;
    for k in 0..ns {
        let tk = if k == intervals {
            duration
        } else {
            k as f64 * step
        };
        traj.sample(tk, &mut q, &mut qd, &mut qdd);
        let fx = if tk >= window.0 && tk <= window.1 {
            inside
        } else {
            outside
        };
        let tau = inverse_dynamics(model, &mut data, fx, &q, &qd, &qdd);
        let w = if k == 0 || k == intervals { 0.5 } else { 1.0 };
        for (j, a) in acc.iter_mut().enumerate() {
            let (x, v) = (tau[j], qd[j]);
            if x.abs() > a.peak {
                a.peak = x.abs();
                a.peak_t = tk;
            }
            a.speed = a.speed.max(v.abs());
            a.power = a.power.max((x * v).abs());
            a.sq += w * x * x;
            if a.first_torque.is_none() && x.abs() > effort[j] {
                a.first_torque = Some(if k == 0 {
                    tk
                } else {
                    crossing(t_prev, a.prev_tau, tk, x, effort[j])
                });
            }
            if a.first_speed.is_none() && v.abs() > velocity[j] {
                a.first_speed = Some(if k == 0 {
                    tk
                } else {
                    crossing(t_prev, a.prev_qd, tk, v, velocity[j])
                });
            }
            a.prev_tau = x;
            a.prev_qd = v;
        }
        if opts.keep_series {
            t.push(tk);
            tau_all.extend_from_slice(tau);
            qd_all.extend_from_slice(&qd);
        }
        t_prev = tk;
    }
    let names = model.dof_names();
    let joints: Vec<JointCheck> = acc
        .iter()
        .enumerate()
        .map(|(j, a)| joint_check(&names[j], a, (effort[j], velocity[j]), duration, step))
        .collect();
    Ok(TorqueReport {
        ok: joints.iter().all(|r| r.ok),
        joints,
        effects: effects.names(),
        duration,
        dt: step,
        samples: ns,
        t,
        tau: tau_all,
        qd: qd_all,
    })
}

/// `x` with 6 significant digits, or `-` when not finite.
fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.6}")
    } else {
        "-".into()
    }
}

impl TorqueReport {
    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// Torque of joint `j` at sample `k`.
    pub fn torque(&self, k: usize, j: usize) -> f64 {
        self.tau[k * self.dof() + j]
    }

    /// The JSON rows, one object per joint (infinite limits as `null`).
    pub fn json_rows(&self) -> serde_json::Value {
        serde_json::to_value(&self.joints).expect("rows serialise")
    }

    /// A readable fixed-width table.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let effects = if self.effects.is_empty() {
            "rigid body only".to_string()
        } else {
            self.effects.join(", ")
        };
        let _ = writeln!(
            s,
            "torque check: {:.4} s sampled every {:.3e} s; effects: {effects}",
            self.duration, self.dt
        );
        let w = self
            .joints
            .iter()
            .map(|r| r.joint.len())
            .max()
            .unwrap_or(5)
            .max(5);
        let _ = writeln!(
            s,
            "{:<w$} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>9} {:>4} {:>12}",
            "joint",
            "peak_torque",
            "rms_torque",
            "limit",
            "margin_%",
            "peak_speed",
            "vel_limit",
            "peak_W",
            "ok",
            "first_viol_s"
        );
        for r in &self.joints {
            let _ = writeln!(
                s,
                "{:<w$} {:>12} {:>12} {:>12} {:>12} {:>12} {:>12} {:>9.2} {:>4} {:>12}",
                r.joint,
                num(r.peak_torque),
                num(r.rms_torque),
                num(r.limit),
                format!("{:.2}", r.margin),
                num(r.peak_speed),
                num(r.velocity_limit),
                r.peak_power,
                if r.ok { "yes" } else { "NO" },
                r.first_violation_s
                    .map_or("-".into(), |x| format!("{x:.6}"))
            );
        }
        let _ = writeln!(
            s,
            "{}",
            if self.ok {
                "all joints within their limits"
            } else {
                "LIMITS EXCEEDED"
            }
        );
        s
    }
}
