//! Position analysis: Newton's method on `Φ(q, s) = 0` for a given input `s`
//! (Haug 1989, §4.3, eq. 4.3.4: `Φ_q(q_k) Δq = −Φ(q_k)`, `q_{k+1} = q_k + Δq`).
//!
//! The step is the minimum-norm solution of the linear system (SVD, see `linalg`), so the
//! iteration still works where `Φ_q` is rank-deficient: redundant constraints (rows that
//! agree), change points and dead centres, where the root is double and the convergence
//! only linear. A backtracking line search on `‖Φ‖` keeps a poor initial guess from
//! diverging, and each step is capped (0.25 rad, 0.25 of the linkage's size) so that a
//! rough guess converges to the nearby assembly mode rather than being thrown into another
//! by one long first step. Which assembly mode the solution lands in is decided by the
//! starting point:
//! the sweep ([`crate::machines::linkage::sweep`]) starts each solve from a prediction along the
//! branch.

use crate::core::least_squares::min_norm_solve;
use crate::machines::linkage::constraints::{jacobian, residual, row_owners, RowOwner};
use crate::machines::linkage::description::Linkage;
use nalgebra::{DMatrix, DVector};

/// Largest angle change per Newton iteration (rad).
const MAX_TURN: f64 = 0.25;
/// Largest translation per Newton iteration, in units of the length scale.
const MAX_SHIFT: f64 = 0.25;

/// Newton gives up after [`STALL_ITERATIONS`] consecutive iterations that leave `‖Φ‖∞`
/// above the accepted residual and reduce it by less than `1 − STALL_RATIO` (a linear
/// convergence to a double root halves it): there is no root nearby.
const STALL_RATIO: f64 = 0.99;
/// See [`STALL_RATIO`].
const STALL_ITERATIONS: usize = 5;

/// Options for [`solve_position`].
#[derive(Clone, Copy, Debug)]
pub struct NewtonOptions {
    /// Iterate until `‖Φ‖∞ ≤ tol · L` (`L` the linkage's length scale, at least 1 m).
    pub tol: f64,
    /// Where the iteration stalls first (rounding near a singular position), accept
    /// `‖Φ‖∞ ≤ accept · L`.
    pub accept: f64,
    /// Iteration limit.
    pub max_iter: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tol: 1e-14,
            accept: 1e-12,
            max_iter: 100,
        }
    }
}

/// A converged position.
#[derive(Clone, Debug)]
pub struct PositionSolution {
    /// Coordinates.
    pub q: DVector<f64>,
    /// Newton iterations used.
    pub iterations: usize,
    /// `‖Φ(q, s)‖∞`.
    pub residual: f64,
}

/// The linkage does not close at that input from that guess.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the linkage does not close at input {input}: {what} is off by {residual:.3e} after {iterations} Newton iterations")]
pub struct AssemblyError {
    /// The input value.
    pub input: f64,
    /// The joint (or `driver`) with the largest remaining residual.
    pub what: String,
    /// Index of that joint in [`Linkage::joints`] (`None` for the driver).
    pub joint: Option<usize>,
    /// `‖Φ‖∞` at the best point found.
    pub residual: f64,
    /// Iterations used.
    pub iterations: usize,
}

/// Solves `Φ(q, s) = 0` by Newton's method from `q0`.
pub fn solve_position(
    l: &Linkage,
    q0: &DVector<f64>,
    s: f64,
    opts: &NewtonOptions,
) -> Result<PositionSolution, AssemblyError> {
    let scale = l.length_scale();
    let tol = opts.tol * scale.max(1.0);
    let mut q = q0.clone();
    let mut phi = DVector::zeros(l.nrows());
    let mut trial_phi = DVector::zeros(l.nrows());
    let mut jac = DMatrix::zeros(l.nrows(), l.ncoords());
    residual(l, &q, s, &mut phi);
    let mut norm = phi.amax();
    let accept = opts.accept * scale.max(1.0);
    let mut it = 0;
    let mut stalled = 0;
    while it < opts.max_iter {
        if norm <= tol {
            break;
        }
        let before = norm;
        it += 1;
        jacobian(l, &q, &mut jac);
        let mut step = min_norm_solve(&jac, &(-&phi), None).x;
        // Trust region: at most MAX_TURN rad and MAX_SHIFT · L per iteration, so that a
        // rough guess is not thrown into another assembly mode by one long first step.
        let mut worst: f64 = 0.0;
        for (k, x) in step.iter().enumerate() {
            let lim = if k % 3 == 2 {
                MAX_TURN
            } else {
                MAX_SHIFT * scale
            };
            worst = worst.max(x.abs() / lim);
        }
        if worst > 1.0 {
            step /= worst;
        }
        // Backtracking on ‖Φ‖∞ (full steps near the root, where Newton is quadratic).
        let mut alpha = 1.0;
        let mut accepted = false;
        for _ in 0..30 {
            let trial = &q + &step * alpha;
            residual(l, &trial, s, &mut trial_phi);
            let tn = trial_phi.amax();
            if tn < norm || (alpha == 1.0 && tn <= 2.0 * tol) {
                q = trial;
                std::mem::swap(&mut phi, &mut trial_phi);
                norm = tn;
                accepted = true;
                break;
            }
            alpha *= 0.5;
        }
        if !accepted {
            break;
        }
        // Far from converged and hardly moving: no root nearby (past a limit position).
        if norm > accept && norm > STALL_RATIO * before {
            stalled += 1;
            if stalled >= STALL_ITERATIONS {
                break;
            }
        } else {
            stalled = 0;
        }
    }
    // One polishing step once converged (cheap, and takes the residual to rounding).
    if norm <= tol && norm > 0.0 {
        jacobian(l, &q, &mut jac);
        let trial = &q + min_norm_solve(&jac, &(-&phi), None).x;
        residual(l, &trial, s, &mut trial_phi);
        if trial_phi.amax() < norm {
            q = trial;
            norm = trial_phi.amax();
        }
    }
    if norm <= accept {
        return Ok(PositionSolution {
            q,
            iterations: it,
            residual: norm,
        });
    }
    let owners = row_owners(l);
    let worst = phi.iamax();
    let (what, joint) = match &owners[worst] {
        RowOwner::Joint(k, _) => (format!("joint '{}'", l.joints[*k].name()), Some(*k)),
        RowOwner::Driver => ("the driver".to_string(), None),
    };
    Err(AssemblyError {
        input: s,
        what,
        joint,
        residual: norm,
        iterations: it,
    })
}
