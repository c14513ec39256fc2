//! Straight-line Cartesian moves: the tool pose interpolated linearly in position and by
//! slerp in rotation, solved by IK at each sample seeded from the previous solution.
//!
//! From the start pose `(p₀, R₀) = FK(q_start)` to the goal `(p₁, R₁)`:
//!
//! `p(σ) = p₀ + σ (p₁ − p₀)`,  `R(σ) = R₀ exp(σ [ω]×)`,  `ω = log(R₀ᵀ R₁)`,
//!
//! the constant-angular-velocity geodesic on SO(3) (Shoemake's slerp, SIGGRAPH 1985, in
//! matrix form). The IK ([`IkSolver`], Levenberg–Marquardt) solves `S` equally spaced
//! samples `σ_i = i/(S−1)`, each seeded from the previous solution, without random
//! restarts by default (a restart could land on another branch). A sample the IK does not
//! converge on is an error ([`TrajectoryError::Unreachable`]) naming it; so is a joint
//! step larger than `max_joint_step` between consecutive samples (a branch change).
//!
//! The samples are joined per joint by a cubic spline in `σ` with not-a-knot end
//! conditions ([`SplinePath`]: `q`, `q'` continuous, `q''` piecewise linear; de Boor, *A
//! Practical Guide to Splines*, ch. IV), so the path has the two derivatives the dynamics
//! need. Between samples the tool leaves the exact line by the spline's interpolation
//! error; the report gives the worst deviation found at the interval midpoints.
//!
//! Timing: `σ(t)` is the rest-to-rest quintic `10u³ − 15u⁴ + 6u⁵`, `u = t/T` (see
//! `quintic.rs`), so the tool's linear and angular speeds peak at `15/8 · L/T` and
//! `15/8 · θ/T`, and accelerations at `10/√3 · L/T²`, `10/√3 · θ/T²` (`L = ‖p₁ − p₀‖`,
//! `θ = ‖ω‖`). `T` is the shortest duration meeting the Cartesian limits and, when given,
//! the joint limits: `q̇ = q'(σ) σ̇`, `q̈ = q'(σ) σ̈ + q''(σ) σ̇²` scale as `1/T` and `1/T²`,
//! so one evaluation at `T = 1` on a fine grid gives the required `T` for each limit.

use crate::core::spatial::{axis_angle, Mat3, Se3, Vec3};
use crate::kinematics::ik::{rotation_log, IkOptions, IkSolver, IkStatus};
use crate::kinematics::{forward_kinematics, frame_placement};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::joint_limits::JointLimits;
use crate::motion::motion_traits::{Path, Trajectory};
use crate::motion::quintic::{sigma, PEAK_ACC, PEAK_VEL};
use crate::motion::trajectory_error::TrajectoryError;
use std::time::Duration;

/// Options of [`cartesian_line`].
#[derive(Clone, Debug)]
pub struct CartesianOptions {
    /// IK samples along the line (≥ 4).
    pub samples: usize,
    /// IK options (defaults: 1e-9 m / 1e-9 rad, no random restarts).
    pub ik: IkOptions,
    /// Tool speed limit (m/s; `inf` for none).
    pub max_linear_speed: f64,
    /// Tool acceleration limit (m/s²).
    pub max_linear_acceleration: f64,
    /// Tool angular speed limit (rad/s).
    pub max_angular_speed: f64,
    /// Tool angular acceleration limit (rad/s²).
    pub max_angular_acceleration: f64,
    /// Joint velocity and acceleration limits to respect as well.
    pub joint_limits: Option<JointLimits>,
    /// A fixed duration (s) instead of the one the limits give.
    pub duration: Option<f64>,
    /// Largest joint step between consecutive samples before it counts as a branch jump
    /// (rad or m).
    pub max_joint_step: f64,
}

impl Default for CartesianOptions {
    fn default() -> Self {
        CartesianOptions {
            samples: 101,
            ik: IkOptions {
                tol_position: 1e-9,
                tol_rotation: 1e-9,
                max_restarts: 0,
                time_budget: Duration::from_millis(100),
                ..Default::default()
            },
            max_linear_speed: 0.25,
            max_linear_acceleration: 1.0,
            max_angular_speed: 1.0,
            max_angular_acceleration: 4.0,
            joint_limits: None,
            duration: None,
            max_joint_step: 0.5,
        }
    }
}

/// Figures of a Cartesian move.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct CartesianReport {
    /// IK samples.
    pub samples: usize,
    /// Duration (s).
    pub duration: f64,
    /// Straight-line length (m).
    pub length: f64,
    /// Rotation angle (rad).
    pub angle: f64,
    /// Worst IK position residual at the samples (m).
    pub worst_position_error: f64,
    /// Worst IK rotation residual at the samples (rad).
    pub worst_rotation_error: f64,
    /// Worst distance of the interpolated tool from the line at the interval midpoints (m).
    pub worst_midpoint_position_deviation: f64,
    /// Worst rotation of the interpolated tool away from the slerp at the midpoints (rad).
    pub worst_midpoint_rotation_deviation: f64,
    /// IK iterations over all samples.
    pub ik_iterations: usize,
    /// Which limit set the duration (`linear_speed`, `joint_velocity`, … or `fixed`).
    pub limited_by: String,
}

/// A per-joint cubic spline through samples at uniform `σ_i = i/(S−1)`, not-a-knot ends.
#[derive(Clone, Debug)]
pub struct SplinePath {
    n: usize,
    segments: usize,
    /// Samples, flat (`S × n`).
    y: Vec<f64>,
    /// Second derivatives at the samples, flat.
    m: Vec<f64>,
}

impl SplinePath {
    /// Through `samples` (each `n` long, at least 4 of them), equally spaced in `σ`.
    pub fn new(samples: &[Vec<f64>]) -> Result<Self, TrajectoryError> {
        let s = samples.len();
        if s < 4 {
            return Err(TrajectoryError::Invalid(format!(
                "spline path: need at least 4 samples (got {s})"
            )));
        }
        let n = crate::motion::waypoints::validate_waypoints(samples)?;
        let h = 1.0 / (s - 1) as f64;
        let y = samples.concat();
        let mut m = vec![0.0; s * n];
        // Interior equations M_{i−1} + 4 M_i + M_{i+1} = r_i, i = 1 … S−2; not-a-knot
        // (M_0 = 2M_1 − M_2, M_{S−1} = 2M_{S−2} − M_{S−3}) turns the first and last into
        // 6 M_1 = r_1 and 6 M_{S−2} = r_{S−2}. Thomas algorithm per joint.
        let ni = s - 2;
        let mut cp = vec![0.0; ni];
        let mut dp = vec![0.0; ni];
        for j in 0..n {
            let r = |i: usize| {
                6.0 * (y[(i + 1) * n + j] - 2.0 * y[i * n + j] + y[(i - 1) * n + j]) / (h * h)
            };
            for k in 0..ni {
                let i = k + 1;
                let (lower, diag, upper) = if k == 0 || k == ni - 1 {
                    (0.0, 6.0, 0.0)
                } else {
                    (1.0, 4.0, 1.0)
                };
                let denom = diag - lower * if k > 0 { cp[k - 1] } else { 0.0 };
                cp[k] = upper / denom;
                dp[k] = (r(i) - lower * if k > 0 { dp[k - 1] } else { 0.0 }) / denom;
            }
            for k in (0..ni).rev() {
                let next = if k + 1 < ni { m[(k + 2) * n + j] } else { 0.0 };
                m[(k + 1) * n + j] = dp[k] - cp[k] * next;
            }
            m[j] = 2.0 * m[n + j] - m[2 * n + j];
            m[(s - 1) * n + j] = 2.0 * m[(s - 2) * n + j] - m[(s - 3) * n + j];
        }
        Ok(SplinePath {
            n,
            segments: s - 1,
            y,
            m,
        })
    }
}

impl Path for SplinePath {
    fn dof(&self) -> usize {
        self.n
    }

    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let n = self.n;
        let h = 1.0 / self.segments as f64;
        let x = s.clamp(0.0, 1.0) * self.segments as f64;
        let i = (x.floor() as usize).min(self.segments - 1);
        let b = x - i as f64;
        let a = 1.0 - b;
        for j in 0..n {
            let (y0, y1) = (self.y[i * n + j], self.y[(i + 1) * n + j]);
            let (m0, m1) = (self.m[i * n + j], self.m[(i + 1) * n + j]);
            q[j] = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
            dq[j] = (y1 - y0) / h - (3.0 * a * a - 1.0) / 6.0 * h * m0
                + (3.0 * b * b - 1.0) / 6.0 * h * m1;
            ddq[j] = a * m0 + b * m1;
        }
    }

    fn eval3(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64], dddq: &mut [f64]) {
        self.eval(s, q, dq, ddq);
        let n = self.n;
        let h = 1.0 / self.segments as f64;
        let x = s.clamp(0.0, 1.0) * self.segments as f64;
        let i = (x.floor() as usize).min(self.segments - 1);
        for (j, d3) in dddq.iter_mut().enumerate() {
            *d3 = (self.m[(i + 1) * n + j] - self.m[i * n + j]) / h;
        }
    }
}

/// A straight-line tool move (see the module docs): a [`SplinePath`] through the IK
/// solutions timed by the quintic `σ(t)`.
#[derive(Clone, Debug)]
pub struct CartesianMove {
    path: SplinePath,
    duration: f64,
    start: Se3,
    goal: Se3,
    /// Figures of the move.
    pub report: CartesianReport,
}

/// The pose on the line at `σ`.
fn line_pose(start: &Se3, dp: &Vec3, omega: &Vec3, sigma: f64) -> Se3 {
    let angle = omega.norm();
    let rot = if angle > 0.0 {
        start.rot * axis_angle(&(omega / angle), sigma * angle)
    } else {
        start.rot
    };
    Se3::new(rot, start.trans + dp * sigma)
}

/// Distance between two poses: position (m) and rotation angle (rad).
fn pose_gap(a: &Se3, b: &Se3) -> (f64, f64) {
    let r: Mat3 = a.rot.transpose() * b.rot;
    ((a.trans - b.trans).norm(), rotation_log(&r).norm())
}

impl CartesianMove {
    /// The geometric path `q(σ)` (for example to time it with [`crate::motion::topp`]).
    pub fn path(&self) -> &SplinePath {
        &self.path
    }

    /// The tool pose the move starts from.
    pub fn start_pose(&self) -> Se3 {
        self.start
    }

    /// The goal pose.
    pub fn goal_pose(&self) -> Se3 {
        self.goal
    }

    /// The exact line pose at time `t` (what the IK aimed at).
    pub fn target_at(&self, t: f64) -> Se3 {
        let (s, _, _) = sigma((t / self.duration).clamp(0.0, 1.0));
        let dp = self.goal.trans - self.start.trans;
        let omega = rotation_log(&(self.start.rot.transpose() * self.goal.rot));
        line_pose(&self.start, &dp, &omega, s)
    }
}

/// Plans a straight-line move of `link` from its pose at `q_start` to `goal` (see the
/// module docs).
pub fn cartesian_line(
    model: &Model,
    link: usize,
    q_start: &[f64],
    goal: &Se3,
    opts: &CartesianOptions,
) -> Result<CartesianMove, TrajectoryError> {
    check_inputs(model, link, q_start, goal, opts)?;
    let names = model.dof_names();
    if let Some(l) = &opts.joint_limits {
        l.validate(&names)?;
    }
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, q_start);
    let start = frame_placement(model, &data, link);
    let dp = goal.trans - start.trans;
    let omega = rotation_log(&(start.rot.transpose() * goal.rot));
    let ns = opts.samples;
    let mut qs: Vec<Vec<f64>> = Vec::with_capacity(ns);
    qs.push(q_start.to_vec());
    let mut report = CartesianReport {
        samples: ns,
        length: dp.norm(),
        angle: omega.norm(),
        ..Default::default()
    };
    let line = (&start, &dp, &omega);
    ik_along_line(model, link, line, opts, &names, &mut qs, &mut report)?;
    let path = SplinePath::new(&qs)?;
    midpoint_deviation(model, link, &path, line, &mut data, &mut report);
    // Duration.
    let need = duration_needs(&path, &report, opts, &names);
    let (duration, limited_by) = match opts.duration {
        Some(d) if d > 0.0 && d.is_finite() => (d, "fixed".to_string()),
        Some(d) => {
            return Err(TrajectoryError::Invalid(format!(
                "Cartesian move: duration {d} is not positive and finite"
            )))
        }
        None => need
            .into_iter()
            .filter(|(t, _)| t.is_finite())
            .max_by(|a, b| a.0.total_cmp(&b.0))
            .filter(|(t, _)| *t > 0.0)
            .ok_or_else(|| {
                TrajectoryError::Invalid(
                    "Cartesian move: no finite limit sets a duration (zero-length move or all \
                     limits infinite): give a duration"
                        .into(),
                )
            })?,
    };
    report.duration = duration;
    report.limited_by = limited_by;
    Ok(CartesianMove {
        path,
        duration,
        start,
        goal: *goal,
        report,
    })
}

/// The start configuration, the link, the sample count and the goal must be usable.
fn check_inputs(
    model: &Model,
    link: usize,
    q_start: &[f64],
    goal: &Se3,
    opts: &CartesianOptions,
) -> Result<(), TrajectoryError> {
    let n = model.nv;
    if q_start.len() != n || q_start.iter().any(|x| !x.is_finite()) {
        return Err(TrajectoryError::Invalid(format!(
            "Cartesian move: the start configuration needs {n} finite values"
        )));
    }
    if link >= model.links.len() {
        return Err(TrajectoryError::Invalid(format!(
            "Cartesian move: link index {link} does not exist"
        )));
    }
    if opts.samples < 4 {
        return Err(TrajectoryError::Invalid(
            "Cartesian move: need at least 4 samples".into(),
        ));
    }
    if !goal
        .rot
        .iter()
        .chain(goal.trans.iter())
        .all(|x| x.is_finite())
    {
        return Err(TrajectoryError::Invalid(
            "Cartesian move: the goal pose is not finite".into(),
        ));
    }
    Ok(())
}

/// The line `(start, dp, omega)`: the pose at `s ∈ [0, 1]` is [`line_pose`].
type Line<'a> = (&'a Se3, &'a Vec3, &'a Vec3);

/// IK at the samples of the line after the first (already in `qs`), each seeded from the
/// previous one; a sample out of reach or a joint step above `max_joint_step` (a branch
/// jump) is an error.
fn ik_along_line(
    model: &Model,
    link: usize,
    (start, dp, omega): Line,
    opts: &CartesianOptions,
    names: &[String],
    qs: &mut Vec<Vec<f64>>,
    report: &mut CartesianReport,
) -> Result<(), TrajectoryError> {
    let ns = opts.samples;
    let mut solver = IkSolver::new(model);
    for i in 1..ns {
        let s = i as f64 / (ns - 1) as f64;
        let target = line_pose(start, dp, omega, s);
        let res = solver.solve(model, link, &target, Some(&qs[i - 1]), &opts.ik);
        report.ik_iterations += res.iterations;
        if res.status != IkStatus::Converged {
            return Err(TrajectoryError::Unreachable {
                index: i,
                samples: ns,
                s,
                status: res.status.as_str(),
                position_error: res.position_error,
                rotation_error: res.rotation_error,
            });
        }
        report.worst_position_error = report.worst_position_error.max(res.position_error);
        report.worst_rotation_error = report.worst_rotation_error.max(res.rotation_error);
        if let Some((j, step)) = res
            .q
            .iter()
            .zip(&qs[i - 1])
            .map(|(a, b)| (a - b).abs())
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(&b.1))
        {
            if step > opts.max_joint_step {
                return Err(TrajectoryError::BranchJump {
                    index: i - 1,
                    joint: names[j].clone(),
                    step,
                    max: opts.max_joint_step,
                });
            }
        }
        qs.push(res.q);
    }
    Ok(())
}

/// The largest deviation of the spline through the samples from the line, at the
/// midpoints between samples.
fn midpoint_deviation(
    model: &Model,
    link: usize,
    path: &SplinePath,
    (start, dp, omega): Line,
    data: &mut Data,
    report: &mut CartesianReport,
) {
    let n = model.nv;
    let ns = report.samples;
    let (mut q, mut dq, mut ddq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for i in 0..ns - 1 {
        let s = (i as f64 + 0.5) / (ns - 1) as f64;
        path.eval(s, &mut q, &mut dq, &mut ddq);
        forward_kinematics(model, data, &q);
        let (dpos, drot) = pose_gap(
            &frame_placement(model, data, link),
            &line_pose(start, dp, omega, s),
        );
        report.worst_midpoint_position_deviation =
            report.worst_midpoint_position_deviation.max(dpos);
        report.worst_midpoint_rotation_deviation =
            report.worst_midpoint_rotation_deviation.max(drot);
    }
}

/// The durations each limit needs (with its name): the tool's linear and angular speed
/// and acceleration, and each joint's velocity and acceleration limit.
fn duration_needs(
    path: &SplinePath,
    report: &CartesianReport,
    opts: &CartesianOptions,
    names: &[String],
) -> Vec<(f64, String)> {
    let n = names.len();
    let ns = report.samples;
    let (mut q, mut dq, mut ddq) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut need: Vec<(f64, String)> = vec![
        (
            PEAK_VEL * report.length / opts.max_linear_speed,
            "linear_speed".into(),
        ),
        (
            (PEAK_ACC * report.length / opts.max_linear_acceleration).sqrt(),
            "linear_acceleration".into(),
        ),
        (
            PEAK_VEL * report.angle / opts.max_angular_speed,
            "angular_speed".into(),
        ),
        (
            (PEAK_ACC * report.angle / opts.max_angular_acceleration).sqrt(),
            "angular_acceleration".into(),
        ),
    ];
    if let Some(l) = &opts.joint_limits {
        // Peaks at T = 1 on a grid of 16 points per IK interval.
        let mut pv = vec![0.0f64; n];
        let mut pa = vec![0.0f64; n];
        let grid = 16 * (ns - 1);
        for k in 0..=grid {
            let u = k as f64 / grid as f64;
            let (s, sd, sdd) = sigma(u);
            path.eval(s, &mut q, &mut dq, &mut ddq);
            for j in 0..n {
                pv[j] = pv[j].max((dq[j] * sd).abs());
                pa[j] = pa[j].max((dq[j] * sdd + ddq[j] * sd * sd).abs());
            }
        }
        for j in 0..n {
            need.push((
                pv[j] / l.velocity[j],
                format!("joint_velocity:{}", names[j]),
            ));
            need.push((
                (pa[j] / l.acceleration[j]).sqrt(),
                format!("joint_acceleration:{}", names[j]),
            ));
        }
    }
    need
}

impl Trajectory for CartesianMove {
    fn dof(&self) -> usize {
        self.path.n
    }

    fn duration(&self) -> f64 {
        self.duration
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let big_t = self.duration;
        let (s, sd, sdd) = sigma((t / big_t).clamp(0.0, 1.0));
        let (sd, sdd) = (sd / big_t, sdd / (big_t * big_t));
        self.path.eval(s, q, qd, qdd);
        for j in 0..self.path.n {
            qdd[j] = qd[j] * sdd + qdd[j] * sd * sd;
            qd[j] *= sd;
        }
    }
}
