//! Time-optimal path parameterisation (TOPP) under joint velocity, acceleration and torque
//! limits, as the convex program of Verscheure, Demeulenaere, Swevers, De Schutter and
//! Diehl, "Time-optimal path tracking for robots: a convex optimization approach", *IEEE
//! Trans. Automatic Control* 54(10), 2009.
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
//! The problem is made a second-order-cone program with their auxiliary variables:
//! `c_i ≤ √b_i` as `‖(2c_i, b_i − 1)‖ ≤ b_i + 1`, and `d_i ≥ 1/(c_i + c_{i+1})` as
//! `‖(2, c_i + c_{i+1} − d_i)‖ ≤ c_i + c_{i+1} + d_i`; minimise `Σ 2Δs_i d_i` subject to the
//! linear constraints, `b_0 = b_N = 0` (rest to rest), solved by clarabel (interior point;
//! `ZeroConeT`, `NonnegativeConeT`, `SecondOrderConeT`).
//!
//! Constraints. Velocity `q'_j(s_i)² b_i ≤ v_j²` at every knot. Acceleration
//! `|q'_j a_i + q''_j b| ≤ a_j` and torque `|m_j a_i + c_j b + g_j| ≤ τ_j` at **both ends of
//! every interval** with that interval's `a_i` (at `(s_i, b_i)` and `(s_{i+1}, b_{i+1})`):
//! the motion actually executed keeps `a_i` until `s_{i+1}`, where the plain scheme (one
//! point per `a_i`) would not look. This makes the discretised problem conservative: its
//! optimum approaches the continuous one from above, at first order in `Δs` (0.2 % at the
//! default 400 intervals on the UR5 test path).
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
//! relative margin) and the SOCP is solved again, until the check passes. Friction, which
//! is not convex in `ṡ` (`τ_f(q' ṡ)`, viscous and Coulomb), enters as a constant term
//! evaluated at the previous solution's speed: a fixed-point iteration, run until the
//! friction estimate settles before any tightening, while the check always uses the exact
//! friction. The result is therefore verified, not merely optimal for the discretised
//! problem. With joint elasticity the inverse dynamics gives the transmitted (link-side)
//! torque; that is what is limited.
//!
//! Why the convex formulation rather than TOPP-RA (Pham & Pham, *IEEE T-RO* 34(3), 2018):
//! it returns the global optimum of the discretised problem in one solve with the conic
//! solver the crate already uses (no controllable-set bookkeeping, no special cases at
//! zero-inertia points), and its constraints are exactly those the check verifies;
//! TOPP-RA is faster (linear in `N`), a speed not needed at a few hundred grid points.

use super::{Path, Trajectory, TrajectoryError};
use crate::data::Data;
use crate::dynamics::{inverse_dynamics, Effects};
use crate::model::Model;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus,
    SupportedConeT, ZeroConeT,
};
use std::time::Instant;

/// Friction fixed-point rounds allowed (besides the refinements).
const MAX_FRICTION_ROUNDS: usize = 20;
/// The friction estimate has converged when no joint's moved by more than this fraction
/// of its effort limit.
const FRICTION_TOL: f64 = 1e-4;

/// Options of [`topp`].
#[derive(Clone, Debug)]
pub struct ToppOptions {
    /// Grid intervals `N` along `s`.
    pub segments: usize,
    /// Dense check points per interval (besides its two ends).
    pub check_points: usize,
    /// Refinement rounds (re-solves) allowed after the first solve.
    pub max_refinements: usize,
    /// Accepted relative excess in the dense check (`|x| ≤ (1 + tol) limit`).
    pub tolerance: f64,
    /// Extra relative tightening added to each excess found.
    pub margin: f64,
    /// Grid grading `β ∈ [0, 1)`: `s_i = φ(i/N)` with `φ(u) = u − β sin(2πu)/(2π)`, so
    /// intervals at the ends are `1 − β` times the uniform `1/N` (paths that start and
    /// end at rest, like the minimum-jerk spline, have `q' → 0` there and need the
    /// resolution); 0 gives a uniform grid.
    pub end_refinement: f64,
}

impl Default for ToppOptions {
    fn default() -> Self {
        ToppOptions {
            segments: 400,
            check_points: 8,
            max_refinements: 10,
            tolerance: 1e-9,
            margin: 1e-8,
            end_refinement: 0.75,
        }
    }
}

/// Figures of a TOPP solve.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ToppStats {
    /// Duration of the time-optimal motion (s).
    pub duration: f64,
    /// Grid intervals.
    pub segments: usize,
    /// SOCP solves (1 + refinements).
    pub solves: usize,
    /// Interior-point iterations over all solves.
    pub solver_iterations: u32,
    /// Time inside clarabel over all solves (s).
    pub solve_time_s: f64,
    /// Wall time of the whole [`topp`] call (s).
    pub wall_time_s: f64,
    /// Largest `|q̇_j| / v_j` on the dense check grid.
    pub max_velocity_ratio: f64,
    /// Largest `|q̈_j| / a_j` on the dense check grid.
    pub max_acceleration_ratio: f64,
    /// Largest `|τ_j| / τ_max,j` on the dense check grid (0 without torque limits).
    pub max_torque_ratio: f64,
}

/// A time-optimal motion along a path: the path, the grid `s_i`, `b_i = ṡ_i²`, `a_i = s̈`
/// on each interval, and the knot times `t_i`.
#[derive(Clone, Debug)]
pub struct ToppTrajectory<P> {
    path: P,
    n: usize,
    s: Vec<f64>,
    b: Vec<f64>,
    a: Vec<f64>,
    t: Vec<f64>,
    stats: ToppStats,
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

    /// Grid `s_i`, path speeds `ṡ_i`, and times `t_i` at the knots.
    pub fn profile(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        (
            self.s.clone(),
            self.b.iter().map(|b| b.sqrt()).collect(),
            self.t.clone(),
        )
    }
}

/// `x ↦ b, a, c, d` variable indices for `N` intervals.
struct Layout {
    n_int: usize,
}

impl Layout {
    fn b(&self, i: usize) -> usize {
        i
    }
    fn a(&self, i: usize) -> usize {
        self.n_int + 1 + i
    }
    fn c(&self, i: usize) -> usize {
        2 * self.n_int + 1 + i
    }
    fn d(&self, i: usize) -> usize {
        3 * self.n_int + 2 + i
    }
    fn len(&self) -> usize {
        4 * self.n_int + 2
    }
}

/// Sparse rows `A x (+ s) = h` under construction.
#[derive(Default)]
struct Rows {
    i: Vec<usize>,
    j: Vec<usize>,
    v: Vec<f64>,
    h: Vec<f64>,
}

impl Rows {
    fn push(&mut self, entries: &[(usize, f64)], h: f64) {
        let r = self.h.len();
        for &(j, v) in entries {
            if v != 0.0 {
                self.i.push(r);
                self.j.push(j);
                self.v.push(v);
            }
        }
        self.h.push(h);
    }
}

/// Path and dynamics at the grid points.
struct Grid {
    dq: Vec<f64>,
    ddq: Vec<f64>,
    m: Vec<f64>,
    c: Vec<f64>,
    g: Vec<f64>,
}

/// The time-optimal parameterisation of `path` under `limits` with the torques of
/// `effects` (see the module docs). Joints with an infinite effort limit have no torque
/// constraint. The returned motion starts and ends at rest and meets every limit on the
/// dense check grid to `opts.tolerance`; otherwise an error says by how much it did not.
pub fn topp<P: Path>(
    model: &Model,
    path: P,
    limits: &super::JointLimits,
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
    effects.validate(model).map_err(TrajectoryError::Invalid)?;
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

    // Tightening (amount subtracted from each limit) per knot (velocity) and per interval
    // (acceleration, torque), and friction at the knots.
    let mut tight_v = vec![0.0; (nn + 1) * n];
    let mut tight_a = vec![0.0; nn * n];
    let mut tight_t = vec![0.0; nn * n];
    let mut fric = vec![0.0; (nn + 1) * n];
    let mut stats = ToppStats {
        segments: nn,
        ..Default::default()
    };
    let lay = Layout { n_int: nn };
    let mut checker = Checker::new(model, n);
    let mut friction_rounds = 0;
    for round in 0..=opts.max_refinements + MAX_FRICTION_ROUNDS {
        let x = solve_socp(
            &lay, &grid, limits, &torque_on, &tight_v, &tight_a, &tight_t, &fric, &ds, &mut stats,
        )?;
        let b: Vec<f64> = (0..=nn).map(|i| x[lay.b(i)].max(0.0)).collect();
        // `a` from `b` so that the rebuilt motion is exactly consistent.
        let a: Vec<f64> = (0..nn).map(|i| (b[i + 1] - b[i]) / (2.0 * ds[i])).collect();
        let t = knot_times(&b, &ds)?;
        // Dense check with the exact dynamics (friction included).
        let report = checker.check(model, effects, &path, limits, &s, &b, &a, opts.check_points);
        stats.max_velocity_ratio = report.ratio[0];
        stats.max_acceleration_ratio = report.ratio[1];
        stats.max_torque_ratio = report.ratio[2];
        let worst = report.ratio.iter().copied().fold(0.0, f64::max);
        // Friction at the new speeds, for the next round; how much it moved.
        let friction_moved = match &effects.friction {
            Some(fr) => update_friction(fr, &grid, &b, limits, &torque_on, &mut fric),
            None => false,
        };
        if worst <= 1.0 + opts.tolerance {
            stats.duration = t[nn];
            stats.wall_time_s = start.elapsed().as_secs_f64();
            return Ok(ToppTrajectory {
                path,
                n,
                s,
                b,
                a,
                t,
                stats,
            });
        }
        if round - friction_rounds == opts.max_refinements {
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
        if friction_moved && friction_rounds < MAX_FRICTION_ROUNDS {
            // Fixed-point step on the friction first: an excess caused by a stale friction
            // estimate must not turn into a permanent tightening.
            friction_rounds += 1;
            continue;
        }
        tighten(
            &report,
            limits,
            &torque_on,
            opts.margin,
            [&mut tight_v, &mut tight_a, &mut tight_t],
        );
    }
    unreachable!("the loop returns on its last round")
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
    limits: &super::JointLimits,
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
    limits: &super::JointLimits,
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
/// margin: velocity at both knots of an interval, acceleration and torque on it.
fn tighten(
    report: &CheckReport,
    limits: &super::JointLimits,
    torque_on: &[bool],
    margin: f64,
    [tight_v, tight_a, tight_t]: [&mut Vec<f64>; 3],
) {
    let n = torque_on.len();
    let nn = tight_a.len() / n.max(1);
    for i in 0..nn {
        for j in 0..n {
            let e = report.excess_v[i * n + j];
            if e > 0.0 {
                let add = e + margin * limits.velocity[j];
                tight_v[i * n + j] += add;
                tight_v[(i + 1) * n + j] += add;
            }
            let e = report.excess_a[i * n + j];
            if e > 0.0 {
                tight_a[i * n + j] += e + margin * limits.acceleration[j];
            }
            let e = report.excess_t[i * n + j];
            if e > 0.0 && torque_on[j] {
                tight_t[i * n + j] += e + margin * limits.effort[j];
            }
        }
    }
}

/// Builds and solves the SOCP; returns `x`.
#[allow(clippy::too_many_arguments)]
fn solve_socp(
    lay: &Layout,
    grid: &Grid,
    limits: &super::JointLimits,
    torque_on: &[bool],
    tight_v: &[f64],
    tight_a: &[f64],
    tight_t: &[f64],
    fric: &[f64],
    ds: &[f64],
    stats: &mut ToppStats,
) -> Result<Vec<f64>, TrajectoryError> {
    let nn = lay.n_int;
    let n = torque_on.len();
    let mut rows = Rows::default();
    // Zero cone: dynamics of b, rest at both ends.
    for (i, dsi) in ds.iter().enumerate() {
        rows.push(
            &[
                (lay.b(i + 1), 1.0),
                (lay.b(i), -1.0),
                (lay.a(i), -2.0 * dsi),
            ],
            0.0,
        );
    }
    rows.push(&[(lay.b(0), 1.0)], 0.0);
    rows.push(&[(lay.b(nn), 1.0)], 0.0);
    let n_zero = rows.h.len();
    // Nonnegative cone: A x ≤ h.
    for i in 0..=nn {
        for j in 0..n {
            let dq = grid.dq[i * n + j];
            if dq != 0.0 {
                let v = (limits.velocity[j] - tight_v[i * n + j]).max(0.0);
                rows.push(&[(lay.b(i), dq * dq)], v * v);
            }
        }
    }
    for i in 0..nn {
        for e in [i, i + 1] {
            for j in 0..n {
                let (dq, ddq) = (grid.dq[e * n + j], grid.ddq[e * n + j]);
                if dq != 0.0 || ddq != 0.0 {
                    let lim = (limits.acceleration[j] - tight_a[i * n + j]).max(0.0);
                    rows.push(&[(lay.a(i), dq), (lay.b(e), ddq)], lim);
                    rows.push(&[(lay.a(i), -dq), (lay.b(e), -ddq)], lim);
                }
                if torque_on[j] {
                    let (m, c) = (grid.m[e * n + j], grid.c[e * n + j]);
                    let g = grid.g[e * n + j] + fric[e * n + j];
                    let lim = (limits.effort[j] - tight_t[i * n + j]).max(0.0);
                    rows.push(&[(lay.a(i), m), (lay.b(e), c)], lim - g);
                    rows.push(&[(lay.a(i), -m), (lay.b(e), -c)], lim + g);
                }
            }
        }
    }
    let n_nonneg = rows.h.len() - n_zero;
    // Second-order cones.
    for i in 0..=nn {
        rows.push(&[(lay.b(i), -1.0)], 1.0);
        rows.push(&[(lay.c(i), -2.0)], 0.0);
        rows.push(&[(lay.b(i), -1.0)], -1.0);
    }
    for i in 0..nn {
        rows.push(
            &[(lay.c(i), -1.0), (lay.c(i + 1), -1.0), (lay.d(i), -1.0)],
            0.0,
        );
        rows.push(&[], 2.0);
        rows.push(
            &[(lay.c(i), -1.0), (lay.c(i + 1), -1.0), (lay.d(i), 1.0)],
            0.0,
        );
    }
    let mut cones: Vec<SupportedConeT<f64>> = vec![ZeroConeT(n_zero), NonnegativeConeT(n_nonneg)];
    cones.extend(std::iter::repeat_n(SecondOrderConeT(3), 2 * nn + 1));
    let nx = lay.len();
    let nrows = rows.h.len();
    let a = CscMatrix::new_from_triplets(nrows, nx, rows.i, rows.j, rows.v);
    let p = CscMatrix::zeros((nx, nx));
    let mut q = vec![0.0; nx];
    for i in 0..nn {
        q[lay.d(i)] = 2.0 * ds[i];
    }
    let settings = DefaultSettings {
        verbose: false,
        max_iter: 300,
        ..Default::default()
    };
    let mut solver = DefaultSolver::new(&p, &q, &a, &rows.h, &cones, settings)
        .map_err(|e| TrajectoryError::Topp(format!("solver setup failed: {e:?}")))?;
    solver.solve();
    let sol = &solver.solution;
    stats.solves += 1;
    stats.solver_iterations += sol.iterations;
    stats.solve_time_s += sol.solve_time;
    match sol.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => Ok(sol.x.clone()),
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            Err(TrajectoryError::Topp(
                "the limits admit no motion along this path (primal infeasible): some torque \
                 limit is below what the path needs even at vanishing speed"
                    .into(),
            ))
        }
        s => Err(TrajectoryError::Topp(format!(
            "the conic solver stopped: {s:?}"
        ))),
    }
}

/// Dense-check results: per interval and joint, the largest excess over each limit, and
/// the largest ratio of each kind (velocity, acceleration, torque).
struct CheckReport {
    excess_v: Vec<f64>,
    excess_a: Vec<f64>,
    excess_t: Vec<f64>,
    ratio: [f64; 3],
}

/// Buffers of the dense check.
struct Checker {
    data: Data,
    q: Vec<f64>,
    dq: Vec<f64>,
    ddq: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    tau: Vec<f64>,
    /// Sampled values of one interval: `(point, kind, joint)`.
    vals: Vec<f64>,
}

/// Sampled maxima at or above this fraction of their limit are refined by a
/// golden-section search between the neighbouring check points.
const REFINE_FROM: f64 = 0.99;

/// The motion on one interval: `s_i`, `Δs`, `b_i`, `a_i`.
#[derive(Clone, Copy)]
struct Interval {
    s: f64,
    ds: f64,
    b: f64,
    a: f64,
}

impl Checker {
    fn new(model: &Model, n: usize) -> Self {
        Checker {
            data: Data::new(model),
            q: vec![0.0; n],
            dq: vec![0.0; n],
            ddq: vec![0.0; n],
            qd: vec![0.0; n],
            qdd: vec![0.0; n],
            tau: vec![0.0; n],
            vals: Vec::new(),
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
    /// the near-active maxima by golden-section search.
    #[allow(clippy::too_many_arguments)]
    fn check<P: Path>(
        &mut self,
        model: &Model,
        effects: &Effects,
        path: &P,
        limits: &super::JointLimits,
        s: &[f64],
        b: &[f64],
        a: &[f64],
        k: usize,
    ) -> CheckReport {
        let n = self.q.len();
        let nn = a.len();
        let mut rep = CheckReport {
            excess_v: vec![0.0; nn * n],
            excess_a: vec![0.0; nn * n],
            excess_t: vec![0.0; nn * n],
            ratio: [0.0; 3],
        };
        let torque = limits.effort.iter().any(|e| e.is_finite());
        let kinds = if torque { 3 } else { 2 };
        let np = k + 2;
        let mut vals = std::mem::take(&mut self.vals);
        vals.resize(np * 3 * n, 0.0);
        let theta = |p: usize| p as f64 / (np - 1) as f64;
        for i in 0..nn {
            let iv = Interval {
                s: s[i],
                ds: s[i + 1] - s[i],
                b: b[i],
                a: a[i],
            };
            for p in 0..np {
                self.eval_at(model, effects, path, iv, theta(p), torque);
                for kind in 0..kinds {
                    for j in 0..n {
                        vals[(p * 3 + kind) * n + j] = self.value(kind, j);
                    }
                }
            }
            for kind in 0..kinds {
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
                        // Golden-section search for the maximum between the neighbours.
                        let (mut lo, mut hi) = (
                            theta(pbest.saturating_sub(1)),
                            theta((pbest + 1).min(np - 1)),
                        );
                        const R: f64 = 0.618_033_988_749_894_9;
                        let mut x1 = hi - R * (hi - lo);
                        let mut x2 = lo + R * (hi - lo);
                        self.eval_at(model, effects, path, iv, x1, kind == 2);
                        let mut f1 = self.value(kind, j);
                        self.eval_at(model, effects, path, iv, x2, kind == 2);
                        let mut f2 = self.value(kind, j);
                        for _ in 0..40 {
                            if f1 > f2 {
                                hi = x2;
                                (x2, f2) = (x1, f1);
                                x1 = hi - R * (hi - lo);
                                self.eval_at(model, effects, path, iv, x1, kind == 2);
                                f1 = self.value(kind, j);
                            } else {
                                lo = x1;
                                (x1, f1) = (x2, f2);
                                x2 = lo + R * (hi - lo);
                                self.eval_at(model, effects, path, iv, x2, kind == 2);
                                f2 = self.value(kind, j);
                            }
                        }
                        best = best.max(f1).max(f2);
                    }
                    let excess = match kind {
                        0 => &mut rep.excess_v,
                        1 => &mut rep.excess_a,
                        _ => &mut rep.excess_t,
                    };
                    excess[i * n + j] = excess[i * n + j].max(best - lim);
                    rep.ratio[kind] = rep.ratio[kind].max(best / lim);
                }
            }
        }
        self.vals = vals;
        rep
    }
}

impl<P: Path> Trajectory for ToppTrajectory<P> {
    fn dof(&self) -> usize {
        self.n
    }

    fn duration(&self) -> f64 {
        *self.t.last().unwrap()
    }

    fn sample(&self, t: f64, q: &mut [f64], qd: &mut [f64], qdd: &mut [f64]) {
        let end = *self.t.last().unwrap_or(&0.0);
        if t < 0.0 || t > end {
            // Held at an end point, at rest (the last interval's deceleration `q' s̈` is
            // one-sided: it must not persist after the end).
            self.sample(t.clamp(0.0, end), q, qd, qdd);
            qd.fill(0.0);
            qdd.fill(0.0);
            return;
        }
        let (i, tau) = super::locate(&self.t, t);
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
}
