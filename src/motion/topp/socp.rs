//! The convex program of one TOPP solve: the variables `b, a, c, d` per knot and
//! interval, the zero, linear and second-order cone rows (dynamics of `b`, rest at the
//! ends, velocity, acceleration and torque limits less their tightening, the time
//! epigraph), and the call to clarabel.

use crate::motion::topp::discretised::Problem;
use crate::motion::topp::topp_options::ToppStats;
use crate::motion::trajectory_error::TrajectoryError;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSolver, IPSolver, NonnegativeConeT, SecondOrderConeT, SolverStatus,
    SupportedConeT, ZeroConeT,
};

/// `x ↦ b, a, c, d` variable indices for `N` intervals.
pub(super) struct Layout {
    pub(super) n_int: usize,
}

impl Layout {
    pub(super) fn b(&self, i: usize) -> usize {
        i
    }
    pub(super) fn a(&self, i: usize) -> usize {
        self.n_int + 1 + i
    }
    pub(super) fn c(&self, i: usize) -> usize {
        2 * self.n_int + 1 + i
    }
    pub(super) fn d(&self, i: usize) -> usize {
        3 * self.n_int + 2 + i
    }
    pub(super) fn len(&self) -> usize {
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

/// Builds and solves the SOCP; returns `x`.
pub(super) fn solve_socp(
    lay: &Layout,
    p: &Problem,
    stats: &mut ToppStats,
) -> Result<Vec<f64>, TrajectoryError> {
    let Problem {
        grid,
        limits,
        torque_on,
        tight_v,
        tight_a,
        tight_t,
        fric,
        ds,
        ..
    } = *p;
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
    push_cones(&mut rows, lay);
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

/// The second-order-cone rows: `c_i ≤ √b_i` as `‖(2c_i, b_i − 1)‖ ≤ b_i + 1`, and
/// `d_i ≥ 1/(c_i + c_{i+1})` as `‖(2, c_i + c_{i+1} − d_i)‖ ≤ c_i + c_{i+1} + d_i`.
fn push_cones(rows: &mut Rows, lay: &Layout) {
    let nn = lay.n_int;
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
}
