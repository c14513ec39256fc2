//! Time-optimal path parameterisation (TOPP) under joint velocity, acceleration and torque
//! limits, and optionally joint jerk limits.
//!
//! Along a geometric path `q(s)`, `s ∈ [0, 1]`, with `b = ṡ²` and `a = s̈`:
//!
//! - `q̇ = q'(s) ṡ`, `q̈ = q'(s) a + q''(s) b`;
//! - `τ = m(s) a + c(s) b + g(s)` with `m = ID(q, 0, q') − g`, `c = ID(q, q', q'') − g`,
//!   `g = ID(q, 0, 0)`, `ID` the inverse dynamics with the selected [`Effects`] (rotor
//!   armature, payload and external wrenches enter `m`, `c`, `g` exactly, since they are
//!   linear in `q̈` or independent of the motion);
//! - `b' = 2a` (since `d(ṡ²)/ds = 2 s̈`), so on a grid `s_0 < … < s_N` with `a` constant
//!   per interval: `b_{i+1} − b_i = 2 Δs_i a_i` (`b` piecewise linear in `s`);
//! - the traversal time `T = ∫ ds/√b` becomes `Σ 2Δs_i / (√b_i + √b_{i+1})`, exact for `s̈`
//!   constant per interval (`Δt = Δs / mean ṡ`).
//!
//! Constraints. Velocity `q'_j(s_i)² b_i ≤ v_j²` at every knot. Acceleration
//! `|q'_j a_i + q''_j b| ≤ a_j` and torque `|m_j a_i + c_j b + g_j| ≤ τ_j` at **both ends of
//! every interval** with that interval's `a_i` (at `(s_i, b_i)` and `(s_{i+1}, b_{i+1})`):
//! the motion actually executed keeps `a_i` until `s_{i+1}`, where the plain scheme (one
//! point per `a_i`) would not look. This makes the discretised problem conservative: its
//! optimum approaches the continuous one from above, at first order in `Δs` (0.2 % at the
//! default 400 intervals on the UR5 test path).
//!
//! Two solvers of this same discretised problem ([`ToppMethod`]):
//!
//! - **reachability** (default, `reachability.rs`): TOPP-RA of Pham and Pham, *IEEE
//!   T-RO* 34(3), 2018 — a backward pass of controllable sets and a greedy forward pass,
//!   each step a two-variable LP solved exactly (`lp2.rs`); linear in `N`, no iterative
//!   solver, microseconds per grid point;
//! - **conic** (`socp.rs`): the second-order-cone program of Verscheure, Demeulenaere,
//!   Swevers, De Schutter and Diehl, *IEEE Trans. Automatic Control* 54(10), 2009, with
//!   their auxiliary variables `c_i ≤ √b_i` and `d_i ≥ 1/(c_i + c_{i+1})`, solved by
//!   clarabel (interior point) — the global optimum in one solve, used as the
//!   independent reference in the tests.
//!
//! Both solve the same discretised problem. The conic program returns its global
//! optimum; TOPP-RA's greedy profile is that optimum wherever the largest speed reachable
//! in one step does not decrease with the speed at the step's start (see
//! `reachability.rs`), and within a few `1e-5` (relative duration) of it on the test paths
//! (`tests/topp.rs` compares the two on the same problems).
//!
//! Grid. `s_i = φ(i/N)`, `φ(u) = u − β sin(2πu)/(2π)`, intervals `1 − β` times finer at
//! the ends than uniform (`β = 0.75` by default): a path that starts at rest, like the
//! minimum-jerk spline, has `q' → 0` at its ends, where `ṡ` varies fastest.
//!
//! Verification and refinement. The solution is rebuilt (`t(s)` from the constant-`s̈`
//! intervals) and checked inside every interval with the full inverse dynamics: at
//! `K + 2` equally spaced points, and where a sampled value is within 1 % of its limit,
//! at its local maximum, found by golden-section search between the neighbouring points.
//! Between knots the limits can be exceeded by the discretisation; each excess found on
//! interval `i` for joint `j` tightens that interval's bound by the excess (plus a small
//! relative margin) and the problem is solved again, until the check passes. The check
//! looks at velocities and accelerations first (path evaluations only) and adds the
//! torques (inverse dynamics at every check point) once those pass, so that the
//! kinematic repair rounds do not pay for the dynamics. Friction, which is not convex in
//! `ṡ` (`τ_f(q' ṡ)`, viscous and Coulomb), enters as a constant term per knot evaluated at
//! the previous solution's speed: a fixed-point iteration. A torque excess found while the
//! friction estimate is still moving updates the estimate instead of tightening (an
//! excess caused by a stale estimate must not become a permanent tightening); velocity
//! and acceleration excesses, which friction does not affect, are tightened at once. The
//! check always uses the exact friction, so the result is verified, not merely optimal
//! for the discretised problem. With joint elasticity the inverse dynamics gives the
//! transmitted (link-side) torque; that is what is limited.
//!
//! Jerk ([`crate::motion::joint_limits::JointLimits::jerk`], `jerk.rs`): the optimum above has a piecewise
//! constant `s̈`, hence unbounded jerk at the knots; with a jerk limit the motion is then
//! smoothed and slowed down until a dense check of `q⃛` passes (see `jerk.rs`).

mod check;
mod discretised;
mod jerk;
mod lp2;
mod reachability;
mod socp;
mod topp_options;
mod topp_trajectory;

pub use crate::motion::topp::topp_options::{ToppMethod, ToppOptions, ToppStats};
pub use crate::motion::topp::topp_trajectory::ToppTrajectory;

use crate::dynamics::{inverse_dynamics, Effects};
use crate::model::data::Data;
use crate::model::Model;
use crate::motion::motion_traits::Path;
use crate::motion::topp::check::{CheckReport, Checker};
use crate::motion::topp::discretised::{Grid, Problem};
use crate::motion::topp::reachability::Reach;
use crate::motion::topp::socp::{solve_socp, Layout};
use crate::motion::trajectory_error::TrajectoryError;
use std::time::Instant;

/// Friction fixed-point rounds allowed (besides the refinements).
const MAX_FRICTION_ROUNDS: usize = 20;
/// The friction estimate has converged when no joint's moved by more than this fraction
/// of its effort limit.
const FRICTION_TOL: f64 = 1e-4;

/// The solver of the discretised problem with its buffers.
enum Solver {
    Reach(Box<Reach>),
    Conic(Layout),
}

impl Solver {
    fn new(method: ToppMethod, nn: usize, n: usize) -> Self {
        match method {
            ToppMethod::Reachability => Solver::Reach(Box::new(Reach::new(nn, n))),
            ToppMethod::Conic => Solver::Conic(Layout { n_int: nn }),
        }
    }

    /// Solves `p` into `b` (clamped at 0).
    fn solve(
        &mut self,
        p: &Problem,
        b: &mut [f64],
        stats: &mut ToppStats,
    ) -> Result<(), TrajectoryError> {
        match self {
            Solver::Reach(r) => {
                let start = Instant::now();
                r.solve(p, b)?;
                stats.solves += 1;
                stats.solver_iterations += 2 * p.ds.len() as u32;
                stats.solve_time_s += start.elapsed().as_secs_f64();
            }
            Solver::Conic(lay) => {
                let x = solve_socp(lay, p, stats)?;
                for (i, bi) in b.iter_mut().enumerate() {
                    *bi = x[lay.b(i)].max(0.0);
                }
            }
        }
        Ok(())
    }
}

/// The time-optimal parameterisation of `path` under `limits` with the torques of
/// `effects` (see the module docs). Joints with an infinite effort limit have no torque
/// constraint. The returned motion starts and ends at rest and meets every limit on the
/// dense check grid to `opts.tolerance`; otherwise an error says by how much it did not.
/// With `limits.jerk`, the motion is smoothed and slowed down until the jerk limits hold
/// too (see `jerk.rs`).
pub fn topp<P: Path>(
    model: &Model,
    path: P,
    limits: &crate::motion::joint_limits::JointLimits,
    effects: &Effects,
    opts: &ToppOptions,
) -> Result<ToppTrajectory<P>, TrajectoryError> {
    let start = Instant::now();
    let n = model.nv;
    let names = model.dof_names();
    if path.dof() != n {
        return Err(TrajectoryError::Invalid(format!(
            "TOPP: the path has {} coordinates, the model {n}",
            path.dof()
        )));
    }
    limits.validate(&names)?;
    effects
        .validate(model)
        .map_err(|e| TrajectoryError::Invalid(e.to_string()))?;
    if opts.segments < 2 || opts.check_points == 0 || !(0.0..1.0).contains(&opts.end_refinement) {
        return Err(TrajectoryError::Invalid(
            "TOPP: need at least 2 segments, 1 check point and end_refinement in [0, 1)".into(),
        ));
    }
    let torque_on: Vec<bool> = limits.effort.iter().map(|e| e.is_finite()).collect();
    let any_torque = torque_on.iter().any(|&x| x);
    let rigid = Effects {
        friction: None,
        ..effects.clone()
    };
    let nn = opts.segments;
    let s = refined_knots(nn, opts.end_refinement);
    let ds: Vec<f64> = s.windows(2).map(|w| w[1] - w[0]).collect();
    let grid = sample_grid(model, &path, &s, any_torque.then_some(&rigid));
    check_static_ends(&grid, nn, limits, &torque_on, &names)?;
    let mut stats = ToppStats {
        segments: nn,
        method: opts.method,
        jerk_slowdown: 1.0,
        ..Default::default()
    };
    let setup = Setup {
        model,
        effects,
        limits,
        opts,
        grid: &grid,
        s: &s,
        ds: &ds,
        torque_on: &torque_on,
    };
    let (b, a, t) = solve_verified(&setup, &path, &mut stats)?;
    stats.duration = t[nn];
    stats.optimal_duration = t[nn];
    let mut traj = ToppTrajectory {
        path,
        n,
        s,
        b,
        a,
        t,
        smooth: None,
        stats,
    };
    if let Some(jl) = &limits.jerk {
        jerk::limit_jerk(model, effects, limits, jl, opts, &mut traj)?;
    }
    traj.stats.wall_time_s = start.elapsed().as_secs_f64();
    Ok(traj)
}

/// What stays fixed over the repair rounds of one [`topp`] call.
struct Setup<'a> {
    model: &'a Model,
    effects: &'a Effects,
    limits: &'a crate::motion::joint_limits::JointLimits,
    opts: &'a ToppOptions,
    grid: &'a Grid,
    s: &'a [f64],
    ds: &'a [f64],
    torque_on: &'a [bool],
}

type Profile = (Vec<f64>, Vec<f64>, Vec<f64>);

/// Solve, check densely, tighten where the check found an excess (or update the friction
/// estimate), until the check passes: `(b, a, t)` at the knots.
fn solve_verified<P: Path>(
    su: &Setup,
    path: &P,
    stats: &mut ToppStats,
) -> Result<Profile, TrajectoryError> {
    let (n, nn) = (su.torque_on.len(), su.ds.len());
    let any_torque = su.torque_on.iter().any(|&x| x);
    let opts = su.opts;
    // Tightening (amount subtracted from each limit) per knot (velocity) and per interval
    // (acceleration, torque), and friction at the knots.
    let mut tight_v = vec![0.0; (nn + 1) * n];
    let mut tight_a = vec![0.0; nn * n];
    let mut tight_t = vec![0.0; nn * n];
    let mut fric = vec![0.0; (nn + 1) * n];
    let mut solver = Solver::new(opts.method, nn, n);
    let mut checker = Checker::new(su.model, n);
    let mut b = vec![0.0; nn + 1];
    let mut a = vec![0.0; nn];
    // Torques join the check once the kinematic limits pass.
    let mut with_torque = !any_torque;
    let (mut refinements, mut friction_rounds) = (0, 0);
    loop {
        let p = Problem {
            grid: su.grid,
            s: su.s,
            ds: su.ds,
            limits: su.limits,
            torque_on: su.torque_on,
            tight_v: &tight_v,
            tight_a: &tight_a,
            tight_t: &tight_t,
            fric: &fric,
        };
        solver.solve(&p, &mut b, stats)?;
        // `a` from `b` so that the rebuilt motion is exactly consistent.
        for i in 0..nn {
            a[i] = (b[i + 1] - b[i]) / (2.0 * su.ds[i]);
        }
        let t = knot_times(&b, su.ds)?;
        let mut check = |torque: bool| {
            let (m, fx, lim) = (su.model, su.effects, su.limits);
            checker.check(m, fx, path, lim, su.s, &b, &a, opts.check_points, torque)
        };
        let mut report = check(with_torque && any_torque);
        if !with_torque && report.worst() <= 1.0 + opts.tolerance {
            with_torque = true;
            report = check(true);
        }
        stats.max_velocity_ratio = report.ratio[0];
        stats.max_acceleration_ratio = report.ratio[1];
        stats.max_torque_ratio = report.ratio[2];
        let worst = report.worst();
        if worst <= 1.0 + opts.tolerance {
            return Ok((b, a, t));
        }
        if refinements == opts.max_refinements {
            return Err(TrajectoryError::Topp(format!(
                "after {} solves the motion still exceeds a limit by {:.3e} (relative; velocity \
                 {:.3e}, acceleration {:.3e}, torque {:.3e}); use more segments",
                stats.solves,
                worst - 1.0,
                report.ratio[0] - 1.0,
                report.ratio[1] - 1.0,
                report.ratio[2] - 1.0
            )));
        }
        // Friction at the new speeds, for the next round; whether it moved.
        let friction_moved = match &su.effects.friction {
            Some(fr) => update_friction(fr, su.grid, &b, su.limits, su.torque_on, &mut fric),
            None => false,
        };
        // Fixed-point step on the friction first: torque excesses wait for it to settle.
        let torque_too = !(friction_moved && friction_rounds < MAX_FRICTION_ROUNDS);
        let tightened = tighten(
            &report,
            su.limits,
            su.torque_on,
            opts.margin,
            torque_too,
            [&mut tight_v, &mut tight_a, &mut tight_t],
        );
        if tightened {
            refinements += 1;
        } else {
            friction_rounds += 1;
        }
    }
}

/// The knots `s_i = φ(i/N)`, `φ(u) = u − β sin(2πu)/(2π)`: spacing `(1 − β)/N` at the
/// ends, where the path starts and stops.
fn refined_knots(nn: usize, beta: f64) -> Vec<f64> {
    (0..=nn)
        .map(|i| {
            let u = i as f64 / nn as f64;
            if i == nn {
                1.0
            } else {
                u - beta * (2.0 * std::f64::consts::PI * u).sin() / (2.0 * std::f64::consts::PI)
            }
        })
        .collect()
}

/// The path's derivatives at the knots and, with `rigid` effects (some joint has a
/// torque limit), the dynamics along it: `τ = m(s) s̈ + c(s) ṡ² + g(s)`.
fn sample_grid<P: Path>(model: &Model, path: &P, s: &[f64], rigid: Option<&Effects>) -> Grid {
    let n = model.nv;
    let len = s.len() * n;
    let mut data = Data::new(model);
    let zero = vec![0.0; n];
    let mut q = vec![0.0; n];
    let mut g = vec![0.0; n];
    let mut grid = Grid {
        dq: vec![0.0; len],
        ddq: vec![0.0; len],
        m: vec![0.0; len],
        c: vec![0.0; len],
        g: vec![0.0; len],
    };
    for (i, &si) in s.iter().enumerate() {
        let r = i * n..(i + 1) * n;
        path.eval(
            si,
            &mut q,
            &mut grid.dq[r.clone()],
            &mut grid.ddq[r.clone()],
        );
        if let Some(rigid) = rigid {
            g.copy_from_slice(inverse_dynamics(model, &mut data, rigid, &q, &zero, &zero));
            let m = inverse_dynamics(model, &mut data, rigid, &q, &zero, &grid.dq[r.clone()]);
            for (k, x) in m.iter().enumerate() {
                grid.m[i * n + k] = x - g[k];
            }
            let c = inverse_dynamics(
                model,
                &mut data,
                rigid,
                &q,
                &grid.dq[r.clone()],
                &grid.ddq[r.clone()],
            );
            for (k, x) in c.iter().enumerate() {
                grid.c[i * n + k] = x - g[k];
            }
            grid.g[r].copy_from_slice(&g);
        }
    }
    grid
}

/// Static feasibility at the ends (at rest, `τ = g`): the arm must be able to hold still.
fn check_static_ends(
    grid: &Grid,
    nn: usize,
    limits: &crate::motion::joint_limits::JointLimits,
    torque_on: &[bool],
    names: &[String],
) -> Result<(), TrajectoryError> {
    let n = torque_on.len();
    for (i, at) in [(0, "start"), (nn, "end")] {
        for j in 0..n {
            let g = grid.g[i * n + j];
            if torque_on[j] && g.abs() > limits.effort[j] {
                return Err(TrajectoryError::Topp(format!(
                    "at the {at} of the path the static torque of joint {} is {g:.4} N m, above \
                     its effort limit {:.4}: the arm cannot even hold still there",
                    names[j], limits.effort[j]
                )));
            }
        }
    }
    Ok(())
}

/// The times at the knots from `b = ṡ²`: `Δt_i = 2 Δs_i / (√b_i + √b_{i+1})`.
fn knot_times(b: &[f64], ds: &[f64]) -> Result<Vec<f64>, TrajectoryError> {
    let nn = ds.len();
    let mut t = vec![0.0; nn + 1];
    for i in 0..nn {
        let sum = b[i].sqrt() + b[i + 1].sqrt();
        if sum <= 0.0 {
            return Err(TrajectoryError::Topp(format!(
                "the path speed is zero on interval {i}: the solution is degenerate"
            )));
        }
        t[i + 1] = t[i] + 2.0 * ds[i] / sum;
    }
    Ok(t)
}

/// The friction torques at the knots at the speeds `√b` into `fric`; whether one moved
/// by more than the tolerance (relative to its joint's effort limit).
fn update_friction(
    fr: &crate::dynamics::Friction,
    grid: &Grid,
    b: &[f64],
    limits: &crate::motion::joint_limits::JointLimits,
    torque_on: &[bool],
    fric: &mut [f64],
) -> bool {
    let n = torque_on.len();
    let mut friction_moved = false;
    for (i, bi) in b.iter().enumerate() {
        let sd = bi.sqrt();
        for j in 0..n {
            let f = fr.torque(j, grid.dq[i * n + j] * sd);
            let lim = limits.effort[j];
            friction_moved |= torque_on[j] && (f - fric[i * n + j]).abs() > FRICTION_TOL * lim;
            fric[i * n + j] = f;
        }
    }
    friction_moved
}

/// Tightens the limits where the dense check found an excess, by the excess plus a
/// margin: velocity at both knots of an interval, acceleration and (if `torque_too`)
/// torque on it. Whether anything was tightened.
fn tighten(
    report: &CheckReport,
    limits: &crate::motion::joint_limits::JointLimits,
    torque_on: &[bool],
    margin: f64,
    torque_too: bool,
    [tight_v, tight_a, tight_t]: [&mut Vec<f64>; 3],
) -> bool {
    let n = torque_on.len();
    let mut any = false;
    let nn = tight_a.len() / n.max(1);
    for i in 0..nn {
        for j in 0..n {
            let e = report.excess_v[i * n + j];
            if e > 0.0 {
                any = true;
                let add = e + margin * limits.velocity[j];
                tight_v[i * n + j] += add;
                tight_v[(i + 1) * n + j] += add;
            }
            let e = report.excess_a[i * n + j];
            if e > 0.0 {
                any = true;
                tight_a[i * n + j] += e + margin * limits.acceleration[j];
            }
            let e = report.excess_t[i * n + j];
            if e > 0.0 && torque_on[j] && torque_too {
                any = true;
                tight_t[i * n + j] += e + margin * limits.effort[j];
            }
        }
    }
    any
}

/// The straight joint-space line `q(s) = q₀ + s (q₁ − q₀)`.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearPath {
    q0: Vec<f64>,
    q1: Vec<f64>,
}

impl LinearPath {
    /// From `q0` to `q1` (same length).
    pub fn new(q0: Vec<f64>, q1: Vec<f64>) -> Result<Self, TrajectoryError> {
        if q0.len() != q1.len() || q0.is_empty() {
            return Err(TrajectoryError::Invalid(format!(
                "linear path: {} and {} coordinates",
                q0.len(),
                q1.len()
            )));
        }
        Ok(LinearPath { q0, q1 })
    }
}

impl Path for LinearPath {
    fn dof(&self) -> usize {
        self.q0.len()
    }

    fn eval(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64]) {
        let s = s.clamp(0.0, 1.0);
        for j in 0..self.q0.len() {
            let d = self.q1[j] - self.q0[j];
            q[j] = self.q0[j] + s * d;
            dq[j] = d;
            ddq[j] = 0.0;
        }
    }

    fn eval3(&self, s: f64, q: &mut [f64], dq: &mut [f64], ddq: &mut [f64], dddq: &mut [f64]) {
        self.eval(s, q, dq, ddq);
        dddq.fill(0.0);
    }
}
