//! Trapezoidal velocity profiles through joint waypoints, stopping at every waypoint.
//!
//! For a segment of length `d_j = |Δq_j|` on joint `j` with velocity limit `v_j` and
//! acceleration limit `a_j`, the fastest rest-to-rest motion (Biagiotti & Melchiorri,
//! *Trajectory Planning for Automatic Machines and Robots*, 2008, ch. 3) takes
//!
//! - `T_j = d_j / v_j + v_j / a_j` when `d_j ≥ v_j² / a_j` (accelerate, cruise, brake);
//! - `T_j = 2 √(d_j / a_j)` otherwise (triangular profile, peak speed `√(a_j d_j)`).
//!
//! The segment lasts `T = max_j T_j` (the slowest joint sets it) and every joint is
//! synchronised to arrive at `T`: it keeps its acceleration `a_j` and lowers its cruise
//! speed to the smaller root of `v² − a_j T v + a_j d_j = 0`,
//!
//! `v_j' = (a_j T − √(a_j² T² − 4 a_j d_j)) / 2`,  accelerating for `t_a = v_j' / a_j ≤ T/2`.
//!
//! For the slowest joint this gives back its own limit profile (`v_j' = v_j`, or the
//! triangle with discriminant 0). Joints therefore all start and stop together; each has
//! its own blend times, so the joint-space path is not a straight line in general.

use crate::motion::joint_limits::JointLimits;
use crate::motion::motion_traits::Trajectory;
use crate::motion::trajectory_error::TrajectoryError;
use crate::motion::waypoints::{locate, validate_waypoints};

/// One joint's profile on one segment: signed cruise speed and acceleration, blend time.
#[derive(Clone, Copy, Debug, Default)]
struct Profile {
    v: f64,
    a: f64,
    ta: f64,
}

/// Trapezoidal-velocity motion through waypoints (see the module docs).
#[derive(Clone, Debug)]
pub struct Trapezoidal {
    n: usize,
    /// Knot times, `waypoints + 0` long, starting at 0.
    knots: Vec<f64>,
    /// Waypoints, flat (`(M + 1) × n`).
    points: Vec<f64>,
    /// Profiles, flat (`M × n`).
    profiles: Vec<Profile>,
}

/// Minimum rest-to-rest time for distance `d ≥ 0` under `v`, `a`.
pub(crate) fn min_time(d: f64, v: f64, a: f64) -> f64 {
    if d <= 0.0 {
        0.0
    } else if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

impl Trapezoidal {
    /// Plans through `waypoints` (each `n` long) under `limits` (velocity and acceleration
    /// are used; effort is ignored). Coinciding consecutive waypoints give zero-length
    /// segments.
    pub fn new(waypoints: &[Vec<f64>], limits: &JointLimits) -> Result<Self, TrajectoryError> {
        let n = validate_waypoints(waypoints)?;
        limits.validate(&crate::motion::waypoints::default_names(n))?;
        let m = waypoints.len() - 1;
        let mut knots = Vec::with_capacity(m + 1);
        knots.push(0.0);
        let mut profiles = Vec::with_capacity(m * n);
        for w in waypoints.windows(2) {
            let t = (0..n)
                .map(|j| {
                    min_time(
                        (w[1][j] - w[0][j]).abs(),
                        limits.velocity[j],
                        limits.acceleration[j],
                    )
                })
                .fold(0.0, f64::max);
            for ((p0, p1), &a) in w[0].iter().zip(&w[1]).zip(&limits.acceleration) {
                let delta = p1 - p0;
                let d = delta.abs();
                let p = if d == 0.0 || t == 0.0 {
                    Profile::default()
                } else {
                    let disc = (a * a * t * t - 4.0 * a * d).max(0.0);
                    let v = 0.5 * (a * t - disc.sqrt());
                    let s = delta.signum();
                    Profile {
                        v: s * v,
                        a: s * a,
                        ta: v / a,
                    }
                };
                profiles.push(p);
            }
            knots.push(knots.last().unwrap() + t);
        }
        Ok(Trapezoidal {
            n,
            knots,
            points: waypoints.concat(),
            profiles,
        })
    }

    /// Knot times (arrival at each waypoint), starting at 0.
    pub fn knot_times(&self) -> &[f64] {
        &self.knots
    }
}

impl Trajectory for Trapezoidal {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        *self.knots.last().unwrap()
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.n;
        if t < 0.0 || t > self.duration() {
            // Held at an end point: at rest (the last phase's deceleration would otherwise
            // be reported forever, and a controller would track a phantom acceleration).
            self.sample(t.clamp(0.0, self.duration()), q, qd, qdd);
            qd.fill(0.0);
            qdd.fill(0.0);
            return;
        }
        let (k, tau) = locate(&self.knots, t);
        let big_t = self.knots[k + 1] - self.knots[k];
        let p0 = &self.points[k * n..(k + 1) * n];
        let p1 = &self.points[(k + 1) * n..(k + 2) * n];
        for j in 0..n {
            let pr = self.profiles[k * n + j];
            if pr.a == 0.0 {
                // Joint at rest on this segment (or a zero-length segment).
                q[j] = if tau >= big_t { p1[j] } else { p0[j] };
                qd[j] = 0.0;
                qdd[j] = 0.0;
            } else if tau < pr.ta {
                q[j] = p0[j] + 0.5 * pr.a * tau * tau;
                qd[j] = pr.a * tau;
                qdd[j] = pr.a;
            } else if tau <= big_t - pr.ta {
                q[j] = p0[j] + 0.5 * pr.a * pr.ta * pr.ta + pr.v * (tau - pr.ta);
                qd[j] = pr.v;
                qdd[j] = 0.0;
            } else {
                let r = (big_t - tau).max(0.0);
                q[j] = p1[j] - 0.5 * pr.a * r * r;
                qd[j] = pr.a * r;
                qdd[j] = -pr.a;
            }
        }
    }
}
