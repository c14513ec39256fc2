//! Velocity and acceleration analysis through the constraint Jacobian (Haug 1989, §§3.1,
//! 4.4, eqs. 3.1.9 and 3.1.11): differentiating `Φ(q, s(t)) = 0` once and twice gives
//!
//! ```text
//! Φ_q q̇ = −Φ_t = ν,        Φ_q q̈ = γ(q, q̇, s̈).
//! ```
//!
//! Both are solved by the minimum-norm SVD solve, optionally nearest to a reference
//! (`x = x_ref + Φ_q⁺ (b − Φ_q x_ref)`): where `Φ_q` is singular but the right side is
//! consistent (a change point, where two branches cross), the reference picks the
//! branch's value; [`crate::machines::linkage::sweep`] refines that by the limit along the branch.
//! The consistency residual `‖Φ_q x − b‖` tells a consistent singular system (finite motion)
//! from a locked one (the input cannot move there).
//!
//! With `ṡ = 1, s̈ = 0` the solutions are the path derivatives `q' = dq/ds` and
//! `q'' = d²q/ds²`; for any input motion `q̇ = q' ṡ`, `q̈ = q'' ṡ² + q' s̈`, because only
//! the driver row depends on `s` (and linearly).

use crate::core::least_squares::{min_norm_solve, Factorization, MinNormSolve};
use crate::machines::linkage::constraints::{gamma, jacobian, jacobian_mat, velocity_rhs};
use crate::machines::linkage::description::Linkage;
use nalgebra::{DMatrix, DVector};

/// Solves `Φ_q q̇ = −Φ_t` for input rate `sd`.
pub fn solve_velocity(
    l: &Linkage,
    q: &DVector<f64>,
    sd: f64,
    reference: Option<&DVector<f64>>,
) -> MinNormSolve {
    let mut jac = DMatrix::zeros(l.nrows(), l.ncoords());
    jacobian(l, q, &mut jac);
    min_norm_solve(&jac, &velocity_rhs(l, sd), reference)
}

/// Solves `Φ_q q̈ = γ(q, q̇, s̈)`.
pub fn solve_acceleration(
    l: &Linkage,
    q: &DVector<f64>,
    qd: &DVector<f64>,
    sdd: f64,
    reference: Option<&DVector<f64>>,
) -> MinNormSolve {
    let mut jac = DMatrix::zeros(l.nrows(), l.ncoords());
    jacobian(l, q, &mut jac);
    let mut g = DVector::zeros(l.nrows());
    gamma(l, q, qd, sdd, &mut g);
    min_norm_solve(&jac, &g, reference)
}

/// Path derivatives `(q', q'')` at `q` (see the module docs), each nearest to its
/// reference when given.
pub fn path_derivatives(
    l: &Linkage,
    q: &DVector<f64>,
    reference: Option<(&DVector<f64>, &DVector<f64>)>,
) -> (MinNormSolve, MinNormSolve) {
    let jac = jacobian_mat(l, q);
    path_derivatives_with(l, q, &jac, &Factorization::new(&jac), reference)
}

/// [`path_derivatives`] with `Φ_q` and its factorization given (one SVD for both solves).
pub fn path_derivatives_with(
    l: &Linkage,
    q: &DVector<f64>,
    jac: &DMatrix<f64>,
    factor: &Factorization,
    reference: Option<(&DVector<f64>, &DVector<f64>)>,
) -> (MinNormSolve, MinNormSolve) {
    let v = factor.solve(jac, &velocity_rhs(l, 1.0), reference.map(|r| r.0));
    let mut g = DVector::zeros(l.nrows());
    gamma(l, q, &v.x, 0.0, &mut g);
    let a = factor.solve(jac, &g, reference.map(|r| r.1));
    (v, a)
}
