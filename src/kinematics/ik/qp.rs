//! Velocity-level IK as a quadratic program (clarabel), with joint position and velocity
//! limits as inequalities and a secondary goal in the null space of the task.
//!
//! Each step solves, with `e` the (clipped) pose error and `J` the world-aligned
//! Jacobian (as in [`crate::kinematics::ik::numeric`]):
//!
//! 1. task: `min ½‖J Δq − e‖²_W + ½ ρ ‖Δq‖²`
//!    s.t. `q_lo − q ≤ Δq ≤ q_hi − q` and `|Δq| ≤ v_max Δt`;
//! 2. secondary (only when the arm has more joints than task rows and a goal is set):
//!    `min ½‖Δq − Δq_s‖²` s.t. `J Δq = J Δq₁` (the task velocity of stage 1 is kept
//!    exactly: the secondary goal acts in the null space) and the same bounds.
//!    `Δq_s = k (q_home − q)` ("stay near home") or `k (q_mid − q)/range`
//!    (Liégeois' joint-range criterion's gradient, range-scaled: "stay away from limits").
//!
//! Iterating the step is a position IK that never leaves the limits; one step is the
//! velocity command of a resolved-rate controller. [`qp_ik`] pursues the secondary goal
//! (its pull capped at 0.1 rad per step) during the first half of its step budget, then
//! polishes the task alone. The QP solver allocates: this is a
//! slower, more general method than [`crate::kinematics::ik::numeric`] (see BENCHMARKS.md).

use crate::core::spatial::Se3;
use crate::kinematics::ik::numeric::{rotation_log, IkResult, IkStatus};
use crate::kinematics::{compute_joint_jacobians, frame_jacobian, frame_placement, Expressed};
use crate::model::data::Data;
use crate::model::Model;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SolverStatus, SupportedConeT,
    ZeroConeT,
};
use nalgebra::{DMatrix, DVector};
use std::time::Instant;

/// A secondary objective for redundant arms.
#[derive(Clone, Debug, PartialEq)]
pub enum Secondary {
    /// None.
    None,
    /// Stay near a home configuration.
    Home(Vec<f64>),
    /// Stay away from the joint limits.
    AwayFromLimits,
}

/// Options of the QP IK.
#[derive(Clone, Debug)]
pub struct QpIkOptions {
    /// Position-only task.
    pub position_only: bool,
    /// Position tolerance (m).
    pub tol_position: f64,
    /// Rotation tolerance (rad).
    pub tol_rotation: f64,
    /// Maximum steps.
    pub max_steps: usize,
    /// Step duration for the velocity limits (s).
    pub dt: f64,
    /// Largest position / rotation error fed to one step (m, rad).
    pub max_error: f64,
    /// Regularisation `ρ`.
    pub damping: f64,
    /// Secondary objective and its gain.
    pub secondary: Secondary,
    /// Gain of the secondary objective.
    pub secondary_gain: f64,
    /// Weight of the rotation rows (m/rad).
    pub rotation_weight: f64,
}

impl Default for QpIkOptions {
    fn default() -> Self {
        Self {
            position_only: false,
            tol_position: 1e-6,
            tol_rotation: 1e-6,
            max_steps: 200,
            dt: 0.05,
            max_error: 0.2,
            damping: 1e-6,
            secondary: Secondary::None,
            secondary_gain: 0.5,
            rotation_weight: 0.5,
        }
    }
}

/// Dense matrix → clarabel CSC (upper triangle only when `triu`).
fn csc(m: &DMatrix<f64>, triu: bool) -> CscMatrix<f64> {
    let (rows, cols) = m.shape();
    let mut colptr = Vec::with_capacity(cols + 1);
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    colptr.push(0);
    for c in 0..cols {
        for r in 0..rows {
            if triu && r > c {
                break;
            }
            let v = m[(r, c)];
            if v != 0.0 {
                rowval.push(r);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    CscMatrix::new(rows, cols, colptr, rowval, nzval)
}

/// `min ½ xᵀ P x + qᵀ x` s.t. `A_eq x = b_eq`, `lo ≤ x ≤ hi`. `None` if not solved.
fn solve_qp(
    p: &DMatrix<f64>,
    q: &[f64],
    eq: Option<(&DMatrix<f64>, &[f64])>,
    lo: &[f64],
    hi: &[f64],
) -> Option<Vec<f64>> {
    let n = q.len();
    let neq = eq.map_or(0, |(a, _)| a.nrows());
    let mut a = DMatrix::zeros(neq + 2 * n, n);
    let mut b = Vec::with_capacity(neq + 2 * n);
    if let Some((ae, be)) = eq {
        a.rows_mut(0, neq).copy_from(ae);
        b.extend_from_slice(be);
    }
    for i in 0..n {
        a[(neq + i, i)] = 1.0;
        b.push(hi[i]);
    }
    for i in 0..n {
        a[(neq + n + i, i)] = -1.0;
        b.push(-lo[i]);
    }
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    if neq > 0 {
        cones.push(ZeroConeT(neq));
    }
    cones.push(NonnegativeConeT(2 * n));
    // Tight tolerances: IK needs Δq accurate far below the default 1e-8 to converge to
    // 1e-9 and beyond when a bound is active.
    let settings = DefaultSettings {
        verbose: false,
        tol_gap_abs: 1e-12,
        tol_gap_rel: 1e-12,
        tol_feas: 1e-12,
        tol_ktratio: 1e-10,
        max_iter: 100,
        ..Default::default()
    };
    let mut solver =
        DefaultSolver::new(&csc(p, true), q, &csc(&a, false), &b, &cones, settings).ok()?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => Some(solver.solution.x.clone()),
        _ => None,
    }
}

/// One QP step at `q` towards `target`; returns `Δq` (inside the limits), or `None` when
/// the QP could not be solved.
pub fn qp_step(
    model: &Model,
    data: &mut Data,
    link: usize,
    target: &Se3,
    q: &[f64],
    opts: &QpIkOptions,
) -> Option<Vec<f64>> {
    let n = model.nv;
    let rows = if opts.position_only { 3 } else { 6 };
    crate::kinematics::forward_kinematics(model, data, q);
    let cur = frame_placement(model, data, link);
    let mut e = DVector::zeros(rows);
    let ep = target.trans - cur.trans;
    let er = rotation_log(&(target.rot * cur.rot.transpose()));
    let clip = |v: crate::core::spatial::Vec3| {
        let nrm = v.norm();
        if nrm > opts.max_error {
            v * (opts.max_error / nrm)
        } else {
            v
        }
    };
    let (ep, er) = (clip(ep), clip(er));
    for i in 0..3 {
        e[i] = ep[i];
        if rows == 6 {
            e[3 + i] = er[i] * opts.rotation_weight;
        }
    }
    let mut jfull = DMatrix::zeros(6, n);
    compute_joint_jacobians(model, data, q);
    frame_jacobian(model, data, link, Expressed::WorldAligned, &mut jfull);
    let mut j = jfull.rows(0, rows).into_owned();
    if rows == 6 {
        for i in 3..6 {
            for c in 0..n {
                j[(i, c)] *= opts.rotation_weight;
            }
        }
    }
    let mut p = j.transpose() * &j;
    for i in 0..n {
        p[(i, i)] += opts.damping;
    }
    let lin: Vec<f64> = (-(j.transpose() * &e)).iter().copied().collect();
    let (mut lo, mut hi) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..n {
        let vmax = model.velocity_limit[k] * opts.dt;
        lo[k] = (model.lower[k] - q[k]).max(-vmax);
        hi[k] = (model.upper[k] - q[k]).min(vmax);
        if lo[k] > hi[k] {
            // q outside its limits: step straight back towards them.
            let mid = 0.5 * (lo[k] + hi[k]);
            lo[k] = mid;
            hi[k] = mid;
        }
    }
    let dq1 = solve_qp(&p, &lin, None, &lo, &hi)?;
    if n <= rows || opts.secondary == Secondary::None {
        return Some(dq1);
    }
    let target_dq: Vec<f64> = match &opts.secondary {
        Secondary::Home(home) => (0..n)
            .map(|k| opts.secondary_gain * (home[k] - q[k]))
            .collect(),
        Secondary::AwayFromLimits => (0..n)
            .map(|k| {
                let (l, u) = model.sampling_bounds(k);
                let range = (u - l).max(1e-9);
                opts.secondary_gain * (0.5 * (l + u) - q[k]) / range
            })
            .collect(),
        Secondary::None => unreachable!(),
    };
    // Cap the null-space pull: its second-order effect on the task grows with its square.
    let norm = target_dq.iter().map(|x| x * x).sum::<f64>().sqrt();
    let cap = 0.1;
    let target_dq: Vec<f64> = if norm > cap {
        target_dq.iter().map(|x| x * cap / norm).collect()
    } else {
        target_dq
    };
    let task = &j * DVector::from_column_slice(&dq1);
    let p2 = DMatrix::identity(n, n);
    let lin2: Vec<f64> = target_dq.iter().map(|x| -x).collect();
    let beq: Vec<f64> = task.iter().copied().collect();
    Some(solve_qp(&p2, &lin2, Some((&j, &beq)), &lo, &hi).unwrap_or(dq1))
}

/// Position IK by iterating [`qp_step`] from `q0`.
pub fn qp_ik(model: &Model, link: usize, target: &Se3, q0: &[f64], opts: &QpIkOptions) -> IkResult {
    let start = Instant::now();
    let mut data = Data::new(model);
    let mut q = q0.to_vec();
    for (k, x) in q.iter_mut().enumerate() {
        *x = x.clamp(model.lower[k], model.upper[k]);
    }
    let errors = |q: &[f64], data: &mut Data| {
        crate::kinematics::forward_kinematics(model, data, q);
        let cur = frame_placement(model, data, link);
        let ep = (target.trans - cur.trans).norm();
        let er = if opts.position_only {
            0.0
        } else {
            rotation_log(&(target.rot * cur.rot.transpose())).norm()
        };
        (ep, er)
    };
    let mut steps = 0;
    let (mut ep, mut er) = errors(&q, &mut data);
    let mut stalled = false;
    // The secondary goal is pursued during the first half of the budget; then the task is
    // polished alone (a null-space pull on a curved self-motion manifold can otherwise
    // hold the task error at the size of the pull's second-order effect).
    let polish = QpIkOptions {
        secondary: Secondary::None,
        ..opts.clone()
    };
    while steps < opts.max_steps && !(ep <= opts.tol_position && er <= opts.tol_rotation) {
        steps += 1;
        let o = if steps <= opts.max_steps / 2 {
            opts
        } else {
            &polish
        };
        let Some(dq) = qp_step(model, &mut data, link, target, &q, o) else {
            stalled = true;
            break;
        };
        let norm: f64 = dq.iter().map(|x| x * x).sum::<f64>().sqrt();
        for (x, d) in q.iter_mut().zip(&dq) {
            *x += d;
        }
        for (k, x) in q.iter_mut().enumerate() {
            *x = x.clamp(model.lower[k], model.upper[k]);
        }
        (ep, er) = errors(&q, &mut data);
        if norm < 1e-13 {
            stalled = true;
            break;
        }
    }
    let status = if ep <= opts.tol_position && er <= opts.tol_rotation {
        IkStatus::Converged
    } else if stalled {
        IkStatus::Unreachable
    } else {
        IkStatus::BestEffort
    };
    IkResult {
        q,
        status,
        position_error: ep,
        rotation_error: er,
        iterations: steps,
        restarts: 0,
        time_us: start.elapsed().as_secs_f64() * 1e6,
    }
}
