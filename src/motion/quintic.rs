//! Rest-to-rest quintic polynomials per segment, and the quintic Hermite segment the
//! minimum-jerk spline is made of.
//!
//! Per segment `q(t) = q₀ + Δ σ(u)`, `u = t/T`, with the minimum-jerk point-to-point
//! profile (Flash & Hogan, *J. Neurosci.* 5(7):1688–1703, 1985):
//!
//! `σ(u) = 10u³ − 15u⁴ + 6u⁵`, so `q̇ = q̈ = 0` at both waypoints.
//!
//! Its peaks are `max σ' = 15/8` at `u = ½` and `max |σ''| = 10/√3` at
//! `u = ½ ∓ √3/6`. Joint `j` therefore needs `T_j = max(15 d_j / (8 v_j), √(10 d_j / (√3 a_j)))`
//! and the segment takes `T = max_j T_j`; the slowest joint reaches its limit, the others
//! move proportionally on the same `σ` (a straight line in joint space).
//!
//! The general quintic Hermite segment on `[0, h]` with end values `(p, v, a)` at both ends
//! has (the quintic with assigned end conditions, e.g. Biagiotti & Melchiorri,
//! *Trajectory Planning for Automatic Machines and Robots*, 2008, ch. 2) `c₀ = p₀`, `c₁ = v₀`, `c₂
//! = a₀/2`,
//!
//! - `c₃ = (20Δp − (8v₁ + 12v₀)h − (3a₀ − a₁)h²) / (2h³)`,
//! - `c₄ = (−30Δp + (14v₁ + 16v₀)h + (3a₀ − 2a₁)h²) / (2h⁴)`,
//! - `c₅ = (12Δp − 6(v₁ + v₀)h + (a₁ − a₀)h²) / (2h⁵)`.

use crate::motion::joint_limits::JointLimits;
use crate::motion::motion_traits::Trajectory;
use crate::motion::trajectory_error::TrajectoryError;
use crate::motion::waypoints::{locate, validate_waypoints};

/// `max σ'` of the quintic profile.
pub(crate) const PEAK_VEL: f64 = 1.875;
/// `max |σ''|` of the quintic profile, `10/√3`.
pub(crate) const PEAK_ACC: f64 = 5.773_502_691_896_258;

/// `σ(u), σ'(u), σ''(u)` of the rest-to-rest quintic, `u ∈ [0, 1]`.
#[inline]
pub(crate) fn sigma(u: f64) -> (f64, f64, f64) {
    let u2 = u * u;
    let u3 = u2 * u;
    (
        u3 * (10.0 + u * (-15.0 + 6.0 * u)),
        u2 * (30.0 + u * (-60.0 + 30.0 * u)),
        u * (60.0 + u * (-180.0 + 120.0 * u)),
    )
}

/// Shortest quintic rest-to-rest time for distance `d` under `v`, `a`.
pub(crate) fn min_time(d: f64, v: f64, a: f64) -> f64 {
    (PEAK_VEL * d / v).max((PEAK_ACC * d / a).sqrt())
}

/// Coefficients `c₀…c₅` (in local time) of the quintic Hermite segment of length `h`
/// with end values `x = [p₀, v₀, a₀, p₁, v₁, a₁]`.
#[inline]
pub(crate) fn hermite(h: f64, x: [f64; 6]) -> [f64; 6] {
    let [p0, v0, a0, p1, v1, a1] = x;
    let dp = p1 - p0;
    let (h2, h3) = (h * h, h * h * h);
    [
        p0,
        v0,
        0.5 * a0,
        (20.0 * dp - (8.0 * v1 + 12.0 * v0) * h - (3.0 * a0 - a1) * h2) / (2.0 * h3),
        (-30.0 * dp + (14.0 * v1 + 16.0 * v0) * h + (3.0 * a0 - 2.0 * a1) * h2) / (2.0 * h3 * h),
        (12.0 * dp - 6.0 * (v1 + v0) * h + (a1 - a0) * h2) / (2.0 * h3 * h2),
    ]
}

/// Value and first two derivatives of `Σ cᵢ τⁱ` (Horner).
#[inline]
pub(crate) fn poly3(c: &[f64; 6], t: f64) -> (f64, f64, f64) {
    let q = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))));
    let qd = c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4] + t * 5.0 * c[5])));
    let qdd = 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]));
    (q, qd, qdd)
}

/// Quintic rest-to-rest segments through waypoints (see the module docs).
#[derive(Clone, Debug)]
pub struct Quintic {
    n: usize,
    knots: Vec<f64>,
    points: Vec<f64>,
}

impl Quintic {
    /// Plans through `waypoints` under `limits` (velocity and acceleration).
    pub fn new(waypoints: &[Vec<f64>], limits: &JointLimits) -> Result<Self, TrajectoryError> {
        let n = validate_waypoints(waypoints)?;
        limits.validate(&crate::motion::waypoints::default_names(n))?;
        let mut knots = vec![0.0];
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
            knots.push(knots.last().unwrap() + t);
        }
        Ok(Quintic {
            n,
            knots,
            points: waypoints.concat(),
        })
    }

    /// Knot times (arrival at each waypoint), starting at 0.
    pub fn knot_times(&self) -> &[f64] {
        &self.knots
    }
}

impl Trajectory for Quintic {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        *self.knots.last().unwrap()
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.n;
        let (k, tau) = locate(&self.knots, t);
        let h = self.knots[k + 1] - self.knots[k];
        let p0 = &self.points[k * n..(k + 1) * n];
        let p1 = &self.points[(k + 1) * n..(k + 2) * n];
        if h <= 0.0 {
            q.copy_from_slice(p1);
            qd.fill(0.0);
            qdd.fill(0.0);
            return;
        }
        let (s, sd, sdd) = sigma((tau / h).clamp(0.0, 1.0));
        for j in 0..n {
            let d = p1[j] - p0[j];
            q[j] = p0[j] + d * s;
            qd[j] = d * sd / h;
            qdd[j] = d * sdd / (h * h);
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::motion::quintic::*;

    #[test]
    fn hermite_meets_its_end_conditions() {
        let h = 0.7;
        let x = [0.3, -1.2, 2.5, 1.1, 0.4, -3.0];
        let c = hermite(h, x);
        let (p0, v0, a0) = poly3(&c, 0.0);
        let (p1, v1, a1) = poly3(&c, h);
        for (got, want) in [p0, v0, a0, p1, v1, a1].iter().zip(x) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn sigma_peaks() {
        let (_, v, _) = sigma(0.5);
        assert!((v - PEAK_VEL).abs() < 1e-15);
        let u = 0.5 - 3f64.sqrt() / 6.0;
        let (_, _, a) = sigma(u);
        assert!((a - PEAK_ACC).abs() < 1e-12);
    }
}
