//! Forward dynamics through the mass matrix: `M(q) q̈ = τ − h(q, q̇)` with `M` from
//! [`super::crba`] and `h` from [`super::rnea`], solved by an in-place Cholesky
//! factorisation `M = L Lᵀ` (no allocation). Works with mimic joints (it uses the
//! projected `M` and `h`); [`forward_dynamics`] picks ABA when the model allows it.

use super::{bias, crba};
use crate::data::Data;
use crate::linalg::{cholesky_in_place, cholesky_solve_in_place, SingularMassMatrix};
use crate::model::Model;
use crate::spatial::Vec3;

/// `q̈` by CRBA + Cholesky into `data.qdd`.
pub fn forward_dynamics_crba<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: &Vec3,
) -> Result<&'a [f64], SingularMassMatrix> {
    bias(model, data, q, qd, gravity);
    for ((out, t), h) in data.qdd.iter_mut().zip(tau).zip(&data.tau) {
        *out = t - h;
    }
    crba(model, data, q);
    data.chol.copy_from(&data.mass);
    cholesky_in_place(&mut data.chol)?;
    cholesky_solve_in_place(&data.chol, &mut data.qdd);
    Ok(&data.qdd)
}

/// `q̈`: ABA when every body has its own coordinate, CRBA + Cholesky with mimic joints
/// (the dispatcher of the effect-aware [`super::forward_dynamics_with`]; a non-finite
/// result is an error either way).
pub fn forward_dynamics<'a>(
    model: &Model,
    data: &'a mut Data,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    gravity: &Vec3,
) -> Result<&'a [f64], SingularMassMatrix> {
    super::effects::forward_rigid(model, data, Some(gravity), q, qd, tau)
}
