//! Every call from the bindings into `armsim::dynamics`, in one place (the dynamics take
//! gravity from `model.gravity`; a change of those signatures touches only this file).

use armsim::dynamics::{self, SingularMassMatrix};
use armsim::nalgebra::DMatrix;
use armsim::{Data, Model};

/// Inverse dynamics `τ = M(q) a + C(q, v) v + g(q)`.
pub fn rnea<'a>(m: &Model, d: &'a mut Data, q: &[f64], v: &[f64], a: &[f64]) -> &'a [f64] {
    dynamics::rnea(m, d, q, v, a)
}

/// Generalised gravity `g(q)`.
pub fn gravity<'a>(m: &Model, d: &'a mut Data, q: &[f64]) -> &'a [f64] {
    dynamics::gravity_torque(m, d, q)
}

/// Nonlinear effects `h(q, v) = C(q, v) v + g(q)`.
pub fn nonlinear_effects<'a>(m: &Model, d: &'a mut Data, q: &[f64], v: &[f64]) -> &'a [f64] {
    dynamics::bias(m, d, q, v)
}

/// Forward dynamics `q̈` (ABA; CRBA + Cholesky with mimic joints).
pub fn aba<'a>(
    m: &Model,
    d: &'a mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'a [f64], SingularMassMatrix> {
    dynamics::forward_dynamics(m, d, q, v, tau)
}

/// The joint-space mass matrix (full, symmetric).
pub fn crba<'a>(m: &Model, d: &'a mut Data, q: &[f64]) -> &'a DMatrix<f64> {
    dynamics::crba(m, d, q)
}
