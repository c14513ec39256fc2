//! Minimum-jerk motion through via points: the quintic spline with continuous derivatives
//! up to the fourth at the interior knots, at rest (zero velocity and acceleration) at
//! both ends.
//!
//! Among all motions through the waypoints at the knot times `t₀ < … < t_M`, the one
//! minimising `∫ ‖q⃛‖² dt` is piecewise quintic with `q`, `q̇`, `q̈`, `q⃛`, `q⁗` continuous at
//! the interior knots (Flash & Hogan 1985): the Euler–Lagrange equation gives `q⁽⁶⁾ = 0`
//! between knots, and since a via point fixes only `q(t_k)`, the boundary terms
//! `[δq̈ q⃛ − δq̇ q⁗]` of the first variation vanish for free `δq̇`, `δq̈` only if `q⃛` and `q⁗`
//! are continuous there.
//!
//! Each segment is the quintic Hermite polynomial of its end values `(p, v, a)` (see
//! `quintic.rs`). The positions are the waypoints and `v = a = 0` at the ends; the
//! `2(M − 1)` unknowns `(v_k, a_k)` at the interior knots come from the `2(M − 1)`
//! conditions
//!
//! `q⃛_{k−1}(t_k⁻) = q⃛_k(t_k⁺)`,  `q⁗_{k−1}(t_k⁻) = q⁗_k(t_k⁺)`,  `k = 1 … M − 1`,
//!
//! a block-tridiagonal linear system (one LU factorisation, one solve per joint). Both
//! jerk and snap are linear in the end values, so the coefficients are read off the
//! Hermite formulas by evaluating them on unit vectors.
//!
//! Segment times: start from each segment's quintic rest-to-rest time under the limits,
//! rebalance a few times (`h_k ← h_k r_k`, with `r_k = max_j max(|q̇|/v_j, √(|q̈|/a_j))`
//! the segment's peak ratio), then scale all times by `r = max_k r_k`. A uniform time
//! scale `t → r t` divides velocities by `r` and accelerations by `r²`, so afterwards every
//! limit holds and the binding one is met exactly. Peaks are found exactly up to rounding:
//! the extrema of each polynomial piece are the roots of its derivative, located by
//! sign changes on a fine grid and refined by bisection.

use crate::motion::joint_limits::JointLimits;
use crate::motion::motion_traits::{Path, Trajectory};
use crate::motion::quintic::{hermite, min_time, poly3};
use crate::motion::trajectory_error::TrajectoryError;
use crate::motion::waypoints::{locate, validate_waypoints};
use nalgebra::DMatrix;

/// Rebalancing rounds of the segment times.
const REBALANCE: usize = 6;

/// Minimum-jerk quintic spline through via points (see the module docs).
#[derive(Clone, Debug)]
pub struct MinJerk {
    n: usize,
    knots: Vec<f64>,
    /// Coefficients in local time, flat (`M × n`).
    coef: Vec<[f64; 6]>,
}

/// `∂(jerk, snap at both ends)/∂x` for a segment of length `h`, `x = [p₀,v₀,a₀,p₁,v₁,a₁]`:
/// rows jerk(0), jerk(h), snap(0), snap(h).
fn end_derivative_maps(h: f64) -> [[f64; 6]; 4] {
    let mut out = [[0.0; 6]; 4];
    for i in 0..6 {
        let mut x = [0.0; 6];
        x[i] = 1.0;
        let c = hermite(h, x);
        out[0][i] = 6.0 * c[3];
        out[1][i] = 6.0 * c[3] + 24.0 * c[4] * h + 60.0 * c[5] * h * h;
        out[2][i] = 24.0 * c[4];
        out[3][i] = 24.0 * c[4] + 120.0 * c[5] * h;
    }
    out
}

/// Evaluates `Σ cᵢ tⁱ` (coefficients in increasing degree).
#[inline]
fn horner(c: &[f64], t: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, x| acc * t + x)
}

/// `max |p(t)|` over `[0, h]` for a polynomial `p` with derivative `dp`: the ends, a fine
/// grid, and the roots of `dp` (sign changes refined by bisection).
pub(crate) fn max_abs_poly(p: &[f64], dp: &[f64], h: f64) -> f64 {
    const GRID: usize = 32;
    let mut best = horner(p, 0.0).abs().max(horner(p, h).abs());
    let mut t0 = 0.0;
    let mut d0 = horner(dp, 0.0);
    for i in 1..=GRID {
        let t1 = h * i as f64 / GRID as f64;
        let d1 = horner(dp, t1);
        best = best.max(horner(p, t1).abs());
        if d0 == 0.0 {
            best = best.max(horner(p, t0).abs());
        } else if d0 * d1 < 0.0 {
            let (mut lo, mut hi) = (t0, t1);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if horner(dp, mid) * d0 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            best = best.max(horner(p, 0.5 * (lo + hi)).abs());
        }
        t0 = t1;
        d0 = d1;
    }
    best
}

impl MinJerk {
    /// Plans through `waypoints` with segment times scaled to `limits` (velocity and
    /// acceleration; see the module docs). Consecutive waypoints must differ.
    pub fn new(waypoints: &[Vec<f64>], limits: &JointLimits) -> Result<Self, TrajectoryError> {
        let n = validate_waypoints(waypoints)?;
        limits.validate(&crate::motion::waypoints::default_names(n))?;
        let mut h: Vec<f64> = waypoints
            .windows(2)
            .map(|w| {
                (0..n)
                    .map(|j| {
                        min_time(
                            (w[1][j] - w[0][j]).abs(),
                            limits.velocity[j],
                            limits.acceleration[j],
                        )
                    })
                    .fold(0.0, f64::max)
            })
            .collect();
        if let Some(k) = h.iter().position(|&x| x <= 0.0) {
            return Err(TrajectoryError::Invalid(format!(
                "minimum-jerk spline: waypoints {k} and {} coincide",
                k + 1
            )));
        }
        let mut spline = Self::with_durations(waypoints, &h)?;
        for _ in 0..REBALANCE {
            let r = spline.segment_ratios(limits);
            for (hk, rk) in h.iter_mut().zip(&r) {
                *hk *= rk;
            }
            spline = Self::with_durations(waypoints, &h)?;
        }
        let r = spline
            .segment_ratios(limits)
            .into_iter()
            .fold(0.0, f64::max);
        for hk in h.iter_mut() {
            *hk *= r;
        }
        Self::with_durations(waypoints, &h)
    }

    /// The spline through `waypoints` with the given segment durations (all > 0).
    pub fn with_durations(
        waypoints: &[Vec<f64>],
        durations: &[f64],
    ) -> Result<Self, TrajectoryError> {
        let n = validate_waypoints(waypoints)?;
        let m = waypoints.len() - 1;
        if durations.len() != m {
            return Err(TrajectoryError::Invalid(format!(
                "{} segment durations for {m} segments",
                durations.len()
            )));
        }
        if let Some(k) = durations.iter().position(|&h| !(h > 0.0 && h.is_finite())) {
            return Err(TrajectoryError::Invalid(format!(
                "segment {k}: duration {} is not positive and finite",
                durations[k]
            )));
        }
        let mut knots = Vec::with_capacity(m + 1);
        knots.push(0.0);
        for h in durations {
            knots.push(knots.last().unwrap() + h);
        }
        // Interior unknowns (v_k, a_k), k = 1 … m−1, at 2(k−1), 2(k−1)+1.
        let nu = 2 * (m - 1);
        let maps: Vec<[[f64; 6]; 4]> = durations.iter().map(|&h| end_derivative_maps(h)).collect();
        let mut a = DMatrix::zeros(nu, nu);
        // rhs_p[row][knot]: coefficient of waypoint `knot`'s position in equation `row`
        // (moved to the right-hand side per joint).
        let mut rhs_p = vec![[0.0f64; 3]; nu];
        for k in 1..m {
            // Rows: jerk continuity, snap continuity at knot k.
            for (r, (end_row, start_row)) in [(1usize, 0usize), (3, 2)].into_iter().enumerate() {
                let row = 2 * (k - 1) + r;
                let left = &maps[k - 1][end_row]; // segment k−1, x = [p,v,a]_{k−1}, [p,v,a]_k
                let right = &maps[k][start_row]; // segment k,   x = [p,v,a]_k,   [p,v,a]_{k+1}
                                                 // Knot index of each x entry for both segments,
                                                 // and the sign.
                for (coefs, first_knot, sign) in [(left, k - 1, 1.0), (right, k, -1.0)] {
                    for (i, &c) in coefs.iter().enumerate() {
                        let knot = first_knot + i / 3;
                        let what = i % 3;
                        let c = sign * c;
                        if what == 0 {
                            rhs_p[row][knot + 1 - k] -= c;
                        } else if knot > 0 && knot < m {
                            a[(row, 2 * (knot - 1) + what - 1)] += c;
                        }
                    }
                }
            }
        }
        let lu = a.lu();
        let mut va = vec![0.0; nu];
        let mut coef = vec![[0.0; 6]; m * n];
        let mut b = nalgebra::DVector::zeros(nu);
        for j in 0..n {
            for row in 0..nu {
                let k = row / 2 + 1;
                b[row] = (0..3)
                    .map(|d| rhs_p[row][d] * waypoints[k - 1 + d][j])
                    .sum();
            }
            if nu > 0 {
                let x = lu.solve(&b).ok_or_else(|| {
                    TrajectoryError::Invalid("minimum-jerk spline: singular system".into())
                })?;
                va.copy_from_slice(x.as_slice());
            }
            let end = |knot: usize| -> (f64, f64) {
                if knot == 0 || knot == m {
                    (0.0, 0.0)
                } else {
                    (va[2 * (knot - 1)], va[2 * (knot - 1) + 1])
                }
            };
            for k in 0..m {
                let (v0, a0) = end(k);
                let (v1, a1) = end(k + 1);
                coef[k * n + j] = hermite(
                    durations[k],
                    [waypoints[k][j], v0, a0, waypoints[k + 1][j], v1, a1],
                );
            }
        }
        Ok(MinJerk { n, knots, coef })
    }

    /// Knot times (arrival at each waypoint), starting at 0.
    pub fn knot_times(&self) -> &[f64] {
        &self.knots
    }

    /// Polynomial coefficients (local time, increasing degree) of joint `j` on segment `k`.
    pub fn coefficients(&self, k: usize, j: usize) -> [f64; 6] {
        self.coef[k * self.n + j]
    }

    /// Peak `|q̇_j|` and `|q̈_j|` over the whole motion, per joint.
    pub fn peaks(&self) -> (Vec<f64>, Vec<f64>) {
        let n = self.n;
        let mut pv = vec![0.0f64; n];
        let mut pa = vec![0.0f64; n];
        for k in 0..self.knots.len() - 1 {
            let h = self.knots[k + 1] - self.knots[k];
            for j in 0..n {
                let (v, a) = Self::segment_peaks(&self.coef[k * n + j], h);
                pv[j] = pv[j].max(v);
                pa[j] = pa[j].max(a);
            }
        }
        (pv, pa)
    }

    fn segment_peaks(c: &[f64; 6], h: f64) -> (f64, f64) {
        let d1 = [c[1], 2.0 * c[2], 3.0 * c[3], 4.0 * c[4], 5.0 * c[5]];
        let d2 = [2.0 * c[2], 6.0 * c[3], 12.0 * c[4], 20.0 * c[5]];
        let d3 = [6.0 * c[3], 24.0 * c[4], 60.0 * c[5]];
        (max_abs_poly(&d1, &d2, h), max_abs_poly(&d2, &d3, h))
    }

    /// Per segment, `max_j max(|q̇_j|/v_j, √(|q̈_j|/a_j))`.
    fn segment_ratios(&self, limits: &JointLimits) -> Vec<f64> {
        let n = self.n;
        (0..self.knots.len() - 1)
            .map(|k| {
                let h = self.knots[k + 1] - self.knots[k];
                (0..n)
                    .map(|j| {
                        let (v, a) = Self::segment_peaks(&self.coef[k * n + j], h);
                        (v / limits.velocity[j]).max((a / limits.acceleration[j]).sqrt())
                    })
                    .fold(0.0, f64::max)
            })
            .collect()
    }
}

impl Trajectory for MinJerk {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        *self.knots.last().unwrap()
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let n = self.n;
        let (k, tau) = locate(&self.knots, t);
        for j in 0..n {
            let (a, b, c) = poly3(&self.coef[k * n + j], tau);
            q[j] = a;
            qd[j] = b;
            qdd[j] = c;
        }
    }
}

/// The spline as a geometric path, `s = t / T`: `q'(s) = T q̇`, `q''(s) = T² q̈`.
impl Path for MinJerk {
    fn dof(&self) -> usize {
        self.n
    }

    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let big_t = self.duration();
        self.sample(s.clamp(0.0, 1.0) * big_t, q, dq, ddq);
        for (d, dd) in dq.iter_mut().zip(ddq.iter_mut()) {
            *d *= big_t;
            *dd *= big_t * big_t;
        }
    }

    fn eval3(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64], dddq: &mut [f64]) {
        self.eval(s, q, dq, ddq);
        let big_t = self.duration();
        let n = self.n;
        let (k, tau) = locate(&self.knots, s.clamp(0.0, 1.0) * big_t);
        for (j, d3) in dddq.iter_mut().enumerate() {
            let c = &self.coef[k * n + j];
            let jerk = 6.0 * c[3] + tau * (24.0 * c[4] + tau * 60.0 * c[5]);
            *d3 = jerk * big_t * big_t * big_t;
        }
    }
}
